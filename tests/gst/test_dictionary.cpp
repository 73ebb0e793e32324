// SPDX-License-Identifier: MIT
// frappedetect's dictionaries: the dictionary property by the library's
// name and by its dashed nick, and dictionary-file (a dictionary of one's
// own, named in the metas; a bad file refused at start or while playing).
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <string>

#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <frappe/dictionary.h>

#include "gstfrappemeta.h"
#include "helpers.h"

using namespace frappe::gsttest;

static auto *const gstEnv = ::testing::AddGlobalTestEnvironment(new GstEnvironment);

namespace {

/* The dictionary property's value name of an element made by
 * gst_parse_launch from `launch`. */
std::string parsedDictionary(const std::string &launch)
{
	GError *error = nullptr;
	GstElement *e = gst_parse_launch(launch.c_str(), &error);
	EXPECT_EQ(error, nullptr) << (error ? error->message : "");
	if (!e)
		return "";
	gchar *value = nullptr;
	g_object_get(e, "dictionary", &value, nullptr);
	gst_object_unref(e);
	std::string name = value ? value : "";
	g_free(value);
	return name;
}

/* The first `count` codes of a built-in dictionary in frappe's text
 * format, under a name of our own. */
std::string dictionaryText(const frappe::Dictionary &d, int count, const char *name)
{
	std::string text = std::string("# dictionary: ") + name + "\n# marker_side_bits: " +
			   std::to_string(d.bits) + "\n";
	for (int i = 0; i < count; ++i) {
		char line[32];
		std::snprintf(line, sizeof(line), "0x%llx\n",
			      static_cast<unsigned long long>(d.codes[static_cast<std::size_t>(i)]));
		text += line;
	}
	return text;
}

} // namespace

/* Every spelling parses to the library's name, for every built-in
 * dictionary, and detection then uses it. */
TEST(Dictionary, ByLibraryNameAndByNick)
{
	for (const auto &d : frappe::dictionaries()) {
		const std::string name(d.name);
		std::string nick = name;
		std::replace(nick.begin(), nick.end(), '_', '-');
		EXPECT_EQ(parsedDictionary("frappedetect dictionary=" + name), name);
		EXPECT_EQ(parsedDictionary("frappedetect dictionary=" + nick), name);
		/* OpenCV's spelling, and AprilTag's for its families: the CLI's and Python's. */
		std::string opencv = "DICT_" + name;
		std::transform(opencv.begin(), opencv.end(), opencv.begin(),
			       [](unsigned char c) { return std::toupper(c); });
		EXPECT_EQ(parsedDictionary("frappedetect dictionary=" + opencv), name);
		if (name.starts_with("apriltag_")) {
			EXPECT_EQ(parsedDictionary("frappedetect dictionary=tag" + name.substr(9)), name);
		}
	}

	const FrameSpec spec{ GST_VIDEO_FORMAT_GRAY8, 320, 240 };
	const Placed marker = square(11, 80.4f, 50.2f, 120.0f);
	for (const char *launch :
	     { "frappedetect dictionary=apriltag_36h11", "frappedetect dictionary=apriltag-36h11" }) {
		SCOPED_TRACE(launch);
		BusHarness t(launch, spec);
		GstBuffer *out = gst_harness_push_and_pull(t.h, makeFrame(spec, { marker }, dict("apriltag_36h11")));
		expectMarkers(out, { marker }, "apriltag_36h11");
		gst_buffer_unref(out);
	}
}

/* A dictionary of one's own: its markers are found and named after it. */
TEST(DictionaryFile, FindsAndNamesItsMarkers)
{
	TempDir dir;
	const std::string file = dir.write("mine.txt", dictionaryText(dict("aruco_mip_36h12"), 10, "mine"));
	const FrameSpec spec{ GST_VIDEO_FORMAT_I420, 320, 240 };
	const Placed marker = square(3, 90.3f, 40.7f, 130.0f);
	/* The built-in dictionary's id 3 is the same pattern. */
	GstBuffer *frame = makeFrame(spec, { marker }, dict("aruco_mip_36h12"));

	BusHarness t(("frappedetect dictionary=apriltag_36h11 dictionary-file=\"" + file + "\"").c_str(), spec);
	GstBuffer *out = gst_harness_push_and_pull(t.h, frame);
	expectMarkers(out, { marker }, "mine");
	gst_buffer_unref(out);
	const BusMessages msgs(t.bus);
	EXPECT_TRUE(msgs.of(GST_MESSAGE_WARNING).empty());
	EXPECT_TRUE(msgs.of(GST_MESSAGE_ERROR).empty());
}

/* A bad file: an error at start with the library's message; set while
 * playing, a warning and the previous dictionary stays. */
TEST(DictionaryFile, BadFileRefused)
{
	TempDir dir;
	const std::string bad = dir.write("bad.txt", "# marker_side_bits: 6\n0x12345\nnot a code\n");
	{
		const MessageError e = startError("videotestsrc num-buffers=1 ! video/x-raw,format=GRAY8 ! "
						  "frappedetect name=d dictionary-file=\"" + bad + "\" ! fakesink");
		EXPECT_EQ(e.code, GST_RESOURCE_ERROR_SETTINGS);
		EXPECT_NE(e.text.find(bad), std::string::npos) << e.text;
		/* The library's message names the line. */
		std::string library;
		try {
			frappe::loadDictionary(bad);
		} catch (const std::exception &ex) {
			library = ex.what();
		}
		EXPECT_FALSE(library.empty());
		EXPECT_NE(e.text.find(library), std::string::npos) << e.text;
	}

	const std::string good = dir.write("mine.txt", dictionaryText(dict("aruco_mip_36h12"), 10, "mine"));
	const FrameSpec spec{ GST_VIDEO_FORMAT_GRAY8, 320, 240 };
	BusHarness t(("frappedetect dictionary-file=\"" + good + "\"").c_str(), spec);
	const Placed marker = square(3, 90.3f, 40.7f, 130.0f);
	GstBuffer *out = gst_harness_push_and_pull(t.h, makeFrame(spec, { marker }, dict("aruco_mip_36h12"), 0));
	expectMarkers(out, { marker }, "mine");
	gst_buffer_unref(out);
	g_object_set(detector(t.h), "dictionary-file", bad.c_str(), nullptr);
	out = gst_harness_push_and_pull(t.h, makeFrame(spec, { marker }, dict("aruco_mip_36h12"), GST_SECOND));
	expectMarkers(out, { marker }, "mine");
	gst_buffer_unref(out);
	gchar *path = nullptr;
	g_object_get(detector(t.h), "dictionary-file", &path, nullptr);
	EXPECT_STREQ(path, good.c_str());
	g_free(path);
	expectOneSettingsWarning(t.bus, bad);
}
