// SPDX-License-Identifier: MIT
// frappedetect in real pipelines: long pipelined streams with buffers
// counted in and out, NULL-PLAYING-NULL cycles with frames in flight, and
// messages on the bus of a pipeline.
#include <atomic>
#include <string>

#include <gst/gst.h>
#include <gtest/gtest.h>

#include "helpers.h"

using namespace frappe::gsttest;

static auto *const gstEnv = ::testing::AddGlobalTestEnvironment(new GstEnvironment);

namespace {

struct Counter {
	std::atomic<int> n{ 0 };
	std::atomic<GstClockTime> last{ GST_CLOCK_TIME_NONE };
	std::atomic<bool> ordered{ true };
};

void onHandoff(GstElement *, GstBuffer *buf, GstPad *, gpointer data)
{
	auto *c = static_cast<Counter *>(data);
	const GstClockTime pts = GST_BUFFER_PTS(buf);
	const GstClockTime last = c->last.load();
	if (GST_CLOCK_TIME_IS_VALID(last) && pts <= last)
		c->ordered = false;
	c->last = pts;
	++c->n;
}

void onIdentityHandoff(GstElement *, GstBuffer *, gpointer data)
{
	++static_cast<Counter *>(data)->n;
}

GstMessage *runToEnd(GstElement *pipeline)
{
	EXPECT_NE(gst_element_set_state(pipeline, GST_STATE_PLAYING), GST_STATE_CHANGE_FAILURE);
	GstBus *bus = gst_element_get_bus(pipeline);
	GstMessage *msg = gst_bus_timed_pop_filtered(bus, 60 * GST_SECOND,
						     static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
	gst_object_unref(bus);
	return msg;
}

} // namespace

static void longPipelinedStream(const char *overlap);

/* Every buffer of a long stream out once and in order, with either overlap. */
TEST(Pipeline, LongPipelinedStreamCountsMatch)
{
	for (const char *overlap : { "frames", "stages" })
		longPipelinedStream(overlap);
}

static void longPipelinedStream(const char *overlap)
{
	SCOPED_TRACE(overlap);
	GError *err = nullptr;
	GstElement *pipeline = gst_parse_launch(
		(std::string("videotestsrc num-buffers=300 pattern=ball ! video/x-raw,format=I420,width=320,height=240 ! "
			     "identity name=in signal-handoffs=true ! frappedetect pipelined=true annotate=true overlap=") +
		 overlap + " ! fakesink name=out signal-handoffs=true sync=false")
			.c_str(),
		&err);
	ASSERT_EQ(err, nullptr);
	Counter in, out;
	GstElement *id = gst_bin_get_by_name(GST_BIN(pipeline), "in");
	GstElement *sink = gst_bin_get_by_name(GST_BIN(pipeline), "out");
	g_signal_connect(id, "handoff", G_CALLBACK(onIdentityHandoff), &in);
	g_signal_connect(sink, "handoff", G_CALLBACK(onHandoff), &out);

	GstMessage *msg = runToEnd(pipeline);
	ASSERT_NE(msg, nullptr);
	EXPECT_EQ(GST_MESSAGE_TYPE(msg), GST_MESSAGE_EOS);
	gst_message_unref(msg);
	EXPECT_EQ(in.n.load(), 300);
	EXPECT_EQ(out.n.load(), 300);
	EXPECT_TRUE(out.ordered.load());

	gst_element_set_state(pipeline, GST_STATE_NULL);
	gst_object_unref(id);
	gst_object_unref(sink);
	gst_object_unref(pipeline);
}

TEST(Pipeline, StateCyclesWithFramesInFlight)
{
	GError *err = nullptr;
	GstElement *pipeline = gst_parse_launch(
		"videotestsrc is-live=true ! video/x-raw,format=NV12,width=640,height=480,framerate=60/1 ! "
		"frappedetect pipelined=true annotate=true ! fakesink sync=true",
		&err);
	ASSERT_EQ(err, nullptr);
	GstBus *bus = gst_element_get_bus(pipeline);
	for (int cycle = 0; cycle < 8; ++cycle) {
		ASSERT_NE(gst_element_set_state(pipeline, GST_STATE_PLAYING), GST_STATE_CHANGE_FAILURE);
		ASSERT_EQ(gst_element_get_state(pipeline, nullptr, nullptr, 10 * GST_SECOND), GST_STATE_CHANGE_SUCCESS);
		g_usleep(static_cast<gulong>(20000 + 7000 * cycle));
		if (cycle % 2) {
			ASSERT_NE(gst_element_set_state(pipeline, GST_STATE_PAUSED), GST_STATE_CHANGE_FAILURE);
		}
		ASSERT_EQ(gst_element_set_state(pipeline, GST_STATE_NULL), GST_STATE_CHANGE_SUCCESS);
		GstMessage *error = gst_bus_pop_filtered(bus, GST_MESSAGE_ERROR);
		EXPECT_EQ(error, nullptr);
		if (error)
			gst_message_unref(error);
	}
	gst_object_unref(bus);
	gst_object_unref(pipeline);
}

TEST(Pipeline, MessagesOnTheBusWithPose)
{
	GError *err = nullptr;
	GstElement *pipeline = gst_parse_launch(
		"appsrc name=src format=time ! frappedetect marker-size=0.1 "
		"camera-matrix=\"<500.0,0.0,319.5,0.0,500.0,239.5,0.0,0.0,1.0>\" ! fakesink",
		&err);
	ASSERT_EQ(err, nullptr);
	FrameSpec spec;
	GstElement *src = gst_bin_get_by_name(GST_BIN(pipeline), "src");
	GstCaps *caps = gst_caps_from_string(capsString(spec).c_str());
	g_object_set(src, "caps", caps, nullptr);
	gst_caps_unref(caps);
	for (int i = 0; i < 5; ++i) {
		GstBuffer *b = makeFrame(spec, { square(i, 200.0f + 10 * i, 150.0f, 200.0f) }, dict("aruco_mip_36h12"),
					 i * GST_SECOND / 30);
		GstFlowReturn ret;
		g_signal_emit_by_name(src, "push-buffer", b, &ret);
		gst_buffer_unref(b);
	}
	GstFlowReturn eosRet;
	g_signal_emit_by_name(src, "end-of-stream", &eosRet);

	ASSERT_NE(gst_element_set_state(pipeline, GST_STATE_PLAYING), GST_STATE_CHANGE_FAILURE);
	GstBus *bus = gst_element_get_bus(pipeline);
	int frames = 0;
	for (;;) {
		GstMessage *msg = gst_bus_timed_pop_filtered(
			bus, 30 * GST_SECOND,
			static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR | GST_MESSAGE_ELEMENT));
		ASSERT_NE(msg, nullptr);
		if (GST_MESSAGE_TYPE(msg) != GST_MESSAGE_ELEMENT) {
			EXPECT_EQ(GST_MESSAGE_TYPE(msg), GST_MESSAGE_EOS);
			gst_message_unref(msg);
			break;
		}
		const GstStructure *s = gst_message_get_structure(msg);
		if (gst_structure_has_name(s, "frappedetect")) {
			const GValue *markers = gst_structure_get_value(s, "markers");
			ASSERT_EQ(gst_value_list_get_size(markers), 1u);
			const GstStructure *m = gst_value_get_structure(gst_value_list_get_value(markers, 0));
			int id = -1;
			gst_structure_get_int(m, "id", &id);
			EXPECT_EQ(id, frames);
			const GValue *tvec = gst_structure_get_value(m, "tvec");
			ASSERT_NE(tvec, nullptr);
			/* 200 px for 0.1 m at f = 500 px: 0.25 m away. */
			EXPECT_NEAR(g_value_get_double(gst_value_array_get_value(tvec, 2)), 0.25, 0.0025);
			++frames;
		}
		gst_message_unref(msg);
	}
	EXPECT_EQ(frames, 5);
	gst_element_set_state(pipeline, GST_STATE_NULL);
	gst_object_unref(bus);
	gst_object_unref(src);
	gst_object_unref(pipeline);
}

