// SPDX-License-Identifier: MIT
// frappe/fixed_warp.h: the perspective warp's arithmetic, defined once in
// integers, so that every backend (the CPU's scalar and vector code, the
// VC4's QPU kernel) computes the same samples to the bit.
//
// The contract. Sample (i, j), 0 <= i, j < side, lies at unit-square
// coordinates ((i + 0.5) / side, (j + 0.5) / side) (CandidateSamples' grid).
// On that grid the quad's homography is three linear forms, quantised once
// per quad by quantiseWarp() (the only floating-point step, identical for
// every backend because they all call it):
//   N_x(i, j) = x.at00 + x.di i + x.dj j       numerator of x - ox
//   N_y(i, j) = y.at00 + y.di i + y.dj j       numerator of y - oy
//   D(i, j)   = d.at00 + d.di i + d.dj j       0 < D < 2^20 on the grid
// position, 10 fraction bits:
//   X = ox 2^10 + floor(2^10 clamp(N_x, 0, 2^11 D - 1) / D),
//   X = clamp(X, 0, (width - 1) 2^10)
// cell and weight: x0 = min(X >> 10, width - 2), fx = X - x0 2^10 (0 .. 1024);
// the same for y. Bilinear, exact:
//   v = (p00 (1024 - fx) + p01 fx) (1024 - fy) + (p10 (1024 - fx) + p11 fx) fy
// sample = (v + 2^19) >> 20, an integer grey level 0 .. 255 (what the
// candidate warp and the QPU kernel give), or, for the warps only the CPU
// runs (the probe's cell centres, warpCellCentres), where sharpening would
// amplify that rounding, the fine sample v 2^-20 rounded to float.
// The image must be at least 2 x 2 pixels. Quads the fixed point cannot
// hold are refused; frappe-core then warps them in float (warpToGrid's one
// fallback), and so does every backend, through the CPU's warper.
#pragma once

#include "frappe/export.h"

#include <array>
#include <cstdint>
#include <optional>

#include "frappe/image.h"

namespace frappe {

inline constexpr int kFixedWarpFracBits = 10; ///< of positions and weights
inline constexpr int kFixedWarpIntBits = 11; ///< position minus origin: 0 .. 2047 px
inline constexpr std::int64_t kFixedWarpDenominatorLimit = std::int64_t{ 1 } << 20; ///< exclusive

/// A linear form over the sample grid: at00 + di i + dj j.
struct FixedWarpForm {
	std::int32_t at00 = 0;
	std::int32_t di = 0;
	std::int32_t dj = 0;
	std::int64_t at(int i, int j) const
	{
		return std::int64_t{ at00 } + std::int64_t{ di } * i + std::int64_t{ dj } * j;
	}
};

/// One quad's warp, quantised for a grid of `side` samples a side.
struct FixedWarp {
	FixedWarpForm x, y, d;
	std::int32_t ox = 0, oy = 0; ///< integer pixel origin of the positions
	int side = 0;
};

/// Quantises the homography taking the unit square to `corners` (clockwise
/// from the grid's top-left, pixel centres at integers) for a grid of
/// `side` (1 .. CandidateSamples::kMaxSide) samples a side. Empty, with the
/// reason in `why` when given, when the quad is degenerate, reaches the
/// horizon, or is too large or too oblique for the fixed-point ranges.
FRAPPE_EXPORT std::optional<FixedWarp> quantiseWarp(const std::array<Point2f, 4> &corners, int side,
						    const char **why = nullptr);

/// Sample (i, j) by the contract above, with 64-bit integer division: the
/// definition every faster form is tested against. i and j may exceed the
/// grid (a backend computing a wider grid) as long as the forms stay in range
/// there (0 < D < 2^20).
FRAPPE_EXPORT std::uint8_t fixedWarpSample(const ImageView &image, const FixedWarp &warp, int i, int j);
/// v of sample (i, j), 2^20 units a grey level, before any rounding.
FRAPPE_EXPORT std::uint32_t fixedWarpValue(const ImageView &image, const FixedWarp &warp, int i, int j);

} // namespace frappe
