// SPDX-License-Identifier: MIT
// The measures of a quadrilateral that the back end's stages share: its
// sides, area, centre and cell size, and the mapping of its corners between
// the scales a frame is read at.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

#include "frappe/image.h"

namespace frappe::detail {

/* Corners clockwise on screen, or anticlockwise: the measures below do not
 * depend on the direction. */
using QuadCorners = std::array<Point2f, 4>;

inline float dist2(Point2f a, Point2f b)
{
	const float dx = a.x - b.x, dy = a.y - b.y;
	return dx * dx + dy * dy;
}

/* Which way a -> b -> c turns: 1 or -1, 0 when the three are collinear or
 * two coincide. In double, where float coordinates multiply exactly. */
inline int turnSign(Point2f a, Point2f b, Point2f c)
{
	const double turn = (static_cast<double>(b.x) - a.x) * (static_cast<double>(c.y) - b.y) -
			    (static_cast<double>(b.y) - a.y) * (static_cast<double>(c.x) - b.x);
	return turn > 0.0 ? 1 : turn < 0.0 ? -1 : 0;
}

/* Every three corners turn the same way, none by 0: a convex quad, as a
 * square seen in perspective is. */
inline bool convexQuad(const QuadCorners &q)
{
	const int sign = turnSign(q[0], q[1], q[2]);
	for (int i = 1; i < 4; ++i)
		if (turnSign(q[i], q[(i + 1) & 3], q[(i + 2) & 3]) != sign)
			return false;
	return sign != 0;
}

/* Where the lines y = v (byRows) or x = v cross a convex quad: its four
 * sides as u = u0 + slope (v - v0) over [vLo, vHi], slopes computed once. */
class QuadSpans {
public:
	QuadSpans(const std::array<Point2f, 4> &q, bool byRows)
	{
		for (int i = 0; i < 4; ++i) {
			const Point2f &a = q[i], &b = q[(i + 1) & 3];
			const float au = byRows ? a.x : a.y, av = byRows ? a.y : a.x;
			const float bu = byRows ? b.x : b.y, bv = byRows ? b.y : b.x;
			Side &s = sides_[i];
			s.vLo = std::min(av, bv);
			s.vHi = std::max(av, bv);
			s.flat = av == bv;
			s.u0 = s.flat ? std::min(au, bu) : au;
			s.u1 = std::max(au, bu);
			s.v0 = av;
			s.slope = s.flat ? 0.0f : (bu - au) / (bv - av);
		}
	}
	/* False when the line misses the quad. */
	bool span(float v, float &lo, float &hi) const
	{
		lo = 1e30f;
		hi = -1e30f;
		for (const Side &s : sides_) {
			if (v < s.vLo || v > s.vHi)
				continue;
			const float u = s.flat ? s.u0 : s.u0 + s.slope * (v - s.v0);
			lo = std::min(lo, u);
			hi = std::max(hi, s.flat ? s.u1 : u);
		}
		return lo <= hi;
	}

private:
	struct Side {
		float vLo, vHi, u0, u1, v0, slope;
		bool flat;
	};
	std::array<Side, 4> sides_;
};

/* A quad's bounding box. */
struct QuadBox {
	float x0, y0, x1, y1;
};
inline QuadBox quadBox(const QuadCorners &q)
{
	QuadBox b{ q[0].x, q[0].y, q[0].x, q[0].y };
	for (const Point2f &p : q) {
		b.x0 = std::min(b.x0, p.x);
		b.x1 = std::max(b.x1, p.x);
		b.y0 = std::min(b.y0, p.y);
		b.y1 = std::max(b.y1, p.y);
	}
	return b;
}

/* The square of the shortest of a quad's four sides. */
inline float shortestSide2(const QuadCorners &q)
{
	float side2 = INFINITY;
	for (int i = 0; i < 4; ++i) {
		const float dx = q[i].x - q[(i + 1) & 3].x, dy = q[i].y - q[(i + 1) & 3].y;
		side2 = std::min(side2, dx * dx + dy * dy);
	}
	return side2;
}

inline bool sidesAtLeast(const QuadCorners &q, float side)
{
	return shortestSide2(q) >= side * side;
}

/* Large enough to read: sides of minSide on average, none under 0.6 of it
 * (a marker tilted 65 degrees is read across its foreshortened sides). */
inline bool bigEnough(const QuadCorners &q, float minSide)
{
	float sum = 0.0f;
	for (int i = 0; i < 4; ++i) {
		const float dx = q[i].x - q[(i + 1) & 3].x, dy = q[i].y - q[(i + 1) & 3].y;
		const float side = std::sqrt(dx * dx + dy * dy);
		if (side < 0.6f * minSide)
			return false;
		sum += side;
	}
	return sum >= 4.0f * minSide;
}

inline float quadArea(const QuadCorners &q)
{
	float twice = 0.0f;
	for (int i = 0; i < 4; ++i)
		twice += q[i].x * q[(i + 1) & 3].y - q[(i + 1) & 3].x * q[i].y;
	return 0.5f * std::abs(twice);
}

inline Point2f quadCentre(const QuadCorners &q)
{
	return { 0.25f * (q[0].x + q[1].x + q[2].x + q[3].x), 0.25f * (q[0].y + q[1].y + q[2].y + q[3].y) };
}

/* A quad's cell size, along its shortest side, for a code of bits x bits
 * cells inside a border of one. */
inline float cellSide(const QuadCorners &q, int bits)
{
	return std::sqrt(shortestSide2(q)) / static_cast<float>(bits + 2);
}

/* A point of a frame scaled by `scale` (traced, or halved into blocks) in
 * the frame's own pixels; pixel centres are at integers in both. */
inline Point2f toFullResolution(Point2f p, float scale)
{
	return { (p.x + 0.5f) / scale - 0.5f, (p.y + 0.5f) / scale - 0.5f };
}

/* The other way round, by a factor: a point in the pixels of the frame
 * scaled by `factor`. (Not toFullResolution(p, 1 / factor): the
 * reciprocal would round, and move corners by an ulp.) */
inline Point2f toScaled(Point2f p, float factor)
{
	return { (p.x + 0.5f) * factor - 0.5f, (p.y + 0.5f) * factor - 0.5f };
}

} // namespace frappe::detail
