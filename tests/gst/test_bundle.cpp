// SPDX-License-Identifier: MIT
// frappedetect's bundle-file (issue 32): a board of markers rendered
// through a known pose, its one pose from all markers in the
// GstFrappeBundleMeta against the truth, the same values in the element
// message and in frappejson's line; no meta without the bundle; a moved
// marker rejected; a bad file or no camera failing the start.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <type_traits>
#include <vector>

#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <frappe/bundle.h>
#include <frappe/pose.h>

#include "gstfrappemeta.h"
#include "helpers.h"

using namespace frappe::gsttest;

static auto *const gstEnv = ::testing::AddGlobalTestEnvironment(new GstEnvironment);

namespace {

/* The fixture: a 2 x 3 grid board of 5 cm markers, ids 0-5. */
const std::string kBoardFile = std::string(FRAPPE_GST_TEST_DIR) + "/bundle-board.yaml";

constexpr double kFocal = 600.0;
const FrameSpec kSpec{ GST_VIDEO_FORMAT_GRAY8, 640, 480 };

/* ROS camera_info YAML of a 640x480 pinhole of focal kFocal. */
std::string calibration()
{
	char text[400];
	std::snprintf(text, sizeof(text),
		      "image_width: 640\nimage_height: 480\ncamera_matrix:\n  rows: 3\n  cols: 3\n"
		      "  data: [%.1f, 0.0, 319.5, 0.0, %.1f, 239.5, 0.0, 0.0, 1.0]\n"
		      "distortion_model: plumb_bob\ndistortion_coefficients:\n  rows: 1\n  cols: 5\n"
		      "  data: [0.0, 0.0, 0.0, 0.0, 0.0]\n",
		      kFocal, kFocal);
	return text;
}

frappe::Camera camera()
{
	return frappe::Camera::pinhole(kFocal, kFocal, 319.5, 239.5, 640, 480);
}

/* The rotation matrix of a Rodrigues vector, row-major. */
std::array<double, 9> matrixOf(const std::array<double, 3> &r)
{
	const double th = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
	if (th < 1e-12)
		return { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
	return rotation({ r[0] / th, r[1] / th, r[2] / th }, th);
}

/* The Rodrigues vector of a rotation of angle below pi. */
std::array<double, 3> rvecOf(const std::array<double, 9> &R)
{
	const double angle = std::acos(std::clamp((R[0] + R[4] + R[8] - 1.0) / 2.0, -1.0, 1.0));
	const double s = angle / (2.0 * std::sin(angle));
	return { s * (R[7] - R[5]), s * (R[2] - R[6]), s * (R[3] - R[1]) };
}

/* Degrees between two rotations. */
double rotationDeg(const std::array<double, 3> &a, const std::array<double, 3> &b)
{
	const auto A = matrixOf(a), B = matrixOf(b);
	double trace = 0.0;
	for (int i = 0; i < 9; ++i)
		trace += A[static_cast<std::size_t>(i)] * B[static_cast<std::size_t>(i)];
	return std::acos(std::clamp((trace - 1.0) / 2.0, -1.0, 1.0)) * 180.0 / G_PI;
}

/* The board facing the camera, tilted by 30 degrees, its centre
 * (0.085, 0.055) 0.5 m ahead, a little off the axis. */
frappe::Pose truth()
{
	const auto R = facingCamera(rotation({ 0.6, 0.8, 0.0 }, 30.0 * G_PI / 180.0));
	frappe::Pose p;
	p.rvec = rvecOf(R);
	const double centre[3] = { 0.085, 0.055, 0.0 };
	const double at[3] = { 0.02, -0.01, 0.5 };
	for (std::size_t i = 0; i < 3; ++i)
		p.tvec[i] = at[i] - (R[3 * i] * centre[0] + R[3 * i + 1] * centre[1] + R[3 * i + 2] * centre[2]);
	return p;
}

/* The board's markers where `pose` puts them (a square under a pinhole is
 * a homography: the render is exact); marker `moved` shifted by `shift`
 * metres along the board's x. */
std::vector<Placed> board(const frappe::Bundle &b, const frappe::Pose &pose, int moved = -1, double shift = 0.0)
{
	std::vector<Placed> out;
	for (const frappe::BundleMarker &m : b.markers) {
		auto corners = m.corners;
		if (m.id == moved)
			for (auto &c : corners)
				c[0] += shift;
		const auto px = frappe::projectPoints(corners, pose, camera());
		out.push_back({ m.id, { px[0], px[1], px[2], px[3] } });
	}
	return out;
}

std::vector<int> ids(const gint *v, guint n)
{
	return std::vector<int>(v, v + n);
}

/* A GstValueArray field of doubles or ints. */
template<typename T>
std::vector<T> values(const GstStructure *s, const char *field)
{
	std::vector<T> out;
	const GValue *array = gst_structure_get_value(s, field);
	for (guint i = 0; array && i < gst_value_array_get_size(array); ++i) {
		const GValue *v = gst_value_array_get_value(array, i);
		if constexpr (std::is_same_v<T, double>)
			out.push_back(g_value_get_double(v));
		else
			out.push_back(g_value_get_int(v));
	}
	return out;
}

/* The `bundle` structure of the last frappedetect message on the bus, or
 * nullptr (`holder` keeps its message). */
const GstStructure *messageBundle(GstBus *bus, GstMessage *&holder)
{
	holder = nullptr;
	while (GstMessage *m = gst_bus_pop_filtered(bus, GST_MESSAGE_ELEMENT)) {
		if (gst_structure_has_name(gst_message_get_structure(m), "frappedetect")) {
			if (holder)
				gst_message_unref(holder);
			holder = m;
		} else {
			gst_message_unref(m);
		}
	}
	if (!holder)
		return nullptr;
	const GValue *v = gst_structure_get_value(gst_message_get_structure(holder), "bundle");
	return v ? gst_value_get_structure(v) : nullptr;
}

/* frappejson's line (max-bytes=0: one) of a buffer. */
std::string jsonLine(GstBuffer *video)
{
	GstHarness *h = gst_harness_new_parse("frappejson max-bytes=0");
	gst_harness_set_src_caps_str(h, capsString(kSpec).c_str());
	GstBuffer *out = gst_harness_push_and_pull(h, gst_buffer_ref(video));
	std::string line;
	if (out) {
		GstMapInfo map;
		gst_buffer_map(out, &map, GST_MAP_READ);
		line.assign(reinterpret_cast<const char *>(map.data), map.size);
		gst_buffer_unmap(out, &map);
		gst_buffer_unref(out);
	}
	gst_harness_teardown(h);
	return line;
}

/* The numbers of `key`'s array in `text` (after its first "key": [). */
std::vector<double> jsonArray(const std::string &text, const std::string &key)
{
	std::vector<double> out;
	std::size_t at = text.find("\"" + key + "\": [");
	if (at == std::string::npos)
		return out;
	const char *p = text.c_str() + at + key.size() + 5;
	while (*p != ']') {
		char *end = nullptr;
		out.push_back(std::strtod(p, &end));
		p = end;
		while (*p == ',' || *p == ' ')
			++p;
	}
	return out;
}

double jsonNumber(const std::string &text, const std::string &key)
{
	const std::size_t at = text.find("\"" + key + "\": ");
	return at == std::string::npos ? NAN : std::strtod(text.c_str() + at + key.size() + 4, nullptr);
}

/* A harness of frappedetect with the board and a calibration file. */
struct BoardHarness {
	TempDir dir;
	const std::string calibrationFile = dir.write("camera.yaml", calibration());
	BusHarness t{ ("frappedetect bundle-file=\"" + kBoardFile + "\" calibration-file=\"" + calibrationFile + "\"")
			      .c_str(),
		      kSpec };
};

} // namespace

/* The meta's pose against the truth; the message and frappejson's line
 * carry the meta's values exactly. */
TEST(Bundle, PoseInTheMetaTheMessageAndTheLine)
{
	const frappe::Bundle b = frappe::loadBundle(kBoardFile);
	ASSERT_EQ(b.markers.size(), 6u);
	const frappe::Pose want = truth();
	BoardHarness f;
	GstBuffer *out = gst_harness_push_and_pull(f.t.h, makeFrame(kSpec, board(b, want), dict("aruco_mip_36h12")));
	ASSERT_NE(out, nullptr);
	ASSERT_EQ(markerMetas(out).size(), 6u);
	const GstFrappeBundleMeta *m = gst_buffer_get_frappe_bundle_meta(out);
	ASSERT_NE(m, nullptr);
	EXPECT_STREQ(m->name, "test_board");
	EXPECT_EQ(ids(m->used, m->n_used).size(), 6u);
	EXPECT_EQ(m->n_rejected, 0u);
	const double distance =
		std::sqrt(want.tvec[0] * want.tvec[0] + want.tvec[1] * want.tvec[1] + want.tvec[2] * want.tvec[2]);
	double terr = 0.0;
	for (std::size_t i = 0; i < 3; ++i)
		terr += (m->tvec[i] - want.tvec[i]) * (m->tvec[i] - want.tvec[i]);
	EXPECT_LT(std::sqrt(terr), 0.005 * distance);
	EXPECT_LT(rotationDeg({ m->rvec[0], m->rvec[1], m->rvec[2] }, want.rvec), 0.5);
	EXPECT_GT(m->reprojection_error, 0.0);
	EXPECT_LT(m->reprojection_error, 1.0);

	GstMessage *msg = nullptr;
	const GstStructure *s = messageBundle(f.t.bus, msg);
	ASSERT_NE(s, nullptr);
	EXPECT_STREQ(gst_structure_get_string(s, "name"), "test_board");
	EXPECT_EQ(values<double>(s, "rvec"), std::vector<double>(m->rvec, m->rvec + 3));
	EXPECT_EQ(values<double>(s, "tvec"), std::vector<double>(m->tvec, m->tvec + 3));
	double error = 0.0;
	EXPECT_TRUE(gst_structure_get_double(s, "reprojection-error", &error));
	EXPECT_EQ(error, m->reprojection_error);
	EXPECT_EQ(values<int>(s, "used"), ids(m->used, m->n_used));
	EXPECT_EQ(values<int>(s, "rejected"), std::vector<int>{});
	gst_message_unref(msg);

	const std::string line = jsonLine(out);
	const std::size_t at = line.find("\"bundle\": {\"name\": \"test_board\", ");
	ASSERT_NE(at, std::string::npos) << line;
	EXPECT_LT(at, line.find("\"markers\": [")) << line; /* a frame field, before the markers */
	const std::string bundle = line.substr(at);
	EXPECT_EQ(jsonArray(bundle, "rvec"), std::vector<double>(m->rvec, m->rvec + 3));
	EXPECT_EQ(jsonArray(bundle, "tvec"), std::vector<double>(m->tvec, m->tvec + 3));
	EXPECT_EQ(jsonNumber(bundle, "reprojection_error"), m->reprojection_error);
	const auto used = jsonArray(bundle, "used");
	EXPECT_EQ(std::vector<int>(used.begin(), used.end()), ids(m->used, m->n_used));
	EXPECT_NE(bundle.find("\"rejected\": []}"), std::string::npos) << line;

	/* A copy of the buffer copies the meta, ids and all. */
	GstBuffer *copy = gst_buffer_copy(out);
	const GstFrappeBundleMeta *c = gst_buffer_get_frappe_bundle_meta(copy);
	ASSERT_NE(c, nullptr);
	EXPECT_NE(c->used, m->used);
	EXPECT_EQ(ids(c->used, c->n_used), ids(m->used, m->n_used));
	EXPECT_EQ(std::vector<double>(c->tvec, c->tvec + 3), std::vector<double>(m->tvec, m->tvec + 3));
	EXPECT_EQ(c->reprojection_error, m->reprojection_error);
	gst_buffer_unref(copy);
	gst_buffer_unref(out);
}

/* A frame with markers but none of the bundle: no bundle meta, no message
 * field, no "bundle" in the line; the next frame with the board has it. */
TEST(Bundle, FrameWithoutTheBundleHasNone)
{
	BoardHarness f;
	GstBuffer *out = gst_harness_push_and_pull(
		f.t.h,
		makeFrame(kSpec, { square(20, 100, 100, 80), square(21, 300, 200, 80) }, dict("aruco_mip_36h12")));
	ASSERT_EQ(markerMetas(out).size(), 2u);
	EXPECT_EQ(gst_buffer_get_frappe_bundle_meta(out), nullptr);
	GstMessage *msg = nullptr;
	EXPECT_EQ(messageBundle(f.t.bus, msg), nullptr);
	ASSERT_NE(msg, nullptr);
	gst_message_unref(msg);
	EXPECT_EQ(jsonLine(out).find("bundle"), std::string::npos);
	gst_buffer_unref(out);

	out = gst_harness_push_and_pull(f.t.h, makeFrame(kSpec, board(frappe::loadBundle(kBoardFile), truth()),
							 dict("aruco_mip_36h12"), GST_SECOND));
	EXPECT_NE(gst_buffer_get_frappe_bundle_meta(out), nullptr);
	gst_buffer_unref(out);
}

/* A marker moved on the board (7 px in the image) is rejected, and the
 * pose stays on the truth. */
TEST(Bundle, MovedMarkerIsAnOutlier)
{
	const frappe::Bundle b = frappe::loadBundle(kBoardFile);
	const frappe::Pose want = truth();
	BoardHarness f;
	GstBuffer *out =
		gst_harness_push_and_pull(f.t.h, makeFrame(kSpec, board(b, want, 4, 0.006), dict("aruco_mip_36h12")));
	const GstFrappeBundleMeta *m = gst_buffer_get_frappe_bundle_meta(out);
	ASSERT_NE(m, nullptr);
	EXPECT_EQ(ids(m->rejected, m->n_rejected), std::vector<int>{ 4 });
	EXPECT_EQ(m->n_used, 5u);
	EXPECT_LT(std::abs(m->tvec[2] - want.tvec[2]), 0.005 * want.tvec[2]);
	EXPECT_LT(rotationDeg({ m->rvec[0], m->rvec[1], m->rvec[2] }, want.rvec), 0.5);
	GstMessage *msg = nullptr;
	const GstStructure *s = messageBundle(f.t.bus, msg);
	ASSERT_NE(s, nullptr);
	EXPECT_EQ(values<int>(s, "rejected"), std::vector<int>{ 4 });
	gst_message_unref(msg);
	EXPECT_NE(jsonLine(out).find("\"rejected\": [4]}"), std::string::npos);
	gst_buffer_unref(out);
}

/* A file that is no bundle, a missing one, or a bundle without a camera:
 * the pipeline does not start, and the error names the property, the file
 * and the reason. */
TEST(Bundle, BadFileOrNoCameraFailsTheStart)
{
	TempDir dir;
	const std::string camera = dir.write("camera.yaml", calibration());
	const std::string bad =
		dir.write("bad.yaml", "board: grid\nrows: 2\ncols: 3\nsize: 0.05\ngap: 0.01\ncolour: red\n");
	const std::string missing = dir.path + "/missing.yaml";
	struct Case {
		std::string bundle, camera, reason;
	};
	for (const Case &c : { Case{ bad, camera, "unknown key 'colour'" }, Case{ missing, camera, "no such file" },
			       Case{ kBoardFile, "", "needs the camera" } }) {
		SCOPED_TRACE(c.bundle);
		const std::string calibrationSetting = c.camera.empty() ? "" : " calibration-file=\"" + c.camera + "\"";
		const MessageError e = startError(
			"videotestsrc num-buffers=1 ! video/x-raw,format=GRAY8 ! "
			"frappedetect name=d bundle-file=\"" +
			c.bundle + "\"" + calibrationSetting + " ! fakesink");
		EXPECT_EQ(e.domain, GST_RESOURCE_ERROR);
		EXPECT_EQ(e.code, GST_RESOURCE_ERROR_SETTINGS);
		EXPECT_NE(e.text.find("bundle-file=\"" + c.bundle + "\" refused"), std::string::npos) << e.text;
		EXPECT_NE(e.text.find(c.reason), std::string::npos) << e.text;
	}
}

/* Set while playing, a bad file is a warning and the bundle stays; "" clears
 * it. */
TEST(Bundle, SetWhilePlaying)
{
	BoardHarness f;
	const std::string bad = f.dir.write("bad.yaml", "board: grid\nrows: 0\ncols: 3\nsize: 0.05\ngap: 0.01\n");
	const auto frame = [&](GstClockTime pts) {
		return makeFrame(kSpec, board(frappe::loadBundle(kBoardFile), truth()), dict("aruco_mip_36h12"), pts);
	};
	GstBuffer *out = gst_harness_push_and_pull(f.t.h, frame(0));
	EXPECT_NE(gst_buffer_get_frappe_bundle_meta(out), nullptr);
	gst_buffer_unref(out);
	{
		const BusMessages drained(f.t.bus);
	}

	g_object_set(detector(f.t.h), "bundle-file", bad.c_str(), nullptr);
	expectOneSettingsWarning(f.t.bus, bad);
	out = gst_harness_push_and_pull(f.t.h, frame(GST_SECOND));
	EXPECT_NE(gst_buffer_get_frappe_bundle_meta(out), nullptr);
	gst_buffer_unref(out);

	g_object_set(detector(f.t.h), "bundle-file", "", nullptr);
	out = gst_harness_push_and_pull(f.t.h, frame(2 * GST_SECOND));
	EXPECT_EQ(gst_buffer_get_frappe_bundle_meta(out), nullptr);
	EXPECT_EQ(markerMetas(out).size(), 6u);
	gst_buffer_unref(out);
}

/* annotate=true draws the bundle frame's axes: the frame differs from the
 * one drawn without bundle-file, at the board's origin (its bottom-left
 * corner, marker 3's), and only there and along the axes. */
TEST(Bundle, AnnotateDrawsTheBundleAxes)
{
	const frappe::Bundle b = frappe::loadBundle(kBoardFile);
	TempDir dir;
	const std::string cam = dir.write("camera.yaml", calibration());
	const auto drawn = [&](const std::string &extra) {
		BusHarness t(("frappedetect annotate=true calibration-file=\"" + cam + "\"" + extra).c_str(), kSpec);
		GstBuffer *out =
			gst_harness_push_and_pull(t.h, makeFrame(kSpec, board(b, truth()), dict("aruco_mip_36h12")));
		std::vector<guint8> luma(static_cast<std::size_t>(kSpec.width * kSpec.height));
		gst_buffer_extract(out, 0, luma.data(), luma.size());
		gst_buffer_unref(out);
		return luma;
	};
	const auto without = drawn(""), with = drawn(" bundle-file=\"" + kBoardFile + "\"");
	const auto origin = frappe::projectPoints(std::array<std::array<double, 3>, 1>{ { { 0.0, 0.0, 0.0 } } },
						  truth(), camera())[0];
	int changed = 0, nearOrigin = 0;
	for (int y = 0; y < kSpec.height; ++y)
		for (int x = 0; x < kSpec.width; ++x) {
			const std::size_t i = static_cast<std::size_t>(y * kSpec.width + x);
			if (with[i] == without[i])
				continue;
			++changed;
			nearOrigin += std::hypot(x - origin.x, y - origin.y) < 6.0;
		}
	EXPECT_GT(changed, 100);
	EXPECT_GT(nearOrigin, 10);
}
