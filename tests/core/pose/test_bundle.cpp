// SPDX-License-Identifier: MIT
// One pose from many markers (frappe/bundle.h): boards rendered through
// known poses and cameras, detected, and their pose against the truth,
// beside each single marker's; a marker moved is rejected; bundle files.
#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "frappe/bundle.h"
#include "frappe/frappe.h"
#include "scene.h"

using namespace frappe;
using namespace frappe::test;

namespace {

constexpr double kPi = 3.14159265358979323846;

/* Rotation vector of a tilt about the board's x axis then a turn about the
 * view axis, the board facing the camera (its z towards it). */
Pose boardPose(double tiltDeg, double rollDeg, double distance, double dx, double dy)
{
	/* Facing the camera: the board's y up is the camera's -y, z towards
	 * the camera is -z: a half turn about x. */
	const double t = tiltDeg * kPi / 180.0, r = rollDeg * kPi / 180.0;
	auto mul = [](const std::array<double, 9> &a, const std::array<double, 9> &b) {
		std::array<double, 9> c{};
		for (int i = 0; i < 3; ++i)
			for (int j = 0; j < 3; ++j)
				for (int k = 0; k < 3; ++k)
					c[3 * i + j] += a[3 * i + k] * b[3 * k + j];
		return c;
	};
	const std::array<double, 9> flip = { 1, 0, 0, 0, -1, 0, 0, 0, -1 };
	const std::array<double, 9> tilt = { 1, 0, 0, 0, std::cos(t), -std::sin(t), 0, std::sin(t), std::cos(t) };
	const std::array<double, 9> roll = { std::cos(r), -std::sin(r), 0, std::sin(r), std::cos(r), 0, 0, 0, 1 };
	const std::array<double, 9> R = mul(roll, mul(flip, tilt));
	/* Rotation vector from R. */
	const double angle = std::acos(std::clamp((R[0] + R[4] + R[8] - 1.0) / 2.0, -1.0, 1.0));
	Pose p;
	if (angle > 1e-9) {
		const double s = angle / (2.0 * std::sin(angle));
		p.rvec = { s * (R[7] - R[5]), s * (R[2] - R[6]), s * (R[3] - R[1]) };
		if (std::abs(angle - kPi) < 1e-6) {
			/* A half turn: the axis from R + I. */
			const double x = std::sqrt(std::max(0.0, (R[0] + 1) / 2)), y = std::sqrt(std::max(0.0, (R[4] + 1) / 2)),
				     z = std::sqrt(std::max(0.0, (R[8] + 1) / 2));
			p.rvec = { angle * x, angle * (R[1] >= 0 ? y : -y), angle * (R[2] >= 0 ? z : -z) };
		}
	}
	p.tvec = { dx, dy, distance };
	return p;
}

/* The angle between two rotations, degrees. */
double rotationDistanceDeg(const Pose &a, const Pose &b)
{
	auto matrix = [](const std::array<double, 3> &r) {
		const double th = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
		std::array<double, 9> R = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
		if (th < 1e-12)
			return R;
		const double x = r[0] / th, y = r[1] / th, z = r[2] / th, c = std::cos(th), s = std::sin(th), C = 1 - c;
		R = { c + x * x * C, x * y * C - z * s, x * z * C + y * s, y * x * C + z * s, c + y * y * C,
		      y * z * C - x * s, z * x * C - y * s, z * y * C + x * s, c + z * z * C };
		return R;
	};
	const auto A = matrix(a.rvec), B = matrix(b.rvec);
	double trace = 0.0; /* trace(A^T B) */
	for (int i = 0; i < 9; ++i)
		trace += A[i] * B[i];
	return std::acos(std::clamp((trace - 1.0) / 2.0, -1.0, 1.0)) * 180.0 / kPi;
}

double distance3(const std::array<double, 3> &a, const std::array<double, 3> &b)
{
	return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

struct Rendered {
	std::vector<Marker> markers;
	int drawn = 0;
};

/* The board's markers drawn where `pose` and `camera` put them (a planar
 * square under a pinhole is a homography: renderMarker is exact), those
 * in `skip` left out, the one of `moved` (if any) shifted by `shift` metres
 * along the board's x. */
Rendered renderBoard(Image &img, const Bundle &board, const Dictionary &dict, const Pose &pose, const Camera &cam,
		     std::mt19937 &rng, int skip = -1, int moved = -1, double shift = 0.0, float noise = 3.0f)
{
	Rendered out;
	for (const BundleMarker &m : board.markers) {
		if (m.id == skip)
			continue;
		std::array<std::array<double, 3>, 4> c = m.corners;
		if (m.id == moved)
			for (auto &p : c)
				p[0] += shift;
		const std::vector<Point2f> px = projectPoints(c, pose, cam);
		std::array<Point2f, 4> q{ px[0], px[1], px[2], px[3] };
		RenderOptions opt;
		opt.black = 25;
		opt.white = 225;
		try {
			renderMarker(img.mut(), dict, m.id, q, opt);
			++out.drawn;
		} catch (const std::invalid_argument &) {
		}
	}
	blur(img, 0.7f);
	addNoise(img, noise, rng);
	return out;
}

} // namespace

TEST(Bundle, GridMatchesOpenCvsGridBoard)
{
	const Bundle b = Bundle::grid(2, 3, 0.04, 0.01, 5);
	ASSERT_EQ(b.markers.size(), 6u);
	/* id 5 at the top-left: its top-left corner at (0, rows*size+(rows-1)*gap). */
	const BundleMarker *m = b.find(5);
	ASSERT_NE(m, nullptr);
	EXPECT_DOUBLE_EQ(m->corners[0][0], 0.0);
	EXPECT_DOUBLE_EQ(m->corners[0][1], 0.09);
	EXPECT_DOUBLE_EQ(m->corners[2][0], 0.04);
	EXPECT_DOUBLE_EQ(m->corners[2][1], 0.05);
	/* id 10 at the bottom-right, its bottom-right corner at (cols*pitch - gap, 0). */
	EXPECT_NEAR(b.find(10)->corners[2][0], 0.14, 1e-12);
	EXPECT_NEAR(b.find(10)->corners[2][1], 0.0, 1e-12);
	EXPECT_THROW(Bundle::grid(0, 3, 0.04, 0.01), std::invalid_argument);
	EXPECT_THROW(Bundle::grid(2, 3, -1.0, 0.01), std::invalid_argument);
}

TEST(Bundle, FilesOfApriltagRosAndGrids)
{
	const Bundle a = parseBundle("tag_bundles:\n"
				     "  [\n"
				     "    {\n"
				     "      name: 'carrier',\n"
				     "      layout:\n"
				     "        [\n"
				     "          {id: 3, size: 0.05, x: 0.0, y: 0.0, z: 0.0, qw: 1.0, qx: 0.0, qy: 0.0, qz: 0.0},\n"
				     "          {id: 7, size: 0.10, x: 0.2, y: 0.1, z: 0.0, qw: 0.7071068, qx: 0.0, qy: 0.0, qz: 0.7071068}\n"
				     "        ]\n"
				     "    }\n"
				     "  ]\n",
				     "tags.yaml");
	EXPECT_EQ(a.name, "carrier");
	ASSERT_EQ(a.markers.size(), 2u);
	EXPECT_NEAR(a.find(3)->corners[0][0], -0.025, 1e-12);
	EXPECT_NEAR(a.find(3)->corners[0][1], 0.025, 1e-12);
	/* A quarter turn about z: the top-left corner (-s/2, s/2) goes to (-s/2, -s/2) + centre. */
	EXPECT_NEAR(a.find(7)->corners[0][0], 0.2 - 0.05, 1e-6);
	EXPECT_NEAR(a.find(7)->corners[0][1], 0.1 - 0.05, 1e-6);
	const Bundle g = parseBundle("board: grid\nrows: 3\ncols: 4\nsize: 0.05\ngap: 0.01\nfirst_id: 10\n", "g.yaml");
	EXPECT_EQ(g.markers.size(), 12u);
	EXPECT_NE(g.find(21), nullptr);
	auto why = [](const std::string &text) {
		try {
			parseBundle(text, "b.yaml");
		} catch (const std::invalid_argument &e) {
			return std::string(e.what());
		}
		return std::string("accepted");
	};
	EXPECT_NE(why("board: hexagon\n").find("b.yaml:1: board: 'hexagon'"), std::string::npos);
	EXPECT_NE(why("board: grid\nrows: 3\ncols: 4\nsize: x\ngap: 0.01\n").find("'size' is not a number"),
		  std::string::npos);
	EXPECT_NE(why("board: grid\nrows: 3\ncols: 4\nsize: 0.05\n").find("no 'gap'"), std::string::npos);
	EXPECT_NE(why("board: grid\nrows: 3\ncols: 4\nsize: 0.05\ngap: 0\ncolour: red\n").find("unknown key 'colour'"),
		  std::string::npos);
	EXPECT_NE(why("tag_bundles: [{layout: [{id: 1, size: 0.05}, {id: 1, size: 0.05}]}]\n").find("id 1 given twice"),
		  std::string::npos);
	EXPECT_NE(why("tag_bundles: [{layout: [{id: 1, size: 0.05, qw: 2}]}]\n").find("quaternion"), std::string::npos);
	EXPECT_NE(why("camera_matrix: 1\n").find("not a bundle"), std::string::npos);
	EXPECT_THROW(loadBundle("/nonexistent/bundle.yaml"), std::runtime_error);
}

/* Boards of 4 to 24 markers at 0.5 to 3 m, tilted, some markers left out:
 * translation within 0.5% of the distance and rotation within 0.5 degrees
 * of the truth, every marker seen used. */
TEST(Bundle, BoardPoseAgainstTruth)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	const Camera cam = Camera::pinhole(900.0, 900.0, 639.5, 359.5, 1280, 720);
	struct Case {
		int rows, cols;
		double size, distance, tilt, roll;
		int skip;
	};
	const Case cases[] = {
		{ 2, 2, 0.06, 0.5, 30.0, 10.0, -1 }, { 3, 4, 0.05, 1.0, 45.0, -20.0, 5 }, { 4, 6, 0.08, 2.0, 20.0, 5.0, 7 },
		{ 4, 6, 0.12, 3.0, 55.0, 30.0, 0 },  { 2, 3, 0.04, 0.7, 0.0, 0.0, -1 },
	};
	std::mt19937 rng(21);
	Config cfg;
	Detector det(cfg);
	for (const Case &c : cases) {
		const Bundle board = Bundle::grid(c.rows, c.cols, c.size, 0.2 * c.size);
		/* The board's centre on the optical axis. */
		const double w = c.cols * c.size * 1.2 - 0.2 * c.size, h = c.rows * c.size * 1.2 - 0.2 * c.size;
		Pose truth = boardPose(c.tilt, c.roll, c.distance, 0.0, 0.0);
		{
			/* Shift so the board's centre (w/2, h/2, 0) lands on the axis. */
			const std::array<std::array<double, 3>, 1> centre{ { { w / 2, h / 2, 0.0 } } };
			const auto px = projectPoints(centre, truth, cam);
			const double z = c.distance;
			truth.tvec[0] -= (px[0].x - 639.5) / 900.0 * z;
			truth.tvec[1] -= (px[0].y - 359.5) / 900.0 * z;
		}
		Image img(1280, 720, 140);
		const Rendered r = renderBoard(img, board, dict, truth, cam, rng, c.skip);
		const Result &res = det.detect(img.view());
		const auto bp = estimateBundlePose(board, res.markers, cam);
		ASSERT_TRUE(bp.has_value()) << c.rows << "x" << c.cols << " at " << c.distance;
		EXPECT_GE(static_cast<int>(bp->used.size()), r.drawn - 1) << c.rows << "x" << c.cols << " at " << c.distance;
		EXPECT_TRUE(bp->rejected.empty());
		const double terr = distance3(bp->pose.tvec, truth.tvec), rerr = rotationDistanceDeg(bp->pose, truth);
		EXPECT_LT(terr, 0.005 * c.distance) << c.rows << "x" << c.cols << " at " << c.distance;
		EXPECT_LT(rerr, 0.5) << c.rows << "x" << c.cols << " at " << c.distance;
		EXPECT_LT(bp->pose.error, 1.0);
	}
}

