// SPDX-License-Identifier: MIT
// Rotation vectors (axis times angle, as cv::Rodrigues) and matrices.
#pragma once

#include <Eigen/Core>

namespace frappe::detail {

/// exp([r]x): the rotation by |r| radians about r.
Eigen::Matrix3d rotationMatrix(const Eigen::Vector3d &r);
/// The inverse: a vector of length in [0, pi]. R must be a rotation.
Eigen::Vector3d rotationVector(const Eigen::Matrix3d &R);

} // namespace frappe::detail
