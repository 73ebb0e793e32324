// SPDX-License-Identifier: MIT
// frappe/settings.h: Config's fields described once, for every surface.
//
// The table (settings()) says of each field its name, type, range, a line
// of text and where it is offered; its default is Config{}'s. The
// library's validation, the element's properties, the CLI's options and
// --help, Python's keywords, the .pyi stubs and the docs' tables iterate
// it, so a new field is its member in config.h plus one entry in
// settings.cpp (a static_assert there counts Config's members).
//
// Since: 0.3
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "frappe/config.h"
#include "frappe/export.h"

namespace frappe {

/// Where a setting is offered beyond C++, which has every field.
enum Surface : unsigned {
	kOnElement = 1u, ///< a frappedetect property, kebab-case
	kOnCli = 2u,     ///< a frappe-detect option --kebab-case
	kOnPython = 4u,  ///< a keyword of frappe.Detector, snake_case
	kEverywhere = kOnElement | kOnCli | kOnPython,
};

/// One field of Config as the surfaces show it.
struct FRAPPE_EXPORT Setting {
	/// The member: its type says the setting's (a number; Mode and the
	/// dictionary's name are choices among names).
	using Member = std::variant<std::string Config::*, Mode Config::*, float Config::*, int Config::*,
				    long long Config::*>;

	std::string_view name; ///< Config's member and Python's keyword, snake_case
	Member member;
	/// The values accepted: [min, max], (min, max] when min_open; max may
	/// be infinite. Unused for choices.
	double min = 0.0, max = 0.0;
	bool min_open = false;
	std::string_view metavar; ///< what --help shows for the value ("E", "NAME")
	std::string_view doc;     ///< one line
	unsigned surfaces = kEverywhere;

	/// The element's and the CLI's name: name with dashes.
	std::string kebabName() const;
	bool isChoice() const;
	bool isInteger() const;
	/// A number's value in `c` (not for choices).
	double number(const Config &c) const;
	/// Sets a number (not for choices): rounded toward zero for integers,
	/// not checked (validate() does).
	void setNumber(Config &c, double v) const;
	/// The value in `c` as text: "0.27" (the shortest that reads back),
	/// "ascale", "aruco_mip_36h12".
	std::string text(const Config &c) const;
	/// Sets the value from text: a number, a mode's name, a dictionary's
	/// name in any spelling findDictionary() accepts (stored as the
	/// library's). Throws std::invalid_argument naming the setting and
	/// the valid values.
	void parse(Config &c, std::string_view text) const;
	/// The names a choice takes: modeNames() or the dictionaries'.
	std::vector<std::string> choices() const;
	/// The range as text, "(0, 4]", "[1, 2^20]", "at least 4"; for a
	/// choice its names joined by ", ".
	std::string rangeText() const;
	/// Whether a number lies in the range (false for NaN).
	bool inRange(double v) const;
	/// Whether two configurations agree on this setting.
	bool same(const Config &a, const Config &b) const;
};

/// Every setting, in Config's order (custom_dictionary, which no text
/// surface can hold, is the only field not listed).
FRAPPE_EXPORT std::span<const Setting> settings();
/// A setting by its snake_case or kebab-case name; nullptr when unknown.
FRAPPE_EXPORT const Setting *findSetting(std::string_view name);

/// A mode's name ("normal", "ascale") and back (case-insensitive;
/// false when unknown).
FRAPPE_EXPORT std::string_view modeName(Mode mode);
FRAPPE_EXPORT bool parseMode(std::string_view name, Mode &mode);
/// "normal, ascale".
FRAPPE_EXPORT std::string modeNames(std::string_view separator = ", ");

/// Throws std::invalid_argument ("frappe::Config: ...") when a field of
/// `c` is out of its range or the dictionary is unknown or malformed: what
/// the Detector's constructor checks.
FRAPPE_EXPORT void validate(const Config &c);

} // namespace frappe
