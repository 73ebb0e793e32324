// SPDX-License-Identifier: MIT
// The real VideoCore IV QPUs behind the same capabilities as the emulator's
// emu::Device: GPU-visible buffers with a CPU view and a bus address, launches of up to
// 12 (uniforms, code) programs, and a fence to wait on. Launch goes through the firmware
// mailbox (execute_qpu); memory comes from a CPU-cached dma-heap imported into vcsm-cma
// for its bus address, or, as a fallback, from the firmware's own allocator mapped through
// /dev/mem (uncached, root only). probe() says, in one sentence, why the GPU cannot be
// used when it cannot. A dma-buf made elsewhere (a camera frame) is imported into vcsm-cma
// once per buffer and read by the QPUs in place. All system calls go through Os, so tests
// run on any machine.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/import_cache.hpp"
#include "runtime/mailbox.hpp"
#include "runtime/os.hpp"

namespace frappe::vc4::runtime {

enum class MemoryKind {
	None,
	DmaHeapVcsm,   // dma-heap buffers (CPU-cached, synced with DMA_BUF_IOCTL_SYNC) + vcsm-cma import
	MailboxDevMem, // firmware allocate/lock + /dev/mem mapping (uncached; legacy fallback)
};
const char *toString(MemoryKind kind);

struct DeviceOptions {
	// dma-heaps tried in order (rpicam-apps and libcamera use the same two).
	std::vector<std::string> heaps = {"/dev/dma_heap/vidbuf_cached", "/dev/dma_heap/linux,cma"};
	std::string vcsm = "/dev/vcsm-cma";
	std::string mailbox = "/dev/vcio";
	std::string devmem = "/dev/mem";
	bool allow_mailbox_memory = true;
};

struct ProbeReport {
	bool usable = false;
	std::string reason;      // why the GPU cannot be used; empty when usable
	std::string model;       // /proc/device-tree/model
	std::string soc;         // "bcm2835", "bcm2837", ... from /proc/device-tree/compatible
	MemoryKind memory = MemoryKind::None;
	std::string heap;        // the dma-heap in use
	std::string memory_note; // why an earlier memory path was skipped
	uint32_t firmware = 0;   // firmware revision (a date stamp)
	uint32_t v3d_hz = 0;     // V3D clock reported by the firmware

	std::string summary() const;
};

// One QPU program: the pair the mailbox execute_qpu control block carries (as emu::Job).
struct Job {
	uint32_t uniforms = 0;
	uint32_t code = 0;
};

struct LaunchResult {
	unsigned programs = 0;
	std::chrono::nanoseconds elapsed{0}; // wall time of the execute_qpu call
};

// A dma-buf of `bytes` from the first of `options.heaps` that allocates (the heaps the
// runtime's own memory comes from, so vcsm-cma can import it): frame memory for a camera
// or an upstream element to fill and the QPUs to read in place. Returns the fd (the
// caller owns it) or -1 with `why` set in one sentence. Never throws.
int allocateDmaHeapBuffer(Os &os, const DeviceOptions &options, std::size_t bytes, std::string &why);

class GpuDevice {
public:
	struct Buffer {
		uint32_t bus = 0;       // address the QPUs use (0xC0000000 uncached alias)
		std::span<uint8_t> cpu; // the ARM's view of the same bytes
	};
	using Fence = uint64_t;

	static constexpr unsigned kMaxPrograms = 12;
	// The kernel abandons a mailbox call after one second (raspberrypi/linux#4321); ask the
	// firmware to give up first so the QPUs are stopped and reset by us.
	static constexpr uint32_t kMaxTimeoutMs = 900;

	// Never throws: a report of what is there and why the GPU can or cannot be used.
	static ProbeReport probe(Os &os = systemOs(), const DeviceOptions &options = {});

	// Probes, enables the QPUs and sets up memory; throws RuntimeError(report.reason).
	explicit GpuDevice(Os &os = systemOs(), DeviceOptions options = {});
	~GpuDevice();
	GpuDevice(const GpuDevice &) = delete;
	GpuDevice &operator=(const GpuDevice &) = delete;

