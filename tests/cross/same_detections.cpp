// SPDX-License-Identifier: MIT
// The same detections on every CPU: the detector runs on frames of the
// shared data (frames.txt, decoded by frames-to-pgm on the build machine)
// and must give what detections.txt records from an x86-64 build: the same
// markers in the same order, ids and corrected bits equal, corners and
// decision margins within kCornerTolerance / kMarginTolerance. Built for
// ARMv6 and aarch64 in CI, it checks that the Pis' kernels (ARMv6 SIMD32,
// NEON) and 32-bit arithmetic find what x86's do.
//
// The tolerances allow libm's last-bit differences between architectures
// (glibc's x86-64 picks FMA variants of some functions), not different
// decisions.
//
// usage: test-same-detections FRAMES.PGM FRAMES.TXT DETECTIONS.TXT [--update]
//   --update rewrites DETECTIONS.TXT from this build (do that on x86-64, after
//   a change that moves detections on purpose, and say so in the commit).
// Exit 77 (skipped) when FRAMES.PGM is empty: no shared data at build time.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "frappe/frappe.h"

namespace {

constexpr double kCornerTolerance = 1e-3; // pixels
constexpr double kMarginTolerance = 1e-4;

struct Frame {
	std::string path, dictionary;
	int width = 0, height = 0;
	std::vector<std::uint8_t> pixels;
};

struct Expected {
	int id = -1, hamming = 0;
	double margin = 0;
	double corners[8] = {};
};

/* Reads FRAMES.TXT's "path dictionary" lines and the matching PGMs. */
bool readFrames(const char *pgmPath, const char *listPath, std::vector<Frame> &frames, std::string &error)
{
	std::ifstream list(listPath);
	if (!list) {
		error = std::string("cannot read ") + listPath;
		return false;
	}
	std::string line;
	while (std::getline(list, line)) {
		if (line.empty() || line[0] == '#')
			continue;
		Frame f;
		std::istringstream(line) >> f.path >> f.dictionary;
		frames.push_back(std::move(f));
	}
	std::ifstream pgm(pgmPath, std::ios::binary);
	for (Frame &f : frames) {
		std::string magic;
		int maxval = 0;
		pgm >> magic >> f.width >> f.height >> maxval;
		pgm.get(); // the one whitespace byte before the pixels
		if (!pgm || magic != "P5" || maxval != 255 || f.width <= 0 || f.height <= 0 ||
		    f.width > 16384 || f.height > 16384) {
			error = std::string(pgmPath) + ": no valid 8-bit PGM for " + f.path;
			return false;
		}
		f.pixels.resize(static_cast<std::size_t>(f.width) * f.height);
		if (!pgm.read(reinterpret_cast<char *>(f.pixels.data()), static_cast<std::streamsize>(f.pixels.size()))) {
			error = std::string(pgmPath) + ": truncated at " + f.path;
			return false;
		}
	}
	return true;
}

/* DETECTIONS.TXT: per frame a line "frame PATH DICTIONARY N", then N lines
 * "marker ID HAMMING MARGIN x0 y0 x1 y1 x2 y2 x3 y3". */
bool readExpected(const char *path, const std::vector<Frame> &frames,
		  std::vector<std::vector<Expected>> &expected, std::string &error)
{
	std::ifstream in(path);
	if (!in) {
		error = std::string("cannot read ") + path;
		return false;
	}
	for (const Frame &f : frames) {
		std::string tag, framePath, dictionary;
		int n = -1;
		in >> tag >> framePath >> dictionary >> n;
		if (!in || tag != "frame" || framePath != f.path || dictionary != f.dictionary || n < 0) {
			error = std::string(path) + ": expected the frame " + f.path + " " + f.dictionary +
				" next (is it out of date with frames.txt? rewrite it with --update)";
			return false;
		}
		std::vector<Expected> markers(n);
		for (Expected &m : markers) {
			in >> tag >> m.id >> m.hamming >> m.margin;
			for (double &c : m.corners)
				in >> c;
			if (!in || tag != "marker") {
				error = std::string(path) + ": bad marker line in " + f.path;
				return false;
			}
		}
		expected.push_back(std::move(markers));
	}
	return true;
}

} // namespace

