// SPDX-License-Identifier: MIT
// frappedetect and buffers whose memory does not hold the frame their caps
// and GstVideoMeta describe (issue 16): one warning per kind of lie, and
// the buffer passes through untouched, once and in order, pipelined or
// not. Before the element checked them, the first three cases read past
// the buffer (AddressSanitizer) and the empty buffer raised a
// GStreamer-CRITICAL (fatal here: G_DEBUG=fatal-criticals).
#include <cstdint>
#include <string>
#include <vector>

#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gst/video/video.h>
#include <gtest/gtest.h>

#include "gstfrappemeta.h"
#include "helpers.h"

using namespace frappe::gsttest;

static auto *const gstEnv = ::testing::AddGlobalTestEnvironment(new GstEnvironment);

namespace {

constexpr GstClockTime kFrame = GST_SECOND / 30;
const char *const kWarning = "Video buffer does not hold the frame it describes; passed through without detection";

/* A buffer of `size` bytes (a ramp, so a copy or a write shows) with a
 * GstVideoMeta claiming the given layout. */
GstBuffer *lyingBuffer(gsize size, GstVideoFormat format, guint width, guint height,
		       std::vector<gsize> offsets, std::vector<gint> strides, GstClockTime pts = 0)
{
	GstBuffer *buf = gst_buffer_new_allocate(nullptr, size, nullptr);
	GstMapInfo map;
	gst_buffer_map(buf, &map, GST_MAP_WRITE);
	for (gsize i = 0; i < size; ++i)
		map.data[i] = static_cast<std::uint8_t>(i * 7);
	gst_buffer_unmap(buf, &map);
	offsets.resize(GST_VIDEO_MAX_PLANES);
	strides.resize(GST_VIDEO_MAX_PLANES);
	GstVideoInfo info;
	gst_video_info_set_format(&info, format, width, height);
	gst_buffer_add_video_meta_full(buf, GST_VIDEO_FRAME_FLAG_NONE, format, width, height,
				       GST_VIDEO_INFO_N_PLANES(&info), offsets.data(), strides.data());
	GST_BUFFER_PTS(buf) = pts;
	GST_BUFFER_DURATION(buf) = kFrame;
	return buf;
}

std::vector<std::uint8_t> bytesOf(GstBuffer *buf)
{
	std::vector<std::uint8_t> out(gst_buffer_get_size(buf));
	if (!out.empty())
		gst_buffer_extract(buf, 0, out.data(), out.size());
	return out;
}

/* The element's warning about a lying buffer, its debug text naming `detail`. */
void expectLieWarning(GstMessage *msg, const std::string &detail)
{
	GError *err = nullptr;
	gchar *debug = nullptr;
	gst_message_parse_warning(msg, &err, &debug);
	EXPECT_TRUE(g_error_matches(err, GST_STREAM_ERROR, GST_STREAM_ERROR_FORMAT)) << err->message;
	EXPECT_EQ(std::string(err->message), kWarning);
	const std::string text(debug ? debug : "");
	EXPECT_NE(text.find(detail), std::string::npos) << text;
	g_error_free(err);
	g_free(debug);
}

/* Pushes a lying buffer alone: it comes out unchanged, without metas,
 * after one warning naming `detail` and no frappedetect message. */
void expectPassedThrough(const char *launch, const FrameSpec &caps, GstBuffer *lying, const std::string &detail)
{
	BusHarness t(launch, caps);
	const auto before = bytesOf(lying);
	gst_buffer_ref(lying);
	ASSERT_EQ(gst_harness_push(t.h, lying), GST_FLOW_OK);
	GstBuffer *out = gst_harness_try_pull(t.h);
	ASSERT_NE(out, nullptr) << "the lying buffer did not come out";
	EXPECT_EQ(out, lying) << "passed through, not copied";
	EXPECT_EQ(bytesOf(out), before);
	EXPECT_EQ(gst_buffer_get_n_frappe_marker_metas(out), 0u);
	EXPECT_EQ(gst_buffer_get_meta(out, GST_VIDEO_REGION_OF_INTEREST_META_API_TYPE), nullptr);
	gst_buffer_unref(out);
	gst_buffer_unref(lying);
	EXPECT_EQ(gst_harness_try_pull(t.h), nullptr);
	EXPECT_EQ(gst_harness_buffers_received(t.h), 1u);
	const BusMessages msgs(t.bus);
	const auto warnings = msgs.of(GST_MESSAGE_WARNING);
	ASSERT_EQ(warnings.size(), 1u) << "one warning about " << detail;
	expectLieWarning(warnings[0], detail);
	EXPECT_TRUE(msgs.of(GST_MESSAGE_ERROR).empty());
	EXPECT_TRUE(msgs.of(GST_MESSAGE_ELEMENT).empty()) << "no frappedetect message";
}

const FrameSpec kGray64{ GST_VIDEO_FORMAT_GRAY8, 64, 64, 0 };
const FrameSpec kI420{ GST_VIDEO_FORMAT_I420, 640, 480, 0 };

} // namespace

