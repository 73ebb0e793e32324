// SPDX-License-Identifier: MIT
// frappe/marker.h: what the detector reports.
#pragma once

#include <array>
#include <cstdint>

#include "frappe/image.h"

namespace frappe {

/// One decoded marker.
struct Marker {
	int id = -1;
	/// Outer corners of the black border, sub-pixel, in OpenCV's order:
	/// top-left, top-right, bottom-right, bottom-left of the marker in its
	/// canonical orientation (clockwise on screen). (0, 0) is the centre of
	/// the top-left pixel.
	std::array<Point2f, 4> corners{};
	/// Bits corrected to reach the codeword.
	int hamming = 0;
	/// How clearly the code was read, in [0, 1]: over the code cells, the
	/// smallest distance of a cell's mean grey level from the threshold
	/// between black and white, as a fraction of half the black-white
	/// contrast. 1: every cell is as dark as the darkest sample or as light
	/// as the lightest; near 0: some cell was nearly a coin toss (blur, a
	/// glint, a cell cut by the edge of a shadow). Filter on it to trade
	/// misses for certainty.
	float margin = 0.0f;
	/// Mode::Track: the marker was found where earlier frames predicted it
	/// (its corners are still measured on this frame, never extrapolated);
	/// false when it was found afresh, and in the other modes.
	bool tracked = false;
};

} // namespace frappe
