// SPDX-License-Identifier: MIT
// frappe::estimatePose beside OpenCV's cv::solvePnP(SOLVEPNP_IPPE_SQUARE) on
// random poses and cameras: the same pose from exact corners, and from
// noisy corners a pose that reprojects no worse than OpenCV's (ours is
// refined with distortion, OpenCV's IPPE is not). Built only where OpenCV is.
#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "frappe/pose.h"

namespace {

double rmsError(const std::vector<cv::Point3d> &obj, const cv::Mat &rvec, const cv::Mat &tvec, const cv::Mat &K,
		const cv::Mat &D, const std::vector<cv::Point2d> &seen)
{
	std::vector<cv::Point2d> proj;
	cv::projectPoints(obj, rvec, tvec, K, D, proj);
	double sum = 0.0;
	for (std::size_t i = 0; i < proj.size(); ++i)
		sum += std::pow(cv::norm(proj[i] - seen[i]), 2);
	return std::sqrt(sum / static_cast<double>(proj.size()));
}

double rotationDegrees(const cv::Mat &a, const cv::Mat &b)
{
	cv::Mat Ra, Rb;
	cv::Rodrigues(a, Ra);
	cv::Rodrigues(b, Rb);
	const cv::Mat d = Ra.t() * Rb;
	return std::acos(std::clamp((cv::trace(d)[0] - 1.0) / 2.0, -1.0, 1.0)) * 180.0 / CV_PI;
}

} // namespace

TEST(PoseOpenCv, AgreesWithSolvePnpIppeSquare)
{
	std::mt19937 rng(13);
	std::uniform_real_distribution<double> uni(0.0, 1.0);
	std::normal_distribution<double> noise(0.0, 0.1);
	int compared = 0;
	for (int trial = 0; trial < 300; ++trial) {
		const double f = 500 + 800 * uni(rng);
		/* One draw a statement, in the order x86 has drawn them: a call's
		 * arguments are evaluated in an unspecified order (GCC for ARM
		 * draws them in another, rendering other scenes). */
		const double cy = 240 + 10 * uni(rng);
		const double cx = 320 + 10 * uni(rng);
		const double fy = f * (0.98 + 0.04 * uni(rng));
		frappe::Camera cam = frappe::Camera::pinhole(f, fy, cx, cy, 640, 480);
		if (trial % 3 != 0)
			cam.distortion = { -0.3 + 0.4 * uni(rng), 0.1 * uni(rng), 0.002 * (uni(rng) - 0.5),
					   0.002 * (uni(rng) - 0.5), 0.02 * (uni(rng) - 0.5) };
		const double side = 0.03 + 0.15 * uni(rng);
		const double z = 0.3 + 1.5 * uni(rng);
		/* A marker facing the camera within 70 degrees, anywhere in view. */
		const double tilt = 70.0 * uni(rng) * CV_PI / 180.0, dir = 2 * CV_PI * uni(rng);
		cv::Mat Rtilt, Rroll, R;
		cv::Rodrigues(cv::Vec3d(std::cos(dir) * tilt, std::sin(dir) * tilt, 0.0), Rtilt);
		cv::Rodrigues(cv::Vec3d(0.0, 0.0, 2 * CV_PI * uni(rng)), Rroll);
		const cv::Mat flip = (cv::Mat_<double>(3, 3) << 1, 0, 0, 0, -1, 0, 0, 0, -1);
		R = Rtilt * Rroll * flip;
		cv::Mat rvec, tvec = (cv::Mat_<double>(3, 1) << z * (uni(rng) - 0.5) * 0.6, z * (uni(rng) - 0.5) * 0.45, z);
		cv::Rodrigues(R, rvec);

		const double h = side / 2;
		const std::vector<cv::Point3d> obj = { { -h, h, 0 }, { h, h, 0 }, { h, -h, 0 }, { -h, -h, 0 } };
		const cv::Mat K(3, 3, CV_64F, cam.matrix.data());
		const cv::Mat D = cam.distortion.empty() ? cv::Mat() : cv::Mat(cam.distortion, true);
		std::vector<cv::Point2d> exact;
		cv::projectPoints(obj, rvec, tvec, K, D, exact);

		for (const bool noisy : { false, true }) {
			std::vector<cv::Point2d> seen = exact;
			std::array<frappe::Point2f, 4> corners;
			for (int i = 0; i < 4; ++i) {
				if (noisy) {
					/* One draw a statement, in the order x86 has drawn them: a call's
					 * arguments are evaluated in an unspecified order (GCC for ARM
					 * draws them in another, rendering other scenes). */
					const double ny = noise(rng);
					const double nx = noise(rng);
					seen[i] += cv::Point2d(nx, ny);
				}
				/* Both get the same float corners, rounded through a
				 * volatile: GCC 12.2's SLP vectoriser drops the double ->
				 * float -> double round trip of an x, y pair (wrong code
				 * at -O2 and -O3; -fno-tree-slp-vectorize avoids it). */
				const volatile float x = static_cast<float>(seen[i].x);
				const volatile float y = static_cast<float>(seen[i].y);
				corners[i] = { x, y };
				seen[i] = cv::Point2d(x, y);
			}
			cv::Mat cv_r, cv_t;
			ASSERT_TRUE(cv::solvePnP(obj, seen, K, D, cv_r, cv_t, false, cv::SOLVEPNP_IPPE_SQUARE));
			const auto ours = frappe::estimatePose(corners, side, cam);
			ASSERT_TRUE(ours.has_value()) << "trial " << trial;
			const cv::Mat our_r = (cv::Mat_<double>(3, 1) << ours->pose.rvec[0], ours->pose.rvec[1], ours->pose.rvec[2]);
			const cv::Mat our_t = (cv::Mat_<double>(3, 1) << ours->pose.tvec[0], ours->pose.tvec[1], ours->pose.tvec[2]);
			const double cv_err = rmsError(obj, cv_r, cv_t, K, D, seen);
			EXPECT_NEAR(rmsError(obj, our_r, our_t, K, D, seen), ours->pose.error, 1e-9);
			EXPECT_LE(ours->pose.error, cv_err + 1e-9) << "trial " << trial << (noisy ? " noisy" : "");
			if (!noisy) {
				/* The truth, which both find (to what float corners
				 * allow: markers here may be 10 px wide). */
				EXPECT_LT(cv::norm(our_t - tvec), 1e-5 * z) << "trial " << trial;
				EXPECT_LT(rotationDegrees(our_r, rvec), 1e-3) << "trial " << trial;
				EXPECT_LT(cv::norm(cv_t - tvec), 1e-5 * z) << "trial " << trial;
				EXPECT_LT(rotationDegrees(cv_r, rvec), 1e-2) /* unrefined */ << "trial " << trial;
				++compared;
			}
		}
	}
	EXPECT_EQ(compared, 300);
}