/* The meta's scale transform in a real videoscale: corners follow the image. */
TEST(Pipeline, MetaSurvivesVideoscale)
{
	GError *err = nullptr;
	GstElement *pipeline = gst_parse_launch(
		"appsrc name=src format=time ! frappedetect ! videoscale ! "
		"video/x-raw,width=320,height=240 ! appsink name=sink sync=false",
		&err);
	ASSERT_EQ(err, nullptr);
	FrameSpec spec{ GST_VIDEO_FORMAT_I420, 640, 480, 0 };
	GstElement *src = gst_bin_get_by_name(GST_BIN(pipeline), "src");
	GstElement *sink = gst_bin_get_by_name(GST_BIN(pipeline), "sink");
	GstCaps *caps = gst_caps_from_string(capsString(spec).c_str());
	g_object_set(src, "caps", caps, nullptr);
	gst_caps_unref(caps);
	const Placed marker = square(9, 100.25f, 120.75f, 200.0f);
	GstBuffer *b = makeFrame(spec, { marker }, dict("aruco_mip_36h12"));
	GstFlowReturn ret;
	g_signal_emit_by_name(src, "push-buffer", b, &ret);
	gst_buffer_unref(b);
	g_signal_emit_by_name(src, "end-of-stream", &ret);

	ASSERT_NE(gst_element_set_state(pipeline, GST_STATE_PLAYING), GST_STATE_CHANGE_FAILURE);
	GstSample *sample = nullptr;
	g_signal_emit_by_name(sink, "pull-sample", &sample);
	ASSERT_NE(sample, nullptr);
	GstBuffer *out = gst_sample_get_buffer(sample);
	const auto metas = markerMetas(out);
	ASSERT_EQ(metas.size(), 1u);
	EXPECT_EQ(metas[0]->id, 9);
	for (int k = 0; k < 4; ++k) {
		EXPECT_NEAR(metas[0]->corners[2 * k], (marker.corners[static_cast<std::size_t>(k)].x + 0.5f) / 2 - 0.5f, 0.3f);
		EXPECT_NEAR(metas[0]->corners[2 * k + 1], (marker.corners[static_cast<std::size_t>(k)].y + 0.5f) / 2 - 0.5f,
			    0.3f);
	}
	gst_sample_unref(sample);
	gst_element_set_state(pipeline, GST_STATE_NULL);
	gst_object_unref(src);
	gst_object_unref(sink);
	gst_object_unref(pipeline);
}