TEST(Lying, MetaLargerThanCaps)
{
	/* 64x64 caps, 4096 bytes, a meta of 640x480 stride 640. */
	expectPassedThrough("frappedetect", kGray64,
			    lyingBuffer(4096, GST_VIDEO_FORMAT_GRAY8, 640, 480, { 0 }, { 640 }),
			    "meta 640x480 GRAY8 n_planes 1, caps 64x64 GRAY8");
}

TEST(Lying, MetaStridePastTheEnd)
{
	/* 64 rows of stride 256 need 63 * 256 + 64 bytes, not 4096. */
	expectPassedThrough("frappedetect", kGray64,
			    lyingBuffer(4096, GST_VIDEO_FORMAT_GRAY8, 64, 64, { 0 }, { 256 }),
			    "plane 0 needs 16192 bytes from offset 0, the buffer has 4096");
}

TEST(Lying, LumaOffsetNearTheEnd)
{
	GstVideoInfo info;
	gst_video_info_set_format(&info, GST_VIDEO_FORMAT_I420, 640, 480);
	const gsize size = GST_VIDEO_INFO_SIZE(&info);
	GstBuffer *buf = lyingBuffer(size, GST_VIDEO_FORMAT_I420, 640, 480,
				     { size - 100, GST_VIDEO_INFO_PLANE_OFFSET(&info, 1),
				       GST_VIDEO_INFO_PLANE_OFFSET(&info, 2) },
				     { 640, 320, 320 });
	expectPassedThrough("frappedetect", kI420, buf,
			    "plane 0 needs 307200 bytes from offset " + std::to_string(size - 100) + ", the buffer has " +
				    std::to_string(size));
}

TEST(Lying, NegativeOrShortStride)
{
	expectPassedThrough("frappedetect", kGray64,
			    lyingBuffer(4096, GST_VIDEO_FORMAT_GRAY8, 64, 64, { 0 }, { -64 }),
			    "plane 0 stride -64 is shorter than a row of 64 bytes");
	expectPassedThrough("frappedetect", kGray64,
			    lyingBuffer(4096, GST_VIDEO_FORMAT_GRAY8, 64, 64, { 0 }, { 32 }),
			    "plane 0 stride 32 is shorter than a row of 64 bytes");
}

TEST(Lying, BufferWithoutMemory)
{
	GstBuffer *empty = gst_buffer_new();
	GST_BUFFER_PTS(empty) = 0;
	expectPassedThrough("frappedetect", kGray64, empty, "no memory");
}

/* An empty buffer flagged GAP has nothing to show: it passes through
 * without a warning, and does not use up the one for an empty buffer. */
TEST(Lying, EmptyGapBufferIsNoLie)
{
	BusHarness t("frappedetect", kGray64);
	GstBuffer *gap = gst_buffer_new();
	GST_BUFFER_FLAG_SET(gap, GST_BUFFER_FLAG_GAP);
	GST_BUFFER_PTS(gap) = 0;
	ASSERT_EQ(gst_harness_push(t.h, gap), GST_FLOW_OK);
	GstBuffer *empty = gst_buffer_new();
	GST_BUFFER_PTS(empty) = kFrame;
	ASSERT_EQ(gst_harness_push(t.h, empty), GST_FLOW_OK);
	EXPECT_EQ(gst_harness_buffers_received(t.h), 2u);
	const BusMessages msgs(t.bus);
	const auto warnings = msgs.of(GST_MESSAGE_WARNING);
	ASSERT_EQ(warnings.size(), 1u) << "for the empty buffer without GAP";
	expectLieWarning(warnings[0], "no memory (buffer pts 0:00:00.033333333)");
}

