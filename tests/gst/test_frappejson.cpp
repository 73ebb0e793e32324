// SPDX-License-Identifier: MIT
// The frappejson element: the exact line a buffer's metas give (the frame's
// fields, the capture time from a reference meta), caps and events, a
// frame's parts under max-bytes with its timestamps (harness and appsink),
// precision and fields, KLV packets, one datagram per line through udpsink
// and 300 posed markers of one frame over UDP.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include <sys/socket.h>

#include <gio/gio.h>
#include <gst/app/gstappsink.h>
#include <gst/app/gstappsrc.h>
#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <frappe/marker_record.h>

#include "gstfrappemeta-record.h"
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

/* A UDP socket on loopback for udpsink to send to (a large receive buffer:
 * a frame may come in a hundred datagrams). */
struct UdpReceiver {
	UdpReceiver()
	{
		socket = g_socket_new(G_SOCKET_FAMILY_IPV4, G_SOCKET_TYPE_DATAGRAM, G_SOCKET_PROTOCOL_UDP, nullptr);
		g_socket_set_option(socket, SOL_SOCKET, SO_RCVBUF, 1 << 22, nullptr);
		GInetAddress *loopback = g_inet_address_new_loopback(G_SOCKET_FAMILY_IPV4);
		GSocketAddress *any = g_inet_socket_address_new(loopback, 0);
		EXPECT_TRUE(g_socket_bind(socket, any, TRUE, nullptr));
		GSocketAddress *bound = g_socket_get_local_address(socket, nullptr);
		port = g_inet_socket_address_get_port(G_INET_SOCKET_ADDRESS(bound));
		g_object_unref(bound);
		g_object_unref(any);
		g_object_unref(loopback);
	}
	~UdpReceiver() { g_object_unref(socket); }

	/* The datagrams waiting, in the order sent (loopback keeps it). */
	std::vector<std::string> receiveAll()
	{
		g_socket_set_blocking(socket, FALSE);
		std::vector<std::string> out;
		for (;;) {
			char data[65536];
			const gssize n = g_socket_receive(socket, data, sizeof(data), nullptr, nullptr);
			if (n <= 0)
				return out;
			out.emplace_back(data, static_cast<std::size_t>(n));
		}
	}

	GSocket *socket = nullptr;
	guint16 port = 0;
};

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
	/* The source's wall-clock time wins over the pipeline's estimate. */
	GstCaps *unix = gst_caps_new_empty_simple("timestamp/x-unix");
	gst_buffer_add_reference_timestamp_meta(in, unix, 1780393200123456789u, GST_CLOCK_TIME_NONE);
	gst_caps_unref(unix);

	GstBuffer *out = gst_harness_push_and_pull(h, in);
	EXPECT_EQ(text(out),
		  "{\"frame\": 37, \"part\": 1, \"parts\": 1, \"pts\": 1234567890, \"running_time\": 1234567890, "
		  "\"width\": 320, \"height\": 240, \"frame_id\": \"camera\", \"capture_time\": 1780393200123456789, "
		  "\"capture_clock\": \"reference\", \"markers\": [{\"id\": 7, \"dictionary\": \"aruco_mip_36h12\", "
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

	/* No metas, no timestamp, no offset: the element's own count (its
	 * second buffer), no time at all. */
	in = gst_buffer_new_allocate(nullptr, 320 * 240, nullptr);
	out = gst_harness_push_and_pull(h, in);
	EXPECT_EQ(text(out),
		  "{\"frame\": 1, \"part\": 1, \"parts\": 1, \"pts\": null, \"running_time\": null, "
		  "\"width\": 320, \"height\": 240, \"frame_id\": \"camera\", \"capture_time\": null, "
		  "\"capture_clock\": null, \"markers\": []}\n");
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
	int pipelineClock = 0;
	for (int i = 0; i < kFrames; ++i) {
		GstSample *sample = gst_app_sink_try_pull_sample(GST_APP_SINK(sink), 10 * GST_SECOND);
		ASSERT_NE(sample, nullptr) << "frame " << i;
		GstBuffer *buf = gst_sample_get_buffer(sample);
		EXPECT_EQ(GST_BUFFER_PTS(buf), static_cast<GstClockTime>(i) * GST_SECOND / 30);
		const std::string line = text(buf);
		/* frappedetect numbered the frames; one part each. */
		const std::string head = "{\"frame\": " + std::to_string(i) + ", \"part\": 1, \"parts\": 1, \"pts\": " +
					 std::to_string(GST_BUFFER_PTS(buf)) +
					 ", \"running_time\": " + std::to_string(GST_BUFFER_PTS(buf)) + ", ";
		EXPECT_EQ(line.rfind(head, 0), 0u) << line;
		EXPECT_EQ(line.find('\n'), line.size() - 1) << line;
		EXPECT_NE(line.find("\"id\": 7, \"dictionary\": \"aruco_mip_36h12\""), std::string::npos) << line;
		EXPECT_NE(line.find("\"id\": 42, \"dictionary\": \"aruco_mip_36h12\""), std::string::npos) << line;
		EXPECT_STREQ(gst_structure_get_name(gst_caps_get_structure(gst_sample_get_caps(sample), 0)),
			     "application/x-json");
		/* No reference meta: the pipeline clock's estimate once it plays
		 * (the preroll frame has no clock yet: null), near the wall clock. */
		long long capture = 0;
		const std::size_t at = line.find("\"capture_time\": ");
		if (std::sscanf(line.c_str() + at, "\"capture_time\": %lld, \"capture_clock\": \"pipeline\"",
				&capture) == 1) {
			++pipelineClock;
			EXPECT_LT(std::abs(capture / 1000 - g_get_real_time()), 60 * G_USEC_PER_SEC) << line;
		} else {
			EXPECT_NE(line.find("\"capture_time\": null, \"capture_clock\": null"), std::string::npos)
				<< line;
		}
		gst_sample_unref(sample);
	}
	EXPECT_GT(pipelineClock, 0);
	GstSample *extra = gst_app_sink_try_pull_sample(GST_APP_SINK(sink), GST_SECOND);
	EXPECT_EQ(extra, nullptr);
	if (extra)
		gst_sample_unref(extra);
	EXPECT_TRUE(gst_app_sink_is_eos(GST_APP_SINK(sink)));
	gst_object_unref(sink);
	gst_element_set_state(pipeline, GST_STATE_NULL);
	gst_object_unref(pipeline);
}

