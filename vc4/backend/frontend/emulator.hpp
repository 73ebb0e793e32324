// SPDX-License-Identifier: MIT
// How the vc4-emu backends (front end, candidate warp) set up and launch the emulator:
// one place for the device configuration that mirrors the hardware's limits and for the
// checks every launch needs.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>

#include "emu/device.hpp"
#include "frontend/vc4_front_end.hpp"

namespace frappe::vc4 {

/// An emulated V3D with at least `bytes` of memory (plus 1 MiB for code and uniforms),
/// strict hazard checks as `options` asks, and the build's TMU depth.
inline std::unique_ptr<emu::Device> openEmulator(const FrontEndOptions &options, uint32_t bytes)
{
	emu::Config config;
	config.strict = options.strict;
	config.tmu_fifo_limit = kTmuDepth; // the build's depth, per QPU (tmu_depth.hpp)
	const uint32_t mib = 1u << 20;
	return std::make_unique<emu::Device>(config, (bytes + mib + mib - 1) / mib * mib);
}

/// Runs one launch with `options`' QPU interleaving (seed 0: round robin) and checks that
/// every program raised the host interrupt, as the firmware's execute_qpu requires.
inline emu::LaunchStats runOnEmulator(emu::Device &device, std::span<const emu::Job> jobs,
				      const FrontEndOptions &options)
{
	emu::LaunchOptions launch;
	if (options.seed) {
		launch.schedule = emu::Schedule::Random;
		launch.seed = options.seed;
	}
	const emu::LaunchStats stats = device.wait(device.launch(jobs, launch));
	if (stats.host_interrupts != jobs.size())
		throw std::runtime_error("vc4-emu: a QPU program ended without raising the host interrupt");
	return stats;
}

} // namespace frappe::vc4