int main(int argc, char **argv)
{
	const bool update = argc == 5 && std::strcmp(argv[4], "--update") == 0;
	if (argc != 4 && !update) {
		std::cerr << "usage: test-same-detections FRAMES.PGM FRAMES.TXT DETECTIONS.TXT [--update]\n";
		return 2;
	}
	std::ifstream probe(argv[1], std::ios::binary | std::ios::ate);
	if (!probe || probe.tellg() == 0) {
		std::printf("no frames in %s: the shared data was not there at build time\n", argv[1]);
		return 77;
	}

	std::vector<Frame> frames;
	std::vector<std::vector<Expected>> expected;
	std::string error;
	if (!readFrames(argv[1], argv[2], frames, error) ||
	    (!update && !readExpected(argv[3], frames, expected, error))) {
		std::cerr << "same-detections: " << error << "\n";
		return 1;
	}

	std::FILE *out = update ? std::fopen(argv[3], "w") : nullptr;
	if (update && !out) {
		std::cerr << "same-detections: cannot write " << argv[3] << "\n";
		return 1;
	}
	int failures = 0, markers = 0;
	double worstCorner = 0, worstMargin = 0;
	for (std::size_t i = 0; i < frames.size(); ++i) {
		const Frame &f = frames[i];
		frappe::Config config;
		config.dictionary = f.dictionary;
		frappe::Detector detector(config);
		const frappe::Result &result =
			detector.detect(frappe::ImageView(f.pixels.data(), f.width, f.height));
		const auto &got = result.markers;
		markers += static_cast<int>(got.size());
		if (update) {
			std::fprintf(out, "frame %s %s %zu\n", f.path.c_str(), f.dictionary.c_str(), got.size());
			for (const frappe::Marker &m : got) {
				/* %.9g: a float read back is the same float. */
				std::fprintf(out, "marker %d %d %.9g", m.id, m.hamming, m.margin);
				for (const frappe::Point2f &c : m.corners)
					std::fprintf(out, " %.9g %.9g", c.x, c.y);
				std::fprintf(out, "\n");
			}
			continue;
		}
		const auto &want = expected[i];
		if (got.size() != want.size()) {
			std::printf("FAIL %s (%s): %zu markers, x86-64 found %zu\n", f.path.c_str(),
				    f.dictionary.c_str(), got.size(), want.size());
			++failures;
			continue;
		}
		for (std::size_t k = 0; k < got.size(); ++k) {
			const frappe::Marker &m = got[k];
			const Expected &e = want[k];
			double corner = 0;
			for (int c = 0; c < 4; ++c)
				corner = std::max({ corner, std::abs(m.corners[c].x - e.corners[2 * c]),
						    std::abs(m.corners[c].y - e.corners[2 * c + 1]) });
			const double margin = std::abs(m.margin - e.margin);
			worstCorner = std::max(worstCorner, corner);
			worstMargin = std::max(worstMargin, margin);
			if (m.id != e.id || m.hamming != e.hamming || corner > kCornerTolerance ||
			    margin > kMarginTolerance) {
				std::printf("FAIL %s (%s) marker %zu: id %d hamming %d, x86-64 id %d hamming %d; "
					    "corners off by %.3g px, margin by %.3g\n",
					    f.path.c_str(), f.dictionary.c_str(), k, m.id, m.hamming, e.id, e.hamming,
					    corner, margin);
				++failures;
			}
		}
	}
	if (update) {
		std::fclose(out);
		std::printf("wrote %s: %zu frames, %d markers\n", argv[3], frames.size(), markers);
		return 0;
	}
	std::printf("%zu frames, %d markers (kernels: %s): %d differ from x86-64; largest corner "
		    "difference %.3g px, margin difference %.3g\n",
		    frames.size(), markers, frappe::simdTarget(), failures, worstCorner, worstMargin);
	return failures ? 1 : 0;
}
