// SPDX-License-Identifier: MIT
// frappedetect's detector properties against the library's settings table:
// one per entry the element offers, Config{}'s defaults, ranges whose ends
// the library accepts, and the dictionary's spellings; every value the
// element refuses: an error at the next start when set while stopped, a
// warning while playing.
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <gst/gst.h>
#include <gtest/gtest.h>

#include <frappe/config.h>
#include <frappe/detector.h>
#include <frappe/dictionary.h>
#include <frappe/settings.h>

#include "helpers.h"

using namespace frappe::gsttest;

static auto *const gstEnv = ::testing::AddGlobalTestEnvironment(new GstEnvironment);

namespace {

struct Element {
	Element() : e(gst_element_factory_make("frappedetect", nullptr)) {}
	~Element() { gst_object_unref(e); }
	GParamSpec *spec(const char *name) const
	{
		GParamSpec *p = g_object_class_find_property(G_OBJECT_GET_CLASS(e), name);
		EXPECT_NE(p, nullptr) << name;
		return p;
	}
	GstElement *e;
};

bool accepted(const std::function<void(frappe::Config &)> &set)
{
	frappe::Config c;
	set(c);
	try {
		frappe::Detector d(c);
		return true;
	} catch (const std::invalid_argument &) {
		return false;
	}
}

/* The value of a numeric property's GParamSpec end as a double. */
double specEnd(GParamSpec *p, bool maximum)
{
	if (G_IS_PARAM_SPEC_FLOAT(p))
		return maximum ? G_PARAM_SPEC_FLOAT(p)->maximum : G_PARAM_SPEC_FLOAT(p)->minimum;
	if (G_IS_PARAM_SPEC_INT(p))
		return maximum ? G_PARAM_SPEC_INT(p)->maximum : G_PARAM_SPEC_INT(p)->minimum;
	return static_cast<double>(maximum ? G_PARAM_SPEC_INT64(p)->maximum : G_PARAM_SPEC_INT64(p)->minimum);
}

} // namespace

/* Every setting of the table the element offers is a property of the
 * kebab-case name, with Config{}'s default and the table's range; the
 * others are not properties. */
TEST(Settings, DetectorPropertiesAreTheTable)
{
	Element el;
	ASSERT_NE(el.e, nullptr);
	const frappe::Config defaults;
	for (const frappe::Setting &s : frappe::settings()) {
		const std::string name = s.kebabName();
		SCOPED_TRACE(name);
		GParamSpec *p = g_object_class_find_property(G_OBJECT_GET_CLASS(el.e), name.c_str());
		if (!(s.surfaces & frappe::kOnElement)) {
			EXPECT_EQ(p, nullptr);
			continue;
		}
		ASSERT_NE(p, nullptr);
		GValue v = G_VALUE_INIT;
		g_value_init(&v, p->value_type);
		g_object_get_property(G_OBJECT(el.e), name.c_str(), &v);
		if (s.isChoice()) {
			ASSERT_TRUE(G_IS_PARAM_SPEC_STRING(p));
			EXPECT_STREQ(G_PARAM_SPEC_STRING(p)->default_value, s.text(defaults).c_str());
			EXPECT_EQ(g_value_get_string(&v), s.text(defaults));
		} else {
			frappe::Config lo, hi, beyond;
			s.setNumber(lo, specEnd(p, false));
			s.setNumber(hi, specEnd(p, true));
			if (s.name == "max_hamming")
				hi.dictionary = "apriltag_standard52h13"; /* the widest dictionary's most */
			EXPECT_TRUE(accepted([&](frappe::Config &c) { c = lo; })) << specEnd(p, false);
			if (std::isfinite(s.max)) {
				EXPECT_TRUE(accepted([&](frappe::Config &c) { c = hi; })) << specEnd(p, true);
				EXPECT_EQ(specEnd(p, true), s.max);
			}
			/* The closed end is the library's; an open one starts just above. */
			EXPECT_EQ(specEnd(p, false) == s.min, !s.min_open);
			GValue d = G_VALUE_INIT;
			g_value_init(&d, G_TYPE_DOUBLE);
			ASSERT_TRUE(g_value_transform(&v, &d));
			EXPECT_EQ(g_value_get_double(&d), s.number(defaults));
			g_value_unset(&d);
		}
		g_value_unset(&v);
	}
}

