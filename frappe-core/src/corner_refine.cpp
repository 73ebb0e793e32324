// SPDX-License-Identifier: MIT
#include "corner_refine.h"

#include <algorithm>
#include <cmath>

#include "sampling.h"

namespace frappe::detail {

namespace {

struct Line {
	/* Points p with n . p = c, |n| = 1. */
	double nx, ny, c;
};

constexpr int kMaxSamples = 48;  /* edge points per side, final pass */
constexpr int kCoarseSamples = 16; /* edge points per side, first pass */
constexpr int kMaxProfile = 64;  /* samples along one normal */
constexpr float kProfileStep = 0.5f;

/* sampleBilinear for 0 <= x <= width - 2, 0 <= y <= height - 2, where its
 * clamps do nothing: the same arithmetic, without them. */
inline float sampleInside(const ImageView &img, float x, float y)
{
	const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
	const float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
	const std::uint8_t *r0 = img.row(y0);
	const std::uint8_t *r1 = img.row(y0 + 1);
	const float top = static_cast<float>(r0[x0]) + fx * static_cast<float>(r0[x0 + 1] - r0[x0]);
	const float bot = static_cast<float>(r1[x0]) + fx * static_cast<float>(r1[x0 + 1] - r1[x0]);
	return top + fy * (bot - top);
}

/* Measures one side from a to b (clockwise quad, so the marker interior is
 * on the right of a->b on screen). */
bool fitSide(const ImageView &img, Point2f a, Point2f b, float search, int maxSamples, Line &line)
{
	const float dx = b.x - a.x, dy = b.y - a.y;
	const float len = std::sqrt(dx * dx + dy * dy);
	if (len < 2.0f)
		return false;
	const float ux = dx / len, uy = dy / len;
	const float nx = -uy, ny = ux; /* inward normal */

	/* Stay clear of the corners, where the neighbouring side interferes. */
	const float margin = std::max(1.5f, 0.12f * len);
	const float usable = len - 2.0f * margin;
	if (usable <= 0.0f)
		return false;
	const int nSamples = std::clamp(static_cast<int>(usable / 1.5f), 3, maxSamples);
	/* ceil without libm (ARMv6 has no rounding instruction) */
	const float steps = search / kProfileStep;
	int stepsUp = static_cast<int>(steps);
	stepsUp += static_cast<float>(stepsUp) < steps;
	const int half = std::min(kMaxProfile / 2 - 1, stepsUp + 1);

	/* The offsets along the normal, once. */
	float offsets[kMaxProfile];
	for (int k = 0; k < 2 * half + 1; ++k)
		offsets[k] = static_cast<float>(k - half) * kProfileStep;

	/* Where sampleInside may be used (-1: nowhere). */
	const float xMax = img.width >= 2 && img.height >= 2 ? static_cast<float>(img.width - 2) : -1.0f;
	const float yMax = img.width >= 2 && img.height >= 2 ? static_cast<float>(img.height - 2) : -1.0f;

	double sw = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
	int used = 0;
	float profile[kMaxProfile];
	for (int i = 0; i < nSamples; ++i) {
		const float t = margin + usable * (static_cast<float>(i) + 0.5f) / static_cast<float>(nSamples);
		const float px = a.x + ux * t, py = a.y + uy * t;
		const int n = 2 * half + 1;
		/* The samples lie on a segment, in order (float rounding is
		 * monotonic), so when both ends are at least a pixel inside the
		 * image all are, and sampleBilinear's clamps change nothing. */
		const float sA = offsets[0], sB = offsets[n - 1];
		const float xA = px + nx * sA, xB = px + nx * sB, yA = py + ny * sA, yB = py + ny * sB;
		if (xA >= 0.0f && xB >= 0.0f && xA <= xMax && xB <= xMax && yA >= 0.0f && yB >= 0.0f &&
		    yA <= yMax && yB <= yMax) {
			for (int k = 0; k < n; ++k)
				profile[k] = sampleInside(img, px + nx * offsets[k], py + ny * offsets[k]);
		} else {
			for (int k = 0; k < n; ++k)
				profile[k] = sampleBilinear(img, px + nx * offsets[k], py + ny * offsets[k]);
		}
		/* Strongest drop in intensity going inwards (white border outside,
		 * black frame inside); steps of the other sign belong to other edges. */
		int best = -1;
		float bestDrop = 0.0f;
		for (int k = 1; k < n - 1; ++k) {
			const float drop = profile[k - 1] - profile[k + 1];
			if (drop > bestDrop) {
				bestDrop = drop;
				best = k;
			}
		}
		/* Below ~4 grey levels per pixel it is noise, not an edge. */
		if (best < 2 || best > n - 3 || bestDrop < 4.0f)
			continue;
		/* The edge lies at the centroid of the intensity drop: exact for an
		 * area-sampled step whatever its sub-pixel phase, and unbiased under
		 * symmetric blur (a parabola through the peak is not: it pulls the
		 * estimate towards pixel-grid positions by up to a third of a pixel).
		 * The window is the run of falling samples around the peak, at most
		 * 3 px either side, so neighbouring edges stay out. */
		int lo = best, hi = best;
		while (lo > 1 && best - lo < 4 && profile[lo - 1] - profile[lo] > 0.0f)
			--lo;
		while (hi < n - 2 && hi - best < 4 && profile[hi] - profile[hi + 1] > 0.0f)
			++hi;
		float mass = 0.0f, moment = 0.0f;
		for (int k = lo - 1; k < hi + 1; ++k) {
			const float fall = profile[k] - profile[k + 1];
			if (fall <= 0.0f)
				continue;
			mass += fall;
			moment += fall * (static_cast<float>(k - half) + 0.5f);
		}
		const float s = moment / mass * kProfileStep;
		if (std::abs(s) > search)
			continue;
		const double ex = px + nx * s, ey = py + ny * s;
		const double wgt = bestDrop;
		sw += wgt;
		sx += wgt * ex;
		sy += wgt * ey;
		sxx += wgt * ex * ex;
		syy += wgt * ey * ey;
		sxy += wgt * ex * ey;
		++used;
	}
	if (used < 3 || used * 2 < nSamples)
		return false;
	/* Weighted total least squares: the normal is the covariance's
	 * eigenvector of the smaller eigenvalue. */
	const double mx = sx / sw, my = sy / sw;
	const double cxx = sxx / sw - mx * mx, cyy = syy / sw - my * my, cxy = sxy / sw - mx * my;
	/* The major axis is at theta = atan2(2 cxy, cxx - cyy) / 2, in
	 * (-pi/2, pi/2]; its cosine and sine from the half-angle formulas, with
	 * square roots only (one VFP instruction each; atan2, sin and cos are
	 * thousands of instructions in a soft-float libm). */
	const double d = cxx - cyy, e = 2.0 * cxy;
	const double r = std::sqrt(d * d + e * e);
	double cosT = 1.0, sinT = 0.0;
	if (r > 0.0) {
		if (d >= 0.0) {
			cosT = std::sqrt((r + d) / (2.0 * r));
			sinT = e / (2.0 * r * cosT);
		} else {
			sinT = std::copysign(std::sqrt((r - d) / (2.0 * r)), e);
			cosT = e / (2.0 * r * sinT);
		}
	}
	line.nx = -sinT;
	line.ny = cosT;
	line.c = line.nx * mx + line.ny * my;
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

bool refineOnce(const ImageView &img, std::array<Point2f, 4> &q, float search, int maxSamples)
{
	Line lines[4];
	for (int i = 0; i < 4; ++i) {
		if (!fitSide(img, q[i], q[(i + 1) & 3], search, maxSamples, lines[i]))
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
	if (!refineOnce(image, q, search, kCoarseSamples))
		return false;
	/* A second, narrow pass: the sides are now well placed, so the
	 * measurement points avoid the corners exactly and the window shrinks. */
	refineOnce(image, q, std::min(search, 1.5f), kMaxSamples);
	corners = q;
	return true;
}

} // namespace frappe::detail
