// SPDX-License-Identifier: MIT
// The VC4 front end on the emulator against frappe-core's CPU front end, byte for byte.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "frappe/edge_map.h"
#include "frappe/dictionary.h"
#include "frappe/render.h"
#include "frontend/vc4_front_end.hpp"

using namespace frappe;

namespace {

struct Img {
	int width = 0, height = 0, stride = 0;
	std::vector<uint8_t> pixels;
	ImageView view() const { return {pixels.data(), width, height, stride}; }
};

Img scene(int width, int height, unsigned seed, int markers, int padding = 0)
{
	Img s{width, height, width + padding, {}};
	s.pixels.assign(static_cast<size_t>(s.stride) * height, 0);
	std::mt19937 rng(seed);
	for (int y = 0; y < height; ++y)
		for (int x = 0; x < width; ++x)
			s.pixels[static_cast<size_t>(y) * s.stride + x] = static_cast<uint8_t>(
				90 + 60 * std::sin(x * 0.05 + y * 0.031) + std::uniform_int_distribution<int>(0, 30)(rng));
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	std::uniform_real_distribution<float> u(0, 1);
	MutableImageView m{s.pixels.data(), width, height, s.stride};
	for (int k = 0; k < markers; ++k) {
		const float side = 16 + 0.4f * std::min(width, height) * u(rng);
		const auto q = perspectiveSquare(side * 0.7f + (width - 1.4f * side) * u(rng),
		                                 side * 0.7f + (height - 1.4f * side) * u(rng), side, 360 * u(rng), 60 * u(rng));
		renderMarker(m, dict, k % dict.size(), q, {.quiet_cells = 1, .supersample = 2, .black = 25, .white = 225});
	}
	return s;
}

size_t last_edges = 0, last_corners = 0;

FrontEndParams params(int64_t edge = 400, int64_t corner = 2000) { return {edge, corner}; }

void expectSame(const EdgeMap &got, const EdgeMap &want, const std::string &what)
{
	ASSERT_EQ(got.width, want.width) << what;
	ASSERT_EQ(got.height, want.height) << what;
	ASSERT_EQ(got.scale, want.scale) << what;
	size_t bad = 0, first = 0;
	for (size_t i = 0; i < want.pixels.size(); ++i)
		if (got.pixels[i] != want.pixels[i] && bad++ == 0)
			first = i;
	EXPECT_EQ(bad, 0u) << what << ": first at (" << first % want.width << ", " << first / want.width
	                   << ") got " << int(got.pixels[first]) << " want " << int(want.pixels[first]);
	EXPECT_EQ(got.tiles, want.tiles) << what << ": tile mask";
}

void compare(const Img &img, float scale, const FrontEndParams &p, unsigned seed, const std::string &what)
{
	EdgeMap want, got;
	makeCpuFrontEnd(1)->run(img.view(), scale, p, want);
	auto fe = vc4::makeFrontEnd({.emulate = true, .seed = seed, .strict = true});
	ASSERT_STREQ(fe->name(), "vc4-emu");
	fe->run(img.view(), scale, p, got);
	expectSame(got, want, what);
	size_t edges = 0, corners = 0;
	for (uint8_t v : want.pixels) {
		edges += v & EdgeMap::kEdge;
		corners += (v & EdgeMap::kCorner) != 0;
	}
	last_edges = edges;
	last_corners = corners;
}

TEST(Vc4FrontEnd, SmallScene)
{
	const Img img = scene(67, 33, 1, 1);
	compare(img, 1.0f, params(), 0, "67x33");
	EXPECT_GT(last_edges, 50u);
}

TEST(Vc4FrontEnd, TinySizes)
{
	for (int h = 1; h <= 5; ++h)
		for (int w = 1; w <= 7; ++w)
			compare(scene(w, h, w * 10 + h, 0), 1.0f, params(0, 0), 0, std::to_string(w) + "x" + std::to_string(h));
}

TEST(Vc4FrontEnd, SizesAndScales)
{
	struct Case { int w, h, pad; float scale; };
	for (const Case c : {Case{67, 33, 0, 1.0f}, Case{130, 70, 3, 1.0f}, Case{200, 150, 1, 0.5f},
	                     Case{161, 97, 0, 0.7f}, Case{320, 240, 0, 0.33f}, Case{64, 32, 0, 1.0f},
	                     Case{65, 33, 2, 1.0f}}) {
		const Img img = scene(c.w, c.h, c.w + c.h, 2, c.pad);
		const std::string what = std::to_string(c.w) + "x" + std::to_string(c.h) + " scale " + std::to_string(c.scale);
		compare(img, c.scale, params(), 0, what);
		EXPECT_GT(last_edges, 0u) << what;
	}
}

TEST(Vc4FrontEnd, Thresholds)
{
	const Img img = scene(150, 90, 7, 2);
	for (const auto p : {params(0, 0), params(-5, -100), params(100, 500), params(2500, 20000),
	                     params(int64_t{1} << 40, 0), params(400, int64_t{1} << 20)})
		compare(img, 1.0f, p, 0, "thresholds " + std::to_string(p.edge_threshold_sq) + " " + std::to_string(p.corner_threshold));
}

TEST(Vc4FrontEnd, Interleavings)
{
	const Img img = scene(300, 200, 11, 4);
	for (unsigned seed : {0u, 1u, 2u, 3u, 12345u}) {
		compare(img, 1.0f, params(), seed, "seed " + std::to_string(seed));
		if (seed == 0) {
			EXPECT_GT(last_corners, 0u);
		}
	}
}

TEST(Vc4FrontEnd, ReusesBuffersAcrossFrames)
{
	auto fe = vc4::makeFrontEnd({.emulate = true, .seed = 5});
	auto cpu = makeCpuFrontEnd(1);
	EdgeMap got, want;
	for (int frame = 0; frame < 4; ++frame) {
		const Img img = scene(frame == 2 ? 90 : 140, frame == 2 ? 60 : 100, 100 + frame, 2);
		cpu->run(img.view(), 1.0f, params(), want);
		fe->run(img.view(), 1.0f, params(), got);
		expectSame(got, want, "frame " + std::to_string(frame));
	}
}

} // namespace
