// SPDX-License-Identifier: MIT
// Pose estimation against known geometry: markers rendered where a known
// pose puts them through a known camera (pinhole, 5 and 8 distortion
// coefficients), detected, and their pose estimated; exact corners; the two
// IPPE solutions; projection and undistortion; bad input.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "frappe/frappe.h"
#include "scene.h"

using namespace frappe;
using namespace frappe::test;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

/* The test's own geometry, written independently of the library's. */
using Mat3 = std::array<std::array<double, 3>, 3>;
using Vec3 = std::array<double, 3>;

Mat3 mul(const Mat3 &a, const Mat3 &b)
{
	Mat3 r{};
	for (int i = 0; i < 3; ++i)
		for (int j = 0; j < 3; ++j)
			for (int k = 0; k < 3; ++k)
				r[i][j] += a[i][k] * b[k][j];
	return r;
}

Mat3 rotX(double a)
{
	return { { { 1, 0, 0 }, { 0, std::cos(a), -std::sin(a) }, { 0, std::sin(a), std::cos(a) } } };
}
Mat3 rotY(double a)
{
	return { { { std::cos(a), 0, std::sin(a) }, { 0, 1, 0 }, { -std::sin(a), 0, std::cos(a) } } };
}
Mat3 rotZ(double a)
{
	return { { { std::cos(a), -std::sin(a), 0 }, { std::sin(a), std::cos(a), 0 }, { 0, 0, 1 } } };
}

/* Axis-angle to matrix, as the rotation's action on each basis vector. */
Mat3 fromRvec(const std::array<double, 3> &r)
{
	const double t = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
	if (t == 0.0)
		return rotZ(0.0);
	const double k[3] = { r[0] / t, r[1] / t, r[2] / t };
	Mat3 m{};
	for (int j = 0; j < 3; ++j) {
		const double e[3] = { j == 0 ? 1.0 : 0.0, j == 1 ? 1.0 : 0.0, j == 2 ? 1.0 : 0.0 };
		const double kxe[3] = { k[1] * e[2] - k[2] * e[1], k[2] * e[0] - k[0] * e[2], k[0] * e[1] - k[1] * e[0] };
		const double kde = k[0] * e[0] + k[1] * e[1] + k[2] * e[2];
		for (int i = 0; i < 3; ++i)
			m[i][j] = e[i] * std::cos(t) + kxe[i] * std::sin(t) + k[i] * kde * (1 - std::cos(t));
	}
	return m;
}

/* Degrees between two rotations. */
double angleBetween(const Mat3 &a, const Mat3 &b)
{
	double tr = 0.0;
	for (int i = 0; i < 3; ++i)
		for (int k = 0; k < 3; ++k)
			tr += a[k][i] * b[k][i];
	return std::acos(std::clamp((tr - 1.0) / 2.0, -1.0, 1.0)) / kDeg;
}

/* OpenCV's camera model, straight from its documentation. */
Point2f projectTruth(const Mat3 &R, const Vec3 &t, const Vec3 &X, const Camera &cam)
{
	double P[3];
	for (int i = 0; i < 3; ++i)
		P[i] = R[i][0] * X[0] + R[i][1] * X[1] + R[i][2] * X[2] + t[i];
	const double x = P[0] / P[2], y = P[1] / P[2];
	double k[8] = {};
	for (std::size_t i = 0; i < cam.distortion.size(); ++i)
		k[i] = cam.distortion[i];
	const double r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
	const double radial = (1 + k[0] * r2 + k[1] * r4 + k[4] * r6) / (1 + k[5] * r2 + k[6] * r4 + k[7] * r6);
	const double xd = x * radial + 2 * k[2] * x * y + k[3] * (r2 + 2 * x * x);
	const double yd = y * radial + k[2] * (r2 + 2 * y * y) + 2 * k[3] * x * y;
	return { static_cast<float>(cam.matrix[0] * xd + cam.matrix[1] * yd + cam.matrix[2]),
		 static_cast<float>(cam.matrix[4] * yd + cam.matrix[5]) };
}

