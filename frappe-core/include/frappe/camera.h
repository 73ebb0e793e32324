// SPDX-License-Identifier: MIT
// frappe/camera.h: a calibrated camera, and the calibration files that
// describe one (ROS camera_info YAML, OpenCV FileStorage YAML and XML).
#pragma once

#include "frappe/export.h"

#include <array>
#include <string>
#include <string_view>
#include <vector>

namespace frappe {

/// A pinhole camera with OpenCV's distortion model. Pixel coordinates as
/// everywhere in frappe: (0, 0) is the centre of the top-left pixel, which
/// is OpenCV's convention too, so an OpenCV or ROS calibration applies
/// unchanged.
struct FRAPPE_EXPORT Camera {
	/// The frame size the calibration was made at; 0 when the file did
	/// not say (then the matrix is used at any frame size, unscaled).
	int width = 0;
	int height = 0;
	/// Row-major fx 0 cx / 0 fy cy / 0 0 1 (a skew in [0][1] is kept).
	std::array<double, 9> matrix{};
	/// OpenCV's order: k1 k2 p1 p2 [k3 [k4 k5 k6]]; empty, 4, 5 or 8
	/// coefficients (ROS's plumb_bob is 5, rational_polynomial 8).
	std::vector<double> distortion;

	/// A camera from fx, fy, cx, cy and no distortion.
	static Camera pinhole(double fx, double fy, double cx, double cy, int width = 0, int height = 0);

	/// Whether validate() would pass.
	bool valid() const;
	/// Throws std::invalid_argument saying what is wrong: a focal length
	/// not positive and finite, a non-finite entry, a last row other than
	/// 0 0 1, a distortion count other than 0, 4, 5 or 8, a non-finite
	/// coefficient, a negative size or one given without the other.
	void validate() const;

	/// Whether frames of `frame_width` x `frame_height` can use this
	/// calibration by scaling it: the same size, an unknown calibration
	/// size, or the same aspect ratio (within half a pixel on either side).
	bool fits(int frame_width, int frame_height) const;
	/// This camera for frames of `frame_width` x `frame_height`: fx, cx
	/// scaled by the ratio of widths, fy, cy by the ratio of heights (the
	/// pixel-centre convention kept: c' = (c + 0.5) * r - 0.5); distortion
	/// unchanged (it is in normalised coordinates). Unchanged when the
	/// calibration size is unknown or equal. Does not check fits(); throws
	/// std::invalid_argument for a frame size that is not positive, or
	/// when the scaled matrix fails validate() (a focal length scaled past
	/// what a double holds).
	Camera scaledTo(int frame_width, int frame_height) const;
};

/// Reads a calibration file, whatever its kind (told by its content):
/// - ROS camera_info YAML (camera_calibration's output): image_width,
///   image_height, camera_matrix {rows, cols, data}, distortion_model,
///   distortion_coefficients {data}; or a CameraInfo message as printed
///   (width, height, K, D, distortion_model);
/// - OpenCV FileStorage YAML (%YAML:1.0, !!opencv-matrix) or XML
///   (<opencv_storage>, type_id="opencv-matrix"), with the keys OpenCV's
///   samples and calibration tools write: camera_matrix or cameraMatrix or
///   K, distortion_coefficients or dist_coeffs or distCoeffs or D,
///   image_width / image_height or imageSize or image_size [w, h].
/// The size is optional, the matrix and the distortion (possibly empty) are
/// not. A distortion_model must be plumb_bob (5 coefficients) or
/// rational_polynomial (8): equidistant (fisheye) is refused. OpenCV's 12
/// or 14 coefficients are accepted when the terms beyond 8 are zero.
/// Throws std::runtime_error when the file cannot be read (missing, not a
/// regular file, over 1 MiB), std::invalid_argument when it is not a
/// calibration (unknown kind, a missing key, a matrix of the wrong size, a
/// number that does not parse, the checks of Camera::validate()); the
/// message names the file and the key.
FRAPPE_EXPORT Camera readCalibration(const std::string &path);

/// The same from the text of a file; `origin` names it in messages.
FRAPPE_EXPORT Camera parseCalibration(std::string_view text, std::string_view origin = "calibration");

} // namespace frappe
