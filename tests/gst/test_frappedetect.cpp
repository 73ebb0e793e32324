// SPDX-License-Identifier: MIT
// The frappedetect element, driven through GstHarness: caps, metas, ROI
// metas, messages, annotation, properties and pose.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <sys/mman.h>
#include <unistd.h>

#include <gst/allocators/gstdmabuf.h>
#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gst/video/video.h>
#include <gtest/gtest.h>

#include <frappe/config.h>

#include "gstfrappemeta.h"
#include "helpers.h"

using namespace frappe::gsttest;

static auto *const gstEnv = ::testing::AddGlobalTestEnvironment(new GstEnvironment);

namespace {

GstHarness *newHarness(const char *launch, const FrameSpec &spec)
{
	GstHarness *h = gst_harness_new_parse(launch);
	gst_harness_set_src_caps_str(h, capsString(spec).c_str());
	return h;
}

std::vector<Placed> twoMarkers(const FrameSpec &s)
{
	/* Sub-pixel corners, one upright, one tilted, both well inside. */
	const float side = std::min(s.width, s.height) * 0.3f;
	return { square(7, s.width * 0.1f + 0.37f, s.height * 0.12f + 0.61f, side),
		 tilted(42, s.width * 0.7f, s.height * 0.6f, side, 0.35f) };
}

} // namespace

struct FormatCase {
	GstVideoFormat format;
	int width, height, padding;
};

class Formats : public ::testing::TestWithParam<FormatCase> {};

TEST_P(Formats, NegotiatesAndFindsMarkers)
{
	const FormatCase c = GetParam();
	FrameSpec spec{ c.format, c.width, c.height, c.padding };
	GstHarness *h = newHarness("frappedetect", spec);
	const auto markers = twoMarkers(spec);
	GstBuffer *out = gst_harness_push_and_pull(h, makeFrame(spec, markers, dict("aruco_mip_36h12")));
	ASSERT_NE(out, nullptr);

	GstCaps *caps = gst_pad_get_current_caps(h->sinkpad);
	GstCaps *expected = gst_caps_from_string(capsString(spec).c_str());
	EXPECT_TRUE(gst_caps_is_equal(caps, expected)) << gst_caps_to_string(caps);
	gst_caps_unref(caps);
	gst_caps_unref(expected);

	expectMarkers(out, markers, "aruco_mip_36h12");
	gst_buffer_unref(out);
	gst_harness_teardown(h);
}

INSTANTIATE_TEST_SUITE_P(
	AllFormats, Formats,
	::testing::Values(FormatCase{ GST_VIDEO_FORMAT_GRAY8, 640, 480, 0 },
			  FormatCase{ GST_VIDEO_FORMAT_I420, 640, 480, 0 },
			  FormatCase{ GST_VIDEO_FORMAT_YV12, 640, 480, 0 },
			  FormatCase{ GST_VIDEO_FORMAT_NV12, 640, 480, 0 },
			  FormatCase{ GST_VIDEO_FORMAT_NV21, 640, 480, 0 },
			  FormatCase{ GST_VIDEO_FORMAT_GRAY8, 333, 251, 0 },
			  FormatCase{ GST_VIDEO_FORMAT_I420, 333, 251, 0 },
			  FormatCase{ GST_VIDEO_FORMAT_NV21, 401, 301, 0 },
			  FormatCase{ GST_VIDEO_FORMAT_GRAY8, 321, 243, 29 },
			  FormatCase{ GST_VIDEO_FORMAT_I420, 640, 480, 64 },
			  FormatCase{ GST_VIDEO_FORMAT_YV12, 333, 251, 13 },
			  FormatCase{ GST_VIDEO_FORMAT_NV12, 401, 301, 7 }));

TEST(Caps, RejectsRgb)
{
	GstHarness *h = gst_harness_new("frappedetect");
	GstCaps *rgb = gst_caps_from_string("video/x-raw,format=RGB,width=64,height=64,framerate=30/1");
	GstCaps *sinkCaps = gst_pad_query_caps(GST_PAD_PEER(h->srcpad), nullptr);
	EXPECT_FALSE(gst_caps_can_intersect(rgb, sinkCaps));
	gst_caps_unref(sinkCaps);
	gst_caps_unref(rgb);
	gst_harness_teardown(h);
}

