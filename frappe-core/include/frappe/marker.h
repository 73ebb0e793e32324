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
};

} // namespace frappe
