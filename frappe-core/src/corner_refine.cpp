// SPDX-License-Identifier: MIT
// CORNER_REFINE: sub-pixel corners from straight-line fits to the four sides.
//
// Each side is measured along image columns (sides nearer horizontal) or rows
// (nearer vertical), at whole pixels: no interpolation, and integer arithmetic
// from the pixels to the line's sums. Call u the axis along the side (x for a
// flat side) and v the axis across it. At a column u, the pixels along v
// cross the side's light-to-dark step; the centroid of the falls between
// consecutive pixels lies exactly where the column crosses the edge line, for
// any sub-pixel phase and any symmetric blur: pixels integrate over their
// area, so the falls sum the edge's profile exactly, and across a slanted
// edge the pixel's footprint only widens that profile symmetrically. The
// crossings (u, v) are fitted by weighted least squares of v on u (u is
// exact, v carries the error), and the corners are the intersections of
// adjacent lines.
//
// The falls are cut to a window, since neighbouring edges (code cells, the
// quiet zone's outer edge) lie a cell away on small markers. A window placed
// on the steepest pixel would pull every crossing towards the pixel grid,
// so the window is centred on a first centroid, with fractional weights at
// its ends.
//
// Two passes: a wide one from the tracer's corners with few columns, then a
// narrow one with more columns from corners that are now within a fraction of
// a pixel, so its columns stay clear of the corners exactly.
#include "corner_refine.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace frappe::detail {

