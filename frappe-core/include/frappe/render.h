// SPDX-License-Identifier: MIT
// frappe/render.h: drawing markers, for printing, tests and sample videos.
#pragma once

#include "frappe/export.h"

#include <array>
#include <cstdint>
#include <vector>

#include "frappe/dictionary.h"
#include "frappe/image.h"

namespace frappe {

/// A writable 8-bit plane.
struct MutableImageView {
	std::uint8_t *data = nullptr;
	int width = 0;
	int height = 0;
	int stride = 0;
	std::uint8_t *row(int y) const { return data + static_cast<std::ptrdiff_t>(y) * stride; }
	operator ImageView() const { return { data, width, height, stride }; }
};

struct RenderOptions {
	int quiet_cells = 1;      ///< white margin around the black border, in cells: 0..32768
	int supersample = 4;      ///< samples per pixel side (anti-aliasing): 1..256
	std::uint8_t black = 0;
	std::uint8_t white = 255;
};

/// Draws marker `id` so that the outer corners of its black border land on
/// `corners` (top-left, top-right, bottom-right, bottom-left in the marker's
/// canonical orientation; pixel centres at integers); for a dictionary with
/// a layout, the corners of its detected square (where its black ring meets
/// its white one: the corners the detector reports), the cells outside it
/// drawn beyond them. Through the
/// homography those corners define. Pixels are area-averaged, so edges fall
/// at their exact sub-pixel place. Throws std::out_of_range for an id not
/// in `dict`, and std::invalid_argument (the message says which argument
/// and why) for corners that are no perspective view of a square
/// (non-finite, three of them collinear or coincident, or not a convex
/// quadrilateral), an image of negative size, null data or a stride
/// smaller than its width, a supersample outside 1..256 or quiet_cells
/// outside 0..32768 (markerImage() refuses the same quiet_cells).
FRAPPE_EXPORT void renderMarker(MutableImageView image, const Dictionary &dict, int id,
		  const std::array<Point2f, 4> &corners, const RenderOptions &options = {});

/// Corners (top-left, top-right, bottom-right, bottom-left) of a square of
/// `side` pixels centred at (cx, cy), tilted by `tilt` degrees about its
/// horizontal axis, seen by a pinhole camera `distance` sides away whose
/// focal length keeps an untilted square `side` wide, then rolled by `roll`
/// degrees in the image plane. For test scenes and samples.
FRAPPE_EXPORT std::array<Point2f, 4> perspectiveSquare(float cx, float cy, float side, float roll, float tilt,
					 float distance = 4.0f);

/// An upright marker image, `cell_px` pixels a cell, with its quiet zone:
/// side = (cells + 2 * quiet_cells) * cell_px, cells = bits + 2 or the
/// layout's size. Throws
/// std::out_of_range for an id not in `dict`, and std::invalid_argument
/// for a cell_px under 1, a negative quiet_cells, or a side beyond 32768.
FRAPPE_EXPORT std::vector<std::uint8_t> markerImage(const Dictionary &dict, int id, int cell_px,
				      int quiet_cells, int &side);

} // namespace frappe
