// SPDX-License-Identifier: MIT
// PERSPECTIVE_WARP on the QPUs: up to 32 candidates a launch, 16 x 16 bilinear samples
// each, bit-exact with warpReference() (warp_reference.hpp). See warp.cpp for the design
// and for why binarise and decode stay on the ARM.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "asm/program.hpp"
#include "kernels/warp_reference.hpp"

namespace frappe::vc4::kernels {

// Uniforms: the 7 per-program values of kWarpProgramUniforms, then per candidate the
// 12 values of kWarpCandidateUniforms (warpUniforms() builds both).
qasm::Program warpKernel();

inline constexpr unsigned kWarpProgramUniforms = 7;
inline constexpr unsigned kWarpCandidateUniforms = 12;
inline constexpr unsigned kWarpOutputBytes = kWarpSamples; // per candidate, row-major u8

// The source image as the QPUs see it (8-bit luma, any stride).
struct WarpImage {
	uint32_t bus = 0;
	uint32_t stride = 0;
	int width = 0;
	int height = 0;
};

// Uniform streams for a launch: candidate k goes to program k % programs and writes its
// 256 samples to out_bus + 256 k. Returns min(programs, candidates) streams (run one QPU
// each); candidates.size() <= kWarpMaxCandidates.
// The same written into caller-owned streams (one per program, each room for
// kWarpProgramUniforms + kWarpCandidateUniforms * ceil(candidates / programs) words), so a
// launch allocates nothing. Returns the number of streams used.
unsigned writeWarpUniforms(const WarpImage &image, std::span<const WarpParams> candidates, uint32_t out_bus,
                           unsigned programs, std::span<uint32_t *const> streams);
std::vector<std::vector<uint32_t>> warpUniforms(const WarpImage &image, std::span<const WarpParams> candidates,
                                                uint32_t out_bus, unsigned programs = 12);

} // namespace frappe::vc4::kernels
