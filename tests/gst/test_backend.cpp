// SPDX-License-Identifier: MIT
// frappedetect's backend property: backend=vc4-emu runs the QPU kernels on
// the emulator and must give exactly the CPU backend's markers, pipelined or
// not, every buffer out once and in order; pipelined on the QPUs it stages
// the frames on one QPU context for the element's life; backend=vc4 without
// a usable GPU fails with a clear error instead of silently using the CPU.
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

/* Small frames: every pixel goes through the emulated QPUs. */
const FrameSpec kSpec{ GST_VIDEO_FORMAT_NV12, 320, 240, 0 };

std::vector<Placed> markersOf(int i)
{
	std::vector<Placed> m{ square(i + 1, 20.0f + 2.3f * static_cast<float>(i), 30.4f, 90.0f) };
	if (i % 2 == 0)
		m.push_back(tilted(i + 50, 230.0f, 150.0f, 80.0f, 0.3f + 0.05f * static_cast<float>(i)));
	return m;
}

/* Runs n frames through `launch` and returns each output buffer's markers,
 * in output order, checking timestamps on the way. */
std::vector<std::vector<Found>> runFrames(const std::string &launch, int n)
{
	GstHarness *h = gst_harness_new_parse(launch.c_str());
	gst_harness_set_src_caps_str(h, capsString(kSpec).c_str());
	std::vector<GstBuffer *> outs;
	for (int i = 0; i < n; ++i) {
		GstBuffer *in = makeFrame(kSpec, markersOf(i), dict("aruco_mip_36h12"), static_cast<GstClockTime>(i) * kFrame,
					  kFrame);
		EXPECT_EQ(gst_harness_push(h, in), GST_FLOW_OK) << launch << " frame " << i;
		while (GstBuffer *out = gst_harness_try_pull(h))
			outs.push_back(out);
	}
	EXPECT_TRUE(gst_harness_push_event(h, gst_event_new_eos()));
	while (GstBuffer *out = gst_harness_try_pull(h))
		outs.push_back(out);

	std::vector<std::vector<Found>> frames;
	EXPECT_EQ(outs.size(), static_cast<std::size_t>(n)) << launch;
	for (std::size_t i = 0; i < outs.size(); ++i) {
		EXPECT_EQ(GST_BUFFER_PTS(outs[i]), static_cast<GstClockTime>(i) * kFrame) << launch;
		frames.push_back(foundMarkers(outs[i]));
		gst_buffer_unref(outs[i]);
	}
	gst_harness_teardown(h);
	return frames;
}

/* A field of the element's stats, as text ("" when absent). */
std::string statsField(GstHarness *h, const char *field)
{
	GstStructure *st = nullptr;
	g_object_get(detector(h), "stats", &st, nullptr);
	std::string out;
	if (st && gst_structure_has_field(st, field)) {
		gchar *v = gst_value_serialize(gst_structure_get_value(st, field));
		out = v;
		g_free(v);
	}
	if (st)
		gst_structure_free(st);
	return out;
}

void expectSameMarkers(const std::vector<Found> &got, const std::vector<Found> &want, int frame)
{
	ASSERT_EQ(got.size(), want.size()) << "frame " << frame;
	for (std::size_t k = 0; k < want.size(); ++k) {
		EXPECT_EQ(got[k].id, want[k].id) << "frame " << frame;
		for (int c = 0; c < 8; ++c)
			EXPECT_EQ(got[k].corners[static_cast<std::size_t>(c)], want[k].corners[static_cast<std::size_t>(c)])
				<< "frame " << frame << " marker " << want[k].id << " coordinate " << c;
	}
}

} // namespace

TEST(Backend, Vc4EmuGivesTheCpuMarkersExactly)
{
	const int n = 5;
	const auto cpu = runFrames("frappedetect backend=cpu", n);
	for (const char *pipelined : { "false", "true" }) {
		const auto emu = runFrames(std::string("frappedetect backend=vc4-emu pipelined=") + pipelined, n);
		ASSERT_EQ(emu.size(), cpu.size());
		for (int i = 0; i < n; ++i) {
			const auto &a = cpu[static_cast<std::size_t>(i)], &b = emu[static_cast<std::size_t>(i)];
			ASSERT_EQ(a.size(), markersOf(i).size()) << "cpu frame " << i;
			ASSERT_EQ(b.size(), a.size()) << "vc4-emu frame " << i << " pipelined=" << pipelined;
			for (std::size_t k = 0; k < a.size(); ++k) {
				EXPECT_EQ(b[k].id, a[k].id);
				/* The same edge map gives the same candidates, so the
				 * refined corners are identical, not merely close. */
				for (int c = 0; c < 8; ++c)
					EXPECT_EQ(b[k].corners[static_cast<std::size_t>(c)], a[k].corners[static_cast<std::size_t>(c)])
						<< "frame " << i << " marker " << a[k].id << " coordinate " << c;
			}
		}
	}
}