TEST(Lying, BufferSmallerThanCapsWithoutMeta)
{
	GstBuffer *small = gst_buffer_new_allocate(nullptr, 4000, nullptr);
	gst_buffer_memset(small, 0, 9, 4000);
	expectPassedThrough("frappedetect", kGray64, small, "plane 0 needs 4096 bytes from offset 0, the buffer has 4000");
}

/* A plane must lie within the one memory a GstVideoMeta maps for it, not
 * only within the buffer's total size. */
TEST(Lying, PlaneAcrossTwoMemories)
{
	GstBuffer *buf = lyingBuffer(2048, GST_VIDEO_FORMAT_GRAY8, 64, 64, { 0 }, { 64 });
	gst_buffer_append_memory(buf, gst_allocator_alloc(nullptr, 2048, nullptr));
	expectPassedThrough("frappedetect", kGray64, buf, "plane 0 is not within one memory");
}

/* Only annotation writes the chroma planes: a lie there matters only with
 * annotate=true. */
TEST(Lying, ChromaPlanesCountOnlyWhenAnnotating)
{
	GstVideoInfo info;
	gst_video_info_set_format(&info, GST_VIDEO_FORMAT_I420, 640, 480);
	const gsize size = GST_VIDEO_INFO_SIZE(&info);
	auto buffer = [&] {
		/* The V plane starts 10 bytes before the end. */
		return lyingBuffer(size, GST_VIDEO_FORMAT_I420, 640, 480,
				   { 0, GST_VIDEO_INFO_PLANE_OFFSET(&info, 1), size - 10 }, { 640, 320, 320 });
	};
	{
		BusHarness t("frappedetect", kI420);
		GstBuffer *out = gst_harness_push_and_pull(t.h, buffer());
		ASSERT_NE(out, nullptr);
		gst_buffer_unref(out);
		const BusMessages msgs(t.bus);
		EXPECT_TRUE(msgs.of(GST_MESSAGE_WARNING).empty());
		EXPECT_EQ(msgs.of(GST_MESSAGE_ELEMENT).size(), 1u) << "detected: one frappedetect message";
	}
	expectPassedThrough("frappedetect annotate=true", kI420, buffer(), "plane 2 needs");
}

/* Issue 34: with annotate=false only the luma plane was checked, and a
 * chroma plane starting at or past the end made gst_video_frame_map() fail:
 * "Could not map the video frame", the buffer lost and the stream stopped.
 * Whatever annotate is, it now passes through with one warning. */
TEST(Lying, ChromaPlanePastTheEndPassesThroughWhateverAnnotate)
{
	GstVideoInfo info;
	gst_video_info_set_format(&info, GST_VIDEO_FORMAT_I420, 640, 480);
	const gsize size = GST_VIDEO_INFO_SIZE(&info);
	for (const gsize vOffset : { size, size + 4096 }) {
		auto buffer = [&] {
			return lyingBuffer(size, GST_VIDEO_FORMAT_I420, 640, 480,
					   { 0, GST_VIDEO_INFO_PLANE_OFFSET(&info, 1), vOffset }, { 640, 320, 320 });
		};
		SCOPED_TRACE(vOffset);
		expectPassedThrough("frappedetect", kI420, buffer(),
				    "plane 2 starts at offset " + std::to_string(vOffset) +
					    ", past the end of the buffer of " + std::to_string(size) + " bytes");
		expectPassedThrough("frappedetect annotate=true", kI420, buffer(),
				    "plane 2 needs 76800 bytes from offset " + std::to_string(vOffset));
	}
	/* Without a meta, a buffer shorter than the caps' frame whose luma
	 * plane is whole. */
	GstBuffer *shortFrame = gst_buffer_new_allocate(nullptr, 640 * 480 + 10, nullptr);
	gst_buffer_memset(shortFrame, 0, 9, 640 * 480 + 10);
	expectPassedThrough("frappedetect", kI420, shortFrame,
			    "the buffer has 307210 bytes, a 640x480 I420 frame 460800");
}