std::array<Point2f, 4> cornersTruth(const Mat3 &R, const Vec3 &t, double side, const Camera &cam)
{
	const double h = side / 2;
	const Vec3 m[4] = { { -h, h, 0 }, { h, h, 0 }, { h, -h, 0 }, { -h, -h, 0 } };
	std::array<Point2f, 4> c;
	for (int i = 0; i < 4; ++i)
		c[i] = projectTruth(R, t, m[i], cam);
	return c;
}

/* A marker facing the camera (its y up is the image's down, its z out is
 * the camera's -z), tilted about its x then y axes, rolled about the
 * optical axis, its centre seen at pixel (u, v) of the undistorted camera
 * at `z` metres. */
struct Scene {
	double roll, tilt_x, tilt_y; ///< degrees
	double u, v, z;
	double max_rotation = 0.5; ///< degrees, for the rendered tests
};

void sceneToPose(const Scene &s, const Camera &cam, Mat3 &R, Vec3 &t)
{
	const Mat3 flip = { { { 1, 0, 0 }, { 0, -1, 0 }, { 0, 0, -1 } } };
	R = mul(rotZ(s.roll * kDeg), mul(mul(flip, rotX(s.tilt_x * kDeg)), rotY(s.tilt_y * kDeg)));
	t = { (s.u - cam.matrix[2]) * s.z / cam.matrix[0], (s.v - cam.matrix[5]) * s.z / cam.matrix[4], s.z };
}

double distance(const Vec3 &a, const std::array<double, 3> &b)
{
	return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

constexpr double kSide = 0.05; /* metres, the sample video's markers */

/* From 50 px face on to 60 degrees of tilt, rolled and off-centre; the
 * rotation error allowed, degrees. 0.5 everywhere but face on at 50 px:
 * there the tilt shows only as perspective foreshortening, and a corner
 * error of e px on a marker w px wide at z metres tilts it by about
 * e / (w * side / z) radians: 2.4 degrees for the 0.15 px the detector's
 * corners are off by in one of these renders. */
const Scene kScenes[] = {
	{ 0, 0, 0, 320, 240, 0.70, 3.0 },     /* 50 px, face on */
	{ 25, 0, 0, 200, 150, 0.50, 0.5 },    /* 70 px, rolled, off-centre */
	{ 0, 30, 0, 420, 300, 0.45, 0.5 },    /* tilted 30 about x */
	{ -40, 0, 45, 250, 330, 0.40, 0.5 },  /* 45 about y */
	{ 70, 60, 0, 330, 230, 0.30, 0.5 },   /* 60 */
	{ 120, 20, 35, 480, 120, 0.35, 0.5 }, /* about 40, in a corner */
	{ 200, -50, 10, 150, 360, 0.30, 0.5 },
	{ 10, 0, -60, 330, 250, 0.28, 0.5 },
	{ 0, 15, 0, 160, 110, 0.60, 0.5 },    /* 58 px, slight tilt, far off-centre */
};

Camera camera700()
{
	return Camera::pinhole(700.0, 700.0, 319.5, 239.5, 640, 480);
}
Camera camera5()
{
	Camera c = camera700();
	c.distortion = { -0.28, 0.09, 0.0012, -0.0007, -0.012 };
	return c;
}
Camera camera8()
{
	Camera c = camera700();
	c.matrix = { 690.0, 0.0, 322.0, 0.0, 705.0, 236.0, 0.0, 0.0, 1.0 };
	c.distortion = { 0.35, -0.12, 0.0009, 0.0005, 0.02, 0.62, -0.06, 0.03 };
	return c;
}

struct Worst {
	double translation_pct = 0.0, rotation_deg = 0.0, rotation_tilted_deg = 0.0;
};

/* Renders each scene, detects it, estimates the pose; the worst errors. */
Worst renderedAccuracy(const Camera &cam, const char *name)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	Detector det(Config{});
	Worst worst;
	int id = 0;
	for (const Scene &s : kScenes) {
		Mat3 R;
		Vec3 t;
		sceneToPose(s, cam, R, t);
		const auto truth = cornersTruth(R, t, kSide, cam);
		Image img(640, 480, 120);
		RenderOptions opt;
		opt.black = 30;
		opt.white = 220;
		renderMarker(img.mut(), dict, id, truth, opt);
		const Result &res = det.detect(img.view());
		const Marker *m = findMarker(res.markers, id);
		EXPECT_NE(m, nullptr) << name << " scene " << id;
		if (!m) {
			++id;
			continue;
		}
		const auto est = estimatePose(m->corners, kSide, cam);
		EXPECT_TRUE(est.has_value()) << name << " scene " << id;
		if (est) {
			const double dt = 100.0 * distance(t, est->pose.tvec) / s.z;
			const double dr = angleBetween(R, fromRvec(est->pose.rvec));
			std::printf("%s scene %d: side %.0f px, corners off by %.3f px, translation %.3f %%, "
				    "rotation %.3f deg, error %.3f px, ambiguity %.1f\n",
				    name, id, 700.0 * kSide / s.z, meanCornerError(m->corners, truth), dt, dr,
				    est->pose.error, est->ambiguity());
			EXPECT_LT(dt, 1.0) << name << " scene " << id;
			EXPECT_LT(dr, s.max_rotation) << name << " scene " << id;
			worst.translation_pct = std::max(worst.translation_pct, dt);
			worst.rotation_deg = std::max(worst.rotation_deg, dr);
			if (s.tilt_x != 0 || s.tilt_y != 0)
				worst.rotation_tilted_deg = std::max(worst.rotation_tilted_deg, dr);
		}
		++id;
	}
	std::printf("%s worst: translation %.3f %% of the distance, rotation %.3f deg (%.3f tilted)\n",
		    name, worst.translation_pct, worst.rotation_deg, worst.rotation_tilted_deg);
	return worst;
}

} // namespace