TEST(Caps, TinyFramesGiveNoMarkers)
{
	for (int side : { 1, 2, 5, 17 }) {
		FrameSpec spec{ GST_VIDEO_FORMAT_I420, side, side + 1, 0 };
		GstHarness *h = newHarness("frappedetect", spec);
		GstBuffer *out = gst_harness_push_and_pull(h, makeFrame(spec, {}, dict("aruco_mip_36h12")));
		ASSERT_NE(out, nullptr) << side;
		EXPECT_EQ(gst_buffer_get_n_frappe_marker_metas(out), 0u);
		gst_buffer_unref(out);
		gst_harness_teardown(h);
	}
}

TEST(Metas, RegionOfInterestPerMarker)
{
	FrameSpec spec;
	GstHarness *h = newHarness("frappedetect", spec);
	const auto markers = twoMarkers(spec);
	GstBuffer *out = gst_harness_push_and_pull(h, makeFrame(spec, markers, dict("aruco_mip_36h12")));
	ASSERT_NE(out, nullptr);

	std::vector<int> ids;
	gpointer state = nullptr;
	GstMeta *meta;
	while ((meta = gst_buffer_iterate_meta_filtered(out, &state, GST_VIDEO_REGION_OF_INTEREST_META_API_TYPE))) {
		auto *roi = reinterpret_cast<GstVideoRegionOfInterestMeta *>(meta);
		EXPECT_STREQ(g_quark_to_string(roi->roi_type), "fiducial");
		GstStructure *s = gst_video_region_of_interest_meta_get_param(roi, "fiducial");
		ASSERT_NE(s, nullptr);
		int id = -1;
		ASSERT_TRUE(gst_structure_get_int(s, "id", &id));
		EXPECT_STREQ(gst_structure_get_string(s, "dictionary"), "aruco_mip_36h12");
		ids.push_back(id);
		/* The box holds the marker's corners. */
		for (const Placed &p : markers) {
			if (p.id != id)
				continue;
			for (const auto &c : p.corners) {
				EXPECT_GE(c.x + 0.5f, static_cast<float>(roi->x));
				EXPECT_LE(c.x + 0.5f, static_cast<float>(roi->x + roi->w));
				EXPECT_GE(c.y + 0.5f, static_cast<float>(roi->y));
				EXPECT_LE(c.y + 0.5f, static_cast<float>(roi->y + roi->h));
			}
		}
	}
	std::sort(ids.begin(), ids.end());
	EXPECT_EQ(ids, (std::vector<int>{ 7, 42 }));
	gst_buffer_unref(out);
	gst_harness_teardown(h);
}

TEST(Metas, CopyAndScaleTransforms)
{
	FrameSpec spec;
	GstBuffer *in = makeFrame(spec, {}, dict("aruco_mip_36h12"));
	const gfloat corners[8] = { 9.5f, 19.5f, 29.5f, 19.5f, 29.5f, 39.5f, 9.5f, 39.5f };
	GstFrappeMarkerMeta *m = gst_buffer_add_frappe_marker_meta(in, 3, "4x4_50", corners, 1);
	m->has_pose = TRUE;
	m->tvec[2] = 1.5;
	m->margin = 0.625f;

	GstBuffer *copy = gst_buffer_copy(in);
	auto metas = markerMetas(copy);
	ASSERT_EQ(metas.size(), 1u);
	EXPECT_EQ(metas[0]->id, 3);
	EXPECT_STREQ(metas[0]->dictionary, "4x4_50");
	EXPECT_EQ(metas[0]->hamming, 1u);
	EXPECT_TRUE(metas[0]->has_pose);
	EXPECT_DOUBLE_EQ(metas[0]->tvec[2], 1.5);
	EXPECT_FLOAT_EQ(metas[0]->corners[2], 29.5f);
	EXPECT_FLOAT_EQ(metas[0]->margin, 0.625f);

	/* Half size: pixel centres move with the image's corner fixed. */
	GstVideoInfo inInfo, outInfo;
	gst_video_info_set_format(&inInfo, GST_VIDEO_FORMAT_GRAY8, 640, 480);
	gst_video_info_set_format(&outInfo, GST_VIDEO_FORMAT_GRAY8, 320, 240);
	GstVideoMetaTransform trans = { &inInfo, &outInfo };
	GstBuffer *scaled = gst_buffer_new();
	const GstMetaInfo *info = GST_FRAPPE_MARKER_META_INFO;
	ASSERT_TRUE(info->transform_func(scaled, &m->meta, in, gst_video_meta_transform_scale_get_quark(), &trans));
	metas = markerMetas(scaled);
	ASSERT_EQ(metas.size(), 1u);
	EXPECT_FLOAT_EQ(metas[0]->corners[0], 4.5f);
	EXPECT_FLOAT_EQ(metas[0]->corners[1], 9.5f);
	EXPECT_FLOAT_EQ(metas[0]->corners[4], 14.5f);
	EXPECT_FLOAT_EQ(metas[0]->margin, 0.625f);

	gst_buffer_unref(scaled);
	gst_buffer_unref(copy);
	gst_buffer_unref(in);
}

