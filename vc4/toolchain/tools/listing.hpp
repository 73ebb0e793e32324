// SPDX-License-Identifier: MIT
// Reading QPU code files: vc4asm hex listings ("0xLLLLLLLL, 0xHHHHHHHH," per instruction,
// low word first, optional "//" comment) or raw little-endian binaries.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace frappe::vc4::tools {

class ListingError : public std::runtime_error {
public:
	using std::runtime_error::runtime_error;
};

std::vector<uint64_t> parseHexListing(const std::string &text);
std::vector<uint64_t> parseBinary(const std::string &bytes);
// Hex listing when the content is text with at least one word, raw binary otherwise.
std::vector<uint64_t> parseCode(const std::string &content);
std::vector<uint64_t> readCodeFile(const std::string &path);
std::string hexListing(const std::vector<uint64_t> &code);

} // namespace frappe::vc4::tools
