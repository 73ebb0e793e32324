// SPDX-License-Identifier: MIT
// The emulator behind the interface the hardware runtime will offer: GPU buffers with a
// CPU view and a bus address, and asynchronous-looking launches completed by a fence.
// Host memory (an mmapped dma-buf) can be mapped in place, as the runtime imports one.
#pragma once

#include <cstdint>
#include <map>
#include <span>

#include "emu/v3d.hpp"

namespace frappe::vc4::emu {

class Device {
public:
	struct Buffer {
		uint32_t bus = 0;          // address the QPUs use
		std::span<uint8_t> cpu;    // the host's view of the same bytes
	};
	using Fence = uint64_t;

	explicit Device(Config config = {}, uint32_t memory_bytes = 64u << 20);

	Buffer alloc(uint32_t bytes, uint32_t align = 4096);
	Buffer upload(std::span<const uint64_t> code);
	Buffer upload(std::span<const uint32_t> words);
	// Frees a buffer that did not fit the arena (see Memory::alloc); others stay.
	void release(const Buffer &buffer)
	{
		memory_.release(buffer.bus);
		live_.erase(buffer.bus);
	}
	// Bytes of the buffers allocated and not released: what the real GPU's runtime would
	// hold in dma-heap buffers (and cache-sync around each launch).
	uint64_t allocatedBytes() const
	{
		uint64_t sum = 0;
		for (const auto &[bus, bytes] : live_)
			sum += bytes;
		return sum;
	}
	// The QPUs read (and, if `writable`, write) `host` in place at the returned bus
	// address until release(); the caller keeps the memory alive until then.
	Buffer importExternal(std::span<uint8_t> host, bool writable = false)
	{
		return {memory_.mapExternal(host, writable), host};
	}

	// Queues one launch of up to 12 (uniforms, code) jobs. The emulator runs it at once;
	// wait() hands back its statistics, as the hardware backend's fence will.
	Fence launch(std::span<const Job> jobs, LaunchOptions options = {});
	LaunchStats wait(Fence fence);

	V3d &v3d() { return v3d_; }

private:
	Memory memory_;
	V3d v3d_;
	Fence next_ = 1;
	std::map<Fence, LaunchStats> done_;
	std::map<uint32_t, uint32_t> live_; // bus -> bytes of alloc()ed buffers
};

} // namespace frappe::vc4::emu