/* mode=track: each marker meta says the frame was tracked and whether the
 * marker continued a track (from the second frame of the same markers on),
 * and frappejson writes `tracked` from them; without mode=track there is no
 * `tracked` anywhere. */
TEST(Json, TrackedOnlyInTrackMode)
{
	constexpr int kFrames = 4;
	for (const bool track : { true, false }) {
		GstElement *pipeline =
			runPipeline(std::string("appsrc name=src ! frappedetect") + (track ? " mode=track" : "") +
					    " ! tee name=t t. ! queue ! appsink name=metas sync=false "
					    "max-buffers=100 t. ! queue ! frappejson max-bytes=0 ! "
					    "appsink name=lines sync=false max-buffers=100",
				    kFrames);
		GstElement *metas = gst_bin_get_by_name(GST_BIN(pipeline), "metas");
		GstElement *lines = gst_bin_get_by_name(GST_BIN(pipeline), "lines");
		for (int i = 0; i < kFrames; ++i) {
			GstSample *sample = gst_app_sink_try_pull_sample(GST_APP_SINK(metas), 10 * GST_SECOND);
			ASSERT_NE(sample, nullptr) << "frame " << i;
			int n = 0;
			gpointer state = nullptr;
			GstMeta *meta;
			while ((meta = gst_buffer_iterate_meta_filtered(gst_sample_get_buffer(sample), &state,
									GST_FRAPPE_MARKER_META_API_TYPE))) {
				const auto *m = reinterpret_cast<const GstFrappeMarkerMeta *>(meta);
				EXPECT_EQ(m->tracking, track) << "frame " << i;
				EXPECT_EQ(m->tracked, track && i > 0) << "frame " << i << " id " << m->id;
				++n;
			}
			EXPECT_EQ(n, 2) << "frame " << i;
			gst_sample_unref(sample);

			sample = gst_app_sink_try_pull_sample(GST_APP_SINK(lines), 10 * GST_SECOND);
			ASSERT_NE(sample, nullptr) << "line " << i;
			const std::string line = text(gst_sample_get_buffer(sample));
			const std::string want = track ? (i > 0 ? "\"tracked\": true" : "\"tracked\": false") : "";
			for (const char *id : { "\"id\": 7, ", "\"id\": 42, " }) {
				const std::size_t at = line.find(id);
				ASSERT_NE(at, std::string::npos) << line;
				const std::size_t end = line.find('}', at);
				const std::string marker = line.substr(at, end - at);
				if (track) {
					EXPECT_NE(marker.find(want), std::string::npos) << marker;
				} else {
					EXPECT_EQ(marker.find("tracked"), std::string::npos) << marker;
				}
			}
			gst_sample_unref(sample);
		}
		gst_object_unref(metas);
		gst_object_unref(lines);
		gst_element_set_state(pipeline, GST_STATE_NULL);
		gst_object_unref(pipeline);
	}
}

