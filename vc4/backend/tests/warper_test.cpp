// SPDX-License-Identifier: MIT
// The QPU candidate warper behind frappe::CandidateWarper: on the emulator its samples
// are the kernel's exact integer warp, within a grey level of the CPU's float warp; it
// batches 32 candidates a launch, sends what the fixed point refuses (and codes wider
// than 16 samples) to the CPU, and a Detector using it finds the CPU's markers.
#include <gtest/gtest.h>

#include <cmath>
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

TEST(Vc4Warper, SamplesWithinAGreyLevelOfTheCpuWarp)
{
	const Scene s = scene(5, 40); /* 40 candidates: two launches */
	auto qpu = vc4::makeWarper({ .emulate = true, .seed = 3 });
	auto cpu = makeCpuWarper();
	const std::size_t n = s.quads.size();
	std::vector<CandidateSamples> a(n), b(n);
	std::vector<std::uint8_t> okA(n), okB(n);
	cpu->warp(s.view(), s.quads, 16, a, okA);
	qpu->warp(s.view(), s.quads, 16, b, okB);
	vc4::WarpCounts counts;
	ASSERT_TRUE(vc4::lastWarpCounts(*qpu, counts));
	EXPECT_EQ(counts.on_qpus + counts.on_cpu, n);
	EXPECT_GE(counts.on_qpus, n - 2);
	EXPECT_EQ(counts.launches, (counts.on_qpus + 31) / 32);
	for (std::size_t k = 0; k < n; ++k) {
		ASSERT_TRUE(okA[k] && okB[k]) << k;
		ASSERT_EQ(b[k].side, 16);
		for (int i = 0; i < 256; ++i)
			EXPECT_LE(std::abs(a[k].samples[static_cast<std::size_t>(i)] - b[k].samples[static_cast<std::size_t>(i)]), 1.0f)
				<< "candidate " << k << " sample " << i;
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

TEST(Vc4Warper, DetectorWithQpuWarpFindsTheCpuMarkers)
{
	const Scene s = scene(9, 6);
	Detector cpu(Config{});
	Detector qpu(Config{});
	qpu.setWarper(vc4::makeWarper({ .emulate = true }));
	const Result a = cpu.detect(s.view());
	const Result &b = qpu.detect(s.view());
	EXPECT_GE(a.markers.size(), 5u);
	ASSERT_EQ(a.markers.size(), b.markers.size());
	for (std::size_t i = 0; i < a.markers.size(); ++i) {
		EXPECT_EQ(a.markers[i].id, b.markers[i].id);
		for (int k = 0; k < 4; ++k)
			EXPECT_EQ(a.markers[i].corners[k].x, b.markers[i].corners[k].x);
	}
}
