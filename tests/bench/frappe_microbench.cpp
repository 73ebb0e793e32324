// SPDX-License-Identifier: MIT
// Google Benchmark micro-benchmarks, one per stage of the detector, on a
// rendered 640x480 scene (no data files needed):
//
//   build/tests/bench/frappe-microbench [--benchmark_filter=FrontEnd]
//
// The front end runs with the scalar kernels (the ARMv6 path) and with the
// vectorised ones, so their ratio is measured in the same run. Not a test.
#include <benchmark/benchmark.h>

#include <random>

#include "contour_trace.h"
#include "corner_refine.h"
#include "decode.h"
#include "front_end_rows.h"
#include "frappe/frappe.h"
#include "frappe/render.h"

namespace {

using namespace frappe;

/* A cluttered ground with `markers` markers, the same for every benchmark. */
struct Scene {
	int width = 640, height = 480;
	std::vector<std::uint8_t> pixels;
	std::vector<std::array<Point2f, 4>> truth;

	explicit Scene(int markers)
		: pixels(static_cast<std::size_t>(width) * height)
	{
		std::mt19937 rng(17);
		std::normal_distribution<float> noise(0.0f, 3.0f);
		std::uniform_int_distribution<int> px(0, 639), py(0, 479), size(5, 60), grey(40, 220);
		for (std::uint8_t &p : pixels)
			p = static_cast<std::uint8_t>(std::clamp(120.0f + noise(rng), 0.0f, 255.0f));
		for (int k = 0; k < 40; ++k) {
			const int x0 = px(rng), y0 = py(rng), w = size(rng), h = size(rng);
			const auto g = static_cast<std::uint8_t>(grey(rng));
			for (int y = y0; y < std::min(height, y0 + h); ++y)
				for (int x = x0; x < std::min(width, x0 + w); ++x)
					pixels[static_cast<std::size_t>(y) * width + x] = g;
		}
		const Dictionary &dict = *findDictionary("aruco_mip_36h12");
		MutableImageView view{ pixels.data(), width, height, width };
		for (int k = 0; k < markers; ++k) {
			const auto corners = perspectiveSquare(55.0f + 105.0f * (k % 6), 60.0f + 120.0f * (k / 6), 62.0f,
							       7.0f * k, 20.0f);
			renderMarker(view, dict, k, corners);
			truth.push_back(corners);
		}
	}
	ImageView view() const { return { pixels.data(), width, height, width }; }
};

const Scene &scene(int markers)
{
	static const Scene one(1), many(24);
	return markers == 1 ? one : many;
}

FrontEndParams params()
{
	return Detector(Config{}).frontEndParams();
}

void frontEnd(benchmark::State &state, const detail::BandKernels &kernels)
{
	const Scene &s = scene(static_cast<int>(state.range(0)));
	auto fe = detail::makeCpuFrontEnd(1, kernels);
	const FrontEndParams p = params();
	EdgeMap edges;
	for (auto _ : state) {
		fe->run(s.view(), 1.0f, p, edges);
		benchmark::DoNotOptimize(edges.pixels.data());
	}
	state.SetItemsProcessed(state.iterations() * s.width * s.height);
	state.SetLabel(kernels.name);
}

void BM_FrontEndScalar(benchmark::State &state) { frontEnd(state, detail::scalarBandKernels()); }
void BM_FrontEndBest(benchmark::State &state) { frontEnd(state, detail::bestBandKernels()); }

void BM_Trace(benchmark::State &state)
{
	const Scene &s = scene(static_cast<int>(state.range(0)));
	EdgeMap edges;
	makeCpuFrontEnd(1)->run(s.view(), 1.0f, params(), edges);
	detail::ContourTracer tracer;
	detail::TraceParams tp;
	tp.min_side = 10.0f;
	std::vector<detail::Quad> quads;
	for (auto _ : state) {
		tracer.trace(edges, tp, quads);
		benchmark::DoNotOptimize(quads.data());
	}
	state.counters["borders"] = tracer.bordersFollowed();
	state.counters["quads"] = static_cast<double>(quads.size());
}

/* Refinement from corners one pixel off the truth. */
void BM_Refine(benchmark::State &state)
{
	const Scene &s = scene(static_cast<int>(state.range(0)));
	std::vector<std::array<Point2f, 4>> start = s.truth;
	for (auto &q : start)
		for (Point2f &p : q) {
			p.x += 0.8f;
			p.y -= 0.6f;
		}
	for (auto _ : state) {
		for (const auto &q0 : start) {
			std::array<Point2f, 4> q = q0;
			benchmark::DoNotOptimize(detail::refineCorners(s.view(), q, 2.5f));
		}
	}
	state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(start.size()));
}

void BM_WarpDecode(benchmark::State &state)
{
	const Scene &s = scene(static_cast<int>(state.range(0)));
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	detail::WarpedMarker warped;
	for (auto _ : state) {
		for (const auto &q : s.truth) {
			detail::warpMarker(s.view(), q, dict.bits, warped);
			const detail::Binarised b = detail::binarise(warped, dict.bits);
			benchmark::DoNotOptimize(detail::decode(dict, b.code, 5));
		}
	}
	state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(s.truth.size()));
}

/* The warp alone, per marker: side 16 (finish()'s 2x2 samples a cell, 6x6
 * codes) or 8 (the trace's probe, a sample a cell). */
void BM_Warp(benchmark::State &state)
{
	const Scene &s = scene(24);
	const int side = static_cast<int>(state.range(0));
	detail::WarpedMarker warped;
	for (auto _ : state) {
		for (const auto &q : s.truth) {
			benchmark::DoNotOptimize(detail::warpToGrid(s.view(), q, side, warped));
			benchmark::DoNotOptimize(warped.samples.data());
		}
	}
	state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(s.truth.size()));
}

void BM_Detect(benchmark::State &state)
{
	const Scene &s = scene(static_cast<int>(state.range(0)));
	Detector det(Config{});
	std::size_t found = 0;
	for (auto _ : state)
		found = det.detect(s.view()).markers.size();
	state.counters["markers"] = static_cast<double>(found);
}

} // namespace

/* Argument: markers in the scene (1 or 24). */
BENCHMARK(BM_FrontEndScalar)->Arg(1)->Arg(24)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FrontEndBest)->Arg(1)->Arg(24)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Trace)->Arg(1)->Arg(24)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Refine)->Arg(1)->Arg(24)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_WarpDecode)->Arg(1)->Arg(24)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Warp)->Arg(8)->Arg(16)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_Detect)->Arg(1)->Arg(24)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