/* A marker moved on the board (or read with wrong corners) is rejected, and
 * the pose stays on the truth. */
TEST(Bundle, MovedMarkerIsRejected)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	const Camera cam = Camera::pinhole(900.0, 900.0, 639.5, 359.5, 1280, 720);
	const Bundle board = Bundle::grid(3, 4, 0.05, 0.01);
	Pose truth = boardPose(30.0, 5.0, 0.9, -0.11, 0.08);
	std::mt19937 rng(4);
	Image img(1280, 720, 140);
	renderBoard(img, board, dict, truth, cam, rng, -1, 6, 0.006);
	Detector det(Config{});
	const Result &res = det.detect(img.view());
	ASSERT_GE(res.markers.size(), 12u);
	const auto bp = estimateBundlePose(board, res.markers, cam);
	ASSERT_TRUE(bp.has_value());
	EXPECT_EQ(bp->rejected, std::vector<int>{ 6 });
	EXPECT_EQ(bp->used.size(), 11u);
	EXPECT_LT(distance3(bp->pose.tvec, truth.tvec), 0.005 * 0.9);
	EXPECT_LT(rotationDistanceDeg(bp->pose, truth), 0.5);
}

/* Small markers face on: each alone may flip its tilt (its two IPPE poses
 * reproject almost alike); the board's pose does not. Counts the flips
 * over noisy frames: single markers some, the bundle none. */
