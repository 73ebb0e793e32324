// SPDX-License-Identifier: MIT
#include "runtime/gpu_device.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <stdexcept>

#include "runtime/uapi.hpp"

namespace frappe::vc4::runtime {

namespace {

constexpr uint32_t kPage = 4096;

std::string trimmed(std::string s)
{
	while (!s.empty() && (s.back() == '\0' || s.back() == '\n' || s.back() == ' '))
		s.pop_back();
	return s;
}

std::string hex(uint32_t v)
{
	char buf[16];
	std::snprintf(buf, sizeof buf, "0x%08x", v);
	return buf;
}

uint32_t roundUp(uint64_t v, uint32_t to)
{
	const uint64_t r = (v + to - 1) / to * to;
	if (r > 0xffffffffu)
		throw RuntimeError("GPU buffer of " + std::to_string(v) + " bytes is too large");
	return static_cast<uint32_t>(r);
}

// The SoC from the devicetree's compatible list ("raspberrypi,model-zero-w\0brcm,bcm2835\0").
std::string socOf(const std::string &compatible)
{
	for (const char *soc : {"bcm2835", "bcm2836", "bcm2837", "bcm2711", "bcm2712"})
		if (compatible.find(std::string("brcm,") + soc) != std::string::npos)
			return soc;
	return {};
}

std::string kmsHint()
{
	return "the firmware refuses QPU mailbox calls while the kernel vc4 driver owns the V3D "
	       "(raspberrypi/firmware#669): remove dtoverlay=vc4-kms-v3d / vc4-fkms-v3d from "
	       "/boot/firmware/config.txt and reboot (vc4/BRINGUP.md step 1)";
}

// Why the kernel's vc4 driver holds the V3D, or empty. The firmware decides from the
// devicetree node's status; the sysfs binding shows the driver actually took it.
std::string kernelOwnsV3d(Os &os)
{
	for (const std::string &dev : os.listDir("/sys/bus/platform/drivers/vc4_v3d"))
		if (dev.find("v3d") != std::string::npos)
			return "the vc4 KMS driver owns the V3D (" + dev + " is bound to vc4_v3d)";
	for (const std::string &node : os.listDir("/proc/device-tree/soc")) {
		if (node.rfind("v3d@", 0) != 0)
			continue;
		const auto status = os.readFile("/proc/device-tree/soc/" + node + "/status");
		if (status && trimmed(*status) == "okay")
			return "the vc4 KMS driver owns the V3D (devicetree node " + node +
			       " is enabled by a vc4-kms-v3d/vc4-fkms-v3d overlay)";
	}
	return {};
}

struct Fd {
	Os &os;
	int fd;
	~Fd()
	{
		if (fd >= 0)
			os.close(fd);
	}
};

std::string openFailure(const std::string &path, int err)
{
	if (err == -ENOENT)
		return path + " does not exist";
	if (err == -EACCES || err == -EPERM)
		return "permission denied on " + path + " (udev rule and group video, see vc4/BRINGUP.md)";
	return path + ": " + errorText(err);
}

// A dma-buf of `bytes` (whole pages) from the heap at `path`, or -1 with why appended to `notes`.
int heapBuffer(Os &os, const std::string &path, uint64_t bytes, std::string &notes)
{
	Fd heap{os, os.open(path, O_RDWR)};
	if (heap.fd < 0) {
		notes += (notes.empty() ? "" : "; ") + openFailure(path, heap.fd);
		return -1;
	}
	uapi::DmaHeapAllocationData alloc;
	alloc.len = (bytes + kPage - 1) / kPage * kPage;
	alloc.fd_flags = O_RDWR | O_CLOEXEC;
	const int e = os.ioctl(heap.fd, uapi::kIoctlDmaHeapAlloc, &alloc);
	if (e < 0) {
		notes += (notes.empty() ? "" : "; ") + path + " allocation of " + std::to_string(alloc.len) +
		         " bytes failed: " + errorText(e);
		return -1;
	}
	return static_cast<int>(alloc.fd);
}

// dma-heap allocation + vcsm-cma import of one page: proves the whole path works.
bool tryDmaHeap(Os &os, const DeviceOptions &o, ProbeReport &r)
{
	std::string notes;
	Fd vcsm{os, os.open(o.vcsm, O_RDWR)};
	if (vcsm.fd < 0) {
		r.memory_note = openFailure(o.vcsm, vcsm.fd) + ", so dma-heap buffers cannot be given "
		                "a bus address";
		return false;
	}
	for (const std::string &path : o.heaps) {
		Fd buf{os, heapBuffer(os, path, kPage, notes)};
		if (buf.fd < 0)
			continue;
		uapi::VcsmImportDmabuf import;
		import.dmabuf_fd = buf.fd;
		import.cached = uapi::kVcsmCacheNone;
		std::memcpy(import.name, "vc4-qpu-probe", 13);
		const int e = os.ioctl(vcsm.fd, uapi::kIoctlVcsmImportDmabuf, &import);
		if (e < 0 || import.handle < 0 || import.dma_addr == 0) {
			notes += (notes.empty() ? "" : "; ") + o.vcsm + " import of a " + path + " buffer failed: " +
			         (e < 0 ? errorText(e) : std::string("no bus address"));
			continue;
		}
		Fd imported{os, import.handle};
		r.heap = path;
		return true;
	}
	r.memory_note = notes;
	return false;
}

bool tryMailboxMemory(Os &os, const DeviceOptions &o, Mailbox &mb, uint32_t flags, ProbeReport &r)
{
	Fd mem{os, os.open(o.devmem, O_RDWR | O_SYNC)};
	if (mem.fd < 0) {
		r.memory_note += (r.memory_note.empty() ? "" : "; ") + std::string("legacy mailbox memory needs ") +
		                 openFailure(o.devmem, mem.fd) + " (root)";
		return false;
	}
	const uint32_t handle = mb.memAllocate(kPage, kPage, flags);
	if (handle == 0) {
		r.memory_note += (r.memory_note.empty() ? "" : "; ") +
		                 std::string("the firmware has no GPU memory to give (raise gpu_mem)");
		return false;
	}
	mb.memRelease(handle);
	return true;
}

uint32_t mailboxFlags(const std::string &soc)
{
	return soc == "bcm2835" ? uapi::kMemFlagL1NonAllocating : uapi::kMemFlagDirect;
}

// Fills `r`; on success leaves the mailbox open in `keep` with the QPUs enabled.
void probeInto(Os &os, const DeviceOptions &o, ProbeReport &r, std::unique_ptr<Mailbox> *keep)
{
	const auto model = os.readFile("/proc/device-tree/model");
	if (!model) {
		r.reason = "not a Raspberry Pi: /proc/device-tree/model is missing";
		return;
	}
	r.model = trimmed(*model);
	r.soc = socOf(os.readFile("/proc/device-tree/compatible").value_or(""));
	if (r.model.find("Raspberry Pi") == std::string::npos) {
		r.reason = "not a Raspberry Pi: the devicetree model is \"" + r.model + "\"";
		return;
	}
	if (r.soc == "bcm2711" || r.soc == "bcm2712") {
		r.reason = r.model + " has a VideoCore VI/VII GPU (" + r.soc +
		           "); the QPU kernels are VideoCore IV code (Pi Zero, Zero 2 W, 1, 2, 3)";
		return;
	}
	if (const std::string owner = kernelOwnsV3d(os); !owner.empty()) {
		r.reason = owner + ": " + kmsHint();
		return;
	}
	std::unique_ptr<Mailbox> mb;
	try {
		mb = std::make_unique<Mailbox>(os, o.mailbox);
		r.firmware = mb->firmwareRevision();
		const uint32_t status = mb->setEnableQpu(true);
		if (status != 0) {
			r.reason = "the firmware refused to enable the QPUs (status " + hex(status) + "); " +
			           kmsHint();
			return;
		}
	} catch (const RuntimeError &e) {
		r.reason = std::string("cannot enable the QPUs: ") + e.what();
		return;
	}
	try {
		r.v3d_hz = mb->clockRate(uapi::kClockV3d);
		if (tryDmaHeap(os, o, r)) {
			r.memory = MemoryKind::DmaHeapVcsm;
		} else if (o.allow_mailbox_memory && tryMailboxMemory(os, o, *mb, mailboxFlags(r.soc), r)) {
			r.memory = MemoryKind::MailboxDevMem;
		} else {
			r.reason = "no GPU-visible memory: " + r.memory_note;
		}
	} catch (const RuntimeError &e) {
		r.reason = std::string("mailbox query failed: ") + e.what();
	}
	if (r.reason.empty() && keep) {
		*keep = std::move(mb);
	} else {
		try {
			mb->setEnableQpu(false);
		} catch (const RuntimeError &) {
		}
	}
	r.usable = r.reason.empty();
}

} // namespace

const char *toString(MemoryKind kind)
{
	switch (kind) {
	case MemoryKind::None: return "none";
	case MemoryKind::DmaHeapVcsm: return "dma-heap + vcsm-cma";
	case MemoryKind::MailboxDevMem: return "mailbox + /dev/mem";
	}
	return "?";
}

std::string ProbeReport::summary() const
{
	std::string s = usable ? "VideoCore IV QPUs usable" : "VideoCore IV QPUs not usable: " + reason;
	if (!model.empty())
		s += "\n  model: " + model + (soc.empty() ? "" : " (" + soc + ")");
	if (firmware)
		s += "\n  firmware revision: " + hex(firmware);
	if (v3d_hz)
		s += "\n  v3d clock: " + std::to_string(v3d_hz / 1000000) + " MHz";
	if (memory != MemoryKind::None)
		s += std::string("\n  memory: ") + toString(memory) + (heap.empty() ? "" : " (" + heap + ")");
	if (!memory_note.empty())
		s += "\n  note: " + memory_note;
	return s;
}

int allocateDmaHeapBuffer(Os &os, const DeviceOptions &options, std::size_t bytes, std::string &why)
{
	std::string notes;
	for (const std::string &path : options.heaps)
		if (const int fd = heapBuffer(os, path, bytes, notes); fd >= 0)
			return fd;
	why = "no dma-heap frame memory: " + (notes.empty() ? std::string("no heap configured") : notes);
	return -1;
}

ProbeReport GpuDevice::probe(Os &os, const DeviceOptions &options)
{
	ProbeReport r;
	probeInto(os, options, r, nullptr);
	return r;
}

GpuDevice::GpuDevice(Os &os, DeviceOptions options) : os_(os), options_(std::move(options))
{
	probeInto(os_, options_, report_, &mailbox_);
	if (!report_.usable)
		throw RuntimeError("VideoCore IV QPUs not usable: " + report_.reason);
	try {
		if (report_.memory == MemoryKind::DmaHeapVcsm) {
			heap_ = os_.open(report_.heap, O_RDWR);
			vcsm_ = os_.open(options_.vcsm, O_RDWR);
			if (heap_ < 0 || vcsm_ < 0)
				throw RuntimeError("cannot reopen " + report_.heap + " / " + options_.vcsm);
		} else {
			devmem_ = os_.open(options_.devmem, O_RDWR | O_SYNC);
			if (devmem_ < 0)
				throw RuntimeError("cannot reopen " + options_.devmem + ": " + errorText(devmem_));
		}
		control_ = alloc(8 * kMaxPrograms);
	} catch (...) {
		cleanup();
		throw;
	}
}

GpuDevice::~GpuDevice() { cleanup(); }

void GpuDevice::cleanup()
{
	imports_.clear([this](Imported &i) { releaseImport(i); });
	for (auto &[bus, a] : buffers_)
		free(a);
	buffers_.clear();
	for (int *fd : {&heap_, &vcsm_, &devmem_}) {
		if (*fd >= 0)
			os_.close(*fd);
		*fd = -1;
	}
	if (mailbox_) {
		try {
			mailbox_->setEnableQpu(false);
		} catch (const RuntimeError &) {
		}
		mailbox_.reset();
	}
}

GpuDevice::Allocation GpuDevice::allocateDmaHeap(uint32_t bytes, uint32_t align)
{
	Allocation a;
	a.map_bytes = roundUp(uint64_t{bytes} + (align > kPage ? align - kPage : 0), kPage);
	uapi::DmaHeapAllocationData req;
	req.len = a.map_bytes;
	req.fd_flags = O_RDWR | O_CLOEXEC;
	int e = os_.ioctl(heap_, uapi::kIoctlDmaHeapAlloc, &req);
	if (e < 0)
		throw RuntimeError(report_.heap + ": cannot allocate " + std::to_string(a.map_bytes) +
		                   " bytes: " + errorText(e) + " (CMA exhausted? raise cma= in cmdline.txt)");
	a.dmabuf = static_cast<int>(req.fd);
	a.map = static_cast<uint8_t *>(os_.mmap(a.map_bytes, a.dmabuf, 0, e));
	if (!a.map) {
		free(a);
		throw RuntimeError("cannot map a dma-heap buffer: " + errorText(e));
	}
	uapi::VcsmImportDmabuf import;
	import.dmabuf_fd = a.dmabuf;
	import.cached = uapi::kVcsmCacheNone;
	std::memcpy(import.name, "vc4-qpu", 7);
	e = os_.ioctl(vcsm_, uapi::kIoctlVcsmImportDmabuf, &import);
	if (e < 0 || import.handle < 0 || import.dma_addr == 0) {
		free(a);
		throw RuntimeError(options_.vcsm + ": import of a dma-heap buffer failed: " +
		                   (e < 0 ? errorText(e) : std::string("no bus address")));
	}
	a.import = import.handle;
	const auto dma = static_cast<uint32_t>(import.dma_addr);
	const uint32_t base = (dma & ~uapi::kBusAliasMask) | uapi::kBusAliasUncached;
	a.offset = (align - base % align) % align;
	a.bus = base + static_cast<uint32_t>(a.offset);
	// Open the CPU's access window; launches close and reopen it.
	uapi::DmaBufSync sync{uapi::kDmaBufSyncStart | uapi::kDmaBufSyncRw};
	os_.ioctl(a.dmabuf, uapi::kIoctlDmaBufSync, &sync);
	return a;
}

GpuDevice::Allocation GpuDevice::allocateMailbox(uint32_t bytes, uint32_t align)
{
	Allocation a;
	a.map_bytes = roundUp(bytes, kPage);
	a.handle = mailbox_->memAllocate(static_cast<uint32_t>(a.map_bytes), std::max(align, kPage),
	                                 mailboxFlags(report_.soc));
	if (a.handle == 0)
		throw RuntimeError("the firmware could not allocate " + std::to_string(a.map_bytes) +
		                   " bytes of GPU memory (raise gpu_mem in config.txt)");
	a.bus = mailbox_->memLock(a.handle);
	if (a.bus == 0) {
		free(a);
		throw RuntimeError("the firmware could not lock GPU memory handle " + std::to_string(a.handle));
	}
	int e = 0;
	a.map = static_cast<uint8_t *>(os_.mmap(a.map_bytes, devmem_, a.bus & ~uapi::kBusAliasMask, e));
	if (!a.map) {
		free(a);
		throw RuntimeError("cannot map GPU memory through " + options_.devmem + ": " + errorText(e));
	}
	return a;
}

void GpuDevice::free(Allocation &a)
{
	if (a.map)
		os_.munmap(a.map, a.map_bytes);
	a.map = nullptr;
	if (a.import >= 0)
		os_.close(a.import);
	if (a.dmabuf >= 0)
		os_.close(a.dmabuf);
	a.import = a.dmabuf = -1;
	if (a.handle != 0 && mailbox_) {
		try {
			if (a.bus != 0)
				mailbox_->memUnlock(a.handle);
			mailbox_->memRelease(a.handle);
		} catch (const RuntimeError &) {
		}
	}
	a.handle = 0;
}

GpuDevice::Buffer GpuDevice::alloc(uint32_t bytes, uint32_t align)
{
	if (bytes == 0 || align == 0 || (align & (align - 1)) != 0)
		throw std::invalid_argument("GpuDevice::alloc: bytes > 0 and a power-of-two alignment");
	Allocation a = report_.memory == MemoryKind::DmaHeapVcsm ? allocateDmaHeap(bytes, align)
	                                                         : allocateMailbox(bytes, align);
	a.bytes = bytes;
	std::memset(a.map + a.offset, 0, bytes);
	const Buffer b{a.bus, std::span<uint8_t>(a.map + a.offset, bytes)};
	buffers_.emplace(a.bus, a);
	return b;
}

GpuDevice::Buffer GpuDevice::upload(std::span<const uint64_t> code)
{
	Buffer b = alloc(static_cast<uint32_t>(code.size_bytes()));
	std::memcpy(b.cpu.data(), code.data(), code.size_bytes());
	return b;
}

GpuDevice::Buffer GpuDevice::upload(std::span<const uint32_t> words)
{
	Buffer b = alloc(static_cast<uint32_t>(words.size_bytes() + 4));
	std::memcpy(b.cpu.data(), words.data(), words.size_bytes());
	return b;
}

void GpuDevice::release(const Buffer &buffer)
{
	auto it = buffers_.find(buffer.bus);
	if (it == buffers_.end())
		throw std::invalid_argument("GpuDevice::release: not a buffer of this device");
	free(it->second);
	buffers_.erase(it);
}

GpuDevice::Import GpuDevice::importDmabuf(int fd)
{
	std::string_view why;
	if (const Import *im = tryImportDmabuf(fd, why))
		return *im;
	throw RuntimeError(std::string(why));
}

const GpuDevice::Import *GpuDevice::tryImportDmabuf(int fd, std::string_view &why)
{
	if (report_.memory != MemoryKind::DmaHeapVcsm) {
		std::snprintf(why_, sizeof why_, "dma-buf import needs vcsm-cma, and this device uses %s memory",
		              toString(report_.memory));
		why = why_;
		return nullptr;
	}
	FileId id;
	if (const int e = os_.fileId(fd, id); e < 0) {
		std::snprintf(why_, sizeof why_, "fstat of dma-buf fd %d failed: %s", fd, errorText(e).c_str());
		why = why_;
		return nullptr;
	}
	Imported *hit = imports_.find(id);
	if (!hit) {
		hit = &imports_.add(id, importOnce(fd, id), [this](Imported &old) { releaseImport(old); });
		if (hit->handle >= 0) {
			// Open the CPU's access window, as for our own buffers; launches close and reopen it.
			uapi::DmaBufSync sync{uapi::kDmaBufSyncStart | uapi::kDmaBufSyncRw};
			os_.ioctl(hit->dmabuf, uapi::kIoctlDmaBufSync, &sync);
		}
	}
	if (hit->handle < 0) {
		why = hit->why;
		return nullptr;
	}
	return &hit->view;
}

GpuDevice::Imported GpuDevice::importOnce(int fd, const FileId &id)
{
	Imported i;
	i.dmabuf = os_.dup(fd);
	if (i.dmabuf < 0) {
		std::snprintf(i.why, sizeof i.why, "cannot dup dma-buf fd %d: %s", fd, errorText(i.dmabuf).c_str());
		i.dmabuf = -1;
		return i;
	}
	uapi::VcsmImportDmabuf import;
	import.dmabuf_fd = i.dmabuf;
	import.cached = uapi::kVcsmCacheNone;
	std::memcpy(import.name, "vc4-frame", 9);
	const int e = os_.ioctl(vcsm_, uapi::kIoctlVcsmImportDmabuf, &import);
	if (e < 0 || import.handle < 0 || import.dma_addr == 0) {
		if (e >= 0 && import.handle >= 0)
			os_.close(import.handle);
		os_.close(i.dmabuf);
		i.dmabuf = -1;
		std::snprintf(i.why, sizeof i.why,
		              "%s refused to import dma-buf fd %d: %s (a buffer the GPU cannot address contiguously?)",
		              options_.vcsm.c_str(), fd, e < 0 ? errorText(e).c_str() : "no bus address");
		return i;
	}
	i.handle = import.handle;
	i.view.bus = (static_cast<uint32_t>(import.dma_addr) & ~uapi::kBusAliasMask) | uapi::kBusAliasUncached;
	i.view.bytes = id.size ? id.size : import.size;
	return i;
}

std::size_t GpuDevice::imports() const
{
	std::size_t n = 0;
	imports_.forEach([&](const Imported &i) { n += i.handle >= 0; });
	return n;
}

void GpuDevice::releaseImport(Imported &i)
{
	if (i.handle >= 0)
		os_.close(i.handle);
	if (i.dmabuf >= 0)
		os_.close(i.dmabuf);
	i.handle = i.dmabuf = -1;
}

void GpuDevice::syncAll(uint64_t flags)
{
	if (report_.memory != MemoryKind::DmaHeapVcsm)
		return; // /dev/mem O_SYNC mappings are uncached
	auto sync = [&](int fd, uint32_t bus) {
		uapi::DmaBufSync s{flags};
		const int e = os_.ioctl(fd, uapi::kIoctlDmaBufSync, &s);
		if (e < 0)
			throw RuntimeError("DMA_BUF_IOCTL_SYNC failed on the buffer at bus " + hex(bus) + ": " +
			                   errorText(e));
	};
	for (auto &[bus, a] : buffers_)
		sync(a.dmabuf, bus);
	imports_.forEach([&](Imported &i) {
		if (i.handle >= 0)
			sync(i.dmabuf, i.view.bus);
	});
}

GpuDevice::Fence GpuDevice::launch(std::span<const Job> jobs, std::chrono::milliseconds timeout)
{
	if (jobs.empty() || jobs.size() > kMaxPrograms)
		throw std::invalid_argument("GpuDevice::launch: 1 to 12 programs");
	const auto n = static_cast<uint32_t>(jobs.size());
	for (uint32_t i = 0; i < n; ++i) {
		const uint32_t pair[2] = {jobs[i].uniforms, jobs[i].code};
		std::memcpy(control_.cpu.data() + 8 * i, pair, 8);
	}
	const auto ms = static_cast<uint32_t>(std::clamp<int64_t>(timeout.count(), 1, kMaxTimeoutMs));
	// Write back the CPU's caches so the QPUs see code, uniforms and inputs (END), run,
	// then invalidate them so the CPU sees what the QPUs wrote (START). execute_qpu with
	// noflush = 0 clears the QPU-side caches (TMU, uniforms, instructions, L2) itself.
	syncAll(uapi::kDmaBufSyncEnd | uapi::kDmaBufSyncRw);
	const auto t0 = std::chrono::steady_clock::now();
	uint32_t status = 0;
	std::string failure;
	bool timed_out = false;
	try {
		status = mailbox_->executeQpu(n, control_.bus, false, ms);
		timed_out = status != 0;
	} catch (const TimeoutError &e) {
		timed_out = true;
		failure = e.what();
	} catch (const RuntimeError &e) {
		failure = e.what();
	}
	const auto elapsed = std::chrono::steady_clock::now() - t0;
	syncAll(uapi::kDmaBufSyncStart | uapi::kDmaBufSyncRw);
	if (timed_out) {
		// Power-cycle the V3D through the firmware so the next launch starts clean.
		try {
			mailbox_->setEnableQpu(false);
			mailbox_->setEnableQpu(true);
		} catch (const RuntimeError &) {
		}
		throw TimeoutError("QPU launch of " + std::to_string(n) + " programs did not end within " +
		                   std::to_string(ms) + " ms (" +
		                   (failure.empty() ? "execute_qpu status " + hex(status) : failure) +
		                   "); the QPUs were reset");
	}
	if (!failure.empty())
		throw RuntimeError("QPU launch failed: " + failure);
	const Fence f = next_++;
	done_.emplace(f, LaunchResult{n, std::chrono::duration_cast<std::chrono::nanoseconds>(elapsed)});
	return f;
}

LaunchResult GpuDevice::wait(Fence fence)
{
	auto it = done_.find(fence);
	if (it == done_.end())
		throw std::invalid_argument("unknown or already waited fence");
	const LaunchResult r = it->second;
	done_.erase(it);
	return r;
}

} // namespace frappe::vc4::runtime
