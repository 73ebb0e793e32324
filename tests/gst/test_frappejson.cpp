// SPDX-License-Identifier: MIT
// The frappejson element: the exact line a buffer's metas give, caps and
// events, one output buffer per input with its timestamps (harness and
// appsink), one datagram per line through udpsink.
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gio/gio.h>
#include <gst/app/gstappsink.h>
#include <gst/app/gstappsrc.h>
#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gtest/gtest.h>

#include "gstfrappemeta.h"
#include "helpers.h"

using namespace frappe::gsttest;

static auto *const gstEnv = ::testing::AddGlobalTestEnvironment(new GstEnvironment);

namespace {

std::string text(GstBuffer *buf)
{
	std::string s(gst_buffer_get_size(buf), '\0');
	gst_buffer_extract(buf, 0, s.data(), s.size());
	return s;
}

const FrameSpec kSpec{ GST_VIDEO_FORMAT_GRAY8, 320, 240 };
const std::vector<Placed> kMarkers{ square(7, 40.3f, 30.6f, 100.0f), tilted(42, 230.0f, 150.0f, 90.0f, 0.3f) };

/* Frames with markers 7 and 42 at 0, 1/30 s, ... */
GstBuffer *frame(int i)
{
	return makeFrame(kSpec, kMarkers, dict("aruco_mip_36h12"), static_cast<GstClockTime>(i) * GST_SECOND / 30);
}

/* A pipeline from `launch` with appsrc "src" fed `n` frames then EOS,
 * played to the end. */
GstElement *runPipeline(const std::string &launch, int n)
{
	GstElement *pipeline = gst_parse_launch(launch.c_str(), nullptr);
	EXPECT_NE(pipeline, nullptr);
	GstElement *src = gst_bin_get_by_name(GST_BIN(pipeline), "src");
	GstCaps *caps = gst_caps_from_string(capsString(kSpec).c_str());
	g_object_set(src, "caps", caps, "format", GST_FORMAT_TIME, nullptr);
	gst_caps_unref(caps);
	EXPECT_NE(gst_element_set_state(pipeline, GST_STATE_PLAYING), GST_STATE_CHANGE_FAILURE);
	for (int i = 0; i < n; ++i)
		EXPECT_EQ(gst_app_src_push_buffer(GST_APP_SRC(src), frame(i)), GST_FLOW_OK);
	gst_app_src_end_of_stream(GST_APP_SRC(src));
	gst_object_unref(src);
	return pipeline;
}

} // namespace

/* Metas made by hand: the line is exactly what they say, numbers in their
 * shortest exact form, infinity as null, the name escaped; timestamps and
 * offsets copied; caps application/x-json; events through. */