TEST(Bundle, NoTiltFlipWhereSingleMarkersFlip)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	const Camera cam = Camera::pinhole(900.0, 900.0, 639.5, 359.5, 1280, 720);
	const Bundle board = Bundle::grid(2, 3, 0.05, 0.03);
	Detector det(Config{});
	std::mt19937 rng(8);
	int singleFlips = 0, singles = 0, bundleFlips = 0, frames = 0;
	for (int k = 0; k < 20; ++k) {
		Pose truth = boardPose(6.0, 3.0 * k, 1.5, -0.09, 0.04);
		Image img(1280, 720, 150);
		renderBoard(img, board, dict, truth, cam, rng, -1, -1, 0.0, 6.0f);
		const Result &res = det.detect(img.view());
		for (const Marker &m : res.markers) {
			const auto mp = estimatePose(m.corners, 0.05, cam);
			if (!mp)
				continue;
			++singles;
			/* Its marker frame is the board's turned by nothing (a grid): the
			 * rotation should be the board's. A flip is tens of degrees off. */
			singleFlips += rotationDistanceDeg(mp->pose, truth) > 6.0;
		}
		const auto bp = estimateBundlePose(board, res.markers, cam);
		if (!bp)
			continue;
		++frames;
		bundleFlips += rotationDistanceDeg(bp->pose, truth) > 6.0;
	}
	std::printf("single markers: %d tilt flips in %d poses; the board: %d in %d frames\n", singleFlips, singles,
		    bundleFlips, frames);
	EXPECT_EQ(frames, 20);
	EXPECT_GT(singleFlips, 0); /* the scene is one where single markers flip */
	EXPECT_EQ(bundleFlips, 0);
}