/* The dictionary property takes every spelling the library does, prints
 * the library's, and refuses an unknown name with a warning that lists
 * the valid ones, keeping the previous value. */
TEST(Settings, DictionaryTakesEverySpelling)
{
	Element el;
	ASSERT_NE(el.e, nullptr);
	for (const char *spelling : { "tag36h11", "DICT_APRILTAG_36h11", "apriltag-36h11", "apriltag_36h11" }) {
		g_object_set(el.e, "dictionary", "4x4_50", nullptr);
		gst_util_set_object_arg(G_OBJECT(el.e), "dictionary", spelling);
		gchar *value = nullptr;
		g_object_get(el.e, "dictionary", &value, nullptr);
		EXPECT_STREQ(value, "apriltag_36h11") << spelling;
		g_free(value);
	}
	gst_util_set_object_arg(G_OBJECT(el.e), "dictionary", "DICT_6X6_250");
	gst_util_set_object_arg(G_OBJECT(el.e), "mode", "ASCALE");
	gchar *dictionary = nullptr, *mode = nullptr;
	g_object_get(el.e, "dictionary", &dictionary, "mode", &mode, nullptr);
	EXPECT_STREQ(dictionary, "6x6_250");
	EXPECT_STREQ(mode, "ascale");
	g_free(dictionary);
	g_free(mode);

	GstBus *bus = gst_bus_new();
	gst_element_set_bus(el.e, bus);
	g_object_set(el.e, "dictionary", "no-such-family", nullptr);
	GstMessage *msg = gst_bus_pop_filtered(bus, GST_MESSAGE_WARNING);
	ASSERT_NE(msg, nullptr);
	GError *err = nullptr;
	gst_message_parse_warning(msg, &err, nullptr);
	EXPECT_NE(std::string(err->message).find("no-such-family"), std::string::npos) << err->message;
	EXPECT_NE(std::string(err->message).find("aruco_mip_36h12"), std::string::npos) << err->message;
	EXPECT_NE(std::string(err->message).find("apriltag_36h11"), std::string::npos) << err->message;
	g_error_free(err);
	gst_message_unref(msg);
	g_object_get(el.e, "dictionary", &dictionary, nullptr);
	EXPECT_STREQ(dictionary, "6x6_250");
	g_free(dictionary);
	gst_element_set_bus(el.e, nullptr);
	gst_object_unref(bus);
}

namespace {

/* A refused value of a property and one it takes. */
struct Refusable {
	std::string property, bad, good;
};

/* Every property that can refuse a value: each choice of the settings
 * table (a new one is here by itself) and the element's own that parse or
 * read what they are given. Numbers, booleans and enums are checked by
 * GLib and gst-launch themselves (check_refused.py). */
std::vector<Refusable> refusables()
{
	std::vector<Refusable> out;
	const frappe::Config defaults;
	for (const frappe::Setting &s : frappe::settings())
		if ((s.surfaces & frappe::kOnElement) && s.isChoice())
			out.push_back({ s.kebabName(), "no-such-value", s.text(defaults) });
	out.push_back({ "marker-sizes", "7=0.1", "7:0.1" });
	out.push_back({ "camera-matrix", "<500.0, 0.0, 320.0, 0.0, 500.0, 240.0, 0.0, 0.0>",
			"<500.0, 0.0, 320.0, 0.0, 500.0, 240.0, 0.0, 0.0, 1.0>" });
	out.push_back({ "distortion", "<0.1, 0.2, 0.3>", "<0.1, 0.2, 0.0, 0.0>" });
	out.push_back({ "calibration-file", "/no/such/calibration.yaml", "" });
	out.push_back({ "dictionary-file", "/no/such/dictionary.txt", "" });
	return out;
}

} // namespace

/* Issue 31: a value refused while the element is stopped (a gst-launch-1.0
 * line sets properties before the pipeline has a bus) fails the next state
 * change with an element error naming the property, the value and what the
 * property takes; set right, the element starts. */