TEST(Pose, RenderedMarkersPinhole)
{
	renderedAccuracy(camera700(), "pinhole");
}

TEST(Pose, RenderedMarkersFiveCoefficients)
{
	renderedAccuracy(camera5(), "5 coefficients");
}

TEST(Pose, RenderedMarkersEightCoefficients)
{
	renderedAccuracy(camera8(), "8 coefficients");
}

/* Corners projected exactly (to float precision) give the pose back. */
TEST(Pose, ExactCornersRecoverThePose)
{
	for (const Camera &cam : { camera700(), camera5(), camera8() }) {
		for (const Scene &s : kScenes) {
			Mat3 R;
			Vec3 t;
			/* A 10 cm marker: 230 px at 0.3 m, so that float corners
			 * (1e-5 px) do not limit the comparison. */
			Scene near = s;
			near.z = std::min(s.z, 0.4);
			sceneToPose(near, cam, R, t);
			const auto est = estimatePose(cornersTruth(R, t, 0.1, cam), 0.1, cam);
			ASSERT_TRUE(est.has_value());
			EXPECT_LT(distance(t, est->pose.tvec), 1e-6);
			EXPECT_LT(angleBetween(R, fromRvec(est->pose.rvec)) * kDeg, 1e-6);
			EXPECT_LT(est->pose.error, 1e-4);
			EXPECT_GE(est->alternative.error, est->pose.error);
		}
	}
}

/* A tilted marker: the second IPPE solution is the mirror tilt, a distinct
 * pose that reprojects worse; face on, the two nearly coincide. */
