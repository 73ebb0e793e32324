// SPDX-License-Identifier: MIT
// frappedetect pipelined=true: one buffer held, N in and N out in order with
// their own metas, the latency answer, EOS drain, flush, caps changes and
// live toggling; with either overlap (whole frames on two detectors, or one
// detector's stages), each saying in the stats which ran.
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

/* Frame i shows marker i (and i + 100 in every third frame). */
std::vector<Placed> markersOf(int i, const FrameSpec &s)
{
	std::vector<Placed> m{ square(i, 40.0f + 3.1f * static_cast<float>(i % 20), 60.25f, 150.0f) };
	if (i % 3 == 0)
		m.push_back(tilted(i + 100, s.width * 0.72f, s.height * 0.55f, 140.0f, 0.2f));
	return m;
}

GstBuffer *frameOf(int i, const FrameSpec &s)
{
	return makeFrame(s, markersOf(i, s), dict("aruco_mip_36h12"), static_cast<GstClockTime>(i) * kFrame, kFrame);
}

void expectFrame(GstBuffer *out, int i, const FrameSpec &s, float tol = 0.3f)
{
	ASSERT_NE(out, nullptr);
	EXPECT_EQ(GST_BUFFER_PTS(out), static_cast<GstClockTime>(i) * kFrame);
	expectMarkers(out, markersOf(i, s), "aruco_mip_36h12", tol);
}

/* The element, pipelined with the overlap under test, and `extra`. */
std::string launch(const std::string &overlap, const std::string &extra = "")
{
	return "frappedetect pipelined=true overlap=" + overlap + (extra.empty() ? "" : " " + extra);
}

std::string statsString(GstElement *e, const char *field)
{
	GstStructure *st = nullptr;
	g_object_get(e, "stats", &st, nullptr);
	const gchar *v = st ? gst_structure_get_string(st, field) : nullptr;
	std::string out = v ? v : "";
	if (st)
		gst_structure_free(st);
	return out;
}

} // namespace

class Pipelined : public ::testing::TestWithParam<std::string>
{
};

INSTANTIATE_TEST_SUITE_P(Overlap, Pipelined, ::testing::Values("frames", "stages"),
			 [](const auto &info) { return info.param; });

TEST_P(Pipelined, NInNOutInOrderWithOwnMetas)
{
	for (const char *mode : { "normal", "ascale" }) {
		FrameSpec spec{ GST_VIDEO_FORMAT_NV12, 640, 480, 0 };
		GstHarness *h = gst_harness_new_parse(launch(GetParam(), std::string("mode=") + mode).c_str());
		gst_harness_set_src_caps_str(h, capsString(spec).c_str());
		GstBus *bus = gst_bus_new();
		gst_element_set_bus(h->element, bus);
		const int n = 40;
		/* ascale traces scaled frames: corners are refined at full
		 * resolution but start further off (frappe-core's accuracy). */
		const float tol = std::string(mode) == "ascale" ? 0.6f : 0.3f;
		for (int i = 0; i < n; ++i) {
			ASSERT_EQ(gst_harness_push(h, frameOf(i, spec)), GST_FLOW_OK);
			/* One buffer is held: the output lags by exactly one. */
			EXPECT_EQ(gst_harness_buffers_received(h), static_cast<guint>(i)) << mode;
			if (i > 0) {
				GstBuffer *out = gst_harness_pull(h);
				expectFrame(out, i - 1, spec, tol);
				gst_buffer_unref(out);
			}
		}
		/* EOS drains the held buffer before the EOS goes downstream. */
		ASSERT_TRUE(gst_harness_push_event(h, gst_event_new_eos()));
		GstBuffer *out = gst_harness_try_pull(h);
		expectFrame(out, n - 1, spec, tol);
		gst_buffer_unref(out);
		EXPECT_EQ(gst_harness_buffers_received(h), static_cast<guint>(n));
		EXPECT_EQ(gst_harness_try_pull(h), nullptr);
		/* The EOS arrives after the drained buffer. */
		GstEvent *ev;
		bool sawEos = false;
		while ((ev = gst_harness_try_pull_event(h))) {
			sawEos |= GST_EVENT_TYPE(ev) == GST_EVENT_EOS;
			gst_event_unref(ev);
		}
		EXPECT_TRUE(sawEos);
		EXPECT_EQ(statsString(detector(h), "overlap"), GetParam()) << "the stats say which overlap ran";
		/* One message per frame, in order, each with its own markers. */
		for (int i = 0; i < n; ++i) {
			GstMessage *msg = gst_bus_pop_filtered(bus, GST_MESSAGE_ELEMENT);
			ASSERT_NE(msg, nullptr);
			const GstStructure *st = gst_message_get_structure(msg);
			guint64 ts = 0;
			gst_structure_get_uint64(st, "timestamp", &ts);
			EXPECT_EQ(ts, static_cast<guint64>(i) * kFrame);
			const GValue *list = gst_structure_get_value(st, "markers");
			EXPECT_EQ(gst_value_list_get_size(list), markersOf(i, spec).size());
			gst_message_unref(msg);
		}
		gst_element_set_bus(h->element, nullptr);
		gst_object_unref(bus);
		gst_harness_teardown(h);
	}
}

