// SPDX-License-Identifier: MIT
// frappedetect's pose settings: calibration files (read at start, scaled
// to the frame size, refused with an error or a warning), per-id marker
// sizes, and the warnings for camera-matrix and distortion values it
// refuses.
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gtest/gtest.h>

#include "../support/blocking_read.h"
#include "gstfrappemeta.h"
#include "helpers.h"

using namespace frappe::gsttest;

static auto *const gstEnv = ::testing::AddGlobalTestEnvironment(new GstEnvironment);

namespace {

/* ROS camera_info YAML, as camera_calibration writes it. */
std::string rosCalibration(int width, int height, double fx, double fy, double cx, double cy)
{
	char text[512];
	std::snprintf(text, sizeof(text),
		      "image_width: %d\nimage_height: %d\ncamera_name: test\ncamera_matrix:\n  rows: 3\n  cols: 3\n"
		      "  data: [%.17g, 0.0, %.17g, 0.0, %.17g, %.17g, 0.0, 0.0, 1.0]\n"
		      "distortion_model: plumb_bob\ndistortion_coefficients:\n  rows: 1\n  cols: 5\n"
		      "  data: [0.0, 0.0, 0.0, 0.0, 0.0]\n",
		      width, height, fx, cx, fy, cy);
	return text;
}

/* A marker of 8 cm at 0.55 m, tilted by 25 degrees: its corners through a
 * pinhole of focal `f` centred on a frame of width x height. */
const std::array<double, 3> kTvec{ 0.03, -0.02, 0.55 };
constexpr double kSide = 0.08;

Placed posed(int id, int width, int height, double f)
{
	const auto m = facingCamera(rotation({ 0.6, 0.8, 0.0 }, 25.0 * G_PI / 180.0));
	return posedMarker(id, f, f, (width - 1) / 2.0, (height - 1) / 2.0, kSide, m, kTvec);
}

/* The single marker meta of the frame after the element. */
GstFrappeMarkerMeta posePushed(GstHarness *h, const FrameSpec &spec, const Placed &placed, GstClockTime pts = 0)
{
	GstBuffer *out = gst_harness_push_and_pull(h, makeFrame(spec, { placed }, dict("aruco_mip_36h12"), pts));
	GstFrappeMarkerMeta copy{};
	const auto metas = markerMetas(out);
	EXPECT_EQ(metas.size(), 1u);
	if (!metas.empty())
		copy = *metas[0];
	gst_buffer_unref(out);
	return copy;
}

void expectTvec(const GstFrappeMarkerMeta &m, const std::array<double, 3> &t, double relative)
{
	ASSERT_TRUE(m.has_pose);
	const double dist = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
	for (int i = 0; i < 3; ++i)
		EXPECT_NEAR(m.tvec[i], t[static_cast<std::size_t>(i)], relative * dist) << "tvec[" << i << "]";
}

std::string stringProperty(GstElement *e, const char *name)
{
	gchar *v = nullptr;
	g_object_get(e, name, &v, nullptr);
	std::string s(v ? v : "");
	g_free(v);
	return s;
}

/* A 640x480 calibration of focal 600 in a file, and a launch line using it
 * for 8 cm markers. */
struct Calibrated {
	TempDir dir;
	const std::string file = dir.write("camera.yaml", rosCalibration(640, 480, 600, 600, 319.5, 239.5));
	const std::string launch = "frappedetect marker-size=0.08 calibration-file=\"" + file + "\"";
};

constexpr const char *kWrongMatrix = "<300.0, 0.0, 100.0, 0.0, 300.0, 100.0, 0.0, 0.0, 1.0>";

} // namespace

/* The file gives the pose; it wins over camera-matrix whichever is set
 * first. */
TEST(Calibration, FileGivesThePoseAndWinsOverTheMatrix)
{
	const Calibrated c;
	const std::string &file = c.file;
	const FrameSpec spec{ GST_VIDEO_FORMAT_GRAY8, 640, 480 };
	const Placed marker = posed(5, 640, 480, 600);

	const std::string fileFirst = c.launch + " camera-matrix=\"" + kWrongMatrix + "\"";
	const std::string matrixFirst = "frappedetect marker-size=0.08 camera-matrix=\"" + std::string(kWrongMatrix) +
					"\" calibration-file=\"" + file + "\"";
	for (const std::string &launch : { fileFirst, matrixFirst }) {
		SCOPED_TRACE(launch);
		BusHarness t(launch.c_str(), spec);
		expectTvec(posePushed(t.h, spec, marker), kTvec, 0.01);
		EXPECT_EQ(stringProperty(detector(t.h), "calibration-file"), file);
		const BusMessages msgs(t.bus);
		EXPECT_TRUE(msgs.of(GST_MESSAGE_WARNING).empty());
	}

	/* Without the file the matrix is used: the wrong one gives another pose. */
	BusHarness t((std::string("frappedetect marker-size=0.08 camera-matrix=\"") + kWrongMatrix + "\"").c_str(),
		     spec);
	const GstFrappeMarkerMeta m = posePushed(t.h, spec, marker);
	ASSERT_TRUE(m.has_pose);
	EXPECT_GT(std::abs(m.tvec[2] - kTvec[2]), 0.1 * kTvec[2]);
}

