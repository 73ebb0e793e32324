// SPDX-License-Identifier: MIT
// The emulated GPU-visible memory: a flat arena of bus addresses with a bump allocator,
// plus regions above it: allocations too large for the arena (each its own, releasable)
// and external host memory mapped in place (a dma-buf the host mmapped), so that the QPUs
// read a camera frame where it lies, as the hardware does after a vcsm-cma import.
#pragma once

#include <cstdint>
#include <cstring>
#include <map>
#include <span>
#include <stdexcept>
#include <vector>

namespace frappe::vc4::emu {

class MemoryError : public std::runtime_error {
public:
	using std::runtime_error::runtime_error;
};

class Memory {
public:
	explicit Memory(uint32_t size = 16u << 20, uint32_t base = 0x10000000u);

	uint32_t base() const { return base_; }
	uint32_t size() const { return static_cast<uint32_t>(bytes_.size()); }

	// Returns a bus address of `bytes` zeroed bytes: in the arena when they fit, else
	// in a region of their own (which release() frees).
	uint32_t alloc(uint32_t bytes, uint32_t align = 4096);
	uint32_t load(std::span<const uint64_t> code);
	uint32_t load(std::span<const uint32_t> words);

	// Maps host memory the caller keeps alive (until release()) at a new bus address, or
	// at `at` when given (a region must not overlap another), without copying; QPU
	// writes to a read-only mapping fault.
	uint32_t mapExternal(std::span<uint8_t> host, bool writable, uint32_t at = 0);
	// Frees a region (own allocation or external mapping) starting at `address`; arena
	// allocations are not freed (a no-op). Throws MemoryError for an unknown address.
	void release(uint32_t address);
	// Regions (own allocations and external mappings) currently live.
	size_t regions() const { return regions_.size(); }

	std::span<uint8_t> bytes(uint32_t address, uint32_t length);
	uint32_t read32(uint32_t address) const;
	void write32(uint32_t address, uint32_t value);
	uint64_t read64(uint32_t address) const;

private:
	struct Region {
		uint32_t size = 0;
		uint8_t *data = nullptr;
		bool writable = true;
		std::vector<uint8_t> own;
	};

	uint8_t *at(uint32_t address, uint32_t length, bool write) const;
	uint8_t *inRegion(uint32_t address, uint32_t length, bool write) const;
	uint32_t addRegion(Region region, uint32_t align);

	uint32_t base_;
	uint32_t next_;
	std::vector<uint8_t> bytes_;
	std::map<uint32_t, Region> regions_; // by bus address, above the arena
	uint32_t next_region_;
	mutable const std::pair<const uint32_t, Region> *last_ = nullptr; // last region hit
};

} // namespace frappe::vc4::emu