TEST(Messages, OnePerFrameWithMarkers)
{
	FrameSpec spec;
	GstHarness *h = newHarness("frappedetect", spec);
	GstBus *bus = gst_bus_new();
	gst_element_set_bus(h->element, bus);
	const auto markers = twoMarkers(spec);

	for (int i = 0; i < 3; ++i) {
		GstBuffer *out = gst_harness_push_and_pull(
			h, makeFrame(spec, i == 1 ? std::vector<Placed>{} : markers, dict("aruco_mip_36h12"),
				     i * GST_SECOND / 30));
		gst_buffer_unref(out);
	}

	for (int i = 0; i < 3; ++i) {
		GstMessage *msg = gst_bus_pop_filtered(bus, GST_MESSAGE_ELEMENT);
		ASSERT_NE(msg, nullptr) << i;
		const GstStructure *s = gst_message_get_structure(msg);
		EXPECT_TRUE(gst_structure_has_name(s, "frappedetect"));
		guint64 ts = 0, rt = 0, st = 0, dur = 0;
		EXPECT_TRUE(gst_structure_get_uint64(s, "timestamp", &ts));
		EXPECT_TRUE(gst_structure_get_uint64(s, "running-time", &rt));
		EXPECT_TRUE(gst_structure_get_uint64(s, "stream-time", &st));
		EXPECT_TRUE(gst_structure_get_uint64(s, "duration", &dur));
		EXPECT_EQ(ts, static_cast<guint64>(i * GST_SECOND / 30));
		EXPECT_EQ(rt, ts);
		EXPECT_EQ(st, ts);
		EXPECT_EQ(dur, static_cast<guint64>(GST_SECOND / 30));
		const GValue *list = gst_structure_get_value(s, "markers");
		ASSERT_NE(list, nullptr);
		ASSERT_TRUE(GST_VALUE_HOLDS_LIST(list));
		const guint n = gst_value_list_get_size(list);
		EXPECT_EQ(n, i == 1 ? 0u : 2u);
		for (guint k = 0; k < n; ++k) {
			const GstStructure *m = gst_value_get_structure(gst_value_list_get_value(list, k));
			int id = -1;
			guint hamming = 99;
			ASSERT_TRUE(gst_structure_get_int(m, "id", &id));
			ASSERT_TRUE(gst_structure_get_uint(m, "hamming", &hamming));
			EXPECT_EQ(hamming, 0u);
			double margin = -1.0;
			ASSERT_TRUE(gst_structure_get_double(m, "margin", &margin));
			EXPECT_GT(margin, 0.5);
			EXPECT_LE(margin, 1.0);
			const GValue *corners = gst_structure_get_value(m, "corners");
			ASSERT_TRUE(GST_VALUE_HOLDS_ARRAY(corners));
			ASSERT_EQ(gst_value_array_get_size(corners), 8u);
			const Placed &p = id == 7 ? markers[0] : markers[1];
			ASSERT_EQ(p.id, id);
			for (guint j = 0; j < 4; ++j) {
				EXPECT_NEAR(g_value_get_double(gst_value_array_get_value(corners, 2 * j)),
					    p.corners[j].x, 0.3);
				EXPECT_NEAR(g_value_get_double(gst_value_array_get_value(corners, 2 * j + 1)),
					    p.corners[j].y, 0.3);
			}
			EXPECT_FALSE(gst_structure_has_field(m, "tvec"));
		}
		gst_message_unref(msg);
	}
	EXPECT_EQ(gst_bus_pop_filtered(bus, GST_MESSAGE_ELEMENT), nullptr);

	/* post-messages=false silences them, live. */
	g_object_set(detector(h), "post-messages", FALSE, nullptr);
	gst_buffer_unref(gst_harness_push_and_pull(h, makeFrame(spec, markers, dict("aruco_mip_36h12"))));
	EXPECT_EQ(gst_bus_pop_filtered(bus, GST_MESSAGE_ELEMENT), nullptr);

	gst_element_set_bus(h->element, nullptr);
	gst_object_unref(bus);
	gst_harness_teardown(h);
}

