// SPDX-License-Identifier: MIT
// The QPU candidate warper behind frappe::CandidateWarper: on the emulator its samples
// are the CPU warper's bit for bit (frappe/fixed_warp.h on both) for every code size the
// kernel takes; it batches 32 candidates a launch, sends what it cannot take (quads the
// fixed point refuses, codes wider than 16 samples) to the CPU, and a Detector using it
// finds the CPU's markers (warper_detector_test.cpp compares whole detections).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "frappe/frappe.h"
#include "frappe/render.h"
#include "frontend/vc4_front_end.hpp"
#include "frontend/vc4_warper.hpp"

using namespace frappe;

namespace {

struct Scene {
	int width = 320, height = 240;
	std::vector<std::uint8_t> pixels;
	std::vector<std::array<Point2f, 4>> quads;
	ImageView view() const { return { pixels.data(), width, height, width }; }
};

Scene scene(unsigned seed, int markers)
{
	Scene s;
	s.pixels.assign(static_cast<std::size_t>(s.width) * s.height, 120);
	std::mt19937 rng(seed);
	std::uniform_real_distribution<float> u(0, 1);
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	MutableImageView m{ s.pixels.data(), s.width, s.height, s.width };
	for (int k = 0; k < markers; ++k) {
		const float side = 30 + 40 * u(rng);
		const auto q = perspectiveSquare(side + (s.width - 2 * side) * u(rng), side + (s.height - 2 * side) * u(rng),
						 side, 360 * u(rng), 50 * u(rng));
		renderMarker(m, dict, k, q);
		s.quads.push_back(q);
	}
	return s;
}

} // namespace

TEST(Vc4Warper, SamplesAreTheCpuWarpsBitForBit)
{
	Scene s = scene(5, 40); /* 40 candidates: two launches */
	/* Quads over the image border, and one too large for the fixed point. */
	s.quads.push_back({ Point2f{ -20, -15 }, { 40, -10 }, { 45, 40 }, { -25, 35 } });
	s.quads.push_back({ Point2f{ 280, 200 }, { 350, 198 }, { 348, 260 }, { 282, 265 } });
	s.quads.push_back({ Point2f{ -1500, -1500 }, { 1800, -1400 }, { 1700, 1600 }, { -1400, 1500 } });
	auto qpu = vc4::makeWarper({ .emulate = true, .seed = 3 });
	auto cpu = makeCpuWarper();
	const std::size_t n = s.quads.size();
	for (int side : { 8, 12, 14, 16 }) { /* 2x2 .. 6x6 codes */
		std::vector<CandidateSamples> a(n), b(n);
		std::vector<std::uint8_t> okA(n), okB(n);
		cpu->warp(s.view(), s.quads, side, a, okA);
		qpu->warp(s.view(), s.quads, side, b, okB);
		vc4::WarpCounts counts;
		ASSERT_TRUE(vc4::lastWarpCounts(*qpu, counts));
		EXPECT_EQ(counts.on_qpus + counts.on_cpu, n);
		EXPECT_EQ(counts.on_cpu, 1u) << "the quad too large for the fixed point";
		EXPECT_EQ(counts.launches, (counts.on_qpus + 31) / 32);
		for (std::size_t k = 0; k < n; ++k) {
			ASSERT_TRUE(okA[k] && okB[k]) << k;
			ASSERT_EQ(b[k].side, side);
			const auto bytes = static_cast<std::size_t>(side * side) * sizeof(float);
			EXPECT_EQ(std::memcmp(a[k].samples.data(), b[k].samples.data(), bytes), 0)
				<< "side " << side << ", candidate " << k;
		}
	}
}

TEST(Vc4Warper, WideCodesAndDegenerateQuadsGoToTheCpu)
{
	const Scene s = scene(6, 3);
	auto qpu = vc4::makeWarper({ .emulate = true });
	std::vector<std::array<Point2f, 4>> quads = s.quads;
	quads.push_back({ Point2f{ 10, 10 }, { 10, 10 }, { 10, 10 }, { 10, 10 } }); /* degenerate */
	std::vector<CandidateSamples> out(quads.size());
	std::vector<std::uint8_t> ok(quads.size(), 7);
	qpu->warp(s.view(), quads, 18, out, ok); /* 7x7 codes: 18 samples a side */
	vc4::WarpCounts counts;
	ASSERT_TRUE(vc4::lastWarpCounts(*qpu, counts));
	EXPECT_EQ(counts.on_qpus, 0u);
	EXPECT_EQ(counts.on_cpu, quads.size());
	EXPECT_EQ(ok[0], 1);
	EXPECT_EQ(out[0].side, 18);
	EXPECT_EQ(ok.back(), 0);

	std::fill(ok.begin(), ok.end(), 7);
	qpu->warp(s.view(), quads, 16, out, ok);
	ASSERT_TRUE(vc4::lastWarpCounts(*qpu, counts));
	EXPECT_EQ(counts.on_qpus, 3u);
	EXPECT_EQ(counts.on_cpu, 1u);
	EXPECT_EQ(ok.back(), 0);
}
