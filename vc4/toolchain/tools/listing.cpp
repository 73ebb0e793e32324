// SPDX-License-Identifier: MIT
#include "tools/listing.hpp"

#include <cctype>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

namespace frappe::vc4::tools {

std::vector<uint64_t> parseHexListing(const std::string &text)
{
	std::vector<uint32_t> words;
	std::istringstream in(text);
	std::string line;
	int number = 0;
	while (std::getline(in, line)) {
		++number;
		if (auto c = line.find("//"); c != std::string::npos)
			line.resize(c);
		size_t pos = 0;
		while (pos < line.size()) {
			const char ch = line[pos];
			if (std::isspace(static_cast<unsigned char>(ch)) || ch == ',') {
				++pos;
				continue;
			}
			const std::string token = line.substr(pos, line.find_first_of(", \t\r", pos) - pos);
			if (token.size() < 3 || token[0] != '0' || (token[1] != 'x' && token[1] != 'X'))
				throw ListingError("line " + std::to_string(number) + ": expected 0x..., got '" + token + "'");
			char *stop = nullptr;
			const unsigned long long v = std::strtoull(token.c_str() + 2, &stop, 16);
			if (*stop != '\0' || token.size() > 10)
				throw ListingError("line " + std::to_string(number) + ": bad word '" + token + "'");
			words.push_back(static_cast<uint32_t>(v));
			pos += token.size();
		}
	}
	if (words.size() % 2)
		throw ListingError("odd number of 32-bit words");
	std::vector<uint64_t> code;
	for (size_t i = 0; i < words.size(); i += 2)
		code.push_back(uint64_t{words[i]} | uint64_t{words[i + 1]} << 32);
	return code;
}

std::vector<uint64_t> parseBinary(const std::string &bytes)
{
	if (bytes.size() % 8)
		throw ListingError("binary size is not a multiple of 8 bytes");
	std::vector<uint64_t> code(bytes.size() / 8);
	for (size_t i = 0; i < code.size(); ++i) {
		uint64_t v = 0;
		for (int b = 7; b >= 0; --b)
			v = v << 8 | static_cast<uint8_t>(bytes[i * 8 + static_cast<size_t>(b)]);
		code[i] = v;
	}
	return code;
}

std::vector<uint64_t> parseCode(const std::string &content)
{
	bool text = !content.empty();
	for (char c : content) {
		const auto u = static_cast<unsigned char>(c);
		if (!(std::isprint(u) || std::isspace(u))) {
			text = false;
			break;
		}
	}
	if (text && content.find("0x") != std::string::npos)
		return parseHexListing(content);
	return parseBinary(content);
}

std::vector<uint64_t> readCodeFile(const std::string &path)
{
	std::ifstream in(path, std::ios::binary);
	if (!in)
		throw ListingError("cannot open " + path);
	std::ostringstream s;
	s << in.rdbuf();
	return parseCode(s.str());
}

std::string hexListing(const std::vector<uint64_t> &code)
{
	std::string out;
	char buf[40];
	for (uint64_t w : code) {
		std::snprintf(buf, sizeof(buf), "0x%08x, 0x%08x,\n", static_cast<uint32_t>(w),
		              static_cast<uint32_t>(w >> 32));
		out += buf;
	}
	return out;
}

} // namespace frappe::vc4::tools