TEST(Pose, BothSolutionsReported)
{
	const Camera cam = camera5();
	Mat3 R;
	Vec3 t;
	sceneToPose({ 30, 40, 0, 300, 260, 0.3 }, cam, R, t);
	const auto est = estimatePose(cornersTruth(R, t, kSide, cam), kSide, cam);
	ASSERT_TRUE(est.has_value());
	EXPECT_LT(angleBetween(R, fromRvec(est->pose.rvec)), 1e-4);
	EXPECT_GT(angleBetween(R, fromRvec(est->alternative.rvec)), 20.0);
	EXPECT_TRUE(std::isfinite(est->alternative.error));
	EXPECT_GT(est->alternative.error, est->pose.error + 0.1);
	EXPECT_GT(est->ambiguity(), 10.0);
	/* The alternative's error is what its own pose reprojects to. */
	const auto alt = projectPoints(std::array<std::array<double, 3>, 4>{ { { -0.025, 0.025, 0 },
									   { 0.025, 0.025, 0 },
									   { 0.025, -0.025, 0 },
									   { -0.025, -0.025, 0 } } },
				       est->alternative, cam);
	const auto truth = cornersTruth(R, t, kSide, cam);
	double sum = 0.0;
	for (int i = 0; i < 4; ++i)
		sum += std::pow(alt[i].x - truth[i].x, 2) + std::pow(alt[i].y - truth[i].y, 2);
	EXPECT_NEAR(std::sqrt(sum / 4), est->alternative.error, 1e-3);

	/* Face on and far: ambiguous, both solutions explain the corners. */
	sceneToPose({ 0, 0, 0, 320, 240, 1.5 }, cam, R, t);
	const auto flat = estimatePose(cornersTruth(R, t, kSide, cam), kSide, cam);
	ASSERT_TRUE(flat.has_value());
	EXPECT_LT(flat->alternative.error, 0.01);
	EXPECT_GE(flat->alternative.error, flat->pose.error);
}

TEST(Pose, DegenerateCornersGiveNothing)
{
	const Camera cam = camera5();
	const float nan = std::numeric_limits<float>::quiet_NaN();
	const float inf = std::numeric_limits<float>::infinity();
	const std::array<Point2f, 4> cases[] = {
		{ { { 100, 100 }, { 100, 100 }, { 100, 100 }, { 100, 100 } } }, /* one point */
		{ { { 100, 100 }, { 150, 100 }, { 200, 100 }, { 120, 160 } } }, /* three collinear */
		{ { { 100, 100 }, { 200, 100 }, { 200, 100 }, { 100, 200 } } }, /* two coincide */
		{ { { 100, 100 }, { 200, 200 }, { 200, 100 }, { 100, 200 } } }, /* crossed, not convex */
		{ { { nan, 100 }, { 200, 100 }, { 200, 200 }, { 100, 200 } } },
		{ { { 100, 100 }, { 200, inf }, { 200, 200 }, { 100, 200 } } },
		/* far beyond the fold of the barrel distortion: no undistorted point */
		{ { { -4000, -4000 }, { 4000, -4000 }, { 4000, 4000 }, { -4000, 4000 } } },
	};
	int i = 0;
	for (const auto &c : cases)
		EXPECT_FALSE(estimatePose(c, kSide, cam).has_value()) << "case " << i++;
}

TEST(Pose, BadSizeOrCameraThrows)
{
	const std::array<Point2f, 4> c = { { { 100, 100 }, { 200, 100 }, { 200, 200 }, { 100, 200 } } };
	for (double size : { 0.0, -0.05, std::numeric_limits<double>::quiet_NaN(),
			     std::numeric_limits<double>::infinity() })
		EXPECT_THROW(estimatePose(c, size, camera700()), std::invalid_argument) << size;

	Camera zero_f = camera700();
	zero_f.matrix[0] = 0.0;
	Camera three = camera700();
	three.distortion = { 0.1, 0.0, 0.0 };
	Camera nan_k = camera5();
	nan_k.distortion[1] = std::numeric_limits<double>::quiet_NaN();
	Camera last_row = camera700();
	last_row.matrix[8] = 2.0;
	for (const Camera &cam : { zero_f, three, nan_k, last_row }) {
		EXPECT_FALSE(cam.valid());
		EXPECT_THROW(estimatePose(c, kSide, cam), std::invalid_argument);
		EXPECT_THROW(projectPoints({}, Pose{}, cam), std::invalid_argument);
		EXPECT_THROW(undistortPoints({}, cam), std::invalid_argument);
	}
	try {
		three.validate();
		FAIL();
	} catch (const std::invalid_argument &e) {
		EXPECT_NE(std::string(e.what()).find("3 coefficients"), std::string::npos) << e.what();
	}
}

