// SPDX-License-Identifier: MIT
// The contour tracer's data-parallel kernels, vectorised where Highway is
// built in: which pixels may start a border, each pixel's neighbours as one
// byte (so that a step of a border reads its neighbourhood with one load
// instead of assembling it from three rows), and how much of a quad's side
// a border covers.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "frappe/image.h"

namespace frappe::detail {

/// Label values the tracer uses (bit 0 set on every non-zero one; see
/// contour_trace.cpp): an edge pixel not yet on a followed border, one on a
/// followed border, and one whose right neighbour was found to be background
/// while following it.
constexpr std::uint8_t kUnfollowed = 1, kFollowed = 9, kFollowedRightBg = 25;

/// labels[i] = edges[i] & kUnfollowed for i in [0, n): an edge pixel not yet
/// on a followed border, or background.
void labelsFromEdges(const std::uint8_t *edges, std::size_t n, std::uint8_t *labels);

/// Bit d of out[x], for x in [x0, x1), is bit 0 of the neighbour of row[x]
/// in direction d: right, up-right, up, up-left, left, down-left, down,
/// down-right (counter-clockwise on screen). The rows above and below and
/// columns x0 - 1 and x1 must be readable. Masks left of x0, down to column
/// max(1, x1 - 64), may be rewritten too, with the same values.
void neighbourMasks(const std::uint8_t *row, std::ptrdiff_t stride, int x0, int x1, std::uint8_t *out);

/// Bit x - x0 of `bits` (64 a word, lowest first) set where a border may
/// start in the label row: an unfollowed pixel with background on its left
/// (an outer border), or a non-zero one not marked kFollowedRightBg with
/// background on its right (a hole border). Reads labels from x0 - 1 to
/// x0 + 64 * words + 1; bits from x1 on are clear.
void borderStartBits(const std::uint8_t *labels, int x0, int x1, std::uint64_t *bits);

/// A side of a candidate quad: points p on it have nx x + ny y = nc, and
/// ux x + uy y - t0 runs from 0 to kSideBins along it.
constexpr int kSideBins = 16;
struct SideLine {
	float nx, ny, nc, ux, uy, t0;

	/// The side from a to b (a != b).
	static SideLine between(Point2f a, Point2f b)
	{
		const float len = std::sqrt((b.x - a.x) * (b.x - a.x) + (b.y - a.y) * (b.y - a.y));
		SideLine side;
		side.nx = -(b.y - a.y) / len;
		side.ny = (b.x - a.x) / len;
		side.nc = side.nx * a.x + side.ny * a.y;
		side.ux = (b.x - a.x) / (len * len) * kSideBins;
		side.uy = (b.y - a.y) / (len * len) * kSideBins;
		side.t0 = side.ux * a.x + side.uy * a.y;
		return side;
	}
};

/// Bit b set when some point (x | y << 16) of pts[0, n) lies within `tol`
/// of the side's line, in its b-th sixteenth: |nx x + ny y - nc| <= tol and
/// b <= ux x + uy y - t0 < b + 1, in float arithmetic without fused
/// multiply-adds. pts must be readable to n + kPointsPadding.
std::uint32_t sideCoverage(const std::uint32_t *pts, std::size_t n, const SideLine &side, float tol);
constexpr std::size_t kPointsPadding = 16;

/// A border's extreme points, from which a quad is made when its corner
/// pixels do not give four corners: i0 the point farthest from the
/// centroid, i2 the point farthest from i0, i1 and i3 the points farthest
/// on either side of the diagonal i0-i2 (most > 0 and least < 0 the cross
/// products there, 0 when that side is empty). Every "farthest" is the first
/// such point. pts as for sideCoverage, n >= 1.
struct OutlineExtremes {
	std::size_t i0 = 0, i1 = 0, i2 = 0, i3 = 0;
	std::int32_t most = 0, least = 0;
};
OutlineExtremes outlineExtremes(const std::uint32_t *pts, std::size_t n);

/// The bounding box of points (x | y << 16) pts[0, n), n >= 1; pts as for
/// sideCoverage.
struct PointsBox {
	std::uint32_t minX, maxX, minY, maxY;
};
PointsBox pointsBox(const std::uint32_t *pts, std::size_t n);

/// The same without SIMD, the references the vectorised forms are tested
/// against.
void neighbourMasksScalar(const std::uint8_t *row, std::ptrdiff_t stride, int x0, int x1, std::uint8_t *out);
void borderStartBitsScalar(const std::uint8_t *labels, int x0, int x1, std::uint64_t *bits);
std::uint32_t sideCoverageScalar(const std::uint32_t *pts, std::size_t n, const SideLine &side, float tol);
OutlineExtremes outlineExtremesScalar(const std::uint32_t *pts, std::size_t n);
PointsBox pointsBoxScalar(const std::uint32_t *pts, std::size_t n);
void labelsFromEdgesScalar(const std::uint8_t *edges, std::size_t n, std::uint8_t *labels);

#if defined(__ARM_FEATURE_SIMD32) && defined(__ARM_FEATURE_DSP) && defined(__ARMEL__) && !defined(FRAPPE_HAVE_HWY)
#define FRAPPE_HAVE_ARMV6_TRACE 1
/// ARMv6 SIMD32 forms (trace_kernels_armv6.cpp), the scalar ones' results
/// exactly; the only ones used on such a build.
void labelsFromEdgesV6(const std::uint8_t *edges, std::size_t n, std::uint8_t *labels);
OutlineExtremes outlineExtremesV6(const std::uint32_t *pts, std::size_t n);
PointsBox pointsBoxV6(const std::uint32_t *pts, std::size_t n);
/// sideCoverage for points with x + y <= bound (the map's width plus
/// height): most points are rejected in integers first. With need > 0 the
/// scan stops once `need` bins are covered: the result is then a subset of
/// sideCoverage's with at least `need` bits, and sideCoverage's exactly
/// when that has fewer. The scan starts at point `first` (< n, or 0) and
/// wraps round.
std::uint32_t sideCoverageV6(const std::uint32_t *pts, std::size_t n, const SideLine &side, float tol, int bound,
			     int need = 0, std::size_t first = 0);
#endif

} // namespace frappe::detail
