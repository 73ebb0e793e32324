// SPDX-License-Identifier: MIT
// Binary 8-bit PGM (P5) reading and writing for the tools.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace frappe::vc4::tools {

struct GreyImage {
	unsigned width = 0;
	unsigned height = 0;
	std::vector<uint8_t> pixels;
};

GreyImage readPgm(const std::string &path);
void writePgm(const std::string &path, const GreyImage &image);

} // namespace frappe::vc4::tools