/* projectPoints is OpenCV's model; behind the camera is NaN. */
TEST(Pose, ProjectPoints)
{
	const Camera cam = camera8();
	Mat3 R;
	Vec3 t;
	sceneToPose({ 35, 25, -20, 280, 200, 0.5 }, cam, R, t);
	Pose pose;
	pose.tvec = t;
	/* rvec by the test's own Rodrigues, checked by its inverse below. */
	const double angle = std::acos(std::clamp((R[0][0] + R[1][1] + R[2][2] - 1) / 2, -1.0, 1.0));
	const double s = 2 * std::sin(angle);
	pose.rvec = { (R[2][1] - R[1][2]) / s * angle, (R[0][2] - R[2][0]) / s * angle,
		      (R[1][0] - R[0][1]) / s * angle };
	ASSERT_LT(angleBetween(R, fromRvec(pose.rvec)), 1e-9);
	const std::array<std::array<double, 3>, 4> pts = { { { 0, 0, 0 }, { 0.1, 0, 0 }, { 0, 0.1, 0 }, { 0, 0, 0.1 } } };
	const auto out = projectPoints(pts, pose, cam);
	ASSERT_EQ(out.size(), 4u);
	for (int i = 0; i < 4; ++i) {
		const Point2f p = projectTruth(R, t, pts[i], cam);
		EXPECT_NEAR(out[i].x, p.x, 1e-3);
		EXPECT_NEAR(out[i].y, p.y, 1e-3);
	}
	/* A point 1 m towards the viewer from a marker 0.5 m away. */
	const std::array<std::array<double, 3>, 1> behind = { { { 0, 0, 1.0 } } };
	const auto b = projectPoints(behind, pose, cam);
	EXPECT_TRUE(std::isnan(b[0].x) && std::isnan(b[0].y));
	/* Into caller's room, the same points; room of the wrong size throws. */
	std::array<Point2f, 4> room;
	projectPoints(pts, pose, cam, room);
	for (int i = 0; i < 4; ++i) {
		EXPECT_EQ(room[i].x, out[i].x);
		EXPECT_EQ(room[i].y, out[i].y);
	}
	std::array<Point2f, 3> small;
	EXPECT_THROW(projectPoints(pts, pose, cam, small), std::invalid_argument);
}

/* undistortPoints inverts the distortion: where the point would be seen by
 * the same camera matrix without distortion. */
TEST(Pose, UndistortPoints)
{
	for (const Camera &cam : { camera5(), camera8() }) {
		Camera pin = cam;
		pin.distortion.clear();
		std::vector<Point2f> distorted, ideal;
		const Mat3 I = rotZ(0.0);
		for (double x = -0.4; x <= 0.4; x += 0.2)
			for (double y = -0.3; y <= 0.3; y += 0.15) {
				distorted.push_back(projectTruth(I, { 0, 0, 0 }, { x, y, 1.0 }, cam));
				ideal.push_back(projectTruth(I, { 0, 0, 0 }, { x, y, 1.0 }, pin));
			}
		const auto out = undistortPoints(distorted, cam);
		ASSERT_EQ(out.size(), ideal.size());
		for (std::size_t i = 0; i < out.size(); ++i) {
			EXPECT_NEAR(out[i].x, ideal[i].x, 1e-3);
			EXPECT_NEAR(out[i].y, ideal[i].y, 1e-3);
		}
		/* Without distortion the points stay put. */
		const auto same = undistortPoints(ideal, pin);
		for (std::size_t i = 0; i < same.size(); ++i) {
			EXPECT_EQ(same[i].x, ideal[i].x);
			EXPECT_EQ(same[i].y, ideal[i].y);
		}
	}
}

TEST(MarkerSizes, ParsesAndLooksUp)
{
	const MarkerSizes sizes = MarkerSizes::parse(" 7:0.1, 0:0.05 ,42 : 0.2", 0.03);
	EXPECT_EQ(sizes(0), 0.05);
	EXPECT_EQ(sizes(7), 0.1);
	EXPECT_EQ(sizes(42), 0.2);
	EXPECT_EQ(sizes(1), 0.03);
	EXPECT_EQ(sizes.defaultSize(), 0.03);
	ASSERT_EQ(sizes.exceptions().size(), 3u);
	EXPECT_EQ(sizes.exceptions()[0].first, 0);
	EXPECT_EQ(sizes.exceptions()[2].first, 42);
	EXPECT_EQ(sizes.toString(), "0:0.05,7:0.1,42:0.2");
	EXPECT_TRUE(sizes.any());
	EXPECT_EQ(MarkerSizes::parse(sizes.toString()).exceptions(), sizes.exceptions());

	EXPECT_FALSE(MarkerSizes::parse("").any());
	EXPECT_FALSE(MarkerSizes::parse("  ").any());
	EXPECT_FALSE(MarkerSizes().any());
	EXPECT_EQ(MarkerSizes()(3), 0.0);
	EXPECT_TRUE(MarkerSizes(0.05).any());
	EXPECT_TRUE(MarkerSizes::parse("3:0.01").any());
	EXPECT_EQ(MarkerSizes::parse("3:0.01")(4), 0.0);
	EXPECT_EQ(MarkerSizes::parse("", 0.05).toString(), "");
}