/* udpsink sends each line as one datagram. */
TEST(Json, UdpsinkSendsOneDatagramPerLine)
{
	UdpReceiver udp;
	constexpr int kFrames = 8;
	GstElement *pipeline = runPipeline(
		"appsrc name=src ! frappedetect ! frappejson ! udpsink host=127.0.0.1 "
		"port=" +
			std::to_string(udp.port) + " sync=false",
		kFrames);
	waitForEos(pipeline);

	const std::vector<std::string> lines = udp.receiveAll();
	ASSERT_EQ(lines.size(), static_cast<std::size_t>(kFrames));
	for (int i = 0; i < kFrames; ++i) {
		const std::string &line = lines[static_cast<std::size_t>(i)];
		const std::string pts = std::to_string(static_cast<GstClockTime>(i) * GST_SECOND / 30);
		EXPECT_EQ(line.rfind("{\"frame\": " + std::to_string(i) +
					     ", \"part\": 1, \"parts\": 1, \"pts\": " + pts + ", ",
				     0),
			  0u)
			<< line;
		EXPECT_EQ(line.find('\n'), line.size() - 1) << line;
		EXPECT_NE(line.find("\"id\": 42"), std::string::npos) << line;
	}
	gst_element_set_state(pipeline, GST_STATE_NULL);
	gst_object_unref(pipeline);
}

namespace {

/* A buffer of `n` posed markers, ids 0 to n-1, whose numbers need every
 * digit (thirds, sevenths) to read back exactly; its PTS 1 s. */
GstBuffer *posedMarkers(int n)
{
	GstBuffer *in = gst_buffer_new_allocate(nullptr, 320 * 240, nullptr);
	GST_BUFFER_PTS(in) = GST_SECOND;
	for (int i = 0; i < n; ++i) {
		gfloat corners[8];
		for (int k = 0; k < 8; ++k)
			corners[k] = static_cast<gfloat>(i) + static_cast<gfloat>(k) / 7.0f;
		GstFrappeMarkerMeta *m = gst_buffer_add_frappe_marker_meta(in, i, "aruco_mip_36h12", corners, 0);
		m->margin = 1.0f / 3.0f;
		m->has_pose = TRUE;
		for (int k = 0; k < 3; ++k) {
			m->rvec[k] = i / 3.0 + k;
			m->tvec[k] = i / 7.0 - k / 9.0;
		}
		m->reprojection_error = i / 11.0;
		m->alternative_reprojection_error = i / 13.0;
	}
	return in;
}

/* What each marker of `in` must read: the library's exact text. */
std::vector<std::string> markerTexts(GstBuffer *in)
{
	std::vector<std::string> out;
	gpointer state = nullptr;
	while (GstMeta *meta = gst_buffer_iterate_meta_filtered(in, &state, GST_FRAPPE_MARKER_META_API_TYPE)) {
		std::string text;
		frappe::appendMarkerJson(
			text, frappe::gst::MetaRecord(*reinterpret_cast<GstFrappeMarkerMeta *>(meta)).record(),
			frappe::JsonNumbers::Exact);
		out.push_back(text);
	}
	return out;
}

/* A part's line taken apart: its header up to "markers", its k and n,
 * and the text inside "markers": [...]. */
struct Part {
	std::string header, markers;
	int part = 0, parts = 0;
};

Part parsePart(const std::string &line)
{
	Part p;
	const std::string open = "\"markers\": [";
	const std::size_t at = line.find(open);
	EXPECT_NE(at, std::string::npos) << line;
	EXPECT_EQ(line.substr(line.size() - 3), "]}\n") << line;
	if (at == std::string::npos || line.size() < at + open.size() + 3)
		return p;
	p.header = line.substr(0, at);
	p.markers = line.substr(at + open.size(), line.size() - 3 - at - open.size());
	EXPECT_EQ(std::sscanf(line.c_str(), "{\"frame\": %*d, \"part\": %d, \"parts\": %d", &p.part, &p.parts), 2)
		<< line;
	return p;
}

/* The parts of one frame, in order, back into its markers' text: every
 * part says "part k of n" with k = 1..n, and the rest of the header is
 * the same in each. */
std::string reassemble(const std::vector<std::string> &lines)
{
	std::string markers, header;
	for (std::size_t k = 0; k < lines.size(); ++k) {
		Part p = parsePart(lines[k]);
		EXPECT_EQ(p.part, static_cast<int>(k + 1));
		EXPECT_EQ(p.parts, static_cast<int>(lines.size()));
		const std::string rest = p.header.substr(p.header.find(", \"pts\""));
		if (k == 0)
			header = rest;
		EXPECT_EQ(rest, header);
		EXPECT_FALSE(p.markers.empty()) << "a part without markers";
		markers += (k ? ", " : "") + p.markers;
	}
	return markers;
}

std::string joined(const std::vector<std::string> &texts)
{
	std::string out;
	for (const std::string &t : texts)
		out += (out.empty() ? "" : ", ") + t;
	return out;
}

} // namespace