TEST(Backend, Vc4WithoutTheGpuIsAnErrorNotASilentFallback)
{
	GstHarness *h = gst_harness_new_parse("frappedetect backend=vc4");
	gst_harness_set_src_caps_str(h, capsString(kSpec).c_str());
	GstBus *bus = gst_bus_new();
	gst_element_set_bus(h->element, bus);
	const GstFlowReturn ret = gst_harness_push(h, makeFrame(kSpec, markersOf(0), dict("aruco_mip_36h12")));
	if (ret == GST_FLOW_OK) {
		/* A Raspberry Pi whose QPUs are usable. */
		gst_object_unref(bus);
		gst_harness_teardown(h);
		GTEST_SKIP() << "the QPUs are usable on this machine";
	}
	/* Caps negotiation builds the detector, so this is not-negotiated or an error. */
	EXPECT_LT(ret, GST_FLOW_OK);
	GstMessage *msg = gst_bus_pop_filtered(bus, GST_MESSAGE_ERROR);
	ASSERT_NE(msg, nullptr);
	GError *err = nullptr;
	gchar *debug = nullptr;
	gst_message_parse_error(msg, &err, &debug);
	EXPECT_NE(std::string(err->message).find("vc4"), std::string::npos) << err->message;
	EXPECT_NE(debug, nullptr);
	EXPECT_GT(std::string(debug ? debug : "").size(), 20u) << "the probe's reason";
	g_error_free(err);
	g_free(debug);
	gst_message_unref(msg);
	gst_object_unref(bus);
	gst_harness_teardown(h);
}

TEST(Backend, AutoDetectsOnAnyMachine)
{
	const auto frames = runFrames("frappedetect backend=auto", 2);
	ASSERT_EQ(frames.size(), 2u);
	EXPECT_EQ(frames[0].size(), markersOf(0).size());
	EXPECT_EQ(frames[1].size(), markersOf(1).size());
}

/* Pipelined on the QPUs, overlap=auto stages the frames: one detector, one
 * QPU context for the element's life (frames, a DRAIN query, a flush, EOS,
 * and frames again), every buffer out once in order (but the one the flush
 * dropped) with exactly the unpipelined element's markers. */
TEST(Backend, Vc4EmuPipelinedStagesOnOneQpuContext)
{
	const int n = 7;
	/* The unpipelined element's markers: the CPU's, which the unpipelined
	 * vc4-emu element gives exactly (Vc4EmuGivesTheCpuMarkersExactly). */
	const auto plain = runFrames("frappedetect backend=cpu", n);
	GstHarness *h = gst_harness_new_parse("frappedetect backend=vc4-emu pipelined=true");
	gst_harness_set_src_caps_str(h, capsString(kSpec).c_str());
	auto push = [&](int i) {
		GstBuffer *in = makeFrame(kSpec, markersOf(i), dict("aruco_mip_36h12"), static_cast<GstClockTime>(i) * kFrame,
					  kFrame);
		EXPECT_EQ(gst_harness_push(h, in), GST_FLOW_OK) << "frame " << i;
	};
	std::vector<int> order;
	auto pullAll = [&] {
		while (GstBuffer *out = gst_harness_try_pull(h)) {
			const int i = static_cast<int>(GST_BUFFER_PTS(out) / kFrame);
			order.push_back(i);
			expectSameMarkers(foundMarkers(out), plain[static_cast<std::size_t>(i)], i);
			gst_buffer_unref(out);
		}
	};
	for (int i = 0; i < 3; ++i)
		push(i);
	pullAll();
	EXPECT_EQ(order, (std::vector<int>{ 0, 1 })) << "one buffer held";
	EXPECT_EQ(statsField(h, "overlap"), "stages");
	EXPECT_EQ(statsField(h, "qpu-contexts"), "1");

	GstQuery *drain = gst_query_new_drain();
	EXPECT_TRUE(gst_pad_peer_query(h->srcpad, drain));
	gst_query_unref(drain);
	pullAll();
	push(3);
	push(4);
	ASSERT_TRUE(gst_harness_push_event(h, gst_event_new_flush_start()));
	ASSERT_TRUE(gst_harness_push_event(h, gst_event_new_flush_stop(TRUE)));
	GstSegment segment;
	gst_segment_init(&segment, GST_FORMAT_TIME);
	ASSERT_TRUE(gst_harness_push_event(h, gst_event_new_segment(&segment)));
	push(5);
	push(6);
	ASSERT_TRUE(gst_harness_push_event(h, gst_event_new_eos()));
	pullAll();
	/* Frame 4 was held at the flush and dropped. */
	EXPECT_EQ(order, (std::vector<int>{ 0, 1, 2, 3, 5, 6 }));
	EXPECT_EQ(statsField(h, "overlap"), "stages");
	EXPECT_EQ(statsField(h, "qpu-contexts"), "1") << "the element's one QPU context, never re-opened";
	gst_harness_teardown(h);
}

