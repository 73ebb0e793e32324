// SPDX-License-Identifier: MIT
// The camera model pose estimation works with: OpenCV's pinhole with its
// 4, 5 or 8 coefficient distortion, in closed form one way and inverted by
// Newton's method the other.
#pragma once

#include <array>

#include "frappe/camera.h"

namespace frappe::detail {

/// A 2x2 Jacobian, row-major: d(out x, out y) / d(in x, in y).
using Jacobian2 = std::array<double, 4>;

class Lens
{
public:
	explicit Lens(const Camera &camera);

	bool distorted() const { return distorted_; }

	/// Normalised (x/z, y/z) to distorted normalised coordinates; `jac`,
	/// when not null, receives the derivative.
	void distort(double x, double y, double &xd, double &yd, Jacobian2 *jac = nullptr) const;
	/// The inverse of distort(): false when it does not converge (far
	/// outside the calibrated field, where the model folds over).
	bool undistort(double xd, double yd, double &x, double &y) const;

	/// Distorted normalised coordinates to pixels and back (K and K^-1).
	void toPixel(double xd, double yd, double &u, double &v) const
	{
		u = fx_ * xd + skew_ * yd + cx_;
		v = fy_ * yd + cy_;
	}
	void fromPixel(double u, double v, double &xd, double &yd) const
	{
		yd = (v - cy_) / fy_;
		xd = (u - cx_ - skew_ * yd) / fx_;
	}
	/// The derivative of toPixel() (K's upper-left 2x2 block).
	Jacobian2 pixelJacobian() const { return { fx_, skew_, 0.0, fy_ }; }

private:
	double fx_, fy_, skew_, cx_, cy_;
	/* k1 k2 p1 p2 k3 k4 k5 k6, zero where the calibration has fewer. */
	std::array<double, 8> k_{};
	bool distorted_ = false;
};

} // namespace frappe::detail