/* Issue 31: 300 posed markers in one frame (about 120 kB) through udpsink
 * on loopback: every datagram at most max-bytes (1400 by default), the
 * parts 1..n of frame 0 in order, and every marker's exact text once, in
 * order: all 300 ids and poses to the last digit. */
TEST(Json, ThreeHundredPosedMarkersOverUdp)
{
	UdpReceiver udp;
	GstElement *pipeline = gst_parse_launch(("appsrc name=src format=time ! frappejson ! udpsink host=127.0.0.1 "
						 "sync=false port=" +
						 std::to_string(udp.port))
							.c_str(),
						nullptr);
	ASSERT_NE(pipeline, nullptr);
	GstElement *src = gst_bin_get_by_name(GST_BIN(pipeline), "src");
	GstCaps *caps = gst_caps_from_string(capsString(kSpec).c_str());
	g_object_set(src, "caps", caps, nullptr);
	gst_caps_unref(caps);
	ASSERT_NE(gst_element_set_state(pipeline, GST_STATE_PLAYING), GST_STATE_CHANGE_FAILURE);
	GstBuffer *in = posedMarkers(300);
	const std::vector<std::string> expected = markerTexts(in);
	ASSERT_EQ(expected.size(), 300u);
	EXPECT_EQ(gst_app_src_push_buffer(GST_APP_SRC(src), in), GST_FLOW_OK);
	gst_app_src_end_of_stream(GST_APP_SRC(src));
	gst_object_unref(src);
	waitForEos(pipeline);

	const std::vector<std::string> lines = udp.receiveAll();
	std::size_t longest = 0;
	for (const std::string &line : lines)
		longest = std::max(longest, line.size());
	std::printf("300 posed markers: %zu datagrams, the longest %zu bytes\n", lines.size(), longest);
	EXPECT_GT(lines.size(), 50u) << "300 posed markers need many parts";
	EXPECT_LE(longest, 1400u);
	EXPECT_EQ(reassemble(lines), joined(expected));
	for (const std::string &line : lines)
		EXPECT_EQ(line.rfind("{\"frame\": 0, ", 0), 0u) << line;

	gst_element_set_state(pipeline, GST_STATE_NULL);
	gst_object_unref(pipeline);
}

/* max-bytes 0: one line whatever its length; a max-bytes below one marker's
 * line: each marker alone in its part, and one warning for the stream. */
