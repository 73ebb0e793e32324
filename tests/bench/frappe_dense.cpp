// SPDX-License-Identifier: MIT
// frappe-dense: the cost of a frame full of small squares (issue 16), which
// no marker is in but every square of is a candidate outline: a grid of
// dark squares (a tiled wall, a dot grid, a perforated sheet) and a
// checkerboard, at 1024, 2048 and 4096 pixels a side. The back end's cost
// should grow with the pixels (16x from 1024 to 4096), not with the square
// of the candidates. Prints the best of --repeat runs per frame; asserts
// nothing (speed is reported, never asserted: docs/speed.md).
//
//   frappe-dense [--repeat N] [--sizes 1024,2048,4096] [--threads T]
//                [--square PX] [--pitch PX] [--min-side PX]
//
// --square and --pitch set the grid (and the checkerboard's square),
// --min-side Config::min_marker_side.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "frappe/frappe.h"

namespace {

/* Dark squares of `square` px on a `pitch` px grid, on white. */
std::vector<std::uint8_t> squareGrid(int side, int square, int pitch)
{
	std::vector<std::uint8_t> img(static_cast<std::size_t>(side) * side, 230);
	for (int y = 0; y < side; ++y)
		for (int x = 0; x < side; ++x)
			if (x % pitch >= (pitch - square) / 2 && x % pitch < (pitch + square) / 2 &&
			    y % pitch >= (pitch - square) / 2 && y % pitch < (pitch + square) / 2)
				img[static_cast<std::size_t>(y) * side + x] = 25;
	return img;
}

/* A checkerboard of `square` px squares. */
std::vector<std::uint8_t> checkerboard(int side, int square)
{
	std::vector<std::uint8_t> img(static_cast<std::size_t>(side) * side);
	for (int y = 0; y < side; ++y)
		for (int x = 0; x < side; ++x)
			img[static_cast<std::size_t>(y) * side + x] = ((x / square + y / square) & 1) ? 230 : 25;
	return img;
}

struct Timing {
	double bestMs = 1e30;
	const frappe::Result *last = nullptr;
};

Timing timeDetect(frappe::Detector &det, const std::vector<std::uint8_t> &img, int side, int repeat)
{
	Timing t;
	const frappe::ImageView view(img.data(), side, side, side);
	for (int r = 0; r < repeat; ++r) {
		const auto t0 = std::chrono::steady_clock::now();
		t.last = &det.detect(view);
		const auto t1 = std::chrono::steady_clock::now();
		t.bestMs = std::min(t.bestMs, std::chrono::duration<double, std::milli>(t1 - t0).count());
	}
	return t;
}

} // namespace

int main(int argc, char **argv)
{
	int repeat = 3, threads = 1, square = 12, pitch = 20;
	float minSide = frappe::Config{}.min_marker_side;
	std::vector<int> sizes{ 1024, 2048, 4096 };
	for (int i = 1; i < argc; ++i) {
		const std::string a = argv[i];
		if (a == "--repeat" && i + 1 < argc) {
			repeat = std::max(1, std::atoi(argv[++i]));
		} else if (a == "--threads" && i + 1 < argc) {
			threads = std::atoi(argv[++i]);
		} else if (a == "--square" && i + 1 < argc) {
			square = std::max(1, std::atoi(argv[++i]));
		} else if (a == "--pitch" && i + 1 < argc) {
			pitch = std::max(2, std::atoi(argv[++i]));
		} else if (a == "--min-side" && i + 1 < argc) {
			minSide = static_cast<float>(std::atof(argv[++i]));
		} else if (a == "--sizes" && i + 1 < argc) {
			sizes.clear();
			for (const char *p = argv[++i]; *p;) {
				sizes.push_back(std::atoi(p));
				p = std::strchr(p, ',');
				if (!p)
					break;
				++p;
			}
		} else {
			std::fprintf(stderr, "usage: frappe-dense [--repeat N] [--sizes 1024,2048,4096] [--threads T]\n"
					     "                    [--square PX] [--pitch PX] [--min-side PX]\n");
			return 2;
		}
	}
	frappe::Config config;
	config.threads = threads;
	config.min_marker_side = minSide;
	std::printf("%-22s %6s %10s %8s %10s %10s %8s\n", "frame", "side", "best ms", "x 1024", "trace ms", "candid.",
		    "dropped");
	const std::string gridName = "grid " + std::to_string(square) + "/" + std::to_string(pitch) + " px";
	const std::string boardName = "checkerboard " + std::to_string(square) + " px";
	for (const bool grid : { true, false }) {
		double base = 0.0;
		for (int side : sizes) {
			frappe::Detector det(config);
			const std::vector<std::uint8_t> img = grid ? squareGrid(side, square, pitch) : checkerboard(side, square);
			const Timing t = timeDetect(det, img, side, repeat);
			if (base == 0.0)
				base = t.bestMs;
			std::printf("%-22s %6d %10.1f %8.1f %10.1f %10d %8d\n", (grid ? gridName : boardName).c_str(), side, t.bestMs, t.bestMs / base,
				    t.last->times[frappe::Stage::Trace], t.last->candidates, t.last->candidates_dropped);
			std::fflush(stdout);
		}
	}
	return 0;
}