static bool samePixels(GstBuffer *a, GstBuffer *b)
{
	GstMapInfo ma, mb;
	gst_buffer_map(a, &ma, GST_MAP_READ);
	gst_buffer_map(b, &mb, GST_MAP_READ);
	const bool same = ma.size == mb.size && std::memcmp(ma.data, mb.data, ma.size) == 0;
	gst_buffer_unmap(a, &ma);
	gst_buffer_unmap(b, &mb);
	return same;
}

TEST(Annotate, ChangesPixelsOnlyWhenOn)
{
	for (GstVideoFormat format : { GST_VIDEO_FORMAT_GRAY8, GST_VIDEO_FORMAT_I420, GST_VIDEO_FORMAT_NV12 }) {
		FrameSpec spec{ format, 640, 480, 0 };
		GstHarness *h = newHarness("frappedetect", spec);
		const auto markers = twoMarkers(spec);
		GstBuffer *ref = makeFrame(spec, markers, dict("aruco_mip_36h12"));

		/* Off: not a byte changes, and the input memory is not copied. */
		GstBuffer *out = gst_harness_push_and_pull(h, gst_buffer_ref(ref));
		EXPECT_TRUE(samePixels(out, ref));
		EXPECT_EQ(gst_buffer_peek_memory(out, 0), gst_buffer_peek_memory(ref, 0));
		gst_buffer_unref(out);

		/* On: the shared input is left alone, the output is drawn on. */
		g_object_set(detector(h), "annotate", TRUE, nullptr);
		out = gst_harness_push_and_pull(h, gst_buffer_ref(ref));
		EXPECT_FALSE(samePixels(out, ref));
		expectMarkers(out, markers, "aruco_mip_36h12");
		gst_buffer_unref(out);

		/* On but nothing to draw: unchanged. */
		GstBuffer *empty = makeFrame(spec, {}, dict("aruco_mip_36h12"));
		out = gst_harness_push_and_pull(h, gst_buffer_ref(empty));
		EXPECT_TRUE(samePixels(out, empty));
		gst_buffer_unref(out);
		gst_buffer_unref(empty);

		/* Off again, live. */
		g_object_set(detector(h), "annotate", FALSE, nullptr);
		out = gst_harness_push_and_pull(h, gst_buffer_ref(ref));
		EXPECT_TRUE(samePixels(out, ref));
		gst_buffer_unref(out);

		gst_buffer_unref(ref);
		gst_harness_teardown(h);
	}
}