TEST_P(Pipelined, LatencyAddsOneFrame)
{
	FrameSpec spec;
	GstHarness *h = gst_harness_new_parse(launch(GetParam()).c_str());
	gst_harness_set_src_caps_str(h, capsString(spec, 25).c_str());
	gst_harness_set_upstream_latency(h, 10 * GST_MSECOND);
	/* The caps reach the element with the first buffer. */
	ASSERT_EQ(gst_harness_push(h, frameOf(0, spec)), GST_FLOW_OK);
	EXPECT_EQ(gst_harness_query_latency(h), 10 * GST_MSECOND + GST_SECOND / 25);

	g_object_set(detector(h), "pipelined", FALSE, nullptr);
	EXPECT_EQ(gst_harness_query_latency(h), 10 * GST_MSECOND);
	gst_harness_teardown(h);
}

TEST_P(Pipelined, FlushDropsTheHeldBuffer)
{
	FrameSpec spec;
	GstHarness *h = gst_harness_new_parse(launch(GetParam()).c_str());
	gst_harness_set_src_caps_str(h, capsString(spec).c_str());
	ASSERT_EQ(gst_harness_push(h, frameOf(0, spec)), GST_FLOW_OK);
	ASSERT_EQ(gst_harness_push(h, frameOf(1, spec)), GST_FLOW_OK);
	EXPECT_EQ(gst_harness_buffers_received(h), 1u);
	gst_buffer_unref(gst_harness_pull(h));

	ASSERT_TRUE(gst_harness_push_event(h, gst_event_new_flush_start()));
	ASSERT_TRUE(gst_harness_push_event(h, gst_event_new_flush_stop(TRUE)));
	GstSegment segment;
	gst_segment_init(&segment, GST_FORMAT_TIME);
	ASSERT_TRUE(gst_harness_push_event(h, gst_event_new_segment(&segment)));
	EXPECT_EQ(gst_harness_buffers_received(h), 1u);

	ASSERT_EQ(gst_harness_push(h, frameOf(2, spec)), GST_FLOW_OK);
	ASSERT_EQ(gst_harness_push(h, frameOf(3, spec)), GST_FLOW_OK);
	ASSERT_TRUE(gst_harness_push_event(h, gst_event_new_eos()));
	/* Frame 1 was dropped by the flush; 2 and 3 come out. */
	for (int i : { 2, 3 }) {
		GstBuffer *out = gst_harness_try_pull(h);
		expectFrame(out, i, spec);
		gst_buffer_unref(out);
	}
	EXPECT_EQ(gst_harness_try_pull(h), nullptr);
	gst_harness_teardown(h);
}

TEST_P(Pipelined, DrainQueryPushesTheHeldBuffer)
{
	FrameSpec spec;
	GstHarness *h = gst_harness_new_parse(launch(GetParam()).c_str());
	gst_harness_set_src_caps_str(h, capsString(spec).c_str());
	ASSERT_EQ(gst_harness_push(h, frameOf(0, spec)), GST_FLOW_OK);
	ASSERT_EQ(gst_harness_push(h, frameOf(1, spec)), GST_FLOW_OK);
	EXPECT_EQ(gst_harness_buffers_received(h), 1u);
	GstQuery *drain = gst_query_new_drain();
	EXPECT_TRUE(gst_pad_peer_query(h->srcpad, drain));
	gst_query_unref(drain);
	EXPECT_EQ(gst_harness_buffers_received(h), 2u);
	for (int i = 0; i < 2; ++i) {
		GstBuffer *out = gst_harness_pull(h);
		expectFrame(out, i, spec);
		gst_buffer_unref(out);
	}
	/* And the stream goes on. */
	ASSERT_EQ(gst_harness_push(h, frameOf(2, spec)), GST_FLOW_OK);
	ASSERT_TRUE(gst_harness_push_event(h, gst_event_new_eos()));
	GstBuffer *out = gst_harness_try_pull(h);
	expectFrame(out, 2, spec);
	gst_buffer_unref(out);
	gst_harness_teardown(h);
}

