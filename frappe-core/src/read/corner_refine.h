// SPDX-License-Identifier: MIT
// CORNER_REFINE: sub-pixel corners from the four sides of a candidate.
#pragma once

#include <array>
#include <cstdint>

#include "frappe/image.h"

namespace frappe::detail {

/// How much of an edge's profile a column's crossing is measured from: the
/// falls at most `run` pixels beyond the steepest pair, weighted by a window
/// of `window16` / 16 - 1/2 pixels either side of their first centroid. The
/// defaults suit sharp and slightly blurred edges next to code cells a few
/// pixels away; a wider window stays unbiased on an edge blurred over many
/// pixels (run at most 8).
///
/// With `symmetric`, the window also reaches no further from the centroid
/// than the falls do on its other side, and is centred again on the new
/// centroid `passes` times in all. A blurred edge next to another (a
/// one-cell quiet zone, a code cell) has its falls cut short on that side,
/// which pulls a plain window's centroid away from it; a cut matched on
/// the other side keeps a symmetric profile's centroid in place. On sharp
/// edges it only narrows the window (more noise): for wide windows.
struct RefineWindow {
	int run = 3;
	int window16 = 32;
	bool symmetric = false;
	int passes = 1; ///< 1..4
};

/// Which code measures the sides' columns: the vector kernel (Highway's best
/// target, where the library is built with it) or the scalar reference,
/// always compiled. Both give the same corners to the bit.
enum class RefineKernels {
	Best,
	Scalar,
};

/// Refines the corners of a clockwise quadrilateral on the full-resolution
/// image. Each side is re-measured: along its normal, at points spread over
/// the side, the strongest light-to-dark step going inwards is located to a
/// fraction of a pixel; a line is fitted through those points, and the
/// corners become the intersections of adjacent lines. Fitting whole sides
/// uses hundreds of pixels per corner, so it stays accurate under blur and
/// noise where a 2D corner search (cornerSubPix) drifts on small markers.
///
/// `search` is how far (pixels) the true side may lie from the initial one.
/// Returns false when a side cannot be measured; the corners are then
/// unchanged.
bool refineCorners(const ImageView &image, std::array<Point2f, 4> &corners, float search,
		   const RefineWindow &window = {}, RefineKernels kernels = RefineKernels::Best);

/// What pulls each column's crossing of a side off the edge, known from
/// the marker's pattern: side k (corners k to k + 1) at fraction t of its
/// length from corner k is measured d[k][t * kSteps] px too far inwards
/// (along the side's normal; negative: outwards).
struct SideOffsets {
	static constexpr int kSteps = 64;
	std::array<std::array<float, kSteps>, 4> d{};
};

/// One more narrow pass of refineCorners() (RefineWindow's defaults) from
/// corners already within a fraction of a pixel, each column's crossing
/// moved back by `offsets`.
bool refineCornersOffset(const ImageView &image, std::array<Point2f, 4> &corners, float search,
			 const SideOffsets &offsets, RefineKernels kernels = RefineKernels::Best);

} // namespace frappe::detail