TEST(Refused, WhileStoppedFailsTheNextStart)
{
	for (const Refusable &r : refusables()) {
		SCOPED_TRACE(r.property + "=" + r.bad);
		GstElement *pipeline = gst_parse_launch(
			"videotestsrc num-buffers=2 ! video/x-raw,format=GRAY8,width=64,height=48 "
			"! frappedetect name=d ! fakesink",
			nullptr);
		ASSERT_NE(pipeline, nullptr);
		GstElement *d = gst_bin_get_by_name(GST_BIN(pipeline), "d");
		gst_util_set_object_arg(G_OBJECT(d), r.property.c_str(), r.bad.c_str());
		EXPECT_EQ(gst_element_set_state(pipeline, GST_STATE_PAUSED), GST_STATE_CHANGE_FAILURE);
		GstBus *bus = gst_element_get_bus(pipeline);
		const BusMessages msgs(bus);
		const auto errors = msgs.of(GST_MESSAGE_ERROR);
		ASSERT_EQ(errors.size(), 1u);
		const MessageError e(errors[0]);
		EXPECT_EQ(e.domain, GST_RESOURCE_ERROR);
		EXPECT_EQ(e.code, GST_RESOURCE_ERROR_SETTINGS);
		const char *blurb =
			g_param_spec_get_blurb(g_object_class_find_property(G_OBJECT_GET_CLASS(d), r.property.c_str()));
		for (const std::string &words : { r.property + "=\"", std::string("refused: "), std::string(blurb) })
			EXPECT_NE(e.text.find(words), std::string::npos) << words << " in " << e.text;
		if (r.bad[0] != '<') {
			EXPECT_NE(e.text.find("=\"" + r.bad + "\""), std::string::npos) << e.text;
		}
		gst_element_set_state(pipeline, GST_STATE_NULL);

		/* Set right: it starts, and plays to the end. */
		gst_util_set_object_arg(G_OBJECT(d), r.property.c_str(), r.good.c_str());
		EXPECT_NE(gst_element_set_state(pipeline, GST_STATE_PLAYING), GST_STATE_CHANGE_FAILURE);
		GstMessage *end = gst_bus_timed_pop_filtered(
			bus, 10 * GST_SECOND, static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
		ASSERT_NE(end, nullptr);
		EXPECT_EQ(GST_MESSAGE_TYPE(end), GST_MESSAGE_EOS);
		gst_message_unref(end);
		gst_element_set_state(pipeline, GST_STATE_NULL);
		gst_object_unref(bus);
		gst_object_unref(d);
		gst_object_unref(pipeline);
	}
}

/* Set while playing, the same values keep today's behaviour: a warning on
 * the bus naming the property, the previous value kept, no error, and the
 * frames go on. */
TEST(Refused, WhilePlayingWarnsAndKeepsThePrevious)
{
	const FrameSpec spec{ GST_VIDEO_FORMAT_GRAY8, 64, 48 };
	for (const Refusable &r : refusables()) {
		SCOPED_TRACE(r.property + "=" + r.bad);
		BusHarness t("frappedetect", spec);
		GstElement *e = detector(t.h);
		GValue before = G_VALUE_INIT;
		GParamSpec *p = g_object_class_find_property(G_OBJECT_GET_CLASS(e), r.property.c_str());
		g_value_init(&before, p->value_type);
		g_object_get_property(G_OBJECT(e), r.property.c_str(), &before);
		gst_util_set_object_arg(G_OBJECT(e), r.property.c_str(), r.bad.c_str());
		expectOneSettingsWarning(t.bus, r.property + "=\"");
		GValue after = G_VALUE_INIT;
		g_value_init(&after, p->value_type);
		g_object_get_property(G_OBJECT(e), r.property.c_str(), &after);
		EXPECT_EQ(gst_value_compare(&before, &after), GST_VALUE_EQUAL);
		g_value_unset(&before);
		g_value_unset(&after);
		EXPECT_EQ(gst_harness_push(t.h, makeFrame(spec, {}, dict("aruco_mip_36h12"), 0)), GST_FLOW_OK);
		GstBuffer *out = gst_harness_try_pull(t.h);
		EXPECT_NE(out, nullptr);
		if (out)
			gst_buffer_unref(out);
		EXPECT_TRUE(BusMessages(t.bus).of(GST_MESSAGE_ERROR).empty());
	}
}
