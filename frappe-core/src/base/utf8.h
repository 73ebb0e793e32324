// SPDX-License-Identifier: MIT
// UTF-8 checks for the text the library hands on (dictionary names): every
// output of it, JSON, GStreamer structures, Python str, must be valid UTF-8.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace frappe::detail {

/// The length of the valid UTF-8 sequence at the start of `s` (1..4), or 0
/// when it starts with an invalid one (overlong forms, surrogates and code
/// points past U+10FFFF are invalid).
inline std::size_t utf8Sequence(std::string_view s)
{
	const auto at = [&](std::size_t i) { return static_cast<unsigned char>(s[i]); };
	const unsigned c = at(0);
	if (c < 0x80)
		return 1;
	std::size_t n;
	unsigned lo = 0x80, hi = 0xbf; /* the range of the second byte */
	if (c >= 0xc2 && c <= 0xdf) {
		n = 2;
	} else if (c >= 0xe0 && c <= 0xef) {
		n = 3;
		lo = c == 0xe0 ? 0xa0 : 0x80;
		hi = c == 0xed ? 0x9f : 0xbf;
	} else if (c >= 0xf0 && c <= 0xf4) {
		n = 4;
		lo = c == 0xf0 ? 0x90 : 0x80;
		hi = c == 0xf4 ? 0x8f : 0xbf;
	} else {
		return 0;
	}
	if (s.size() < n || at(1) < lo || at(1) > hi)
		return 0;
	for (std::size_t i = 2; i < n; ++i)
		if (at(i) < 0x80 || at(i) > 0xbf)
			return 0;
	return n;
}

/// The offset of the first byte of `s` that is not part of valid UTF-8, or
/// npos when it is all valid.
inline std::size_t invalidUtf8At(std::string_view s)
{
	for (std::size_t i = 0; i < s.size();) {
		const std::size_t n = utf8Sequence(s.substr(i));
		if (n == 0)
			return i;
		i += n;
	}
	return std::string_view::npos;
}

/// `s` as valid UTF-8 of at most `maxBytes` bytes: each byte that is not
/// part of valid UTF-8 read as Latin-1 (the CLI writes such bytes as
/// \u00XX), cut at a character's start.
inline std::string toUtf8(std::string_view s, std::size_t maxBytes)
{
	std::string out;
	for (std::size_t i = 0; i < s.size();) {
		std::size_t n = utf8Sequence(s.substr(i));
		char latin1[2];
		std::string_view piece = s.substr(i, n);
		if (n == 0) {
			const auto c = static_cast<unsigned char>(s[i]);
			latin1[0] = static_cast<char>(0xc0 | c >> 6);
			latin1[1] = static_cast<char>(0x80 | (c & 0x3f));
			piece = std::string_view(latin1, 2);
			n = 1;
		}
		if (out.size() + piece.size() > maxBytes)
			break;
		out.append(piece);
		i += n;
	}
	return out;
}

} // namespace frappe::detail