TEST(Json, ExactLineFromMetas)
{
	GstHarness *h = gst_harness_new("frappejson");
	gst_harness_set_src_caps_str(h, capsString(kSpec).c_str());

	GstBuffer *in = gst_buffer_new_allocate(nullptr, 320 * 240, nullptr);
	GST_BUFFER_PTS(in) = 1234567890;
	GST_BUFFER_DTS(in) = 1234567000;
	GST_BUFFER_DURATION(in) = 33333333;
	GST_BUFFER_OFFSET(in) = 37;
	GST_BUFFER_OFFSET_END(in) = 38;
	const gfloat corners[8] = { 10.5f, 20.25f, 110.125f, 20.0f, 110.0f, 120.0f, 10.0f, 120.0625f };
	GstFrappeMarkerMeta *m = gst_buffer_add_frappe_marker_meta(in, 7, "aruco_mip_36h12", corners, 1);
	m->margin = 0.75f;
	m->has_pose = TRUE;
	const double rvec[3] = { 3.0, -0.125, 1e-7 }, tvec[3] = { 0.0123456789, -0.5, 0.27 };
	for (int i = 0; i < 3; ++i) {
		m->rvec[i] = rvec[i];
		m->tvec[i] = tvec[i];
	}
	m->reprojection_error = 0.03125;
	m->alternative_reprojection_error = std::numeric_limits<double>::infinity();
	m = gst_buffer_add_frappe_marker_meta(in, 0, "my \"dict\"\\1\n", corners, 0);
	m->margin = 0.5f;

	GstBuffer *out = gst_harness_push_and_pull(h, in);
	EXPECT_EQ(text(out),
		  "{\"pts\": 1234567890, \"markers\": [{\"id\": 7, \"dictionary\": \"aruco_mip_36h12\", "
		  "\"corners\": [[10.5, 20.25], [110.125, 20], [110, 120], [10, 120.0625]], \"hamming\": 1, "
		  "\"margin\": 0.75, \"rvec\": [3, -0.125, 1e-07], \"tvec\": [0.0123456789, -0.5, 0.27], "
		  "\"reprojection_error\": 0.03125, \"alternative_reprojection_error\": null}, "
		  "{\"id\": 0, \"dictionary\": \"my \\\"dict\\\"\\\\1\\u000a\", \"corners\": [[10.5, 20.25], "
		  "[110.125, 20], [110, 120], [10, 120.0625]], \"hamming\": 0, \"margin\": 0.5}]}\n");
	EXPECT_EQ(GST_BUFFER_PTS(out), 1234567890u);
	EXPECT_EQ(GST_BUFFER_DTS(out), 1234567000u);
	EXPECT_EQ(GST_BUFFER_DURATION(out), 33333333u);
	EXPECT_EQ(GST_BUFFER_OFFSET(out), 37u);
	EXPECT_EQ(GST_BUFFER_OFFSET_END(out), 38u);
	EXPECT_EQ(gst_buffer_get_n_frappe_marker_metas(out), 0u);
	gst_buffer_unref(out);

	/* No metas, no timestamp. */
	in = gst_buffer_new_allocate(nullptr, 320 * 240, nullptr);
	out = gst_harness_push_and_pull(h, in);
	EXPECT_EQ(text(out), "{\"pts\": null, \"markers\": []}\n");
	EXPECT_FALSE(GST_BUFFER_PTS_IS_VALID(out));
	gst_buffer_unref(out);

	/* Caps, stream-start and segment reached the sink; EOS follows. */
	GstCaps *caps = gst_pad_get_current_caps(h->sinkpad);
	ASSERT_NE(caps, nullptr);
	gchar *capsText = gst_caps_to_string(caps);
	EXPECT_STREQ(capsText, "application/x-json");
	g_free(capsText);
	gst_caps_unref(caps);
	bool streamStart = false, segment = false;
	while (GstEvent *e = gst_harness_try_pull_event(h)) {
		streamStart |= GST_EVENT_TYPE(e) == GST_EVENT_STREAM_START;
		segment |= GST_EVENT_TYPE(e) == GST_EVENT_SEGMENT;
		gst_event_unref(e);
	}
	EXPECT_TRUE(streamStart);
	EXPECT_TRUE(segment);
	EXPECT_TRUE(gst_harness_push_event(h, gst_event_new_eos()));
	GstEvent *eos = gst_harness_try_pull_event(h);
	ASSERT_NE(eos, nullptr);
	EXPECT_EQ(GST_EVENT_TYPE(eos), GST_EVENT_EOS);
	gst_event_unref(eos);
	gst_harness_teardown(h);
}

/* Issue 34: a meta's dictionary name that is not UTF-8 (any application
 * may attach one) made every line invalid UTF-8. Such bytes are written
 * \u00XX; UTF-8 is written as it is. */
TEST(Json, LinesAreUtf8WhateverTheName)
{
	GstHarness *h = gst_harness_new("frappejson");
	gst_harness_set_src_caps_str(h, capsString(kSpec).c_str());
	GstBuffer *in = gst_buffer_new_allocate(nullptr, 320 * 240, nullptr);
	const gfloat corners[8] = { 1, 2, 3, 4, 5, 6, 7, 8 };
	gst_buffer_add_frappe_marker_meta(in, 1, "caf\xe9-\xc3\xa9-\xe6\x97\xa5-\xed\xa0\x80-\xc0\xae", corners, 0);
	GstBuffer *out = gst_harness_push_and_pull(h, in);
	const std::string line = text(out);
	EXPECT_TRUE(g_utf8_validate(line.data(), static_cast<gssize>(line.size()), nullptr)) << line;
	EXPECT_NE(line.find("\"dictionary\": \"caf\\u00e9-\xc3\xa9-\xe6\x97\xa5-\\u00ed\\u00a0\\u0080-\\u00c0\\u00ae\""),
		  std::string::npos)
		<< line;
	gst_buffer_unref(out);
	gst_harness_teardown(h);
}

/* Caps other than application/x-json downstream: no negotiation. */
TEST(Json, RefusesOtherCapsDownstream)
{
	GstHarness *h = gst_harness_new("frappejson");
	gst_harness_set_sink_caps_str(h, "text/x-raw,format=utf8");
	gst_harness_set_src_caps_str(h, capsString(kSpec).c_str());
	EXPECT_EQ(gst_harness_push(h, gst_buffer_new_allocate(nullptr, 320 * 240, nullptr)),
		  GST_FLOW_NOT_NEGOTIATED);
	gst_harness_teardown(h);
}

