// SPDX-License-Identifier: MIT
// The settings table (frappe/settings.h) against Config and the Detector:
// every default in range and accepted, both ends of every range accepted
// and just beyond refused, text that reads back, names that find.
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "frappe/detector.h"
#include "frappe/settings.h"

using frappe::Config;
using frappe::Setting;

namespace {

bool accepted(const Config &c)
{
	try {
		frappe::validate(c);
		frappe::Detector d(c);
		return true;
	} catch (const std::invalid_argument &) {
		return false;
	}
}

/* The next value beyond a bound, in the member's type. */
double beyond(const Setting &s, double bound, double away)
{
	if (s.isInteger())
		return bound + (away > bound ? 1.0 : -1.0);
	return std::nextafter(static_cast<float>(bound), static_cast<float>(away));
}

} // namespace

TEST(Settings, DefaultsAreConfigsAndInRange)
{
	const Config defaults;
	EXPECT_TRUE(accepted(defaults));
	for (const Setting &s : frappe::settings()) {
		SCOPED_TRACE(std::string(s.name));
		if (!s.isChoice()) {
			EXPECT_TRUE(s.inRange(s.number(defaults)));
		}
		/* The text reads back to the same value. */
		Config c;
		c.threads = 3; /* something else changed, to see only this one is set */
		s.parse(c, s.text(defaults));
		EXPECT_TRUE(s.same(c, defaults));
	}
}

TEST(Settings, RangesAreTheValidations)
{
	for (const Setting &s : frappe::settings()) {
		if (s.isChoice())
			continue;
		SCOPED_TRACE(std::string(s.name));
		Config c;
		const bool dictionaryBound = s.name == "max_hamming"; /* the widest over the dictionaries */
		if (dictionaryBound)
			c.dictionary = "apriltag_standard52h13";
		if (!s.min_open) {
			s.setNumber(c, s.min);
			EXPECT_TRUE(accepted(c)) << s.text(c);
		}
		s.setNumber(c, beyond(s, s.min, s.min_open ? s.max : -1e30));
		EXPECT_EQ(accepted(c), s.min_open) << s.text(c);
		if (std::isfinite(s.max)) {
			/* threads at 256 and max_pixels at 2^30 would be costly to build. */
			if (s.name != "threads") {
				s.setNumber(c, s.max);
				EXPECT_TRUE(accepted(c)) << s.text(c);
			}
			s.setNumber(c, beyond(s, s.max, 1e30));
			EXPECT_FALSE(accepted(c)) << s.text(c);
		}
		s.setNumber(c, std::numeric_limits<double>::quiet_NaN());
		EXPECT_FALSE(accepted(c)) << "NaN";
	}
}

TEST(Settings, RefusalsNameTheSettingAndTheRange)
{
	Config c;
	c.edge_threshold = 0.0f;
	try {
		frappe::validate(c);
		FAIL();
	} catch (const std::invalid_argument &e) {
		EXPECT_STREQ(e.what(), "frappe::Config: edge_threshold must be in (0, 4], got 0");
	}
	c = Config{};
	c.max_pixels = 0;
	try {
		frappe::validate(c);
		FAIL();
	} catch (const std::invalid_argument &e) {
		EXPECT_STREQ(e.what(), "frappe::Config: max_pixels must be in [1, 2^30], got 0");
	}
}

TEST(Settings, NamesFindAndAreUnique)
{
	std::set<std::string> names;
	for (const Setting &s : frappe::settings()) {
		EXPECT_TRUE(names.insert(std::string(s.name)).second) << s.name;
		EXPECT_EQ(frappe::findSetting(s.name), &s);
		EXPECT_EQ(frappe::findSetting(s.kebabName()), &s);
		EXPECT_FALSE(s.doc.empty());
		EXPECT_FALSE(s.metavar.empty());
	}
	EXPECT_EQ(frappe::findSetting("no_such_setting"), nullptr);
}

TEST(Settings, ChoicesTakeEverySpellingAndStoreTheLibrarys)
{
	const Setting *dictionary = frappe::findSetting("dictionary");
	ASSERT_NE(dictionary, nullptr);
	Config c;
	for (const char *spelling : { "apriltag_36h11", "apriltag-36h11", "tag36h11", "DICT_APRILTAG_36h11" }) {
		c.dictionary.clear();
		dictionary->parse(c, spelling);
		EXPECT_EQ(c.dictionary, "apriltag_36h11") << spelling;
	}
	for (const char *spelling : { "6x6_250", "6x6-250", "DICT_6X6_250", "opencv_6x6_250" }) {
		dictionary->parse(c, spelling);
		EXPECT_EQ(c.dictionary, "6x6_250") << spelling;
	}
	try {
		dictionary->parse(c, "nope");
		FAIL();
	} catch (const std::invalid_argument &e) {
		EXPECT_NE(std::string(e.what()).find("aruco_mip_36h12"), std::string::npos) << e.what();
	}
	const Setting *mode = frappe::findSetting("mode");
	mode->parse(c, "ASCALE");
	EXPECT_EQ(c.mode, frappe::Mode::AScale);
	EXPECT_EQ(mode->text(c), "ascale");
	EXPECT_THROW(mode->parse(c, "fast"), std::invalid_argument);
	const Setting *edge = frappe::findSetting("edge-threshold");
	EXPECT_THROW(edge->parse(c, "high"), std::invalid_argument);
	EXPECT_THROW(edge->parse(c, "0.3x"), std::invalid_argument);
	EXPECT_THROW(frappe::findSetting("max_hamming")->parse(c, "1.5"), std::invalid_argument);
}