/* A 640x480 calibration on 320x240 frames is scaled: the same pose. */
TEST(Calibration, ScaledToTheFrameSize)
{
	const Calibrated c;
	const FrameSpec full{ GST_VIDEO_FORMAT_I420, 640, 480 };
	BusHarness a(c.launch.c_str(), full);
	const GstFrappeMarkerMeta big = posePushed(a.h, full, posed(5, 640, 480, 600));

	/* Half the size: focal 300, centre (319.5 + 0.5) / 2 - 0.5. */
	const FrameSpec half{ GST_VIDEO_FORMAT_I420, 320, 240 };
	BusHarness b(c.launch.c_str(), half);
	const GstFrappeMarkerMeta small = posePushed(b.h, half, posed(5, 320, 240, 300));

	expectTvec(big, kTvec, 0.01);
	expectTvec(small, kTvec, 0.01);
	for (int i = 0; i < 3; ++i)
		EXPECT_NEAR(small.rvec[i], big.rvec[i], 0.05) << "rvec[" << i << "]";
	const BusMessages msgs(b.bus);
	EXPECT_TRUE(msgs.of(GST_MESSAGE_WARNING).empty());
}

/* Another aspect ratio cannot be scaled: one warning, no pose. */
TEST(Calibration, OtherAspectRatioWarnsOnceAndGivesNoPose)
{
	const Calibrated c;
	const FrameSpec wide{ GST_VIDEO_FORMAT_NV12, 640, 360 };
	BusHarness t(c.launch.c_str(), wide);
	for (int i = 0; i < 2; ++i) {
		const GstFrappeMarkerMeta m = posePushed(t.h, wide, posed(5, 640, 360, 600), i * GST_SECOND / 30);
		EXPECT_EQ(m.id, 5);
		EXPECT_FALSE(m.has_pose);
	}
	expectOneSettingsWarning(t.bus, "640x480 frames, not 640x360");
}

/* A file that cannot be used is an element error at start naming it, and
 * the pipeline does not start. */
TEST(Calibration, BadFileIsAnErrorAtStart)
{
	TempDir dir;
	const std::string malformed = dir.write("malformed.yaml", "image_width: 640\nimage_height: [oops\n");
	const std::string missing = dir.path + "/missing.yaml";
	for (const std::string &file : { malformed, missing }) {
		SCOPED_TRACE(file);
		const MessageError e = startError("videotestsrc num-buffers=1 ! video/x-raw,format=GRAY8 ! "
						  "frappedetect name=d marker-size=0.05 calibration-file=\"" +
						  file + "\" ! fakesink");
		EXPECT_EQ(e.domain, GST_RESOURCE_ERROR);
		EXPECT_EQ(e.code, GST_RESOURCE_ERROR_SETTINGS);
		EXPECT_NE(e.text.find(file), std::string::npos) << e.text;
	}
}

/* Set while playing, a bad file is a warning and the camera stays; a good
 * one is read at once. */
TEST(Calibration, SetWhilePlaying)
{
	TempDir dir;
	const std::string good = dir.write("good.yaml", rosCalibration(640, 480, 600, 600, 319.5, 239.5));
	const std::string other = dir.write("other.yaml", rosCalibration(640, 480, 300, 300, 319.5, 239.5));
	const std::string bad = dir.write("bad.yaml", "camera_matrix: {rows: 3}\n");
	const FrameSpec spec{ GST_VIDEO_FORMAT_GRAY8, 640, 480 };
	BusHarness t(("frappedetect marker-size=0.08 calibration-file=\"" + good + "\"").c_str(), spec);
	const Placed marker = posed(5, 640, 480, 600);
	expectTvec(posePushed(t.h, spec, marker, 0), kTvec, 0.01);

	g_object_set(detector(t.h), "calibration-file", bad.c_str(), nullptr);
	EXPECT_EQ(stringProperty(detector(t.h), "calibration-file"), good);
	expectTvec(posePushed(t.h, spec, marker, GST_SECOND), kTvec, 0.01);
	expectOneSettingsWarning(t.bus, bad);

	/* Half the focal length: the marker seems half as far. */
	g_object_set(detector(t.h), "calibration-file", other.c_str(), nullptr);
	const GstFrappeMarkerMeta m = posePushed(t.h, spec, marker, 2 * GST_SECOND);
	ASSERT_TRUE(m.has_pose);
	EXPECT_NEAR(m.tvec[2], kTvec[2] / 2, 0.01 * kTvec[2]);
}

