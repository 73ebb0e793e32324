// SPDX-License-Identifier: MIT
// frames-to-pgm: decodes the same-detections test's frames (frames.txt) from
// the shared data into one file of concatenated binary PGMs, on the build
// machine, so that the test itself needs no image library on the Pi's CPU.
// Without the shared data it writes an empty file, and the test skips.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include <opencv2/imgcodecs.hpp>

int main(int argc, char **argv)
{
	if (argc != 4) {
		std::cerr << "usage: frames-to-pgm SYNTH_DIR FRAMES.TXT OUT.PGM\n";
		return 2;
	}
	const std::filesystem::path synth = argv[1];
	std::ofstream out(argv[3], std::ios::binary | std::ios::trunc);
	if (!out) {
		std::cerr << "frames-to-pgm: cannot write " << argv[3] << "\n";
		return 1;
	}
	if (!std::filesystem::is_directory(synth))
		return 0;

	std::ifstream list(argv[2]);
	std::string line;
	while (std::getline(list, line)) {
		if (line.empty() || line[0] == '#')
			continue;
		std::istringstream fields(line);
		std::string path;
		fields >> path;
		const cv::Mat img = cv::imread((synth / path).string(), cv::IMREAD_GRAYSCALE);
		if (img.empty()) {
			std::cerr << "frames-to-pgm: cannot read " << (synth / path).string() << "\n";
			return 1;
		}
		out << "P5\n" << img.cols << " " << img.rows << "\n255\n";
		for (int y = 0; y < img.rows; ++y)
			out.write(reinterpret_cast<const char *>(img.ptr(y)), img.cols);
	}
	return out ? 0 : 1;
}
