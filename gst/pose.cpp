/* SPDX-License-Identifier: MIT
 *
 * pose.cpp: see pose.h.
 */
#include "pose.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

namespace frappe::gst {

namespace {

cv::Mat cameraMatrix(const Camera &camera)
{
	cv::Mat k(3, 3, CV_64F);
	for (int i = 0; i < 9; ++i)
		k.at<double>(i / 3, i % 3) = camera.matrix[static_cast<std::size_t>(i)];
	return k;
}

cv::Mat distortion(const Camera &camera)
{
	if (camera.distortion.empty())
		return cv::Mat();
	cv::Mat d(1, static_cast<int>(camera.distortion.size()), CV_64F);
	for (std::size_t i = 0; i < camera.distortion.size(); ++i)
		d.at<double>(0, static_cast<int>(i)) = camera.distortion[i];
	return d;
}

} // namespace

bool estimatePose(const Marker &marker, double size, const Camera &camera, Pose &pose)
{
	const double h = size / 2.0;
	const std::vector<cv::Point3d> object{ { -h, h, 0 }, { h, h, 0 }, { h, -h, 0 }, { -h, -h, 0 } };
	std::vector<cv::Point2d> image;
	for (const Point2f &c : marker.corners)
		image.emplace_back(c.x, c.y);

	const cv::Mat k = cameraMatrix(camera);
	const cv::Mat d = distortion(camera);
	std::vector<cv::Mat> rvecs, tvecs;
	cv::Mat rvec, tvec;
	try {
		/* IPPE gives both planar solutions, best first. */
		const int n = cv::solvePnPGeneric(object, image, k, d, rvecs, tvecs, false, cv::SOLVEPNP_IPPE_SQUARE);
		if (n < 1)
			return false;
		auto rms = [&](const cv::Mat &r, const cv::Mat &t) {
			std::vector<cv::Point2d> projected;
			cv::projectPoints(object, r, t, k, d, projected);
			double sum = 0.0;
			for (std::size_t i = 0; i < 4; ++i) {
				const cv::Point2d e = projected[i] - image[i];
				sum += e.dot(e);
			}
			return std::sqrt(sum / 4.0);
		};
		std::size_t best = 0;
		std::vector<double> errs;
		for (int i = 0; i < n; ++i) {
			errs.push_back(rms(rvecs[static_cast<std::size_t>(i)], tvecs[static_cast<std::size_t>(i)]));
			if (errs.back() < errs[best])
				best = static_cast<std::size_t>(i);
		}
		rvec = rvecs[best];
		tvec = tvecs[best];
		pose.reprojectionError = errs[best];
		pose.alternativeError = std::numeric_limits<double>::infinity();
		for (std::size_t i = 0; i < errs.size(); ++i)
			if (i != best)
				pose.alternativeError = std::min(pose.alternativeError, errs[i]);
	} catch (const cv::Exception &) {
		return false;
	}
	for (int i = 0; i < 3; ++i) {
		pose.rvec[static_cast<std::size_t>(i)] = rvec.at<double>(i);
		pose.tvec[static_cast<std::size_t>(i)] = tvec.at<double>(i);
	}
	return true;
}

std::vector<Point2f> projectPoints(const std::vector<std::array<double, 3>> &points, const Pose &pose,
				   const Camera &camera)
{
	std::vector<cv::Point3d> object;
	for (const auto &p : points)
		object.emplace_back(p[0], p[1], p[2]);
	const cv::Mat rvec(3, 1, CV_64F, const_cast<double *>(pose.rvec.data()));
	const cv::Mat tvec(3, 1, CV_64F, const_cast<double *>(pose.tvec.data()));
	std::vector<cv::Point2d> projected;
	std::vector<Point2f> out;
	try {
		cv::projectPoints(object, rvec, tvec, cameraMatrix(camera), distortion(camera), projected);
	} catch (const cv::Exception &) {
		return out;
	}
	for (const cv::Point2d &p : projected)
		out.push_back({ static_cast<float>(p.x), static_cast<float>(p.y) });
	return out;
}

std::vector<std::optional<Pose>> estimatePoses(const std::vector<Marker> &markers, double size,
					       const Camera &camera)
{
	std::vector<std::optional<Pose>> poses(markers.size());
	if (!(size > 0.0) || !camera.valid())
		return poses;
	for (std::size_t i = 0; i < markers.size(); ++i) {
		Pose pose;
		if (estimatePose(markers[i], size, camera, pose))
			poses[i] = pose;
	}
	return poses;
}

} // namespace frappe::gst
