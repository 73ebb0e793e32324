// SPDX-License-Identifier: MIT
// What the QPU front end and the candidate warper of one detector share: one device (the
// real GPU or the emulator, opened once and never re-created) and the frame both read.
// A frame in a dma-buf is read in place: imported once per buffer (runtime::GpuDevice's
// vcsm-cma import on the GPU; on the emulator the fd mmapped and mapped into its bus space);
// otherwise, as the fallback, copied once into a buffer with 4-aligned rows, with the
// reason kept for the caller's one debug line.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string_view>
#include <type_traits>

#include <sys/mman.h>
#include <sys/stat.h>

#include "emu/device.hpp"
#include "frappe/candidate_warp.h"
#include "frappe/image.h"
#include "frontend/emulator.hpp"
#include "frontend/vc4_front_end.hpp"
#include "runtime/import_cache.hpp"
#if FRAPPE_VC4_HAVE_RUNTIME
#include "runtime/gpu_device.hpp"
#endif

namespace frappe::vc4 {

// Where the QPUs read the frame: row y at bus + y * stride (stride a multiple of 4).
struct FrameSource {
	uint32_t bus = 0;
	uint32_t stride = 0;
};

// What a QPU front end's or warper's context holds, for tests and logs.
struct ContextInfo {
	const void *context = nullptr;   // equal for a front end and a warper sharing one device
	std::size_t imports = 0;         // dma-bufs imported now (cached)
	std::size_t copy_bytes = 0;      // bytes of the last frame copied (front end + warp)
	std::string_view copy_reason;    // why they were copied; empty when read in place
	uint64_t total_copy_bytes = 0;   // bytes of all frames copied since the context opened
	uint64_t device_bytes = 0;       // GPU memory the device holds (its buffers, not imports)
};
template <class Device>
class QpuContext {
public:
	using Buffer = typename Device::Buffer;
	static constexpr bool kEmulated = std::is_same_v<Device, emu::Device>;

	QpuContext(std::unique_ptr<Device> device, const FrontEndOptions &options)
		: device_(std::move(device)), options_(options)
	{
	}
	~QpuContext()
	{
		if constexpr (kEmulated)
			mapped_.clear([this](Mapped &m) { unmap(m); });
	}
	QpuContext(const QpuContext &) = delete;
	QpuContext &operator=(const QpuContext &) = delete;

	Device &device() { return *device_; }
	const FrontEndOptions &options() const { return options_; }

	// A new frame: count its copies from zero. The frames staged before stay staged for
	// their warps (a pipeline warps frame N after staging frame N+1).
	void beginFrame() { copy_bytes_ = 0; }

	// A frame the front end runs without the QPUs: an earlier staging of a buffer at the
	// same address must not stand for it.
	void forget(const ImageView &image)
	{
		for (Staged &st : staged_)
			st.valid = st.valid && !same(st.image, image);
	}

	// The frame as the QPUs read it. The front end stages each frame (`remember`: always
	// afresh, as a recycled buffer may hold new pixels at the same address); the warper
	// then finds it among the last kStaged staged frames and reads it without a second
	// import or copy.
	FrameSource frame(const ImageView &image, bool remember)
	{
		if (!remember) {
			// Newest first: an older entry at the same address is a frame since freed.
			for (int k = 1; k <= kStaged; ++k) {
				const Staged &st = staged_[(next_ + kStaged - k) % kStaged];
				if (st.valid && same(st.image, image))
					return st.source;
			}
		} else {
			forget(image);
		}
		// The oldest staged frame's place (or, for a frame never staged, the warper's own).
		Staged &st = remember ? staged_[next_] : unstaged_;
		if (remember)
			next_ = (next_ + 1) % kStaged;
		st.valid = false;
		FrameSource src;
		if (!inPlace(image, src))
			src = copy(image, st);
		if (remember) {
			st.image = image;
			st.source = src;
			st.valid = true;
		}
		return src;
	}