/* Issue 34: a calibration-file (or dictionary-file) name swapped for a
 * FIFO between the check and the open blocked the property thread
 * forever. Set while playing, again and again as the name is swapped, the
 * property never blocks; the FIFO is refused with a warning naming it. */
TEST(Calibration, FileSwappedForAFifoNeverBlocksTheProperty)
{
	TempDir dir;
	const FrameSpec spec{ GST_VIDEO_FORMAT_GRAY8, 640, 480 };
	BusHarness t("frappedetect marker-size=0.08", spec);
	GstElement *e = detector(t.h);
	for (const char *property : { "calibration-file", "dictionary-file" }) {
		SCOPED_TRACE(property);
		const bool calibration = std::string(property) == "calibration-file";
		const std::string text = calibration ? rosCalibration(640, 480, 600, 600, 319.5, 239.5) : "0x1234\n0xff00\n";
		EXPECT_FALSE(frappe::test::blockedBySwappedFifo(dir.path + "/swapped", text, 0.5, [&](const std::string &p) {
			g_object_set(e, property, p.c_str(), nullptr);
		}));
		const std::string fifo = dir.path + "/fifo";
		EXPECT_EQ(frappe::test::readingFifo(fifo, [&](const std::string &p) { g_object_set(e, property, p.c_str(), nullptr); }),
			  "read without an error");
		bool named = false;
		const BusMessages msgs(t.bus);
		for (GstMessage *m : msgs.of(GST_MESSAGE_WARNING))
			named |= MessageError(m).text.find(fifo + ": not a regular file (a FIFO)") != std::string::npos ||
				 MessageError(m).text.find(fifo + "': not a regular file (a FIFO)") != std::string::npos;
		EXPECT_TRUE(named) << "a warning names the FIFO";
	}
}

/* marker-sizes: an id of its own size has its tvec scaled by the ratio of
 * sizes; the others keep marker-size's. */
TEST(MarkerSizes, PerIdSizesScaleTvec)
{
	const FrameSpec spec{ GST_VIDEO_FORMAT_GRAY8, 640, 480 };
	BusHarness t("frappedetect marker-size=0.05 "
		     "camera-matrix=\"<600.0,0.0,319.5,0.0,600.0,239.5,0.0,0.0,1.0>\"",
		     spec);
	const std::vector<Placed> placed{ square(7, 60.3f, 80.6f, 150.0f), tilted(42, 450.0f, 300.0f, 140.0f, 0.3f) };
	auto tvecs = [&](GstClockTime pts) {
		GstBuffer *out = gst_harness_push_and_pull(t.h, makeFrame(spec, placed, dict("aruco_mip_36h12"), pts));
		std::array<std::array<double, 3>, 2> tv{};
		for (const auto *m : markerMetas(out)) {
			EXPECT_TRUE(m->has_pose) << m->id;
			for (int i = 0; i < 3; ++i)
				tv[m->id == 7 ? 0 : 1][static_cast<std::size_t>(i)] = m->tvec[i];
		}
		gst_buffer_unref(out);
		return tv;
	};
	const auto before = tvecs(0);
	g_object_set(detector(t.h), "marker-sizes", "42:0.10, 3:0.2", nullptr);
	EXPECT_EQ(stringProperty(detector(t.h), "marker-sizes"), "42:0.10, 3:0.2");
	const auto after = tvecs(GST_SECOND);
	for (int i = 0; i < 3; ++i) {
		EXPECT_NEAR(after[0][static_cast<std::size_t>(i)], before[0][static_cast<std::size_t>(i)], 1e-9);
		EXPECT_NEAR(after[1][static_cast<std::size_t>(i)], 2 * before[1][static_cast<std::size_t>(i)],
			    1e-6 * std::abs(before[1][2]));
	}
	EXPECT_GT(before[1][2], 0.1);
	const BusMessages msgs(t.bus);
	EXPECT_TRUE(msgs.of(GST_MESSAGE_WARNING).empty());
}

