// SPDX-License-Identifier: MIT
// cli_text.h: the command-line tools' strict number parsing and JSON strings.
#pragma once

#include <charconv>
#include <string>
#include <system_error>

namespace frappe::cli {

/// The whole of `text` as a T (an integer or a float type), within the
/// type's range; false for anything else ("", "12x", " 5", "1e999").
template<typename T>
bool parseNumber(const std::string &text, T &value)
{
	const char *first = text.data(), *last = text.data() + text.size();
	if (first != last && *first == '+') /* from_chars takes no '+' */
		++first;
	T v{};
	const auto [end, ec] = std::from_chars(first, last, v);
	if (ec != std::errc() || end != last || first == last)
		return false;
	value = v;
	return true;
}

/// `s` as the inside of a JSON string. Valid UTF-8 is copied as it is
/// (names print exactly as listed); each byte that is not part of valid
/// UTF-8 becomes the escape \u00XX of its value, so the output is always
/// valid JSON and the byte can be told from the text.
std::string jsonEscape(const std::string &s);

} // namespace frappe::cli
