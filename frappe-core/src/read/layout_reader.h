// SPDX-License-Identifier: MIT
// Reading a marker of a layout family (frappe/layout.h) from its samples:
// one at the centre of each cell of the layout and of the ring around it,
// warped from the detected square's homography extended to the whole grid.
#pragma once

#include <array>
#include <cstdint>

#include "decode.h"
#include "frappe/layout.h"
#include "verify.h"

namespace frappe::detail {

/// Samples a side of a layout's grid: its cells and the ring around them,
/// one sample each (at most 16, what the QPU warp computes).
inline int layoutGridSide(const MarkerLayout &layout)
{
	return layout.size + 2;
}

/// The corners of the quad whose CandidateSamples grid of layoutGridSide()
/// samples puts one at the centre of every cell, from the detected square's
/// clockwise corners. False when the square is degenerate.
bool layoutGrid(const std::array<Point2f, 4> &square, const MarkerLayout &layout, std::array<Point2f, 4> &grid);

/// A layout's cells read against a threshold that follows the light: planes
/// fitted to the two rings beside the square's edge (black and white by
/// construction), the threshold halfway between them at each cell. Where
/// a cell that must be black clips (samples at or above `clip`: glare), every
/// clipped cell is unknown: no ring or plain evidence, a weak bit.
struct LayoutCells {
	std::uint64_t code = 0;
	std::uint64_t weak = 0;  ///< bits read weakly, in the code's order
	int ringErrors = 0;      ///< cells of the two rings on the wrong side
	int ringCells = 0;       ///< cells of the two rings read (not unknown)
	int ringUnknown = 0;     ///< cells of the two rings clipped under glare
	/// The other cells that are no bits (always black, or of no matter:
	/// a circle family's corners) read clearly (margin at least the weak
	/// margin), and those of them that read light.
	int plainCells = 0;
	int plainLight = 0;
	float contrast = 0.0f;   ///< the white ring's mean less the black ring's
	float margin = 0.0f;     ///< the weakest bit's distance from its threshold over half the contrast
};
LayoutCells readLayoutCells(const WarpedMarker &grid, const MarkerLayout &layout, float weakMargin, float clip);

/// Whether the two rings beside the square read three quarters right, on
/// the samples as warped: a cheap look before refining a guessed square.
bool ringsNearlyWhole(const WarpedMarker &grid, const MarkerLayout &layout);

/// Decodes and checks a read: enough contrast, rings nearly whole, the
/// plain cells beyond them one colour but for one in eight (black as
/// libapriltag draws them, or a circle family's paper), at most
/// policy.maxHamming clear bits corrected (policy.maxTotal with weak ones),
/// an id clearly nearer than any other.
MarkerRead decodeLayout(const LayoutCells &cells, const CodeBook &codes, const DecodePolicy &policy);

} // namespace frappe::detail