/* A malformed marker-sizes is refused with a warning naming it; the
 * previous value stays. */
TEST(MarkerSizes, MalformedIsRefusedWithAWarning)
{
	const FrameSpec spec{ GST_VIDEO_FORMAT_GRAY8, 64, 48 };
	BusHarness t("frappedetect marker-sizes=\"0:0.05\"", spec);
	GstElement *e = detector(t.h);
	for (const char *bad : { "0:0.05,7", "-1:0.1", "3:0", "x:0.1", "3:0.1,3:0.2" }) {
		SCOPED_TRACE(bad);
		g_object_set(e, "marker-sizes", bad, nullptr);
		EXPECT_EQ(stringProperty(e, "marker-sizes"), "0:0.05");
		expectOneSettingsWarning(t.bus, bad);
	}
}

/* Issue 34: marker-sizes was parsed in quadratic time under the object
 * lock the streaming thread takes (400,000 ids in descending order: 107 s).
 * The longest value accepted now takes milliseconds, a longer one is
 * refused with a warning saying why, the previous value kept. */
TEST(MarkerSizes, LongValuesAreQuickOrRefused)
{
	const FrameSpec spec{ GST_VIDEO_FORMAT_GRAY8, 64, 48 };
	BusHarness t("frappedetect marker-sizes=\"0:0.05\"", spec);
	GstElement *e = detector(t.h);
	std::string longest;
	for (int id = 999999; longest.size() + 16 < (1u << 20); --id)
		longest += std::to_string(id) + ":0.05,";
	longest += "7:0.25";
	const gint64 t0 = g_get_monotonic_time();
	g_object_set(e, "marker-sizes", longest.c_str(), nullptr);
	EXPECT_LT(g_get_monotonic_time() - t0, 1000000) << "microseconds to set " << longest.size() << " bytes";
	EXPECT_EQ(stringProperty(e, "marker-sizes"), longest);
	EXPECT_TRUE(BusMessages(t.bus).of(GST_MESSAGE_WARNING).empty());

	const std::string over = longest + std::string(1u << 20, ' ');
	g_object_set(e, "marker-sizes", over.c_str(), nullptr);
	EXPECT_EQ(stringProperty(e, "marker-sizes"), longest);
	expectOneSettingsWarning(t.bus, "refused: marker sizes: " + std::to_string(over.size()) +
						" bytes, more than the 1048576 a list of sizes may have");
}

/* camera-matrix of another count or an invalid matrix, distortion of
 * another count: a warning on the bus, the previous value kept. */
TEST(CameraMatrix, RefusedValuesWarn)
{
	const FrameSpec spec{ GST_VIDEO_FORMAT_GRAY8, 64, 48 };
	BusHarness t("frappedetect camera-matrix=\"<500.0,0.0,320.0,0.0,500.0,240.0,0.0,0.0,1.0>\"", spec);
	GstElement *e = detector(t.h);
	const struct {
		const char *property, *value, *words;
	} cases[] = {
		{ "camera-matrix", "<500.0, 0.0, 320.0, 0.0, 500.0, 240.0, 0.0, 0.0>", "9 numbers" },
		{ "camera-matrix", "<-500.0, 0.0, 320.0, 0.0, 500.0, 240.0, 0.0, 0.0, 1.0>", "camera-matrix" },
		{ "camera-matrix", "<500.0, 0.0, 320.0, 0.0, 500.0, 240.0, 0.0, 0.5, 1.0>", "camera-matrix" },
		{ "distortion", "<0.1, 0.2, 0.3>", "distortion" },
	};
	for (const auto &c : cases) {
		SCOPED_TRACE(c.value);
		gst_util_set_object_arg(G_OBJECT(e), c.property, c.value);
		expectOneSettingsWarning(t.bus, c.words);
	}
	GValue v = G_VALUE_INIT;
	g_value_init(&v, GST_TYPE_ARRAY);
	g_object_get_property(G_OBJECT(e), "camera-matrix", &v);
	ASSERT_EQ(gst_value_array_get_size(&v), 9u);
	EXPECT_DOUBLE_EQ(g_value_get_double(gst_value_array_get_value(&v, 0)), 500.0);
	EXPECT_DOUBLE_EQ(g_value_get_double(gst_value_array_get_value(&v, 7)), 0.0);
	g_value_unset(&v);
	g_value_init(&v, GST_TYPE_ARRAY);
	g_object_get_property(G_OBJECT(e), "distortion", &v);
	EXPECT_EQ(gst_value_array_get_size(&v), 0u);
	g_value_unset(&v);
}