TEST(MarkerSizes, BadEntriesThrowNamingThem)
{
	const struct {
		const char *spec, *mention;
	} cases[] = {
		{ "7", "\"7\": expected id:size" },
		{ "7:0.1,", "empty entry" },
		{ "7:0.1,,8:0.2", "empty entry" },
		{ "x:0.1", "\"x:0.1\": the id is not an integer" },
		{ "-1:0.1", "negative" },
		{ "3:abc", "\"3:abc\": the size is not a number" },
		{ "3:0", "positive" },
		{ "3:-0.1", "positive" },
		{ "3:inf", "positive" },
		{ "3:0.1cm", "not a number" },
		{ "3:0.1,3:0.2", "id 3 is given twice" },
	};
	for (const auto &c : cases) {
		try {
			MarkerSizes::parse(c.spec);
			ADD_FAILURE() << c.spec << " parsed";
		} catch (const std::invalid_argument &e) {
			EXPECT_NE(std::string(e.what()).find(c.mention), std::string::npos)
				<< c.spec << ": " << e.what();
		}
	}
	EXPECT_THROW(MarkerSizes::parse("", -1.0), std::invalid_argument);
	EXPECT_THROW(MarkerSizes::parse("", std::nan("")), std::invalid_argument);
}

/* Issue 34: inserting each id in order made a long list in descending
 * order quadratic (400,000 ids: 107 s, under the element's lock). Now the
 * longest list accepted parses in milliseconds, in any order, and a longer
 * one is refused saying why. */
TEST(MarkerSizes, LongListsParseFastOrAreRefused)
{
	std::string spec;
	int n = 0;
	for (int id = 999999; spec.size() + 16 < MarkerSizes::kMaxSpecBytes; --id, ++n)
		spec += std::to_string(id) + ":0.05,";
	spec += "7:0.25";
	const auto t0 = std::chrono::steady_clock::now();
	const MarkerSizes sizes = MarkerSizes::parse(spec, 0.01);
	const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
	EXPECT_LT(ms, 1000.0) << n << " ids in descending order";
	ASSERT_EQ(sizes.exceptions().size(), static_cast<std::size_t>(n) + 1);
	EXPECT_TRUE(std::is_sorted(sizes.exceptions().begin(), sizes.exceptions().end()));
	EXPECT_EQ(sizes(7), 0.25);
	EXPECT_EQ(sizes(999999), 0.05);
	EXPECT_EQ(sizes(8), 0.01);

	try {
		MarkerSizes::parse(spec + ",8:0.1" + std::string(MarkerSizes::kMaxSpecBytes, ' '));
		ADD_FAILURE() << "a spec over 1 MiB parsed";
	} catch (const std::invalid_argument &e) {
		EXPECT_EQ(std::string(e.what()), "marker sizes: " + std::to_string(spec.size() + 6 + MarkerSizes::kMaxSpecBytes) +
							 " bytes, more than the 1048576 a list of sizes may have");
	}
	/* Out of order, the repeat named is the first one in the text. */
	try {
		MarkerSizes::parse("9:0.1, 5:0.1,3:0.2 , 5:0.3,3:0.4");
		ADD_FAILURE() << "a repeated id parsed";
	} catch (const std::invalid_argument &e) {
		EXPECT_EQ(std::string(e.what()), "marker sizes: \"5:0.3\": id 5 is given twice");
	}
}
