// SPDX-License-Identifier: MIT
#include "emu/memory.hpp"

#include <cstdio>
#include <string>

namespace frappe::vc4::emu {

Memory::Memory(uint32_t size, uint32_t base) : base_(base), next_(base), bytes_(size) {}

size_t Memory::offset(uint32_t address, uint32_t length) const
{
	if (address < base_ || uint64_t{address} - base_ + length > bytes_.size())
		throw MemoryError("bus address 0x" + [&] {
			char buf[16];
			std::snprintf(buf, sizeof(buf), "%08x", address);
			return std::string(buf);
		}() + " outside emulated memory");
	return address - base_;
}

uint32_t Memory::alloc(uint32_t bytes, uint32_t align)
{
	const uint32_t address = (next_ + align - 1) / align * align;
	offset(address, bytes);
	next_ = address + bytes;
	std::memset(&bytes_[address - base_], 0, bytes);
	return address;
}

uint32_t Memory::load(std::span<const uint64_t> code)
{
	const uint32_t address = alloc(static_cast<uint32_t>(code.size() * 8));
	if (!code.empty()) /* an empty span's data() may be null: no memcpy */
		std::memcpy(&bytes_[address - base_], code.data(), code.size() * 8);
	return address;
}

uint32_t Memory::load(std::span<const uint32_t> words)
{
	const uint32_t address = alloc(static_cast<uint32_t>(words.size() * 4 + 4));
	if (!words.empty())
		std::memcpy(&bytes_[address - base_], words.data(), words.size() * 4);
	return address;
}

std::span<uint8_t> Memory::bytes(uint32_t address, uint32_t length)
{
	return {&bytes_[offset(address, length)], length};
}

uint32_t Memory::read32(uint32_t address) const
{
	uint32_t v;
	std::memcpy(&v, &bytes_[offset(address, 4)], 4);
	return v;
}

void Memory::write32(uint32_t address, uint32_t value)
{
	std::memcpy(&bytes_[offset(address, 4)], &value, 4);
}

uint64_t Memory::read64(uint32_t address) const
{
	uint64_t v;
	std::memcpy(&v, &bytes_[offset(address, 8)], 8);
	return v;
}

} // namespace frappe::vc4::emu