TEST(Json, MaxBytesZeroOrTooSmall)
{
	GstHarness *h = gst_harness_new_parse("frappejson max-bytes=0");
	gst_harness_set_src_caps_str(h, capsString(kSpec).c_str());
	GstBuffer *in = posedMarkers(300);
	const std::string all = joined(markerTexts(in));
	GstBuffer *out = gst_harness_push_and_pull(h, in);
	EXPECT_EQ(reassemble({ text(out) }), all);
	EXPECT_GT(gst_buffer_get_size(out), 100000u);
	gst_buffer_unref(out);
	EXPECT_EQ(gst_harness_try_pull(h), nullptr);
	gst_harness_teardown(h);

	GstBus *bus = gst_bus_new();
	h = gst_harness_new_parse("frappejson max-bytes=100");
	gst_element_set_bus(h->element, bus);
	gst_harness_set_src_caps_str(h, capsString(kSpec).c_str());
	for (int frame = 0; frame < 2; ++frame) {
		in = posedMarkers(3);
		GST_BUFFER_PTS(in) = frame * GST_SECOND;
		const std::vector<std::string> texts = markerTexts(in);
		ASSERT_EQ(gst_harness_push(h, in), GST_FLOW_OK);
		std::vector<std::string> lines;
		while (GstBuffer *b = gst_harness_try_pull(h)) {
			EXPECT_EQ(GST_BUFFER_PTS(b), frame * GST_SECOND) << "each part has the frame's timestamps";
			lines.push_back(text(b));
			gst_buffer_unref(b);
		}
		ASSERT_EQ(lines.size(), 3u);
		for (std::size_t k = 0; k < 3; ++k)
			EXPECT_EQ(parsePart(lines[k]).markers, texts[k]);
	}
	const BusMessages msgs(bus);
	const auto warnings = msgs.of(GST_MESSAGE_WARNING);
	ASSERT_EQ(warnings.size(), 1u) << "one warning for the stream";
	const MessageError w(warnings[0]);
	EXPECT_NE(w.text.find("max-bytes=100"), std::string::npos) << w.text;
	gst_element_set_bus(h->element, nullptr);
	gst_object_unref(bus);
	gst_harness_teardown(h);
}

/* precision: significant digits of the corners, margin, pose and errors;
 * fields: only those asked for (the id always); frame-id named; an NTP
 * reference time converted to the Unix epoch. */
TEST(Json, PrecisionFieldsAndFrameId)
{
	GstHarness *h = gst_harness_new_parse("frappejson precision=3 fields=corners+tvec frame-id=front_cam");
	gst_harness_set_src_caps_str(h, capsString(kSpec).c_str());
	GstBuffer *in = posedMarkers(2);
	GstCaps *ntp = gst_caps_new_empty_simple("timestamp/x-ntp");
	gst_buffer_add_reference_timestamp_meta(in, ntp, 2208988800u * GST_SECOND + 5, GST_CLOCK_TIME_NONE);
	gst_caps_unref(ntp);
	GstBuffer *out = gst_harness_push_and_pull(h, in);
	const std::string line = text(out);
	EXPECT_NE(line.find("\"frame_id\": \"front_cam\", \"capture_time\": 5, \"capture_clock\": \"reference\""),
		  std::string::npos)
		<< line;
	EXPECT_EQ(parsePart(line).markers,
		  "{\"id\": 0, \"corners\": [[0, 0.143], [0.286, 0.429], [0.571, 0.714], [0.857, 1]], "
		  "\"tvec\": [0, -0.111, -0.222]}, "
		  "{\"id\": 1, \"corners\": [[1, 1.14], [1.29, 1.43], [1.57, 1.71], [1.86, 2]], "
		  "\"tvec\": [0.143, 0.0317, -0.0794]}");
	gst_buffer_unref(out);
	gst_harness_teardown(h);
}

/* Src caps meta/x-klv: each line one KLV packet, Frappe's 16-byte key, the
 * BER length (long form past 127 bytes), the line. */
TEST(Json, KlvPackets)
{
	GstHarness *h = gst_harness_new("frappejson");
	gst_harness_set_sink_caps_str(h, "meta/x-klv, parsed=(boolean)true");
	gst_harness_set_src_caps_str(h, capsString(kSpec).c_str());
	GstBuffer *in = posedMarkers(1);
	GST_BUFFER_OFFSET(in) = 5;
	GstBuffer *out = gst_harness_push_and_pull(h, in);
	const std::string packet = text(out);
	ASSERT_GT(packet.size(), 19u);
	EXPECT_EQ(packet.substr(0, 16), "frappe/markers/1");
	const std::size_t length = packet.size() - 19;
	ASSERT_GT(length, 255u);
	ASSERT_LT(length, 65536u);
	EXPECT_EQ(static_cast<unsigned char>(packet[16]), 0x82);
	EXPECT_EQ(static_cast<unsigned char>(packet[17]) * 256u + static_cast<unsigned char>(packet[18]), length);
	const std::string line = packet.substr(19);
	EXPECT_EQ(line.rfind("{\"frame\": 5, \"part\": 1, \"parts\": 1, ", 0), 0u) << line;
	EXPECT_EQ(line.back(), '\n');
	GstCaps *caps = gst_pad_get_current_caps(h->sinkpad);
	EXPECT_TRUE(gst_structure_has_name(gst_caps_get_structure(caps, 0), "meta/x-klv"));
	gst_caps_unref(caps);
	gst_buffer_unref(out);
	gst_harness_teardown(h);
}
