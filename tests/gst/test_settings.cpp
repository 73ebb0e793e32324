// SPDX-License-Identifier: MIT
// frappedetect's detector properties against the library: their defaults
// are frappe::Config{}'s, and the ends of their ranges are values the
// library's validation accepts (and just beyond, where the GParamSpec end is
// the library's, values it refuses).
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include <gst/gst.h>
#include <gtest/gtest.h>

#include <frappe/config.h>
#include <frappe/detector.h>
#include <frappe/dictionary.h>

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

/* A float property: default, both ends accepted, beyond max refused. */
void checkFloat(const Element &el, const char *name, float frappe::Config::*field, bool minIsLibrarys)
{
	SCOPED_TRACE(name);
	auto *p = G_PARAM_SPEC_FLOAT(el.spec(name));
	ASSERT_NE(p, nullptr);
	EXPECT_EQ(p->default_value, frappe::Config{}.*field);
	EXPECT_TRUE(accepted([&](frappe::Config &c) { c.*field = p->minimum; }));
	EXPECT_TRUE(accepted([&](frappe::Config &c) { c.*field = p->maximum; }));
	EXPECT_FALSE(accepted([&](frappe::Config &c) { c.*field = std::nextafter(p->maximum, 1e9f); }));
	if (minIsLibrarys) {
		EXPECT_FALSE(accepted([&](frappe::Config &c) { c.*field = std::nextafter(p->minimum, -1e9f); }));
	}
}

/* An int property: default, both ends accepted, beyond either refused. */
void checkInt(const Element &el, const char *name, int frappe::Config::*field)
{
	SCOPED_TRACE(name);
	auto *p = G_PARAM_SPEC_INT(el.spec(name));
	ASSERT_NE(p, nullptr);
	EXPECT_EQ(p->default_value, frappe::Config{}.*field);
	EXPECT_TRUE(accepted([&](frappe::Config &c) { c.*field = p->minimum; }));
	EXPECT_TRUE(accepted([&](frappe::Config &c) { c.*field = p->maximum; }));
	EXPECT_FALSE(accepted([&](frappe::Config &c) { c.*field = p->minimum - 1; }));
	EXPECT_FALSE(accepted([&](frappe::Config &c) { c.*field = p->maximum + 1; }));
}

} // namespace

TEST(Settings, DetectorPropertiesFollowTheLibrary)
{
	Element el;
	ASSERT_NE(el.e, nullptr);
	/* edge_threshold is (0, 4]: a closed GParamSpec range starts above 0. */
	checkFloat(el, "edge-threshold", &frappe::Config::edge_threshold, false);
	checkFloat(el, "corner-threshold", &frappe::Config::corner_threshold, true);
	checkFloat(el, "region-contrast", &frappe::Config::region_contrast, true);
	checkFloat(el, "light-floor", &frappe::Config::light_floor, true);
	checkFloat(el, "scaled-size", &frappe::Config::scaled_size, true);

	checkInt(el, "max-scaled-frames", &frappe::Config::max_scaled_frames);
	checkInt(el, "track-cover-frames", &frappe::Config::track_cover_frames);

	/* max-hamming: the element clamps to the dictionary; its maximum is
	 * the largest some dictionary accepts. */
	auto *hamming = G_PARAM_SPEC_INT(el.spec("max-hamming"));
	EXPECT_EQ(hamming->default_value, frappe::Config{}.max_hamming);
	EXPECT_TRUE(accepted([&](frappe::Config &c) { c.max_hamming = hamming->minimum; }));
	EXPECT_FALSE(accepted([&](frappe::Config &c) { c.max_hamming = hamming->minimum - 1; }));
	bool someAcceptMax = false;
	for (const auto &d : frappe::dictionaries()) {
		const std::string name(d.name);
		someAcceptMax |= accepted([&](frappe::Config &c) {
			c.dictionary = name;
			c.max_hamming = hamming->maximum;
		});
		EXPECT_FALSE(accepted([&](frappe::Config &c) {
			c.dictionary = name;
			c.max_hamming = hamming->maximum + 1;
		})) << name;
	}
	EXPECT_TRUE(someAcceptMax);

	/* dictionary and mode default to the library's. */
	auto *dictionary = G_PARAM_SPEC_ENUM(el.spec("dictionary"));
	GEnumValue *v = g_enum_get_value(dictionary->enum_class, dictionary->default_value);
	ASSERT_NE(v, nullptr);
	std::string nick(v->value_nick);
	std::replace(nick.begin(), nick.end(), '-', '_');
	EXPECT_EQ(nick, frappe::Config{}.dictionary);
	auto *mode = G_PARAM_SPEC_ENUM(el.spec("mode"));
	v = g_enum_get_value(mode->enum_class, mode->default_value);
	ASSERT_NE(v, nullptr);
	EXPECT_STREQ(v->value_nick, frappe::Config{}.mode == frappe::Mode::AScale ? "ascale" : "normal");
}
