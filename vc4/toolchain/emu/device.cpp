// SPDX-License-Identifier: MIT
#include "emu/device.hpp"

#include <cstring>

namespace frappe::vc4::emu {

Device::Device(Config config, uint32_t memory_bytes) : memory_(memory_bytes), v3d_(memory_, config) {}

Device::Buffer Device::alloc(uint32_t bytes, uint32_t align)
{
	const uint32_t bus = memory_.alloc(bytes, align);
	live_[bus] = bytes;
	return {bus, memory_.bytes(bus, bytes)};
}

Device::Buffer Device::upload(std::span<const uint64_t> code)
{
	Buffer b = alloc(static_cast<uint32_t>(code.size_bytes()));
	std::memcpy(b.cpu.data(), code.data(), code.size_bytes());
	return b;
}

Device::Buffer Device::upload(std::span<const uint32_t> words)
{
	Buffer b = alloc(static_cast<uint32_t>(words.size_bytes() + 4));
	std::memcpy(b.cpu.data(), words.data(), words.size_bytes());
	return b;
}

Device::Fence Device::launch(std::span<const Job> jobs, LaunchOptions options)
{
	const Fence f = next_++;
	done_.emplace(f, v3d_.launch(jobs, options));
	return f;
}

LaunchStats Device::wait(Fence fence)
{
	auto it = done_.find(fence);
	if (it == done_.end())
		throw std::invalid_argument("unknown or already waited fence");
	LaunchStats s = std::move(it->second);
	done_.erase(it);
	return s;
}

} // namespace frappe::vc4::emu