/* Issue 34: caps over 32768 pixels a side (under max_pixels) passed
 * negotiation, then the first buffer failed "Marker detection failed" and
 * the stream stopped. They are refused at negotiation. */
TEST(Lying, CapsBeyondTheLongestSideAreRefused)
{
	for (const FrameSpec huge : { FrameSpec{ GST_VIDEO_FORMAT_GRAY8, 40000, 16, 0 },
				      FrameSpec{ GST_VIDEO_FORMAT_GRAY8, 16, 32769, 0 } }) {
		BusHarness t("frappedetect", huge);
		EXPECT_EQ(gst_harness_push(t.h, gst_buffer_new_allocate(nullptr, 64, nullptr)), GST_FLOW_NOT_NEGOTIATED);
		EXPECT_EQ(gst_harness_buffers_received(t.h), 0u);
		GstMessage *msg = gst_bus_pop_filtered(t.bus, GST_MESSAGE_ERROR);
		ASSERT_NE(msg, nullptr);
		GError *err = nullptr;
		gst_message_parse_error(msg, &err, nullptr);
		EXPECT_TRUE(g_error_matches(err, GST_CORE_ERROR, GST_CORE_ERROR_NEGOTIATION)) << err->message;
		EXPECT_EQ(std::string(err->message), "Frames of " + std::to_string(huge.width) + "x" +
							     std::to_string(huge.height) +
							     " are wider or taller than the detector accepts (32768 pixels a side)");
		g_error_free(err);
		gst_message_unref(msg);
	}
}

/* One warning per kind of lie, not one per frame; every buffer still out. */
TEST(Lying, OneWarningPerKind)
{
	BusHarness t("frappedetect", kGray64);
	for (int i = 0; i < 5; ++i)
		ASSERT_EQ(gst_harness_push(t.h, lyingBuffer(4096, GST_VIDEO_FORMAT_GRAY8, 64, 64, { 0 }, { 256 },
							    static_cast<GstClockTime>(i) * kFrame)),
			  GST_FLOW_OK);
	ASSERT_EQ(gst_harness_push(t.h, gst_buffer_new()), GST_FLOW_OK);
	ASSERT_EQ(gst_harness_push(t.h, gst_buffer_new()), GST_FLOW_OK);
	EXPECT_EQ(gst_harness_buffers_received(t.h), 7u);
	const BusMessages msgs(t.bus);
	const auto warnings = msgs.of(GST_MESSAGE_WARNING);
	ASSERT_EQ(warnings.size(), 2u);
	expectLieWarning(warnings[0], "plane 0 needs 16192 bytes");
	expectLieWarning(warnings[1], "no memory");
}

/* Pipelined (either overlap), a lying buffer must not overtake the held
 * one: the held frame is finished first and both come out in order. */
static void PipelinedKeepsOrder(const char *overlap)
{
	const FrameSpec spec{ GST_VIDEO_FORMAT_GRAY8, 640, 480, 0 };
	BusHarness t((std::string("frappedetect pipelined=true overlap=") + overlap).c_str(), spec);
	auto good = [&](int i) {
		return makeFrame(spec, { square(i, 100.0f, 80.0f, 150.0f) }, dict("aruco_mip_36h12"),
				 static_cast<GstClockTime>(i) * kFrame, kFrame);
	};
	ASSERT_EQ(gst_harness_push(t.h, good(0)), GST_FLOW_OK);
	EXPECT_EQ(gst_harness_buffers_received(t.h), 0u) << "frame 0 held";
	ASSERT_EQ(gst_harness_push(t.h, lyingBuffer(640 * 480, GST_VIDEO_FORMAT_GRAY8, 640, 480, { 0 }, { 1000 },
						    kFrame)),
		  GST_FLOW_OK);
	EXPECT_EQ(gst_harness_buffers_received(t.h), 2u) << "frame 0, then the lying frame 1";
	ASSERT_EQ(gst_harness_push(t.h, good(2)), GST_FLOW_OK);
	ASSERT_EQ(gst_harness_push(t.h, good(3)), GST_FLOW_OK);
	ASSERT_TRUE(gst_harness_push_event(t.h, gst_event_new_eos()));
	EXPECT_EQ(gst_harness_buffers_received(t.h), 4u);
	for (int i = 0; i < 4; ++i) {
		GstBuffer *out = gst_harness_try_pull(t.h);
		ASSERT_NE(out, nullptr) << i;
		EXPECT_EQ(GST_BUFFER_PTS(out), static_cast<GstClockTime>(i) * kFrame);
		const auto metas = markerMetas(out);
		if (i == 1) {
			EXPECT_TRUE(metas.empty());
		} else {
			ASSERT_EQ(metas.size(), 1u) << i;
			EXPECT_EQ(metas[0]->id, i);
		}
		gst_buffer_unref(out);
	}
	EXPECT_EQ(gst_harness_try_pull(t.h), nullptr);
	const BusMessages msgs(t.bus);
	const auto warnings = msgs.of(GST_MESSAGE_WARNING);
	ASSERT_EQ(warnings.size(), 1u);
	expectLieWarning(warnings[0], "plane 0 needs 479640 bytes from offset 0, the buffer has 307200");
	EXPECT_TRUE(msgs.of(GST_MESSAGE_ERROR).empty());
	/* One frappedetect message per detected frame, none for the lie. */
	EXPECT_EQ(msgs.of(GST_MESSAGE_ELEMENT).size(), 3u);
}

