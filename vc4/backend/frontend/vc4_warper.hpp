// SPDX-License-Identifier: MIT
// frappe::CandidateWarper on the VideoCore IV QPUs: PERSPECTIVE_WARP of a frame's
// candidates, up to 32 a launch (kernels/warp.hpp), on the real GPU or the emulator.
//
// The kernel implements frappe-core's fixed-point warp (frappe/fixed_warp.h) exactly, so
// its samples are the CPU warper's bit for bit. Candidates it cannot take (the fixed
// point refuses them, or their forms leave its ranges on the kernel's 16 x 16 grid: see
// kernels::warpParams()) and codes wider than 6x6 (more than 16 samples a side) go to
// frappe::makeCpuWarper(), which warps them by the same definition or its one float
// fallback.
#pragma once

#include <cstdint>
#include <memory>

#include "frappe/candidate_warp.h"
#include "frontend/vc4_front_end.hpp"

namespace frappe::vc4 {

/// options.emulate selects the emulator; otherwise the real GPU, and then throws
/// std::runtime_error with the probe's reason when it cannot be used.
std::unique_ptr<frappe::CandidateWarper> makeWarper(const FrontEndOptions &options = {});

/// Candidates of the last warp() call that ran on the QPUs, and the launches it took.
struct WarpCounts {
	unsigned on_qpus = 0;
	unsigned on_cpu = 0;
	unsigned launches = 0;
	uint64_t slowest_cycles = 0; // emulator: the launches' slowest-QPU cycles, summed (emu::Timing)
};
/// False when `warper` is not a VC4 warper.
bool lastWarpCounts(const frappe::CandidateWarper &warper, WarpCounts &out);

} // namespace frappe::vc4
