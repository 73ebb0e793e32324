// SPDX-License-Identifier: MIT
// frappe/marker_record.h: a marker as every output writes it, and the one
// JSON writer of a frame's markers.
//
// forEachMarkerField() is the one list of a marker's output fields, in
// order. The JSON of frappe-detect, frappejson, the sweep tool and the
// example is appendMarkerJson()'s; the element's bus message and ROI
// parameters iterate the list (names in kebab-case there); Python's Marker
// and the tests check their fields against markerFieldNames(). A new
// output field is one line in forEachMarkerField() (and its name in
// markerFieldNames(), which a test holds to the list).
//
// Since: 0.3
#pragma once

#include <array>
#include <span>
#include <string>
#include <string_view>

#include "frappe/export.h"
#include "frappe/marker.h"
#include "frappe/pose.h"

namespace frappe {

/// One marker of a frame with what the outputs add: its dictionary's name
/// and, when known, its pose.
struct MarkerRecord {
	const Marker *marker = nullptr;
	std::string_view dictionary;
	const MarkerPose *pose = nullptr; ///< nullptr: no pose
	/// The output says whether the marker was tracked (Mode::Track's
	/// outputs, the element's message); false: no `tracked` field.
	bool tracking = false;
};

/// A count that outputs typed by kind write unsigned (GStreamer's uint).
struct Count {
	int value = 0;
};

/// Calls f(name, value) for each output field of `r`, in the outputs'
/// order; name is snake_case. `tracked` only when r.tracking, the pose's
/// fields only with a pose.
template<typename F>
void forEachMarkerField(const MarkerRecord &r, F &&f)
{
	const Marker &m = *r.marker;
	f(std::string_view("id"), m.id);
	f(std::string_view("dictionary"), r.dictionary);
	f(std::string_view("corners"), m.corners);
	f(std::string_view("hamming"), Count{ m.hamming });
	f(std::string_view("margin"), m.margin);
	if (r.tracking)
		f(std::string_view("tracked"), m.tracked);
	if (r.pose) {
		f(std::string_view("rvec"), r.pose->pose.rvec);
		f(std::string_view("tvec"), r.pose->pose.tvec);
		f(std::string_view("reprojection_error"), r.pose->pose.error);
		f(std::string_view("alternative_reprojection_error"), r.pose->alternative.error);
	}
}

/// Every field's name forEachMarkerField() gives with tracking and a pose,
/// in order.
FRAPPE_EXPORT std::span<const std::string_view> markerFieldNames();

/// How numbers are written. Exact: the shortest text that reads back the
/// same float or double (frappejson, the example). Rounded: the
/// benchmarks' lines (frappe-detect, the sweep tool), corners and margin
/// to 3 decimals, rvec and tvec to 6, errors to 4. Either writes a value
/// that is not finite as null.
enum class JsonNumbers { Exact, Rounded };

/// How appendMarkerJson() writes a marker: its numbers and which fields
/// (frappejson's precision and fields properties).
struct JsonStyle {
	JsonNumbers numbers = JsonNumbers::Exact;
	/// With Exact: 0 for the shortest exact text, 1-17 for that many
	/// significant digits (printf's %.*g).
	int digits = 0;
	/// Bit i leaves out markerFieldNames()[i]; the id (bit 0) is always
	/// written.
	unsigned omit = 0;
};

/// Appends `r` as one JSON object: {"id": 7, "dictionary": "...",
/// "corners": [[x, y], ...], ...}. Allocates only when `out` grows.
FRAPPE_EXPORT void appendMarkerJson(std::string &out, const MarkerRecord &r, JsonNumbers numbers);
/// The same in a style: rounded or to some digits, some fields left out.
FRAPPE_EXPORT void appendMarkerJson(std::string &out, const MarkerRecord &r, const JsonStyle &style);
/// Appends `s` as a JSON string: valid UTF-8 kept, a byte that is not part
/// of it written \u00XX, quotes, backslashes and control characters escaped.
FRAPPE_EXPORT void appendJsonString(std::string &out, std::string_view s);

} // namespace frappe
