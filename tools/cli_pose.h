// SPDX-License-Identifier: MIT
// cli_pose.h: frappe-detect's pose: the camera its options give (a
// calibration file or fx,fy,cx,cy), fitted to each image's size, and each
// marker's pose as JSON fields or a line of text.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "frappe/camera.h"
#include "frappe/marker.h"
#include "frappe/pose.h"

namespace frappe::cli {

/// "fx,fy,cx,cy" (pixels) as a pinhole camera without distortion, for
/// frames of any size; false with `error` saying what is wrong.
bool parseCameraSpec(const std::string &text, Camera &camera, std::string &error);

/// A calibration applied to images of whatever size they come in: scaled
/// when the aspect ratio matches the calibration's, refused when not.
class CameraFitter {
public:
	explicit CameraFitter(Camera camera) : camera_(std::move(camera)) {}

	/// The camera for an image of width x height, or nullptr with `error`
	/// set when the calibration cannot apply. `note` is set the first time
	/// a size needs scaling (for standard error), else left empty.
	const Camera *fit(int width, int height, std::string &note, std::string &error);

private:
	Camera camera_;
	Camera scaled_;
	int width_ = -1, height_ = -1; /* the size scaled_ is for */
	std::vector<std::pair<int, int>> noted_;
};

/// Each marker's pose (nullopt for a marker without a size or whose
/// corners give none).
std::vector<std::optional<MarkerPose>> markerPoses(const std::vector<Marker> &markers, const MarkerSizes &sizes,
						   const Camera &camera);

/// A bundle's pose as JSON members (frappe-detect --bundle): `, "rvec":
/// [...], "tvec": [...], "pose_error": e`. A marker's pose is the marker
/// record's (frappe/marker_record.h).
std::string poseJson(const Pose &pose);

/// A readable line: the distance, the position and the rotation.
std::string poseText(const Pose &pose);

} // namespace frappe::cli
