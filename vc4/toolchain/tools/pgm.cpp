// SPDX-License-Identifier: MIT
#include "tools/pgm.hpp"

#include <cctype>
#include <fstream>
#include <stdexcept>

namespace frappe::vc4::tools {

namespace {
// Next header token, skipping whitespace and '#' comments.
std::string token(std::istream &in)
{
	std::string t;
	int c;
	while ((c = in.get()) != EOF) {
		if (c == '#') {
			while ((c = in.get()) != EOF && c != '\n') {
			}
			continue;
		}
		if (std::isspace(c)) {
			if (!t.empty())
				break;
			continue;
		}
		t += static_cast<char>(c);
	}
	return t;
}
} // namespace

GreyImage readPgm(const std::string &path)
{
	std::ifstream in(path, std::ios::binary);
	if (!in)
		throw std::runtime_error("cannot open " + path);
	if (token(in) != "P5")
		throw std::runtime_error(path + ": not a binary PGM (P5)");
	GreyImage img;
	img.width = static_cast<unsigned>(std::stoul(token(in)));
	img.height = static_cast<unsigned>(std::stoul(token(in)));
	if (std::stoul(token(in)) > 255)
		throw std::runtime_error(path + ": only 8-bit PGM is supported");
	img.pixels.resize(size_t{img.width} * img.height);
	in.read(reinterpret_cast<char *>(img.pixels.data()), static_cast<std::streamsize>(img.pixels.size()));
	if (!in)
		throw std::runtime_error(path + ": truncated pixel data");
	return img;
}

void writePgm(const std::string &path, const GreyImage &img)
{
	std::ofstream out(path, std::ios::binary);
	if (!out)
		throw std::runtime_error("cannot write " + path);
	out << "P5\n" << img.width << ' ' << img.height << "\n255\n";
	out.write(reinterpret_cast<const char *>(img.pixels.data()), static_cast<std::streamsize>(img.pixels.size()));
}

} // namespace frappe::vc4::tools