TEST_P(Pipelined, CapsChangeDrains)
{
	FrameSpec a{ GST_VIDEO_FORMAT_I420, 640, 480, 0 };
	FrameSpec b{ GST_VIDEO_FORMAT_GRAY8, 480, 360, 0 };
	GstHarness *h = gst_harness_new_parse(launch(GetParam()).c_str());
	gst_harness_set_src_caps_str(h, capsString(a).c_str());
	ASSERT_EQ(gst_harness_push(h, frameOf(0, a)), GST_FLOW_OK);
	ASSERT_EQ(gst_harness_push(h, frameOf(1, a)), GST_FLOW_OK);
	/* New caps: the held frame 1 comes out first, with the old caps. */
	gst_harness_set_src_caps_str(h, capsString(b).c_str());
	ASSERT_EQ(gst_harness_push(h, frameOf(2, b)), GST_FLOW_OK);
	ASSERT_TRUE(gst_harness_push_event(h, gst_event_new_eos()));
	for (int i = 0; i < 3; ++i) {
		GstBuffer *out = gst_harness_try_pull(h);
		expectFrame(out, i, i < 2 ? a : b);
		gst_buffer_unref(out);
	}
	gst_harness_teardown(h);
}

TEST_P(Pipelined, ToggleAndRetuneWhilePlaying)
{
	FrameSpec spec{ GST_VIDEO_FORMAT_I420, 640, 480, 0 };
	GstHarness *h = gst_harness_new_parse(("frappedetect overlap=" + GetParam()).c_str());
	gst_harness_set_src_caps_str(h, capsString(spec).c_str());
	const int n = 30;
	for (int i = 0; i < n; ++i) {
		if (i % 7 == 3)
			g_object_set(detector(h), "pipelined", (i / 7) % 2 == 0, nullptr);
		if (i % 5 == 4)
			g_object_set(detector(h), "edge-threshold", i % 2 ? 0.25f : 0.27f, "annotate", i % 2 == 0,
				     nullptr);
		ASSERT_EQ(gst_harness_push(h, frameOf(i, spec)), GST_FLOW_OK);
	}
	ASSERT_TRUE(gst_harness_push_event(h, gst_event_new_eos()));
	EXPECT_EQ(gst_harness_buffers_received(h), static_cast<guint>(n));
	for (int i = 0; i < n; ++i) {
		GstBuffer *out = gst_harness_try_pull(h);
		expectFrame(out, i, spec);
		gst_buffer_unref(out);
	}
	gst_harness_teardown(h);
}

TEST_P(Pipelined, StateCyclesWithAFrameInFlight)
{
	FrameSpec spec;
	GstHarness *h = gst_harness_new_parse(launch(GetParam()).c_str());
	gst_harness_set_src_caps_str(h, capsString(spec).c_str());
	for (int cycle = 0; cycle < 5; ++cycle) {
		ASSERT_EQ(gst_harness_push(h, frameOf(2 * cycle, spec)), GST_FLOW_OK);
		/* The frame is held (its detection may still be running). */
		ASSERT_EQ(gst_element_set_state(h->element, GST_STATE_NULL), GST_STATE_CHANGE_SUCCESS);
		ASSERT_EQ(gst_element_set_state(h->element, GST_STATE_PLAYING), GST_STATE_CHANGE_SUCCESS);
		/* The sink pad lost its sticky events: send them again. */
		gst_harness_push_event(h, gst_event_new_stream_start("cycle"));
		gst_harness_set_src_caps_str(h, capsString(spec).c_str());
		GstSegment segment;
		gst_segment_init(&segment, GST_FORMAT_TIME);
		gst_harness_push_event(h, gst_event_new_segment(&segment));
	}
	ASSERT_EQ(gst_harness_push(h, frameOf(1, spec)), GST_FLOW_OK);
	ASSERT_TRUE(gst_harness_push_event(h, gst_event_new_eos()));
	GstBuffer *out;
	GstBuffer *last = nullptr;
	while ((out = gst_harness_try_pull(h))) {
		if (last)
			gst_buffer_unref(last);
		last = out;
	}
	expectFrame(last, 1, spec);
	gst_buffer_unref(last);
	gst_harness_teardown(h);
}
