// SPDX-License-Identifier: MIT
// The one JSON writer of a marker (frappe/marker_record.h).
#include "frappe/marker_record.h"

#include <algorithm>
#include <charconv>
#include <iterator>
#include <cmath>
#include <cstdio>
#include <type_traits>

#include "utf8.h"

namespace frappe {

namespace {

constexpr std::string_view kFieldNames[] = { "id",
					     "dictionary",
					     "corners",
					     "hamming",
					     "margin",
					     "tracked",
					     "rvec",
					     "tvec",
					     "reprojection_error",
					     "alternative_reprojection_error" };

/* How a field's floating-point numbers are written: `decimals` >= 0 that
 * many decimals, else `digits` > 0 that many significant digits, else the
 * shortest exact text. */
struct NumberStyle {
	int decimals = -1;
	int digits = 0;
};

template<typename T>
void appendNumber(std::string &out, T v, NumberStyle style)
{
	char text[48];
	if constexpr (std::is_floating_point_v<T>) {
		if (!std::isfinite(v)) {
			out += "null";
			return;
		}
		if (style.decimals >= 0) {
			const int n = std::snprintf(text, sizeof(text), "%.*f", style.decimals, static_cast<double>(v));
			out.append(text, static_cast<std::size_t>(n));
			return;
		}
		if (style.digits > 0) { /* printf's %g, without its locale and parsing */
			const auto r = std::to_chars(text, text + sizeof(text), static_cast<double>(v),
						     std::chars_format::general, style.digits);
			out.append(text, r.ptr);
			return;
		}
	}
	const auto r = std::to_chars(text, text + sizeof(text), v);
	out.append(text, r.ptr);
}

/* The decimals of a field when rounded. */
int roundedDecimals(std::string_view name)
{
	if (name == "rvec" || name == "tvec")
		return 6;
	if (name.ends_with("_error"))
		return 4;
	return 3;
}

} // namespace

std::span<const std::string_view> markerFieldNames()
{
	return kFieldNames;
}

void appendJsonString(std::string &out, std::string_view s)
{
	static const char hex[] = "0123456789abcdef";
	out += '"';
	std::size_t i = 0;
	while (i < s.size()) {
		const unsigned char c = static_cast<unsigned char>(s[i]);
		if (c >= 0x80) {
			const std::size_t n = detail::utf8Sequence(s.substr(i));
			if (n > 0) {
				out.append(s.data() + i, n);
				i += n;
				continue;
			}
		}
		if (c == '"' || c == '\\') {
			out += '\\';
			out += static_cast<char>(c);
		} else if (c < 0x20 || c >= 0x80) {
			out += "\\u00";
			out += hex[c >> 4];
			out += hex[c & 15];
		} else {
			out += static_cast<char>(c);
		}
		++i;
	}
	out += '"';
}

void appendMarkerJson(std::string &out, const MarkerRecord &r, JsonNumbers numbers)
{
	appendMarkerJson(out, r, JsonStyle{ numbers, 0, 0 });
}

void appendMarkerJson(std::string &out, const MarkerRecord &r, const JsonStyle &jsonStyle)
{
	bool first = true;
	out += '{';
	forEachMarkerField(r, [&](std::string_view name, const auto &value) {
		using T = std::remove_cvref_t<decltype(value)>;
		const std::size_t index = static_cast<std::size_t>(
			std::find(std::begin(kFieldNames), std::end(kFieldNames), name) - std::begin(kFieldNames));
		if (index > 0 && index < 32 && (jsonStyle.omit >> index & 1u))
			return;
		NumberStyle style;
		if (jsonStyle.numbers == JsonNumbers::Rounded)
			style.decimals = roundedDecimals(name);
		else
			style.digits = jsonStyle.digits;
		out += first ? "\"" : ", \"";
		first = false;
		out += name;
		out += "\": ";
		if constexpr (std::is_same_v<T, std::string_view>) {
			appendJsonString(out, value);
		} else if constexpr (std::is_same_v<T, bool>) {
			out += value ? "true" : "false";
		} else if constexpr (std::is_same_v<T, Count>) {
			appendNumber(out, value.value, NumberStyle{});
		} else if constexpr (std::is_same_v<T, std::array<Point2f, 4>>) {
			out += '[';
			for (std::size_t k = 0; k < value.size(); ++k) {
				out += k ? ", [" : "[";
				appendNumber(out, value[k].x, style);
				out += ", ";
				appendNumber(out, value[k].y, style);
				out += ']';
			}
			out += ']';
		} else if constexpr (std::is_same_v<T, std::array<double, 3>>) {
			out += '[';
			for (std::size_t k = 0; k < value.size(); ++k) {
				if (k)
					out += ", ";
				appendNumber(out, value[k], style);
			}
			out += ']';
		} else {
			appendNumber(out, value, std::is_floating_point_v<T> ? style : NumberStyle{});
		}
	});
	out += '}';
}

} // namespace frappe
