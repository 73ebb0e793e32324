// SPDX-License-Identifier: MIT
// OpenCV's distortion model, forwards and inverted.
#include "lens.h"

#include <cmath>

namespace frappe::detail {

Lens::Lens(const Camera &camera)
	: fx_(camera.matrix[0]), fy_(camera.matrix[4]), skew_(camera.matrix[1]), cx_(camera.matrix[2]),
	  cy_(camera.matrix[5])
{
	/* 4 coefficients are k1 k2 p1 p2: the same order, k3 and on zero. */
	for (std::size_t i = 0; i < camera.distortion.size() && i < k_.size(); ++i) {
		k_[i] = camera.distortion[i];
		distorted_ = distorted_ || k_[i] != 0.0;
	}
}

void Lens::distort(double x, double y, double &xd, double &yd, Jacobian2 *jac) const
{
	if (!distorted_) {
		xd = x;
		yd = y;
		if (jac)
			*jac = { 1.0, 0.0, 0.0, 1.0 };
		return;
	}
	const double k1 = k_[0], k2 = k_[1], p1 = k_[2], p2 = k_[3];
	const double k3 = k_[4], k4 = k_[5], k5 = k_[6], k6 = k_[7];
	const double r2 = x * x + y * y;
	const double num = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
	const double den = 1.0 + r2 * (k4 + r2 * (k5 + r2 * k6));
	const double radial = num / den;
	xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
	yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
	if (!jac)
		return;
	/* d radial / d r2, then the chain rule through r2 = x^2 + y^2. */
	const double dnum = k1 + r2 * (2.0 * k2 + r2 * 3.0 * k3);
	const double dden = k4 + r2 * (2.0 * k5 + r2 * 3.0 * k6);
	const double dradial = (dnum * den - num * dden) / (den * den);
	const double cross = 2.0 * x * y * dradial + 2.0 * p1 * x + 2.0 * p2 * y;
	*jac = { radial + 2.0 * x * x * dradial + 2.0 * p1 * y + 6.0 * p2 * x, cross,
		 cross, radial + 2.0 * y * y * dradial + 6.0 * p1 * y + 2.0 * p2 * x };
}

bool Lens::undistort(double xd, double yd, double &x, double &y) const
{
	x = xd;
	y = yd;
	if (!distorted_)
		return std::isfinite(x) && std::isfinite(y);
	/* Newton's method on distort(x, y) = (xd, yd) from the distorted point,
	 * a step halved while it does not reduce the residual (strong barrel
	 * distortion near the edge overshoots otherwise). */
	constexpr int kMaxIterations = 30;
	constexpr double kTolerance = 1e-15;
	double ex, ey;
	Jacobian2 j;
	distort(x, y, ex, ey, &j);
	ex -= xd;
	ey -= yd;
	double err = ex * ex + ey * ey;
	for (int it = 0; it < kMaxIterations && err > kTolerance * kTolerance; ++it) {
		const double det = j[0] * j[3] - j[1] * j[2];
		if (!std::isfinite(det) || std::abs(det) < 1e-12)
			return false;
		double sx = (j[3] * ex - j[1] * ey) / det;
		double sy = (j[0] * ey - j[2] * ex) / det;
		bool improved = false;
		for (int half = 0; half < 30 && !improved; ++half, sx *= 0.5, sy *= 0.5) {
			double nx = x - sx, ny = y - sy, fx, fy;
			Jacobian2 nj;
			distort(nx, ny, fx, fy, &nj);
			fx -= xd;
			fy -= yd;
			const double nerr = fx * fx + fy * fy;
			if (nerr < err) {
				x = nx;
				y = ny;
				ex = fx;
				ey = fy;
				err = nerr;
				j = nj;
				improved = true;
			}
		}
		if (!improved)
			break;
	}
	/* A millionth of a pixel for a focal length of 1000 px, on the side of
	 * the fold the image is on (beyond it the model maps back inwards). */
	return std::isfinite(x) && std::isfinite(y) && err < 1e-18 && j[0] * j[3] - j[1] * j[2] > 0.0;
}

} // namespace frappe::detail
