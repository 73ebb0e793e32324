// SPDX-License-Identifier: MIT
#include "frontend/vc4_warper.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "emu/device.hpp"
#include "frontend/emulator.hpp"
#include "kernels/warp.hpp"
#include "kernels/warp_reference.hpp"
#if FRAPPE_VC4_HAVE_RUNTIME
#include "runtime/gpu_device.hpp"
#endif

namespace frappe::vc4 {

namespace {

constexpr unsigned kPrograms = 12;
/* Per program: 7 words, then 12 a candidate for up to ceil(32 / 12) = 3 candidates. */
constexpr uint32_t kUniformBytes = 4 * (kernels::kWarpProgramUniforms + 3 * kernels::kWarpCandidateUniforms);
constexpr uint32_t kOutputBytes = kernels::kWarpOutputBytes * kernels::kWarpMaxCandidates;

uint32_t roundUp(uint32_t v, uint32_t m) { return (v + m - 1) / m * m; }

/* The emulator: one device, re-created when a larger frame arrives. */
struct EmuTarget {
	using Device = emu::Device;
	using Job = emu::Job;
	FrontEndOptions options;
	std::unique_ptr<emu::Device> device;

	static const char *name() { return "vc4-emu"; }
	Device &open(uint32_t bytes)
	{
		device = openEmulator(options, bytes);
		return *device;
	}
	void run(std::span<const Job> jobs) { runOnEmulator(*device, jobs, options); }
};

#if FRAPPE_VC4_HAVE_RUNTIME
/* The real GPU: buffers released and allocated again when a larger frame arrives. */
struct GpuTarget {
	using Device = runtime::GpuDevice;
	using Job = runtime::Job;
	std::unique_ptr<runtime::GpuDevice> device;
	std::vector<Device::Buffer> owned;

	static const char *name() { return "vc4"; }
	Device &open(uint32_t)
	{
		if (!device)
			device = std::make_unique<runtime::GpuDevice>();
		for (const auto &b : owned)
			device->release(b);
		owned.clear();
		return *device;
	}
	void run(std::span<const Job> jobs) { device->wait(device->launch(jobs)); }
};
#endif

template <class Target>
class QpuWarper final : public CandidateWarper {
public:
	using Device = typename Target::Device;
	using Job = typename Target::Job;

	explicit QpuWarper(Target target) : target_(std::move(target)), program_(kernels::warpKernel()),
					    cpu_(makeCpuWarper())
	{
	}
	const char *name() const override { return Target::name(); }

	void warp(const ImageView &image, std::span<const std::array<Point2f, 4>> quads, int side,
		  std::span<CandidateSamples> out, std::span<std::uint8_t> ok) override
	{
		counts_ = {};
		const std::size_t n = quads.size();
		if (n == 0)
			return;
		if (side > kernels::kWarpSide || image.width < 2 || image.height < 2) {
			cpu_->warp(image, quads, side, out, ok);
			counts_.on_cpu = static_cast<unsigned>(n);
			return;
		}
		prepare(image.width, image.height);
		const uint32_t stride = roundUp(static_cast<uint32_t>(image.width), 4);
		for (int y = 0; y < image.height; ++y)
			std::memcpy(src_.cpu.data() + static_cast<std::size_t>(y) * stride, image.row(y),
				    static_cast<std::size_t>(image.width));
		const kernels::WarpImage qpuImage{ src_.bus, stride, image.width, image.height };

		/* Quantise every candidate; the ones the fixed point refuses go to the CPU. */
		onQpu_.clear();
		params_.clear();
		for (std::size_t k = 0; k < n; ++k) {
			if (auto p = kernels::warpParams(quads[k], side)) {
				onQpu_.push_back(k);
				params_.push_back(*p);
			} else {
				cpu_->warp(image, quads.subspan(k, 1), side, out.subspan(k, 1), ok.subspan(k, 1));
				++counts_.on_cpu;
			}
		}
		for (std::size_t first = 0; first < params_.size(); first += kernels::kWarpMaxCandidates) {
			const std::size_t count = std::min<std::size_t>(kernels::kWarpMaxCandidates, params_.size() - first);
			/* Uniforms straight into the device buffers: a launch allocates nothing. */
			uint32_t *streams[kPrograms];
			for (unsigned p = 0; p < kPrograms; ++p)
				streams[p] = reinterpret_cast<uint32_t *>(unif_[p].cpu.data());
			const unsigned programs = kernels::writeWarpUniforms(
				qpuImage, std::span<const kernels::WarpParams>(params_).subspan(first, count), out_.bus, kPrograms,
				streams);
			Job jobs[kPrograms];
			for (unsigned p = 0; p < programs; ++p)
				jobs[p] = { unif_[p].bus, code_.bus };
			target_.run(std::span<const Job>(jobs, programs));
			++counts_.launches;
			for (std::size_t c = 0; c < count; ++c) {
				const std::size_t k = onQpu_[first + c];
				const std::uint8_t *s = out_.cpu.data() + kernels::kWarpOutputBytes * c;
				out[k].side = side;
				for (int j = 0; j < side; ++j)
					for (int i = 0; i < side; ++i)
						out[k].samples[static_cast<std::size_t>(j * side + i)] =
							static_cast<float>(s[j * kernels::kWarpSide + i]);
				ok[k] = 1;
			}
			counts_.on_qpus += static_cast<unsigned>(count);
		}
	}