namespace {

struct Line {
	/* Points p with n . p = c, |n| = 1. */
	double nx, ny, c;
};

constexpr int kCoarsePoints = 12; /* columns per side, first pass */
constexpr int kFinePoints = 48;  /* columns per side, second pass */
/* How far (pixels along the column) the falls may extend beyond the two
 * differences at the steepest point: a blurred edge spreads over a few
 * pixels, but more lets noise and neighbouring edges in. */
constexpr int kRun = 3;
/* Half the final window, in 1/16 pixel, plus half a pixel: the window is
 * 1.5 px either side of the first centroid, and a difference (a pixel wide)
 * counts by how much of it lies inside. */
constexpr int kWindow16 = 32;
constexpr int kMaxReach = 23; /* search window, pixels either side */
constexpr int kMaxProfile = 2 * (kMaxReach + kRun + 1) + 1;
/* Steepest fall over two pixels below which a column is noise, not edge. */
constexpr int kMinDrop = 6;

/* floor and ceil with conversions only (ARMv6 has no rounding instruction,
 * and these run a few times per side). */
inline int floorInt(float x)
{
	const int i = static_cast<int>(x);
	return static_cast<float>(i) > x ? i - 1 : i;
}
inline int ceilInt(float x)
{
	const int i = static_cast<int>(x);
	return static_cast<float>(i) < x ? i + 1 : i;
}

/* The edge's crossing of one column. p(j) is the pixel j steps inwards of
 * the side's nearest pixel, for |j| <= kLo/kHi's reach + kRun + 1; the
 * steepest fall is looked for at kLo..kHi. Returns the windowed falls' total
 * w (0: no edge) and their moment2, so that the crossing is at
 * moment2 / (2 w) steps, both in sixteenths of the falls. */
template <typename Pixel>
inline int measureColumn(Pixel p, int kLo, int kHi, int &moment2Out)
{
	/* Strongest fall in intensity going inwards (white border outside,
	 * black frame inside); rises belong to other edges. */
	int best = 0, bestDrop = 0;
	for (int k = kLo; k <= kHi; ++k) {
		const int drop = p(k - 1) - p(k + 1);
		if (drop > bestDrop) {
			bestDrop = drop;
			best = k;
		}
	}
	if (bestDrop < kMinDrop)
		return 0;
	/* The falls around it: the two differences at the peak, extended while
	 * the intensity keeps falling, at most kRun pixels. The difference
	 * p(k) - p(k + 1) lies at k + 1/2. */
	int lo = best - 1, hi = best + 1;
	int prev = p(lo);
	for (int next; lo > best - 1 - kRun && (next = p(lo - 1)) > prev; prev = next)
		--lo;
	prev = p(hi);
	for (int next; hi <= best + kRun && prev > (next = p(hi + 1)); prev = next)
		++hi;
	/* falls[i] at lo + i; hi is one past the last. */
	int falls[2 * kRun + 2];
	int mass = 0, moment2 = 0;
	prev = p(lo);
	for (int k = lo; k < hi; ++k) {
		const int next = p(k + 1);
		const int fall = std::max(prev - next, 0);
		prev = next;
		falls[k - lo] = fall;
		mass += fall;
		moment2 += fall * (2 * k + 1);
	}
	/* Their centroid, in 1/16 pixel (rounded), centres the window. */
	const int c16 = (8 * moment2 + (moment2 >= 0 ? mass / 2 : -mass / 2)) / mass;
	int wMass = 0, wMoment2 = 0;
	for (int k = lo; k < hi; ++k) {
		const int f16 = std::clamp(kWindow16 - std::abs(16 * k + 8 - c16), 0, 16);
		const int wf = f16 * falls[k - lo];
		wMass += wf;
		wMoment2 += wf * (2 * k + 1);
	}
	moment2Out = wMoment2;
	return wMass;
}

/* Measures one side from a to b (clockwise quad, so the marker interior is
 * on the right of a->b on screen). */
bool fitSide(const ImageView &img, Point2f a, Point2f b, float search, int maxPoints, Line &line)
{
	const float dx = b.x - a.x, dy = b.y - a.y;
	const float len = std::sqrt(dx * dx + dy * dy);
	if (len < 2.0f || img.width < 1 || img.height < 1)
		return false;
	/* u along the side's dominant axis, v across it. */
	const bool flat = std::abs(dx) >= std::abs(dy);
	const float au = flat ? a.x : a.y, av = flat ? a.y : a.x;
	const float du = flat ? dx : dy, dv = flat ? dy : dx;
	/* The inward normal is (-dy, dx) / len; its v component says which way
	 * along the column is inwards, its size how much of the normal one pixel
	 * of column covers (at least 1/sqrt(2)). */
	const float nv = (flat ? dx : -dy) / len;
	const int dir = nv > 0.0f ? 1 : -1;
	const float cosV = std::abs(nv);
	const int uDim = flat ? img.width : img.height, vDim = flat ? img.height : img.width;
	/* One step along u or v, in bytes; along v inwards. */
	const std::ptrdiff_t uStep = flat ? 1 : img.stride, vStep = flat ? img.stride : 1;
	const std::ptrdiff_t step = dir * vStep;

	/* Stay clear of the corners, where the neighbouring side interferes. */
	const float margin = std::max(1.5f, 0.12f * len);
	if (len <= 2.0f * margin)
		return false;
	const float marginU = margin * cosV;
	const int u0 = ceilInt(std::min(au, au + du) + marginU);
	const int u1 = floorInt(std::max(au, au + du) - marginU);
	const int count = u1 - u0 + 1;
	if (count < 3)
		return false;
	const int nPoints = std::min(count, maxPoints);

	/* The side's v at column u, in 16.16 fixed point: it only places the
	 * window and checks the search distance, so its rounding is harmless. */
	const float slope = dv / du;
	const std::int32_t vFix0 = floorInt((av + (static_cast<float>(u0) - au) * slope) * 65536.0f + 0.5f);
	const std::int32_t slopeFix = floorInt(slope * 65536.0f + 0.5f);
	const int vRef = (vFix0 + 32768) >> 16;
	/* The steepest fall may lie up to search - 1/2 from the side along its
	 * normal (as when profiles were sampled along it in half pixels), its
	 * centroid up to search; in pixels along the column, 16.16. */
	const float peakV = std::max(0.0f, search - 0.5f) / cosV;
	const std::int32_t peakFix = floorInt(std::min(peakV, static_cast<float>(kMaxReach) - 0.5f) * 65536.0f);
	const std::int64_t reachFix = static_cast<std::int64_t>(search / cosV * 65536.0f);
	const int reach = ceilInt(std::min(peakV, static_cast<float>(kMaxReach) - 0.5f) + 0.5f);
	const int half = reach + kRun + 1; /* the profile: -half..half */

	/* Columns spread evenly, in 16.16 steps (one division per side). */
	const std::int32_t stepFix = (count << 16) / nPoints;
	std::int32_t accFix = stepFix >> 1;

	/* Weighted sums over the crossings, weight = the windowed falls' total
	 * w; with U = u - u0 and q = 2 w (v - vRef) they are all integers. */
	std::int64_t sw = 0, su = 0, suu = 0, sq = 0, suq = 0;
	int used = 0;
	int buf[kMaxProfile];
	int *const p = buf + half; /* near the image border: p[j], the pixel j steps inwards of the side, clamped */
	for (int i = 0; i < nPoints; ++i, accFix += stepFix) {
		const int U = accFix >> 16;
		const int u = u0 + U;
		const std::int32_t vFix = vFix0 + slopeFix * U;
		const int vc = (vFix + 32768) >> 16;
		const std::int32_t frac = dir * (vFix - (vc << 16)); /* the side at p[frac], |frac| <= 1/2 */
		const int kLo = (frac - peakFix + 65535) >> 16, kHi = (frac + peakFix) >> 16;
		int wMass, wMoment2 = 0;
		if (u >= 0 && u < uDim && vc - half >= 0 && vc + half < vDim) {
			const std::uint8_t *px = img.data + u * uStep + vc * vStep;
			wMass = measureColumn([px, step](int j) { return static_cast<int>(px[j * step]); }, kLo, kHi,
					      wMoment2);
		} else {
			/* Clamped to the image, as a bilinear sampler would. */
			const int uc = std::clamp(u, 0, uDim - 1);
			for (int j = -half; j <= half; ++j)
				p[j] = img.data[uc * uStep + std::clamp(vc + dir * j, 0, vDim - 1) * vStep];
			wMass = measureColumn([p](int j) { return p[j]; }, kLo, kHi, wMoment2);
		}
		if (wMass <= 0)
			continue;
		/* The crossing is at vc + dir * wMoment2 / (2 wMass); it must lie
		 * within the search of the side. Both sides times 2 wMass 2^16. */
		const std::int64_t m2 = 2 * static_cast<std::int64_t>(wMass);
		const std::int64_t off = m2 * ((static_cast<std::int64_t>(vc) << 16) - vFix) +
					 static_cast<std::int64_t>(dir * wMoment2) * 65536;
		if ((off < 0 ? -off : off) > m2 * reachFix)
			continue;
		const std::int64_t q = m2 * (vc - vRef) + dir * wMoment2;
		sw += wMass;
		su += static_cast<std::int64_t>(wMass) * U;
		suu += static_cast<std::int64_t>(wMass) * U * U;
		sq += q;
		suq += q * U;
		++used;
	}
	if (used < 3 || used * 2 < nPoints)
		return false;
	/* v = vRef + meanV + m (u - u0 - meanU), by weighted least squares. */
	const double w = static_cast<double>(sw);
	const double den = w * static_cast<double>(suu) - static_cast<double>(su) * static_cast<double>(su);
	if (den <= 0.0)
		return false;
	const double m = (w * static_cast<double>(suq) - static_cast<double>(su) * static_cast<double>(sq)) / (2.0 * den);
	const double meanU = static_cast<double>(su) / w, meanV = static_cast<double>(sq) / (2.0 * w);
	/* As n . (u, v) = c with n = (-m, 1) / |(-m, 1)|, then back to (x, y). */
	const double norm = 1.0 / std::sqrt(1.0 + m * m);
	const double nu = -m * norm;
	line.c = (static_cast<double>(vRef) + meanV - m * (static_cast<double>(u0) + meanU)) * norm;
	line.nx = flat ? nu : norm;
	line.ny = flat ? norm : nu;
	return true;
}

bool intersect(const Line &l1, const Line &l2, Point2f &p)
{
	const double det = l1.nx * l2.ny - l1.ny * l2.nx;
	if (std::abs(det) < 1e-6)
		return false;
	p.x = static_cast<float>((l1.c * l2.ny - l1.ny * l2.c) / det);
	p.y = static_cast<float>((l1.nx * l2.c - l1.c * l2.nx) / det);
	return true;
}

bool refineOnce(const ImageView &img, std::array<Point2f, 4> &q, float search, int maxPoints)
{
	Line lines[4];
	for (int i = 0; i < 4; ++i) {
		if (!fitSide(img, q[i], q[(i + 1) & 3], search, maxPoints, lines[i]))
			return false;
	}
	std::array<Point2f, 4> r;
	for (int i = 0; i < 4; ++i) {
		/* Corner i joins side i-1 (ending at it) and side i (starting at it). */
		if (!intersect(lines[(i + 3) & 3], lines[i], r[i]))
			return false;
		const float dx = r[i].x - q[i].x, dy = r[i].y - q[i].y;
		if (dx * dx + dy * dy > 4.0f * search * search + 4.0f)
			return false;
	}
	q = r;
	return true;
}

} // namespace

bool refineCorners(const ImageView &image, std::array<Point2f, 4> &corners, float search)
{
	std::array<Point2f, 4> q = corners;
	/* The wide first pass only has to place the sides roughly: few points. */
	if (!refineOnce(image, q, search, kCoarsePoints))
		return false;
	/* A second, narrow pass: the sides are now well placed, so the
	 * measurement points avoid the corners exactly and the window shrinks. */
	refineOnce(image, q, std::min(search, 1.5f), kFinePoints);
	corners = q;
	return true;
}

} // namespace frappe::detail
