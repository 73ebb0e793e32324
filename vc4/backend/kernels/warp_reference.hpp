// SPDX-License-Identifier: MIT
// The perspective warp as the QPU computes it, in plain C++: the bit-exact reference of
// the warp kernel (warp.hpp). Integer arithmetic only, so that the ARM, x86 and the
// QPUs agree to the bit:
//
//   sample (i, j), 0 <= i, j < 16, lies at unit-square coordinates ((i + 0.5) / side,
//   (j + 0.5) / side) (frappe-core's warpMarker convention). On that grid the homography
//   is three linear forms, quantised once per candidate by warpParams():
//     N_x(i,j) = x.at00 + x.di * i + x.dj * j      (numerator of x - ox, scaled)
//     N_y(i,j) = y.at00 + y.di * i + y.dj * j
//     D(i,j)   = d.at00 + d.di * i + d.dj * j      (0 < D < 2^20 on the whole grid)
//   position, 10 fraction bits:  X = ox * 2^10 + floor(2^10 * clamp(N_x, 0, 2^11 D - 1) / D)
//   clamped to the image:        X = clamp(X, 0, (width - 1) * 2^10)
//   cell and weight:             x0 = min(X >> 10, width - 2),  fx = X - x0 * 2^10  (0..1024)
//   bilinear, exact:             v = (p00 (1024 - fx) + p01 fx) (1024 - fy) + (p10 (1024 - fx) + p11 fx) fy
//   sample:                      (v + 2^19) >> 20
// The division is what the QPU does with 21 restoring-division steps; everything else is
// 32-bit integer arithmetic that cannot overflow for parameters warpParams() accepts.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "frappe/image.h"

namespace frappe::vc4::kernels {

inline constexpr int kWarpSide = 16;        // samples per side the kernel computes
inline constexpr int kWarpSamples = kWarpSide * kWarpSide;
inline constexpr int kWarpFracBits = 10;    // of positions and bilinear weights
inline constexpr int kWarpIntBits = 11;     // position minus origin: 0 .. 2047 pixels
inline constexpr int kWarpDivisionSteps = kWarpIntBits + kWarpFracBits;
inline constexpr int64_t kWarpDenominatorLimit = int64_t{1} << 20; // exclusive
inline constexpr int kWarpMaxCandidates = 32;

// A linear form over the sample grid: at00 + di * i + dj * j.
struct WarpForm {
	int32_t at00 = 0;
	int32_t di = 0;
	int32_t dj = 0;
	int64_t at(int i, int j) const { return int64_t{at00} + int64_t{di} * i + int64_t{dj} * j; }
};

struct WarpParams {
	WarpForm x, y, d;
	int32_t ox = 0, oy = 0; // integer pixel origin of the positions
};

// Quantises the homography taking the unit square to `corners` (top-left, top-right,
// bottom-right, bottom-left; pixel centres at integers) for a marker of `side` samples a
// side (side <= 16; (bits + 2) * 2 in frappe-core). Empty, with the reason in `why`,
// when the quad is degenerate or too large/too oblique for the fixed-point ranges; the
// caller then warps that candidate on the CPU.
std::optional<WarpParams> warpParams(const std::array<Point2f, 4> &corners, int side = kWarpSide,
                                     std::string *why = nullptr);

// 16 x 16 samples, row-major. The image must be at least 2 x 2 pixels.
void warpReference(const ImageView &image, const WarpParams &p, std::span<uint8_t, kWarpSamples> out);

// The same before the final rounding: 2^20 units per grey level (for accuracy studies).
void warpReferenceFixed(const ImageView &image, const WarpParams &p, std::span<uint32_t, kWarpSamples> out);

} // namespace frappe::vc4::kernels