	const ProbeReport &report() const { return report_; }

	// Zeroed GPU-visible memory; `align` is a power of two (bus address alignment).
	Buffer alloc(uint32_t bytes, uint32_t align = 4096);
	Buffer upload(std::span<const uint64_t> code);
	Buffer upload(std::span<const uint32_t> words);
	void release(const Buffer &buffer);

	// A dma-buf of someone else's (a camera frame) as the QPUs see it, in place.
	struct Import {
		uint32_t bus = 0;   // of the dma-buf's first byte (uncached alias)
		uint64_t bytes = 0; // the dma-buf's size
	};
	// Imports `fd`'s dma-buf into vcsm-cma, once per buffer: the import (of a dup of
	// `fd`, so the caller may close or reuse its number) is cached by the file's identity
	// (st_dev, st_ino), up to ImportCache::kCapacity buffers, the least recently used
	// released beyond that and all on destruction. Imports are cache-synced around
	// launches like the device's own buffers. Throws RuntimeError saying why when the
	// buffer cannot be imported (mailbox memory in use, not contiguous, ...).
	Import importDmabuf(int fd);
	// The same without throwing or allocating once a buffer has been seen, for the frame
	// path: nullptr when it cannot be imported, with `why` (valid until the next call). A
	// refusal is remembered per buffer too, so a refused buffer is not retried each frame.
	const Import *tryImportDmabuf(int fd, std::string_view &why);
	// dma-bufs imported now (cached; refusals not counted).
	std::size_t imports() const;

	// Runs jobs[i] on one QPU each and returns when all have ended (execute_qpu blocks;
	// run it on a worker thread to overlap with the CPU). CPU caches of every buffer are
	// written back before and invalidated after. Throws TimeoutError when the programs do
	// not end within `timeout` (clamped to kMaxTimeoutMs; the QPUs are then reset), and
	// RuntimeError for anything else.
	Fence launch(std::span<const Job> jobs,
	             std::chrono::milliseconds timeout = std::chrono::milliseconds(500));
	LaunchResult wait(Fence fence);

	// Bytes of the dma-heap buffers held now: what launch() cache-syncs before and after
	// each run, beside the imports.
	uint64_t allocatedBytes() const
	{
		uint64_t sum = 0;
		for (const auto &[bus, a] : buffers_)
			sum += a.map_bytes;
		return sum;
	}

private:
	struct Allocation {
		uint32_t bus = 0;
		uint8_t *map = nullptr; // start of the mapping
		size_t map_bytes = 0;
		size_t offset = 0;      // of the aligned buffer inside the mapping
		uint32_t bytes = 0;
		int dmabuf = -1;        // dma-heap buffer
		int import = -1;        // vcsm-cma import of it
		uint32_t handle = 0;    // firmware memory handle
	};

	Allocation allocateDmaHeap(uint32_t bytes, uint32_t align);
	Allocation allocateMailbox(uint32_t bytes, uint32_t align);
	void free(Allocation &a);
	struct Imported {
		Import view;
		int dmabuf = -1;    // our dup of the caller's fd
		int handle = -1;    // vcsm-cma import; -1: refused, for the reason in `why`
		char why[200] = {};
	};

	void syncAll(uint64_t flags);
	Imported importOnce(int fd, const FileId &id);
	void releaseImport(Imported &i);
	void cleanup();

	Os &os_;
	DeviceOptions options_;
	ProbeReport report_;
	std::unique_ptr<Mailbox> mailbox_;
	int heap_ = -1, vcsm_ = -1, devmem_ = -1;
	std::map<uint32_t, Allocation> buffers_;
	ImportCache<Imported> imports_;
	char why_[200] = {}; // the last failure not tied to a buffer (fstat)
	Buffer control_;
	Fence next_ = 1;
	std::map<Fence, LaunchResult> done_;
};

} // namespace frappe::vc4::runtime