TEST(Lying, PipelinedKeepsOrder)
{
	for (const char *overlap : { "frames", "stages" }) {
		SCOPED_TRACE(overlap);
		PipelinedKeepsOrder(overlap);
	}
}

/* Caps beyond frappe::Config::max_pixels are refused at negotiation: no
 * buffer can then claim a larger frame, its meta having to match them. */
TEST(Lying, CapsBeyondMaxPixelsAreRefused)
{
	const FrameSpec huge{ GST_VIDEO_FORMAT_GRAY8, 8192, 8193, 0 };
	BusHarness t("frappedetect", huge);
	EXPECT_EQ(gst_harness_push(t.h, gst_buffer_new_allocate(nullptr, 64, nullptr)), GST_FLOW_NOT_NEGOTIATED);
	EXPECT_EQ(gst_harness_buffers_received(t.h), 0u);
	GstMessage *msg = gst_bus_pop_filtered(t.bus, GST_MESSAGE_ERROR);
	ASSERT_NE(msg, nullptr);
	GError *err = nullptr;
	gst_message_parse_error(msg, &err, nullptr);
	EXPECT_TRUE(g_error_matches(err, GST_CORE_ERROR, GST_CORE_ERROR_NEGOTIATION)) << err->message;
	EXPECT_NE(std::string(err->message).find("8192x8193"), std::string::npos) << err->message;
	g_error_free(err);
	gst_message_unref(msg);
}

/* "Every buffer comes out" holds for the buffers QoS lets through: with
 * qos=true (GstVideoFilter's default) a buffer already late by the last
 * QoS event is dropped before detection; qos=false keeps it. */
TEST(Qos, LateBufferDroppedUnlessQosIsOff)
{
	for (const bool qos : { true, false }) {
		BusHarness t(qos ? "frappedetect" : "frappedetect qos=false", kGray64);
		EXPECT_EQ(gst_harness_push(t.h, makeFrame(kGray64, {}, dict("aruco_mip_36h12"), 0)), GST_FLOW_OK);
		/* Downstream reports the frame at 1 s rendered 100 ms late. */
		ASSERT_TRUE(gst_harness_push_upstream_event(
			t.h, gst_event_new_qos(GST_QOS_TYPE_UNDERFLOW, 1.5, 100 * GST_MSECOND, GST_SECOND)));
		EXPECT_EQ(gst_harness_push(t.h, makeFrame(kGray64, {}, dict("aruco_mip_36h12"), kFrame)), GST_FLOW_OK);
		EXPECT_EQ(gst_harness_buffers_received(t.h), qos ? 1u : 2u) << "qos=" << qos;
		int messages = 0;
		while (GstMessage *msg = gst_bus_pop_filtered(t.bus, GST_MESSAGE_ELEMENT)) {
			++messages;
			gst_message_unref(msg);
		}
		EXPECT_EQ(messages, qos ? 1 : 2) << "qos=" << qos;
	}
}