	// Bytes copied from the frames into GPU memory since beginFrame(), and why (empty when
	// the QPUs read the frame in place).
	std::size_t copyBytes() const { return copy_bytes_; }
	std::string_view copyReason() const { return copy_bytes_ ? std::string_view(reason_) : std::string_view(); }
	ContextInfo info() const
	{
		return {this, imports(), copyBytes(), copyReason(), total_copy_bytes_, device_->allocatedBytes()};
	}
	std::size_t imports() const
	{
		if constexpr (kEmulated)
			return mapped_.size();
		else
			return device_->imports();
	}

private:
	struct Imported {
		uint32_t bus = 0;
		uint64_t bytes = 0;
	};

	template <class... Args>
	void because(const char *format, Args... args)
	{
		std::snprintf(reason_, sizeof(reason_), format, args...);
	}

	bool inPlace(const ImageView &image, FrameSource &src)
	{
		if (image.dmabuf_fd < 0) {
			because("the frame is in system memory, not in a dma-buf");
			return false;
		}
		if (image.stride % 4 != 0 || image.dmabuf_offset % 4 != 0) {
			because("the frame's stride (%d bytes) or offset in its dma-buf (%zu) is not a multiple of 4, "
			        "as the QPUs' row gathers need",
			        image.stride, image.dmabuf_offset);
			return false;
		}
		Imported im;
		if (!import(image.dmabuf_fd, im))
			return false;
		const uint64_t need = image.dmabuf_offset + uint64_t(image.stride) * uint64_t(image.height);
		if (need > im.bytes) {
			because("the frame's dma-buf (%llu bytes) is smaller than the frame (%llu bytes from offset %zu)",
			        static_cast<unsigned long long>(im.bytes), static_cast<unsigned long long>(need),
			        image.dmabuf_offset);
			return false;
		}
		src = {im.bus + static_cast<uint32_t>(image.dmabuf_offset), static_cast<uint32_t>(image.stride)};
		return true;
	}

	// Frames staged at once: the newest and the two before it, so that a pipeline of up to
	// three frames in flight (frappe::Pipeline's stages) warps each without a second copy.
	static constexpr int kStaged = 3;
	struct Staged {
		ImageView image;
		FrameSource source;
		Buffer staging; // its copy, when it needed one (grows, never per frame)
		uint32_t staging_bytes = 0;
		bool valid = false;
	};

	static bool same(const ImageView &a, const ImageView &b)
	{
		return a.data == b.data && a.width == b.width && a.height == b.height && a.stride == b.stride &&
		       a.dmabuf_fd == b.dmabuf_fd && a.dmabuf_offset == b.dmabuf_offset;
	}

	// The fallback: the frame copied once into the staged place's buffer, rows 4-aligned.
	FrameSource copy(const ImageView &image, Staged &st)
	{
		const uint32_t stride = (static_cast<uint32_t>(image.width) + 3) & ~3u;
		const uint32_t bytes = stride * static_cast<uint32_t>(image.height) + 64;
		if (bytes > st.staging_bytes) {
			if (st.staging_bytes)
				device_->release(st.staging);
			st.staging = device_->alloc(bytes);
			st.staging_bytes = bytes;
		}
		for (int y = 0; y < image.height; ++y)
			std::memcpy(st.staging.cpu.data() + static_cast<std::size_t>(y) * stride, image.row(y),
			            static_cast<std::size_t>(image.width));
		const std::size_t copied = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
		copy_bytes_ += copied;
		total_copy_bytes_ += copied;
		return {st.staging.bus, stride};
	}

