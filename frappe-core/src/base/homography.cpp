// SPDX-License-Identifier: MIT
#include "frappe/homography.h"

#include <cmath>

namespace frappe {

std::optional<Homography> Homography::fromUnitSquare(const std::array<Point2f, 4> &q)
{
	/* Heckbert's closed form for the square-to-quadrilateral projection. */
	const double x0 = q[0].x, y0 = q[0].y, x1 = q[1].x, y1 = q[1].y;
	const double x2 = q[2].x, y2 = q[2].y, x3 = q[3].x, y3 = q[3].y;
	const double sx = x0 - x1 + x2 - x3, sy = y0 - y1 + y2 - y3;
	const double dx1 = x1 - x2, dx2 = x3 - x2, dy1 = y1 - y2, dy2 = y3 - y2;
	const double den = dx1 * dy2 - dx2 * dy1;
	if (std::abs(den) < 1e-12)
		return std::nullopt;
	const double g = (sx * dy2 - dx2 * sy) / den;
	const double hh = (dx1 * sy - sx * dy1) / den;
	Homography H;
	H.h = { x1 - x0 + g * x1, x3 - x0 + hh * x3, x0,
		y1 - y0 + g * y1, y3 - y0 + hh * y3, y0,
		g, hh, 1.0 };
	return H;
}

std::optional<Homography> Homography::inverse() const
{
	const auto &m = h;
	const double c00 = m[4] * m[8] - m[5] * m[7];
	const double c01 = m[5] * m[6] - m[3] * m[8];
	const double c02 = m[3] * m[7] - m[4] * m[6];
	const double det = m[0] * c00 + m[1] * c01 + m[2] * c02;
	if (std::abs(det) < 1e-15)
		return std::nullopt;
	const double k = 1.0 / det;
	Homography r;
	r.h = { c00 * k, (m[2] * m[7] - m[1] * m[8]) * k, (m[1] * m[5] - m[2] * m[4]) * k,
		c01 * k, (m[0] * m[8] - m[2] * m[6]) * k, (m[2] * m[3] - m[0] * m[5]) * k,
		c02 * k, (m[1] * m[6] - m[0] * m[7]) * k, (m[0] * m[4] - m[1] * m[3]) * k };
	return r;
}

} // namespace frappe
