// SPDX-License-Identifier: MIT
// frappedetect: a detection that fails is an element error and a flow
// error, pipelined or not, on the buffer whose detection failed; no buffer
// leaves without its markers.
//
// The failure is injected without a hook in the element: this program
// defines frappe::Detector::detect itself and exports it, so the calls of
// libfrappe-core's Pipeline reach this definition first (ELF
// interposition), which throws from the call numbered failFrom on and
// otherwise calls the library's. The staged overlap runs a frame stage by
// stage, not through detect(): there frappe::scaledLength, which the front
// end stage calls once a frame with the frame's width, is interposed alike
// and throws for the frame numbered failFrame. Where interposition does not
// happen (a static libfrappe-core) the tests skip.
#include <atomic>
#include <climits>
#include <stdexcept>
#include <string>

#include <dlfcn.h>

#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <frappe/detector.h>

#include "helpers.h"

using namespace frappe::gsttest;

static auto *const gstEnv = ::testing::AddGlobalTestEnvironment(new GstEnvironment);

namespace {

/* Calls are numbered from 0; pipelined, frames run on two threads, so the
 * tests name the call that fails, not the moment. */
std::atomic<int> detectCalls{ 0 };
std::atomic<int> failFrom{ INT_MAX };

/* Front-end stages of frames kSpec.width wide, numbered from 0. */
std::atomic<int> widthCalls{ 0 };
std::atomic<int> failFrame{ INT_MAX };

using Detect = const frappe::Result &(*)(frappe::Detector *, const frappe::ImageView &);
using ScaledLength = int (*)(int, float);

ScaledLength libraryScaledLength()
{
	static const auto fn = reinterpret_cast<ScaledLength>(dlsym(RTLD_NEXT, "_ZN6frappe12scaledLengthEif"));
	return fn;
}

Detect libraryDetect()
{
	static const auto fn =
		reinterpret_cast<Detect>(dlsym(RTLD_NEXT, "_ZN6frappe8Detector6detectERKNS_9ImageViewE"));
	return fn;
}

} // namespace

const frappe::Result &frappe::Detector::detect(const ImageView &image)
{
	if (detectCalls++ >= failFrom)
		throw std::runtime_error("injected detection failure");
	return libraryDetect()(this, image);
}

namespace {

const FrameSpec kSpec;

} // namespace

int frappe::scaledLength(int full, float scale)
{
	if (full == kSpec.width && widthCalls++ == failFrame.load())
		throw std::runtime_error("injected detection failure");
	return libraryScaledLength()(full, scale);
}

namespace {

GstBuffer *frame(int i)
{
	return makeFrame(kSpec, { square(i, 100.0f, 80.0f, 150.0f) }, dict("aruco_mip_36h12"),
			 static_cast<GstClockTime>(i) * (GST_SECOND / 30));
}

/* The one ERROR message on the bus says detection failed and why. */
void expectDetectionError(GstBus *bus)
{
	GstMessage *msg = gst_bus_pop_filtered(bus, GST_MESSAGE_ERROR);
	ASSERT_NE(msg, nullptr) << "no element error";
	GError *err = nullptr;
	gchar *debug = nullptr;
	gst_message_parse_error(msg, &err, &debug);
	EXPECT_TRUE(g_error_matches(err, GST_STREAM_ERROR, GST_STREAM_ERROR_FAILED)) << err->message;
	EXPECT_EQ(std::string(err->message), "Marker detection failed");
	EXPECT_NE(std::string(debug ? debug : "").find("injected detection failure"), std::string::npos);
	g_error_free(err);
	g_free(debug);
	gst_message_unref(msg);
	EXPECT_EQ(gst_bus_pop_filtered(bus, GST_MESSAGE_ERROR), nullptr);
}

struct Harness {
	explicit Harness(const char *launch)
		: h(gst_harness_new_parse(launch)), bus(gst_bus_new())
	{
		gst_harness_set_src_caps_str(h, capsString(kSpec).c_str());
		gst_element_set_bus(h->element, bus);
	}
	~Harness()
	{
		failFrom = INT_MAX;
		failFrame = INT_MAX;
		gst_object_unref(bus);
		gst_harness_teardown(h);
	}
	GstHarness *h;
	GstBus *bus;
};

/* How many calls of the staged overlap's front-end stage come here a
 * frame (the CPU front end calls it too), 0 when none. */
int stagesInterposed()
{
	if (!libraryScaledLength())
		return 0;
	Harness t("frappedetect pipelined=true overlap=stages");
	const int before = widthCalls;
	if (gst_harness_push(t.h, frame(0)) != GST_FLOW_OK)
		return 0;
	return widthCalls - before;
}

/* Whether the plugin's detections come here. */
bool interposed()
{
	if (!libraryDetect())
		return false;
	Harness t("frappedetect");
	const int before = detectCalls;
	if (gst_harness_push(t.h, frame(0)) != GST_FLOW_OK)
		return false;
	gst_buffer_unref(gst_harness_pull(t.h));
	return detectCalls > before;
}

} // namespace