	// The frame's dma-buf as the QPUs see it, imported once per buffer; false with the
	// reason set when it cannot be (a refusal costs nothing more on later frames).
	bool import(int fd, Imported &out)
	{
		if constexpr (kEmulated) {
			// The emulator reads host memory: the dma-buf mmapped once and mapped in place.
			struct stat st;
			if (::fstat(fd, &st) != 0) {
				because("the frame's dma-buf fd %d cannot be fstat'ed", fd);
				return false;
			}
			const runtime::FileId id{static_cast<uint64_t>(st.st_dev), static_cast<uint64_t>(st.st_ino),
			                         static_cast<uint64_t>(st.st_size)};
			if (const Mapped *hit = mapped_.find(id)) {
				out = {hit->bus, hit->bytes};
				return true;
			}
			void *p = st.st_size > 0 ? ::mmap(nullptr, static_cast<std::size_t>(st.st_size), PROT_READ, MAP_SHARED, fd, 0)
			                         : MAP_FAILED;
			if (p == MAP_FAILED) {
				because("the frame's dma-buf fd %d cannot be mapped", fd);
				return false;
			}
			Mapped m{0, p, static_cast<uint64_t>(st.st_size)};
			try {
				m.bus = device_->importExternal({static_cast<uint8_t *>(p), static_cast<std::size_t>(m.bytes)}).bus;
			} catch (const std::exception &e) {
				::munmap(p, static_cast<std::size_t>(m.bytes));
				because("the frame's dma-buf could not be mapped into the emulator: %s", e.what());
				return false;
			}
			mapped_.add(id, m, [this](Mapped &old) { unmap(old); });
			out = {m.bus, m.bytes};
			return true;
		} else {
#if FRAPPE_VC4_HAVE_RUNTIME
			std::string_view why;
			const auto *im = device_->tryImportDmabuf(fd, why);
			if (!im) {
				because("the frame's dma-buf could not be imported: %.*s", static_cast<int>(why.size()), why.data());
				return false;
			}
			out = {im->bus, im->bytes};
			return true;
#else
			because("the frame's dma-buf fd %d cannot be imported without the runtime", fd);
			return false;
#endif
		}
	}

	struct Mapped {
		uint32_t bus = 0;
		void *map = nullptr;
		uint64_t bytes = 0;
	};
	void unmap(Mapped &m)
	{
		device_->release(Buffer{m.bus, {}});
		::munmap(m.map, static_cast<std::size_t>(m.bytes));
	}

	std::unique_ptr<Device> device_;
	FrontEndOptions options_;
	runtime::ImportCache<Mapped> mapped_; // emulator only
	Staged staged_[kStaged];
	int next_ = 0;
	Staged unstaged_; // a frame the warper was given that no front end staged
	std::size_t copy_bytes_ = 0;
	uint64_t total_copy_bytes_ = 0;
	char reason_[256] = {};
};

// A context on the emulator: its memory arena holds code and uniforms; larger buffers
// (gradient planes, frames) are regions of their own, released when the geometry changes.
inline std::shared_ptr<QpuContext<emu::Device>> makeEmuContext(const FrontEndOptions &options)
{
	return std::make_shared<QpuContext<emu::Device>>(openEmulator(options, 3u << 20), options);
}

// The front end and the warper on a shared context (one device per detector).
std::unique_ptr<frappe::FrontEnd> makeFrontEnd(std::shared_ptr<QpuContext<emu::Device>> context);
std::unique_ptr<frappe::CandidateWarper> makeWarper(std::shared_ptr<QpuContext<emu::Device>> context);

#if FRAPPE_VC4_HAVE_RUNTIME
// A context on the real GPU through `os` (a fake kernel in tests); throws RuntimeError
// with the probe's reason when the GPU cannot be used.
inline std::shared_ptr<QpuContext<runtime::GpuDevice>> makeGpuContext(runtime::Os &os, runtime::DeviceOptions options)
{
	return std::make_shared<QpuContext<runtime::GpuDevice>>(std::make_unique<runtime::GpuDevice>(os, std::move(options)),
	                                                        FrontEndOptions{.emulate = false});
}
std::unique_ptr<frappe::FrontEnd> makeFrontEnd(std::shared_ptr<QpuContext<runtime::GpuDevice>> context);
std::unique_ptr<frappe::CandidateWarper> makeWarper(std::shared_ptr<QpuContext<runtime::GpuDevice>> context);
#endif

// False when `front_end` / `warper` is not a QPU one.
bool contextInfo(const frappe::FrontEnd &front_end, ContextInfo &out);
bool contextInfo(const frappe::CandidateWarper &warper, ContextInfo &out);

// contextInfo() for the first of the classes `Qpu...` that `object` is.
template <class... Qpu, class Base>
bool contextInfoOf(const Base &object, ContextInfo &out)
{
	auto one = [&](const auto *qpu) {
		if (qpu)
			out = qpu->context().info();
		return qpu != nullptr;
	};
	return (one(dynamic_cast<const Qpu *>(&object)) || ...);
}

} // namespace frappe::vc4
