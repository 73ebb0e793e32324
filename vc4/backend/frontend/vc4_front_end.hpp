// SPDX-License-Identifier: MIT
// frappe::FrontEnd on the VideoCore IV QPUs (issue 6): pass 1 and pass 2 of
// kernels/kernels.hpp and the region map's two passes, on the real GPU (backend "vc4") or
// on the emulator ("vc4-emu"), producing exactly the CPU front end's EdgeMap.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "frappe/edge_map.h"

namespace frappe::vc4 {

// Wider scaled frames run on the CPU front end (the VDW stride field holds 13 bits).
inline constexpr int kMaxQpuWidth = 2048;

struct FrontEndOptions {
	bool emulate = true; // true: run the kernels on the emulator (backend "vc4-emu"); false: on the real GPU (backend "vc4")
	unsigned seed = 0;   // emulator: 0 = round-robin QPU interleaving, else seeded random interleaving
	bool strict = true;  // emulator: hazard checks fault
};

// Throws std::runtime_error with a one-sentence reason when the real GPU cannot be used
// (runtime::GpuDevice::probe()).
std::unique_ptr<frappe::FrontEnd> makeFrontEnd(const FrontEndOptions &options = {});

// Empty when the real QPUs are usable, else the probe's one-sentence reason. Never throws.
std::string probeGpu();

// Counts of the last frame's passes (emulator only: instructions are exact, cycles
// follow emu::Timing, an uncalibrated model).
struct PassCounts {
	uint64_t instructions = 0;    // all QPUs
	uint64_t slowest_cycles = 0;  // the slowest QPU of the launch
	unsigned tiles = 0;           // 64x32 tiles
	unsigned units = 0;           // work units (pass 1: strips of a band; pass 2: half tiles)
	unsigned programs = 0;        // QPUs used
	uint64_t dram_read = 0;       // bytes the QPUs read: TMU gathers, VDR, uniforms
	uint64_t dram_written = 0;    // bytes the QPUs wrote (VDW)
};
struct FrameCounts {
	PassCounts pass[2];
	PassCounts region[2]; // the region map's means and dark passes (tiles: 64x16 blocks of the map)
};
// False when `front_end` is not an emulated VC4 front end or has not run a QPU frame.
bool lastFrameCounts(const frappe::FrontEnd &front_end, FrameCounts &out);

// The gradient buffer of the last QPU frame (pass 1's output, layout in
// kernels/kernels.hpp): `pitch_words` 32-bit words per image row. Emulator only; for tests.
bool lastGradientBuffer(const frappe::FrontEnd &front_end, std::vector<uint32_t> &words, int &pitch_words);

} // namespace frappe::vc4
