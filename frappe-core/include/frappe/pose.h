// SPDX-License-Identifier: MIT
// frappe/pose.h: where a marker is, from its four corners.
//
// Camera frame: OpenCV's (x right, y down, z forward, metres). Marker
// frame: OpenCV aruco's: origin at the marker centre, x right, y up, z out
// of the marker towards the viewer; the corners (top-left, top-right,
// bottom-right, bottom-left, as Marker::corners) are at (-s/2, s/2, 0),
// (s/2, s/2, 0), (s/2, -s/2, 0), (-s/2, -s/2, 0) for a side s.
#pragma once

#include "frappe/export.h"

#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "frappe/camera.h"
#include "frappe/image.h"

namespace frappe {

/// A rigid motion from the marker frame to the camera frame.
struct Pose {
	std::array<double, 3> rvec{}; ///< rotation vector (axis times angle, radians), as cv::Rodrigues
	std::array<double, 3> tvec{}; ///< marker centre in the camera frame, metres
	double error = 0.0;           ///< RMS reprojection error of the four corners, pixels
};

/// Both poses a square's four corners allow. A planar square seen from
/// afar or face on is ambiguous: two poses, mirror images about the line of
/// sight, project it almost alike. IPPE finds both in closed form; the one
/// that reprojects better is refined by a few Levenberg-Marquardt
/// steps (Gauss-Newton kept from diverging).
struct FRAPPE_EXPORT MarkerPose {
	Pose pose;        ///< the better solution, refined
	Pose alternative; ///< the other (unrefined); alternative.error is infinity when there was none
	/// How far apart the two are in evidence: alternative.error /
	/// pose.error (infinity when there was no alternative). Near 1 the pose
	/// is ambiguous and may flip between frames.
	double ambiguity() const;
};

/// The pose of a square marker of side `marker_size` (metres, > 0) whose
/// corners the camera saw at `corners` (distorted pixels, as the detector
/// reports them; they are undistorted first). std::nullopt when the
/// corners are degenerate (not finite, collinear, behind the camera after
/// undistortion). Throws std::invalid_argument for a size that is not
/// positive and finite or a camera that fails Camera::validate().
FRAPPE_EXPORT std::optional<MarkerPose> estimatePose(const std::array<Point2f, 4> &corners, double marker_size,
						     const Camera &camera);

/// Projects points of the marker frame into the image (distortion applied),
/// e.g. the axes to draw. A point at or behind the camera's plane
/// (z <= 0 in the camera frame) comes out as NaN. Throws
/// std::invalid_argument for a camera that fails Camera::validate().
FRAPPE_EXPORT std::vector<Point2f> projectPoints(std::span<const std::array<double, 3>> points, const Pose &pose,
						 const Camera &camera);
/// The same into `out`, which must have one element per point (else
/// std::invalid_argument): no allocation, for drawing on every frame.
FRAPPE_EXPORT void projectPoints(std::span<const std::array<double, 3>> points, const Pose &pose,
				 const Camera &camera, std::span<Point2f> out);

/// Undistorts pixel points: where each would be under the same camera
/// matrix with no distortion (OpenCV's undistortPoints with P = K). A
/// point the distortion model cannot invert (beyond where it folds over,
/// far outside the calibrated field) comes out as NaN. Throws
/// std::invalid_argument for a camera that fails Camera::validate().
FRAPPE_EXPORT std::vector<Point2f> undistortPoints(std::span<const Point2f> points, const Camera &camera);

/// The side of each marker id, metres: one default and exceptions, written
/// "0:0.05,7:0.10" (id:size, comma-separated; spaces allowed).
class FRAPPE_EXPORT MarkerSizes {
public:
	MarkerSizes() = default;
	explicit MarkerSizes(double default_size) : default_(default_size) {}
	/// The longest `spec` parse() takes (1 MiB, some 80,000 entries): a
	/// bound on its time, a few milliseconds, for any value accepted.
	static constexpr std::size_t kMaxSpecBytes = 1 << 20;
	/// Parses `spec` ("" for none) in O(n log n) of its entries. Throws
	/// std::invalid_argument naming the bad entry: not id:size, an id
	/// below 0, a size not positive and finite, an id given twice; or a
	/// spec longer than kMaxSpecBytes.
	static MarkerSizes parse(std::string_view spec, double default_size = 0.0);

	/// The side of `id`: its own, else the default (0: no pose).
	double operator()(int id) const;
	double defaultSize() const { return default_; }
	const std::vector<std::pair<int, double>> &exceptions() const { return sizes_; }
	/// Whether some id has a positive size.
	bool any() const;
	/// "0:0.05,7:0.1", as parse() reads it (the default not included).
	std::string toString() const;

private:
	double default_ = 0.0;
	std::vector<std::pair<int, double>> sizes_; ///< sorted by id
};

} // namespace frappe
