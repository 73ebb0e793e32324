// SPDX-License-Identifier: MIT
#include "cli_text.h"

#include <cstdint>
#include <cstdio>

namespace frappe::cli {

namespace {

/* The length of the valid UTF-8 sequence at s[i], or 0 (RFC 3629: no
 * overlong forms, no surrogates, nothing above U+10FFFF). */
std::size_t utf8Length(const std::string &s, std::size_t i)
{
	auto at = [&](std::size_t k) { return static_cast<std::uint8_t>(s[k]); };
	const std::uint8_t b = at(i);
	std::size_t len = 0;
	std::uint8_t lo = 0x80, hi = 0xbf; /* the range of the second byte */
	if (b >= 0xc2 && b <= 0xdf) {
		len = 2;
	} else if (b >= 0xe0 && b <= 0xef) {
		len = 3;
		if (b == 0xe0)
			lo = 0xa0;
		else if (b == 0xed)
			hi = 0x9f;
	} else if (b >= 0xf0 && b <= 0xf4) {
		len = 4;
		if (b == 0xf0)
			lo = 0x90;
		else if (b == 0xf4)
			hi = 0x8f;
	} else {
		return 0;
	}
	if (s.size() - i < len || at(i + 1) < lo || at(i + 1) > hi)
		return 0;
	for (std::size_t k = 2; k < len; ++k)
		if ((at(i + k) & 0xc0) != 0x80)
			return 0;
	return len;
}

} // namespace

std::string jsonEscape(const std::string &s)
{
	std::string out;
	out.reserve(s.size());
	char buf[8];
	for (std::size_t i = 0; i < s.size();) {
		const auto b = static_cast<std::uint8_t>(s[i]);
		if (b < 0x80) {
			switch (b) {
			case '"': out += "\\\""; break;
			case '\\': out += "\\\\"; break;
			case '\n': out += "\\n"; break;
			case '\t': out += "\\t"; break;
			default:
				if (b < 0x20) {
					std::snprintf(buf, sizeof(buf), "\\u%04x", b);
					out += buf;
				} else {
					out += static_cast<char>(b);
				}
			}
			++i;
		} else if (const std::size_t len = utf8Length(s, i)) {
			out.append(s, i, len);
			i += len;
		} else {
			std::snprintf(buf, sizeof(buf), "\\u%04x", b);
			out += buf;
			++i;
		}
	}
	return out;
}

} // namespace frappe::cli
