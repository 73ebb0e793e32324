// SPDX-License-Identifier: MIT
#include "emu/memory.hpp"

#include <cstdio>
#include <string>

namespace frappe::vc4::emu {

namespace {

constexpr uint32_t kRegionGap = 1u << 16; // unmapped bytes between regions: overruns fault

std::string hex(uint32_t v)
{
	char buf[16];
	std::snprintf(buf, sizeof(buf), "%08x", v);
	return buf;
}

} // namespace

Memory::Memory(uint32_t size, uint32_t base)
	: base_(base), next_(base), bytes_(size),
	  next_region_(static_cast<uint32_t>((uint64_t{base} + size + kRegionGap + 0xfffff) & ~uint64_t{0xfffff}))
{
}

uint8_t *Memory::inRegion(uint32_t address, uint32_t length, bool write) const
{
	const auto *hit = last_;
	if (!hit || address < hit->first || uint64_t{address} - hit->first + length > hit->second.size) {
		auto it = regions_.upper_bound(address);
		if (it == regions_.begin())
			hit = nullptr;
		else
			hit = &*std::prev(it);
		if (!hit || uint64_t{address} - hit->first + length > hit->second.size)
			throw MemoryError("bus address 0x" + hex(address) + " outside emulated memory");
		last_ = hit;
	}
	if (write && !hit->second.writable)
		throw MemoryError("bus address 0x" + hex(address) + " is read-only external memory");
	return hit->second.data + (address - hit->first);
}

uint8_t *Memory::at(uint32_t address, uint32_t length, bool write) const
{
	if (address >= base_ && uint64_t{address} - base_ + length <= bytes_.size())
		return const_cast<uint8_t *>(bytes_.data()) + (address - base_);
	return inRegion(address, length, write);
}

uint32_t Memory::addRegion(Region region, uint32_t align)
{
	const uint64_t bus = (uint64_t{next_region_} + align - 1) / align * align;
	if (bus + region.size + kRegionGap > 0xfffff000u)
		throw MemoryError("emulated bus address space exhausted");
	next_region_ = static_cast<uint32_t>((bus + region.size + kRegionGap + 0xffff) & ~uint64_t{0xffff});
	regions_.emplace(static_cast<uint32_t>(bus), std::move(region));
	return static_cast<uint32_t>(bus);
}

uint32_t Memory::alloc(uint32_t bytes, uint32_t align)
{
	const uint64_t address = (uint64_t{next_} + align - 1) / align * align;
	if (address + bytes <= uint64_t{base_} + bytes_.size()) {
		next_ = static_cast<uint32_t>(address + bytes);
		std::memset(&bytes_[address - base_], 0, bytes);
		return static_cast<uint32_t>(address);
	}
	Region r;
	r.own.assign(bytes, 0);
	r.size = bytes;
	r.data = r.own.data();
	return addRegion(std::move(r), align);
}

uint32_t Memory::mapExternal(std::span<uint8_t> host, bool writable, uint32_t at)
{
	if (host.empty() || host.size() > 0x7fffffffu)
		throw MemoryError("external memory of " + std::to_string(host.size()) + " bytes cannot be mapped");
	Region r;
	r.size = static_cast<uint32_t>(host.size());
	r.data = host.data();
	r.writable = writable;
	if (!at)
		return addRegion(std::move(r), 4096);
	const uint64_t end = uint64_t{at} + r.size;
	const auto next = regions_.lower_bound(at);
	const bool overlaps = (at < base_ + bytes_.size() && end > base_) ||
			      (next != regions_.end() && next->first < end) ||
			      (next != regions_.begin() && uint64_t{std::prev(next)->first} + std::prev(next)->second.size > at);
	if (overlaps || end > 0x100000000ull)
		throw MemoryError("external memory at bus address 0x" + hex(at) + " overlaps mapped memory");
	regions_.emplace(at, std::move(r));
	return at;
}

void Memory::release(uint32_t address)
{
	if (address >= base_ && address < base_ + bytes_.size())
		return;
	auto it = regions_.find(address);
	if (it == regions_.end())
		throw MemoryError("release of bus address 0x" + hex(address) + ": not a region");
	if (last_ == &*it)
		last_ = nullptr;
	regions_.erase(it);
}

uint32_t Memory::load(std::span<const uint64_t> code)
{
	const uint32_t address = alloc(static_cast<uint32_t>(code.size() * 8));
	if (!code.empty()) /* an empty span's data() may be null: no memcpy */
		std::memcpy(at(address, static_cast<uint32_t>(code.size() * 8), true), code.data(), code.size() * 8);
	return address;
}

uint32_t Memory::load(std::span<const uint32_t> words)
{
	const uint32_t address = alloc(static_cast<uint32_t>(words.size() * 4 + 4));
	if (!words.empty())
		std::memcpy(at(address, static_cast<uint32_t>(words.size() * 4), true), words.data(), words.size() * 4);
	return address;
}

std::span<uint8_t> Memory::bytes(uint32_t address, uint32_t length)
{
	return {at(address, length, false), length};
}

uint32_t Memory::read32(uint32_t address) const
{
	uint32_t v;
	std::memcpy(&v, at(address, 4, false), 4);
	return v;
}

void Memory::write32(uint32_t address, uint32_t value)
{
	std::memcpy(at(address, 4, true), &value, 4);
}

uint64_t Memory::read64(uint32_t address) const
{
	uint64_t v;
	std::memcpy(&v, at(address, 8, false), 8);
	return v;
}

} // namespace frappe::vc4::emu
