// SPDX-License-Identifier: MIT
// The emulated GPU-visible memory: a flat range of bus addresses with a bump allocator.
#pragma once

#include <cstdint>
#include <cstring>
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

	// Returns a bus address of `bytes` zeroed bytes.
	uint32_t alloc(uint32_t bytes, uint32_t align = 4096);
	uint32_t load(std::span<const uint64_t> code);
	uint32_t load(std::span<const uint32_t> words);

	std::span<uint8_t> bytes(uint32_t address, uint32_t length);
	uint32_t read32(uint32_t address) const;
	void write32(uint32_t address, uint32_t value);
	uint64_t read64(uint32_t address) const;

private:
	size_t offset(uint32_t address, uint32_t length) const;

	uint32_t base_;
	uint32_t next_;
	std::vector<uint8_t> bytes_;
};

} // namespace frappe::vc4::emu