TEST(Properties, ChangeWhilePlaying)
{
	FrameSpec spec;
	GstHarness *h = newHarness("frappedetect", spec);
	const std::vector<Placed> markers{ square(17, 100.3f, 80.6f, 160.0f) };
	GstBuffer *frame6x6 = makeFrame(spec, markers, dict("6x6_250"));
	GstBuffer *frameMip = makeFrame(spec, markers, dict("aruco_mip_36h12"));

	GstBuffer *out = gst_harness_push_and_pull(h, gst_buffer_ref(frameMip));
	expectMarkers(out, markers, "aruco_mip_36h12");
	gst_buffer_unref(out);

	gst_util_set_object_arg(G_OBJECT(detector(h)), "dictionary", "6x6-250");
	out = gst_harness_push_and_pull(h, gst_buffer_ref(frame6x6));
	expectMarkers(out, markers, "6x6_250");
	gst_buffer_unref(out);

	/* Thresholds nothing passes (no edges, no dark regions): no markers;
	 * back to the defaults: found. */
	g_object_set(detector(h), "edge-threshold", 4.0f, "region-contrast", 0.0f, nullptr);
	out = gst_harness_push_and_pull(h, gst_buffer_ref(frame6x6));
	EXPECT_EQ(gst_buffer_get_n_frappe_marker_metas(out), 0u);
	gst_buffer_unref(out);
	g_object_set(detector(h), "edge-threshold", 0.27f, "region-contrast", 0.16f, "mode", "ascale", "max-hamming", 2,
		     "scaled-size", 20.0f, "max-scaled-frames", 3, "backend", 1, nullptr);
	for (int i = 0; i < 6; ++i) {
		out = gst_harness_push_and_pull(h, gst_buffer_ref(frame6x6));
		expectMarkers(out, markers, "6x6_250", 0.5f);
		gst_buffer_unref(out);
	}

	/* A max-hamming above what the dictionary allows is clamped, not fatal. */
	gst_util_set_object_arg(G_OBJECT(detector(h)), "dictionary", "4x4-50");
	g_object_set(detector(h), "max-hamming", 24, nullptr);
	out = gst_harness_push_and_pull(h, gst_buffer_ref(frame6x6));
	ASSERT_NE(out, nullptr);
	gst_buffer_unref(out);

	/* The stats describe the last frame. */
	GstStructure *stats = nullptr;
	g_object_get(detector(h), "stats", &stats, nullptr);
	ASSERT_NE(stats, nullptr);
	guint64 frames = 0;
	double total = -1, frontEnd = -1;
	EXPECT_TRUE(gst_structure_get_uint64(stats, "frames", &frames));
	EXPECT_EQ(frames, 10u);
	EXPECT_TRUE(gst_structure_get_double(stats, "total-ms", &total));
	EXPECT_TRUE(gst_structure_get_double(stats, "front-end-ms", &frontEnd));
	EXPECT_GT(total, 0.0);
	EXPECT_GE(total, frontEnd);
	EXPECT_TRUE(gst_structure_has_field(stats, "trace-ms"));
	gst_structure_free(stats);

	gst_buffer_unref(frame6x6);
	gst_buffer_unref(frameMip);
	gst_harness_teardown(h);
}

TEST(Properties, DefaultsAndArrays)
{
	GstElement *e = gst_element_factory_make("frappedetect", nullptr);
	ASSERT_NE(e, nullptr);
	gboolean postMessages = FALSE, annotate = TRUE, pipelined = TRUE;
	gdouble size = -1;
	g_object_get(e, "post-messages", &postMessages, "annotate", &annotate, "pipelined", &pipelined,
		     "marker-size", &size, nullptr);
	EXPECT_TRUE(postMessages);
	EXPECT_FALSE(annotate);
	EXPECT_FALSE(pipelined);
	EXPECT_EQ(size, 0.0);

	gst_util_set_object_arg(G_OBJECT(e), "camera-matrix", "<500.0, 0.0, 320.0, 0.0, 510.0, 240.0, 0.0, 0.0, 1.0>");
	gst_util_set_object_arg(G_OBJECT(e), "distortion", "<0.1, -0.2, 0.0, 0.0, 0.05>");
	GValue v = G_VALUE_INIT;
	g_value_init(&v, GST_TYPE_ARRAY);
	g_object_get_property(G_OBJECT(e), "camera-matrix", &v);
	ASSERT_EQ(gst_value_array_get_size(&v), 9u);
	EXPECT_DOUBLE_EQ(g_value_get_double(gst_value_array_get_value(&v, 4)), 510.0);
	g_value_unset(&v);
	g_value_init(&v, GST_TYPE_ARRAY);
	g_object_get_property(G_OBJECT(e), "distortion", &v);
	ASSERT_EQ(gst_value_array_get_size(&v), 5u);
	EXPECT_DOUBLE_EQ(g_value_get_double(gst_value_array_get_value(&v, 1)), -0.2);
	g_value_unset(&v);
	gst_object_unref(e);
}