/* Through frappedetect to an appsink: one buffer per input, in order, with
 * its PTS and a line naming both markers. */
TEST(Json, AppsinkGetsOneLinePerFrame)
{
	constexpr int kFrames = 12;
	GstElement *pipeline = runPipeline("appsrc name=src ! frappedetect ! frappejson ! "
					   "appsink name=sink sync=false max-buffers=100",
					   kFrames);
	GstElement *sink = gst_bin_get_by_name(GST_BIN(pipeline), "sink");
	for (int i = 0; i < kFrames; ++i) {
		GstSample *sample = gst_app_sink_try_pull_sample(GST_APP_SINK(sink), 10 * GST_SECOND);
		ASSERT_NE(sample, nullptr) << "frame " << i;
		GstBuffer *buf = gst_sample_get_buffer(sample);
		EXPECT_EQ(GST_BUFFER_PTS(buf), static_cast<GstClockTime>(i) * GST_SECOND / 30);
		const std::string line = text(buf);
		const std::string head =
			"{\"pts\": " + std::to_string(GST_BUFFER_PTS(buf)) + ", \"markers\": [{\"id\": ";
		EXPECT_EQ(line.rfind(head, 0), 0u) << line;
		EXPECT_EQ(line.find('\n'), line.size() - 1) << line;
		EXPECT_NE(line.find("\"id\": 7, \"dictionary\": \"aruco_mip_36h12\""), std::string::npos) << line;
		EXPECT_NE(line.find("\"id\": 42, \"dictionary\": \"aruco_mip_36h12\""), std::string::npos) << line;
		EXPECT_STREQ(gst_structure_get_name(gst_caps_get_structure(gst_sample_get_caps(sample), 0)),
			     "application/x-json");
		gst_sample_unref(sample);
	}
	GstSample *extra = gst_app_sink_try_pull_sample(GST_APP_SINK(sink), GST_SECOND);
	EXPECT_EQ(extra, nullptr);
	if (extra)
		gst_sample_unref(extra);
	EXPECT_TRUE(gst_app_sink_is_eos(GST_APP_SINK(sink)));
	gst_object_unref(sink);
	gst_element_set_state(pipeline, GST_STATE_NULL);
	gst_object_unref(pipeline);
}

/* udpsink sends each line as one datagram. */
TEST(Json, UdpsinkSendsOneDatagramPerLine)
{
	GSocket *socket = g_socket_new(G_SOCKET_FAMILY_IPV4, G_SOCKET_TYPE_DATAGRAM, G_SOCKET_PROTOCOL_UDP, nullptr);
	ASSERT_NE(socket, nullptr);
	GInetAddress *loopback = g_inet_address_new_loopback(G_SOCKET_FAMILY_IPV4);
	GSocketAddress *any = g_inet_socket_address_new(loopback, 0);
	ASSERT_TRUE(g_socket_bind(socket, any, TRUE, nullptr));
	GSocketAddress *bound = g_socket_get_local_address(socket, nullptr);
	const guint16 port = g_inet_socket_address_get_port(G_INET_SOCKET_ADDRESS(bound));

	constexpr int kFrames = 8;
	GstElement *pipeline = runPipeline("appsrc name=src ! frappedetect ! frappejson ! udpsink host=127.0.0.1 "
					   "port=" + std::to_string(port) + " sync=false",
					   kFrames);
	waitForEos(pipeline);

	g_socket_set_timeout(socket, 5);
	for (int i = 0; i < kFrames; ++i) {
		char data[65536];
		const gssize n = g_socket_receive(socket, data, sizeof(data), nullptr, nullptr);
		ASSERT_GT(n, 0) << "datagram " << i;
		const std::string line(data, static_cast<std::size_t>(n));
		const std::string pts = std::to_string(static_cast<GstClockTime>(i) * GST_SECOND / 30);
		EXPECT_EQ(line.rfind("{\"pts\": " + pts + ", ", 0), 0u) << line;
		EXPECT_EQ(line.find('\n'), line.size() - 1) << line;
		EXPECT_NE(line.find("\"id\": 42"), std::string::npos) << line;
	}
	gst_element_set_state(pipeline, GST_STATE_NULL);
	gst_object_unref(pipeline);
	g_object_unref(bound);
	g_object_unref(any);
	g_object_unref(loopback);
	g_object_unref(socket);
}
