/* SPDX-License-Identifier: MIT
 *
 * pose.h: marker pose from its four refined corners (OpenCV's IPPE square
 * solver), and projection of points for drawing the axes.
 *
 * Camera frame: OpenCV's (x right, y down, z forward). Marker frame: OpenCV
 * aruco's: origin at the marker centre, x right, y up, z out of the marker;
 * the corners (top-left, top-right, bottom-right, bottom-left) are at
 * (-s/2, s/2, 0), (s/2, s/2, 0), (s/2, -s/2, 0), (-s/2, -s/2, 0).
 */
#pragma once

#include <array>
#include <optional>
#include <vector>

#include <frappe/marker.h>

namespace frappe::gst {

struct Camera {
	std::array<double, 9> matrix{}; ///< row-major fx 0 cx / 0 fy cy / 0 0 1
	std::vector<double> distortion; ///< OpenCV order k1 k2 p1 p2 [k3 [k4 k5 k6 [s1..s4 [tx ty]]]]
	bool valid() const { return matrix[0] > 0.0 && matrix[4] > 0.0; }
};

struct Pose {
	std::array<double, 3> rvec{};
	std::array<double, 3> tvec{};
	double reprojectionError = 0.0; ///< RMS, pixels
	/// RMS error of IPPE's other solution (the planar flip); close to
	/// reprojectionError when the pose is ambiguous (small or far markers
	/// seen face on). Infinity when there was a single solution.
	double alternativeError = 0.0;
};

/// Solves the pose of a marker of side `size` (metres). False when OpenCV
/// finds no solution.
bool estimatePose(const Marker &marker, double size, const Camera &camera, Pose &pose);

/// The poses of a frame's markers, in their order: all empty unless `size`
/// is positive and the camera valid; empty for a marker with no solution.
std::vector<std::optional<Pose>> estimatePoses(const std::vector<Marker> &markers, double size,
					       const Camera &camera);

/// Projects marker-frame points into the image with the pose.
std::vector<Point2f> projectPoints(const std::vector<std::array<double, 3>> &points, const Pose &pose,
				   const Camera &camera);

} // namespace frappe::gst