/* Pose: a marker of 8 cm rendered through a known pinhole camera. */
TEST(Pose, MatchesKnownCamera)
{
	const double fx = 600.0, fy = 600.0, cx = 319.5, cy = 239.5, side = 0.08;
	const std::array<double, 3> tvec{ 0.03, -0.02, 0.55 };
	/* Rotation: 25 degrees about an axis tilted in x and y. */
	const std::array<double, 9> M = facingCamera(rotation({ 0.6, 0.8, 0.0 }, 25.0 * G_PI / 180.0));
	const Placed placed = posedMarker(5, fx, fy, cx, cy, side, M, tvec);

	FrameSpec spec{ GST_VIDEO_FORMAT_I420, 640, 480, 0 };
	GstHarness *h = newHarness("frappedetect marker-size=0.08 annotate=true", spec);
	gst_util_set_object_arg(G_OBJECT(detector(h)), "camera-matrix",
				"<600.0, 0.0, 319.5, 0.0, 600.0, 239.5, 0.0, 0.0, 1.0>");
	GstBuffer *out = gst_harness_push_and_pull(h, makeFrame(spec, { placed }, dict("aruco_mip_36h12")));
	expectMarkers(out, { placed }, "aruco_mip_36h12");
	const auto metas = markerMetas(out);
	ASSERT_EQ(metas.size(), 1u);
	const GstFrappeMarkerMeta *m = metas[0];
	ASSERT_TRUE(m->has_pose);
	const double dist = std::sqrt(tvec[0] * tvec[0] + tvec[1] * tvec[1] + tvec[2] * tvec[2]);
	for (int i = 0; i < 3; ++i)
		EXPECT_NEAR(m->tvec[i], tvec[i], 0.01 * dist) << "tvec[" << i << "]";
	EXPECT_NEAR(m->tvec[2], tvec[2], 0.01 * tvec[2]);
	EXPECT_LT(m->reprojection_error, 0.5);
	/* Tilted by 25 degrees at 0.55 m: the flipped solution fits far worse. */
	EXPECT_GT(m->alternative_reprojection_error, 4 * m->reprojection_error);

	/* The rotation: z of the marker points back at the camera. */
	const double th = std::sqrt(m->rvec[0] * m->rvec[0] + m->rvec[1] * m->rvec[1] + m->rvec[2] * m->rvec[2]);
	const std::array<double, 9> Rm = rotation({ m->rvec[0] / th, m->rvec[1] / th, m->rvec[2] / th }, th);
	for (int i = 0; i < 9; ++i)
		EXPECT_NEAR(Rm[i], M[i], 0.03) << "R[" << i << "]";
	gst_buffer_unref(out);
	gst_harness_teardown(h);
}

/* A dmabuf-backed frame (a memfd stands in for the camera's dmabuf): with
 * annotate=false the very same memory comes out, nothing is copied. */