/* What each overlap opens, said by the stats: whole frames on the QPUs take
 * a context per detector; on the CPU (backend=cpu, or auto without QPUs)
 * auto takes whole frames and opens none; not pipelined overlaps nothing. */
TEST(Backend, StatsSayWhichOverlapRanAndTheQpuContextsOpened)
{
	struct Case {
		const char *launch, *overlap, *contexts;
	};
	const Case cases[] = {
		{ "frappedetect backend=vc4-emu pipelined=true overlap=frames", "frames", "2" },
		{ "frappedetect backend=vc4-emu", "none", "1" },
		{ "frappedetect backend=cpu pipelined=true", "frames", "0" },
		{ "frappedetect backend=cpu pipelined=true overlap=stages", "stages", "0" },
#if !defined(__arm__) && !defined(__aarch64__)
		/* No QPUs off a Pi: auto falls back to the CPU, and so to whole frames. */
		{ "frappedetect backend=auto pipelined=true", "frames", "0" },
#endif
	};
	for (const Case &c : cases) {
		GstHarness *h = gst_harness_new_parse(c.launch);
		gst_harness_set_src_caps_str(h, capsString(kSpec).c_str());
		for (int i = 0; i < 2; ++i) /* pipelined, the second push brings the first frame out */
			ASSERT_EQ(gst_harness_push(h, makeFrame(kSpec, markersOf(i), dict("aruco_mip_36h12"),
								static_cast<GstClockTime>(i) * kFrame, kFrame)),
				  GST_FLOW_OK);
		EXPECT_EQ(statsField(h, "overlap"), c.overlap) << c.launch;
		EXPECT_EQ(statsField(h, "qpu-contexts"), c.contexts) << c.launch;
		gst_harness_teardown(h);
	}
}

/* overlap means nothing unpipelined: setting it keeps the pipeline and its
 * context; pipelined=true then rebuilds it (every new pipeline opens its own
 * contexts, which qpu-contexts counts: here two for whole frames). */
TEST(Backend, OverlapUnpipelinedKeepsTheQpuContext)
{
	GstHarness *h = gst_harness_new_parse("frappedetect backend=vc4-emu");
	gst_harness_set_src_caps_str(h, capsString(kSpec).c_str());
	auto push = [&](int i) {
		ASSERT_EQ(gst_harness_push(h, makeFrame(kSpec, markersOf(i), dict("aruco_mip_36h12"),
							static_cast<GstClockTime>(i) * kFrame, kFrame)),
			  GST_FLOW_OK);
	};
	push(0);
	g_object_set(detector(h), "overlap", 1 /* frames */, nullptr);
	push(1);
	EXPECT_EQ(statsField(h, "overlap"), "none");
	EXPECT_EQ(statsField(h, "qpu-contexts"), "1");
	g_object_set(detector(h), "pipelined", TRUE, nullptr);
	push(2);
	push(3);
	EXPECT_EQ(statsField(h, "overlap"), "frames");
	EXPECT_EQ(statsField(h, "qpu-contexts"), "3");
	gst_harness_teardown(h);
}
