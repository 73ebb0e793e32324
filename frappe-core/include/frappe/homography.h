// SPDX-License-Identifier: MIT
// frappe/homography.h: the plane-to-plane maps used by the warp and the
// marker renderer.
#pragma once

#include "frappe/export.h"

#include <array>
#include <optional>

#include "frappe/image.h"

namespace frappe {

/// A 3x3 projective map, row-major, applied to (x, y, 1).
struct FRAPPE_EXPORT Homography {
	std::array<double, 9> h{ 1, 0, 0, 0, 1, 0, 0, 0, 1 };

	Point2f map(double x, double y) const
	{
		const double w = h[6] * x + h[7] * y + h[8];
		return { static_cast<float>((h[0] * x + h[1] * y + h[2]) / w),
			 static_cast<float>((h[3] * x + h[4] * y + h[5]) / w) };
	}

	/// The map taking the unit square's corners (0,0), (1,0), (1,1), (0,1)
	/// to q[0..3]. Empty when three of the points are collinear.
	static std::optional<Homography> fromUnitSquare(const std::array<Point2f, 4> &q);
	/// The inverse map; empty when singular.
	std::optional<Homography> inverse() const;
};

} // namespace frappe
