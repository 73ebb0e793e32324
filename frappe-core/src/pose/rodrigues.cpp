// SPDX-License-Identifier: MIT
// Rodrigues' formula both ways.
#include "rodrigues.h"

#include <algorithm>
#include <cmath>

namespace frappe::detail {

Eigen::Matrix3d rotationMatrix(const Eigen::Vector3d &r)
{
	const double theta = r.norm();
	Eigen::Matrix3d K;
	K << 0.0, -r.z(), r.y(), r.z(), 0.0, -r.x(), -r.y(), r.x(), 0.0;
	/* R = I + sin(t)/t K + (1 - cos(t))/t^2 K^2, the ratios by their series
	 * near 0 where the division would lose every digit. */
	double a, b;
	if (theta < 1e-4) {
		const double t2 = theta * theta;
		a = 1.0 - t2 / 6.0;
		b = 0.5 - t2 / 24.0;
	} else {
		a = std::sin(theta) / theta;
		b = (1.0 - std::cos(theta)) / (theta * theta);
	}
	return Eigen::Matrix3d::Identity() + a * K + b * K * K;
}

Eigen::Vector3d rotationVector(const Eigen::Matrix3d &R)
{
	/* Through the unit quaternion, built from its largest component
	 * (Shepperd): accurate at every angle, 0 and pi included. */
	const double tr = R.trace();
	double w, x, y, z;
	if (tr >= R(0, 0) && tr >= R(1, 1) && tr >= R(2, 2)) {
		const double s = 2.0 * std::sqrt(std::max(1.0 + tr, 0.0));
		w = 0.25 * s;
		x = (R(2, 1) - R(1, 2)) / s;
		y = (R(0, 2) - R(2, 0)) / s;
		z = (R(1, 0) - R(0, 1)) / s;
	} else if (R(0, 0) >= R(1, 1) && R(0, 0) >= R(2, 2)) {
		const double s = 2.0 * std::sqrt(std::max(1.0 + R(0, 0) - R(1, 1) - R(2, 2), 0.0));
		w = (R(2, 1) - R(1, 2)) / s;
		x = 0.25 * s;
		y = (R(0, 1) + R(1, 0)) / s;
		z = (R(0, 2) + R(2, 0)) / s;
	} else if (R(1, 1) >= R(2, 2)) {
		const double s = 2.0 * std::sqrt(std::max(1.0 - R(0, 0) + R(1, 1) - R(2, 2), 0.0));
		w = (R(0, 2) - R(2, 0)) / s;
		x = (R(0, 1) + R(1, 0)) / s;
		y = 0.25 * s;
		z = (R(1, 2) + R(2, 1)) / s;
	} else {
		const double s = 2.0 * std::sqrt(std::max(1.0 - R(0, 0) - R(1, 1) + R(2, 2), 0.0));
		w = (R(1, 0) - R(0, 1)) / s;
		x = (R(0, 2) + R(2, 0)) / s;
		y = (R(1, 2) + R(2, 1)) / s;
		z = 0.25 * s;
	}
	if (w < 0.0) { /* the same rotation; the angle then stays in [0, pi] */
		w = -w;
		x = -x;
		y = -y;
		z = -z;
	}
	const double vn = std::sqrt(x * x + y * y + z * z);
	if (vn < 1e-300)
		return Eigen::Vector3d::Zero();
	const double theta = 2.0 * std::atan2(vn, w);
	return Eigen::Vector3d(x, y, z) * (theta / vn);
}

} // namespace frappe::detail