	const WarpCounts &counts() const { return counts_; }

private:
	/* Device buffers for frames up to this size; kept while frames fit. */
	void prepare(int width, int height)
	{
		const uint32_t bytes = roundUp(static_cast<uint32_t>(width), 4) * static_cast<uint32_t>(height) + 64;
		if (device_ && bytes <= srcBytes_)
			return;
		const uint32_t total = bytes + kOutputBytes + kPrograms * roundUp(kUniformBytes, 64) +
				       4 * 4096 + static_cast<uint32_t>(8 * program_.code.size());
		device_ = &target_.open(total);
		src_ = device_->alloc(bytes);
		out_ = device_->alloc(kOutputBytes);
		for (auto &u : unif_)
			u = device_->alloc(kUniformBytes, 64);
		code_ = device_->upload(program_.code);
		remember();
		srcBytes_ = bytes;
	}
	void remember()
	{
#if FRAPPE_VC4_HAVE_RUNTIME
		if constexpr (std::is_same_v<Target, GpuTarget>) {
			target_.owned = { src_, out_, code_ };
			target_.owned.insert(target_.owned.end(), std::begin(unif_), std::end(unif_));
		}
#endif
	}

	Target target_;
	qasm::Program program_;
	std::unique_ptr<CandidateWarper> cpu_;
	Device *device_ = nullptr;
	typename Device::Buffer src_, out_, code_, unif_[kPrograms];
	uint32_t srcBytes_ = 0;
	std::vector<std::size_t> onQpu_;
	std::vector<kernels::WarpParams> params_;
	WarpCounts counts_;
};

} // namespace

std::unique_ptr<frappe::CandidateWarper> makeWarper(const FrontEndOptions &options)
{
	if (options.emulate) {
		EmuTarget t;
		t.options = options;
		return std::make_unique<QpuWarper<EmuTarget>>(std::move(t));
	}
#if FRAPPE_VC4_HAVE_RUNTIME
	const std::string reason = probeGpu();
	if (!reason.empty())
		throw std::runtime_error(reason);
	return std::make_unique<QpuWarper<GpuTarget>>(GpuTarget{});
#else
	throw std::runtime_error("the VideoCore IV runtime is only built for Linux.");
#endif
}

bool lastWarpCounts(const frappe::CandidateWarper &warper, WarpCounts &out)
{
	if (const auto *w = dynamic_cast<const QpuWarper<EmuTarget> *>(&warper)) {
		out = w->counts();
		return true;
	}
#if FRAPPE_VC4_HAVE_RUNTIME
	if (const auto *w = dynamic_cast<const QpuWarper<GpuTarget> *>(&warper)) {
		out = w->counts();
		return true;
	}
#endif
	return false;
}

} // namespace frappe::vc4