TEST(Errors, DetectionFailureIsAnErrorUnpipelined)
{
	if (!interposed())
		GTEST_SKIP() << "frappe::Detector::detect cannot be interposed in this build";
	Harness t("frappedetect");
	failFrom = detectCalls + 1;
	ASSERT_EQ(gst_harness_push(t.h, frame(0)), GST_FLOW_OK);
	EXPECT_EQ(gst_harness_push(t.h, frame(1)), GST_FLOW_ERROR);
	expectDetectionError(t.bus);
	/* Frame 0 came out with its marker; frame 1 did not come out. */
	GstBuffer *out = gst_harness_try_pull(t.h);
	ASSERT_NE(out, nullptr);
	EXPECT_EQ(markerMetas(out).size(), 1u);
	gst_buffer_unref(out);
	EXPECT_EQ(gst_harness_try_pull(t.h), nullptr);
}

TEST(Errors, DetectionFailureIsAnErrorPipelined)
{
	if (!interposed())
		GTEST_SKIP() << "frappe::Detector::detect cannot be interposed in this build";
	Harness t("frappedetect pipelined=true");
	failFrom = detectCalls + 1;
	ASSERT_EQ(gst_harness_push(t.h, frame(0)), GST_FLOW_OK);
	/* Frame 0 comes out now; frame 1's detection fails on one of the
	 * two threads; frame 2 finishes frame 1 and gets the error. */
	ASSERT_EQ(gst_harness_push(t.h, frame(1)), GST_FLOW_OK);
	EXPECT_EQ(gst_harness_push(t.h, frame(2)), GST_FLOW_ERROR);
	expectDetectionError(t.bus);
	GstBuffer *out = gst_harness_try_pull(t.h);
	ASSERT_NE(out, nullptr);
	EXPECT_EQ(GST_BUFFER_PTS(out), 0u);
	EXPECT_EQ(markerMetas(out).size(), 1u);
	gst_buffer_unref(out);
	EXPECT_EQ(gst_harness_try_pull(t.h), nullptr) << "a buffer left without its markers";
}

TEST(Errors, DetectionFailureOfTheHeldBufferAtEosIsAnError)
{
	if (!interposed())
		GTEST_SKIP() << "frappe::Detector::detect cannot be interposed in this build";
	Harness t("frappedetect pipelined=true");
	failFrom = detectCalls.load();
	ASSERT_EQ(gst_harness_push(t.h, frame(0)), GST_FLOW_OK);
	gst_harness_push_event(t.h, gst_event_new_eos());
	expectDetectionError(t.bus);
	EXPECT_EQ(gst_harness_try_pull(t.h), nullptr) << "a buffer left without its markers";
}

/* Staged: frame 2's front end fails while frame 1 is traced; frames 0 and 1
 * come out with their markers, the push that would bring frame 2 out (frame
 * 3's) is the error, and frame 3, whose front end ran, is still held and
 * comes out at EOS: the failure stays on its own buffer. */
TEST(Errors, DetectionFailureStagedFailsItsOwnBuffer)
{
	const int perFrame = stagesInterposed();
	if (perFrame == 0)
		GTEST_SKIP() << "frappe::scaledLength cannot be interposed in this build";
	Harness t("frappedetect pipelined=true overlap=stages");
	failFrame = widthCalls + 2 * perFrame; /* the front-end stage's own call comes first */
	ASSERT_EQ(gst_harness_push(t.h, frame(0)), GST_FLOW_OK);
	ASSERT_EQ(gst_harness_push(t.h, frame(1)), GST_FLOW_OK);
	ASSERT_EQ(gst_harness_push(t.h, frame(2)), GST_FLOW_OK);
	EXPECT_EQ(gst_harness_push(t.h, frame(3)), GST_FLOW_ERROR);
	expectDetectionError(t.bus);
	for (int i : { 0, 1 }) {
		GstBuffer *out = gst_harness_try_pull(t.h);
		ASSERT_NE(out, nullptr);
		EXPECT_EQ(GST_BUFFER_PTS(out), static_cast<GstClockTime>(i) * (GST_SECOND / 30));
		EXPECT_EQ(markerMetas(out).size(), 1u);
		gst_buffer_unref(out);
	}
	EXPECT_EQ(gst_harness_try_pull(t.h), nullptr) << "a buffer left without its markers";
	gst_harness_push_event(t.h, gst_event_new_eos());
	GstBuffer *out = gst_harness_try_pull(t.h);
	ASSERT_NE(out, nullptr) << "frame 3 was lost with frame 2";
	EXPECT_EQ(GST_BUFFER_PTS(out), 3 * (GST_SECOND / 30));
	EXPECT_EQ(markerMetas(out).size(), 1u);
	gst_buffer_unref(out);
	EXPECT_EQ(gst_harness_try_pull(t.h), nullptr);
}