TEST(Memory, DmabufIsNotCopied)
{
	FrameSpec spec{ GST_VIDEO_FORMAT_NV12, 640, 480, 0 };
	const auto markers = twoMarkers(spec);
	GstBuffer *sysFrame = makeFrame(spec, markers, dict("aruco_mip_36h12"));
	const gsize size = gst_buffer_get_size(sysFrame);

	const int fd = memfd_create("frappe-test", MFD_CLOEXEC);
	ASSERT_GE(fd, 0);
	ASSERT_EQ(ftruncate(fd, static_cast<off_t>(size)), 0);
	GstAllocator *alloc = gst_dmabuf_allocator_new();
	GstMemory *mem = gst_dmabuf_allocator_alloc(alloc, fd, size);
	ASSERT_NE(mem, nullptr);
	ASSERT_TRUE(gst_is_dmabuf_memory(mem));
	GstBuffer *frame = gst_buffer_new();
	gst_buffer_append_memory(frame, mem);
	GstMapInfo map;
	ASSERT_TRUE(gst_buffer_map(frame, &map, GST_MAP_WRITE));
	gst_buffer_extract(sysFrame, 0, map.data, size);
	gst_buffer_unmap(frame, &map);
	gst_buffer_unref(sysFrame);

	GstHarness *h = newHarness("frappedetect", spec);
	GstBuffer *out = gst_harness_push_and_pull(h, gst_buffer_ref(frame));
	ASSERT_NE(out, nullptr);
	EXPECT_EQ(gst_buffer_peek_memory(out, 0), mem);
	EXPECT_TRUE(gst_is_dmabuf_memory(gst_buffer_peek_memory(out, 0)));
	expectMarkers(out, markers, "aruco_mip_36h12");
	/* The caller's buffer got no metas: they went on a shallow copy. */
	EXPECT_EQ(gst_buffer_get_n_frappe_marker_metas(frame), 0u);
	gst_buffer_unref(out);
	gst_harness_teardown(h);
	gst_buffer_unref(frame);
	gst_object_unref(alloc);
}

/* A frame full of squares (a tiled wall) has more candidates than
 * Config::max_candidates reads: one element warning for the stream, the
 * count in the stats on every such frame, and the buffer still out. */
TEST(Stats, DroppedCandidatesAreReported)
{
	const FrameSpec spec{ GST_VIDEO_FORMAT_GRAY8, 1600, 1600, 0, 230 };
	GstHarness *h = newHarness("frappedetect", spec);
	GstBus *bus = gst_bus_new();
	gst_element_set_bus(h->element, bus);
	auto tiledWall = [&](GstClockTime pts) {
		GstBuffer *buf = makeFrame(spec, {}, dict("aruco_mip_36h12"), pts);
		GstMapInfo map;
		EXPECT_TRUE(gst_buffer_map(buf, &map, GST_MAP_WRITE));
		/* 12 px dark squares on a 20 px pitch: 6400 candidates. */
		for (int y = 0; y < spec.height; ++y)
			for (int x = 0; x < spec.width; ++x)
				if (x % 20 >= 4 && x % 20 < 16 && y % 20 >= 4 && y % 20 < 16)
					map.data[static_cast<std::size_t>(y) * spec.width + x] = 20;
		gst_buffer_unmap(buf, &map);
		return buf;
	};
	for (int i = 0; i < 2; ++i) {
		GstBuffer *out = gst_harness_push_and_pull(h, tiledWall(static_cast<GstClockTime>(i) * GST_SECOND / 30));
		ASSERT_NE(out, nullptr) << "frame " << i;
		gst_buffer_unref(out);
		GstStructure *stats = nullptr;
		g_object_get(detector(h), "stats", &stats, nullptr);
		ASSERT_NE(stats, nullptr);
		gint dropped = 0, read = 0;
		EXPECT_TRUE(gst_structure_get_int(stats, "candidates-dropped", &dropped));
		EXPECT_TRUE(gst_structure_get_int(stats, "candidates", &read));
		EXPECT_GT(dropped, 0) << "frame " << i;
		EXPECT_EQ(read, frappe::Config{}.max_candidates) << "frame " << i;
		gst_structure_free(stats);
	}
	GstMessage *msg = gst_bus_pop_filtered(bus, GST_MESSAGE_WARNING);
	ASSERT_NE(msg, nullptr) << "no warning";
	GError *err = nullptr;
	gst_message_parse_warning(msg, &err, nullptr);
	EXPECT_NE(std::string(err->message).find("Too many marker candidates"), std::string::npos) << err->message;
	g_error_free(err);
	gst_message_unref(msg);
	EXPECT_EQ(gst_bus_pop_filtered(bus, GST_MESSAGE_WARNING), nullptr) << "one warning for the stream";
	gst_object_unref(bus);
	gst_harness_teardown(h);
}
