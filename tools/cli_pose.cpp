// SPDX-License-Identifier: MIT
#include "cli_pose.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "cli_text.h"

namespace frappe::cli {

bool parseCameraSpec(const std::string &text, Camera &camera, std::string &error)
{
	double v[4];
	std::size_t begin = 0;
	for (int k = 0; k < 4; ++k) {
		const std::size_t comma = k < 3 ? text.find(',', begin) : text.size();
		if (comma == std::string::npos || (k == 3 && text.find(',', begin) != std::string::npos)) {
			error = "takes fx,fy,cx,cy (four numbers, pixels), got '" + text + "'";
			return false;
		}
		const std::string item = text.substr(begin, comma - begin);
		if (!parseNumber(item, v[k]) || !std::isfinite(v[k])) {
			error = "takes fx,fy,cx,cy (four numbers, pixels), got '" + item + "' in '" + text + "'";
			return false;
		}
		begin = comma + 1;
	}
	camera = Camera::pinhole(v[0], v[1], v[2], v[3]);
	try {
		camera.validate();
	} catch (const std::invalid_argument &e) {
		error = std::string("'") + text + "': " + e.what();
		return false;
	}
	return true;
}

const Camera *CameraFitter::fit(int width, int height, std::string &note, std::string &error)
{
	note.clear();
	if (width == width_ && height == height_)
		return &scaled_;
	if (!camera_.fits(width, height)) {
		error = "the calibration is for " + std::to_string(camera_.width) + " x " +
			std::to_string(camera_.height) + ", the image is " + std::to_string(width) + " x " +
			std::to_string(height) + ": another aspect ratio, no pose";
		return nullptr;
	}
	scaled_ = camera_.scaledTo(width, height);
	width_ = width;
	height_ = height;
	const bool scaled = camera_.width > 0 && (camera_.width != width || camera_.height != height);
	const std::pair<int, int> size{ width, height };
	if (scaled && std::find(noted_.begin(), noted_.end(), size) == noted_.end()) {
		noted_.push_back(size);
		note = "the calibration, for " + std::to_string(camera_.width) + " x " + std::to_string(camera_.height) +
		       ", is scaled to the image's " + std::to_string(width) + " x " + std::to_string(height);
	}
	return &scaled_;
}

std::vector<std::optional<MarkerPose>> markerPoses(const std::vector<Marker> &markers, const MarkerSizes &sizes,
						   const Camera &camera)
{
	std::vector<std::optional<MarkerPose>> poses;
	poses.reserve(markers.size());
	for (const Marker &m : markers) {
		const double side = sizes(m.id);
		std::optional<MarkerPose> p;
		if (side > 0.0)
			p = estimatePose(m.corners, side, camera);
		poses.push_back(p);
	}
	return poses;
}

namespace {

std::string triple(const std::array<double, 3> &v, const char *format)
{
	char buf[128];
	std::snprintf(buf, sizeof buf, format, v[0], v[1], v[2]);
	return buf;
}

} // namespace

std::string poseJson(const Pose &pose)
{
	char error[32];
	std::snprintf(error, sizeof error, "%.4f", pose.error);
	return ", \"rvec\": " + triple(pose.rvec, "[%.6f, %.6f, %.6f]") + ", \"tvec\": " +
	       triple(pose.tvec, "[%.6f, %.6f, %.6f]") + ", \"pose_error\": " + error;
}

std::string poseText(const Pose &pose)
{
	const auto &t = pose.tvec;
	char buf[64];
	std::snprintf(buf, sizeof buf, "distance %.4f m  ", std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]));
	const double angle = std::sqrt(pose.rvec[0] * pose.rvec[0] + pose.rvec[1] * pose.rvec[1] +
				       pose.rvec[2] * pose.rvec[2]);
	char rest[64];
	std::snprintf(rest, sizeof rest, "  rotated %.1f deg  reprojection %.2f px", angle * 180.0 / M_PI, pose.error);
	return buf + triple(t, "at (%.4f, %.4f, %.4f) m") + rest;
}

} // namespace frappe::cli
