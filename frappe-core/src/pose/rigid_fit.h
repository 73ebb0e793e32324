// SPDX-License-Identifier: MIT
// A rigid motion fitted to points seen through a camera: the reprojection
// error in distorted pixels and its Levenberg-Marquardt refinement, for one
// marker's four corners (pose.cpp) and a bundle's many (bundle.cpp).
#pragma once

#include <limits>
#include <span>

#include <Eigen/Core>

#include "frappe/image.h"
#include "lens.h"

namespace frappe::detail {

/// Where a camera-frame point lands in distorted pixels; false at or
/// behind the camera's plane.
bool projectPoint(const Eigen::Vector3d &p, const Lens &lens, double &u, double &v);

/// The sum over the points of the squared distance between R m + t
/// projected and its observation, pixels^2; infinity when a point is
/// behind the camera.
double squaredReprojection(const Eigen::Matrix3d &R, const Eigen::Vector3d &t, std::span<const Eigen::Vector3d> model,
			   std::span<const Point2f> observed, const Lens &lens);

/// Levenberg-Marquardt (Gauss-Newton kept from diverging) on R and t over
/// the points: six parameters, a small rotation w applied on the left
/// (R <- exp([w]x) R) and the translation; a point p = R m + t moves by
/// -[R m]x w + dt. At most `iterations` steps; R and t only move to a
/// smaller error. Returns the final squaredReprojection().
double refineRigid(Eigen::Matrix3d &R, Eigen::Vector3d &t, std::span<const Eigen::Vector3d> model,
		   std::span<const Point2f> observed, const Lens &lens, int iterations);

} // namespace frappe::detail
