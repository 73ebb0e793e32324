// SPDX-License-Identifier: MIT
// The VC4 front end on the emulator against frappe-core's CPU front end, byte for byte.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <random>

#include "asm/lint.hpp"
#include "asm/text.hpp"
#include "frappe/detector.h"
#include "frappe/edge_map.h"
#include "front_end_rows.h" // frappe-core's row kernels (internal header)
#include "region_map.h"     // frappe-core's region map (internal header)
#include "emu/device.hpp"
#include "isa/disasm.hpp"
#include "isa/setup_words.hpp"
#include "kernels/kernels.hpp"
#include "frappe/dictionary.h"
#include "frappe/render.h"
#include "frontend/vc4_front_end.hpp"
#if FRAPPE_VC4_TEST_OPENCV
#include <opencv2/imgcodecs.hpp>
#endif

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

size_t last_edges = 0, last_corners = 0, last_dark = 0;

// Region contrast 41: Config's default 0.16, so every comparison covers the region map too;
// light floor 16: Config's default 0.063 (thresholds that follow the light below mid-grey).
FrontEndParams params(int64_t edge = 400, int64_t corner = 2000, int region = 41, int floor = 16)
{
	return {edge, corner, region, floor};
}

// The light floors every kind of comparison runs at: the default, none (thresholds scaled
// down to zero in black), and 128 (the absolute thresholds of the paper).
constexpr int kFloors[] = {16, 0, 128};

// Under qemu (FRAPPE_VC4_QUICK, set by the cross builds' meson) a sweep keeps its first
// and last values: the emulator inside an emulated CPU is twenty times slower.
bool quick()
{
	static const bool q = std::getenv("FRAPPE_VC4_QUICK") != nullptr;
	return q;
}

// Whether the k-th of n values of a sweep runs.
bool sweeps(std::size_t k, std::size_t n)
{
	return !quick() || k == 0 || k + 1 == n;
}

// A dim copy of a scene (grey levels times num / den): most of it below mid-grey, where the
// thresholds follow the light.
Img dimmed(Img img, int num, int den)
{
	for (uint8_t &v : img.pixels)
		v = static_cast<uint8_t>(v * num / den);
	return img;
}

void expectSameMap(const TraceMap &got, const TraceMap &want, const std::string &what)
{
	ASSERT_EQ(got.width, want.width) << what;
	ASSERT_EQ(got.height, want.height) << what;
	ASSERT_EQ(got.scale, want.scale) << what;
	ASSERT_EQ(got.pixels.size(), want.pixels.size()) << what;
	size_t bad = 0, first = 0;
	for (size_t i = 0; i < want.pixels.size(); ++i)
		if (got.pixels[i] != want.pixels[i] && bad++ == 0)
			first = i;
	EXPECT_EQ(bad, 0u) << what << ": first at (" << first % want.width << ", " << first / want.width
	                   << ") got " << int(got.pixels[first]) << " want " << int(want.pixels[first]);
	EXPECT_EQ(got.tiles, want.tiles) << what << ": tile mask";
}

void expectSame(const EdgeMap &got, const EdgeMap &want, const std::string &what)
{
	expectSameMap(got, want, what);
	expectSameMap(got.regions, want.regions, what + " (regions)");
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
	last_dark = static_cast<size_t>(std::count(want.regions.pixels.begin(), want.regions.pixels.end(), TraceMap::kEdge));
}

// Pass 1's planes from frappe-core's own scaling, smoothing and Sobel rows: B = q << 24 |
// m << 2 | dir (q = min(smoothed + floor, 128)) and the tensor products summed over rows
// y-1 .. y+1 (zero beyond the frame).
struct Planes {
	int w = 0, h = 0;
	std::vector<uint32_t> b, xx, yy, xy;
};

Planes referencePlanes(const Img &img, float scale, int floor)
{
	Planes r;
	r.w = scale < 1.0f ? scaledLength(img.width, scale) : img.width;
	r.h = scale < 1.0f ? scaledLength(img.height, scale) : img.height;
	const int w = r.w, h = r.h;
	std::vector<uint8_t> src(static_cast<size_t>(w) * h);
	detail::scaleNearest(img.view(), w, h, src.data());
	std::vector<uint8_t> sm(static_cast<size_t>(w) * h);
	std::vector<uint16_t> tmp(w);
	auto row = [&](int y) { return src.data() + static_cast<size_t>(std::clamp(y, 0, h - 1)) * w; };
	for (int y = 0; y < h; ++y)
		detail::smoothRow(row(y - 1), row(y), row(y + 1), w, sm.data() + static_cast<size_t>(y) * w, tmp.data());
	std::vector<int32_t> gx(static_cast<size_t>(w) * h, 0), gy(gx.size(), 0);
	std::vector<int16_t> gxr(w), gyr(w), sep(2 * w);
	std::vector<int32_t> mag(w);
	for (int y = 1; y < h - 1; ++y) {
		detail::gradientRow(sm.data() + static_cast<size_t>(y - 1) * w, sm.data() + static_cast<size_t>(y) * w,
		                    sm.data() + static_cast<size_t>(y + 1) * w, w, gxr.data(), gyr.data(), mag.data(),
		                    sep.data());
		for (int x = 0; x < w; ++x) {
			gx[static_cast<size_t>(y) * w + x] = gxr[x];
			gy[static_cast<size_t>(y) * w + x] = gyr[x];
		}
	}
	const size_t n = static_cast<size_t>(w) * h;
	r.b.assign(n, 0);
	r.xx.assign(n, 0);
	r.yy.assign(n, 0);
	r.xy.assign(n, 0);
	for (int y = 0; y < h; ++y)
		for (int x = 0; x < w; ++x) {
			const size_t i = static_cast<size_t>(y) * w + x;
			const int ax = std::abs(gx[i]), ay = std::abs(gy[i]);
			const uint32_t dir = 256 * ay <= 106 * ax ? 0 : 256 * ax <= 106 * ay ? 1 : (gx[i] > 0) == (gy[i] > 0) ? 2 : 3;
			const uint32_t q = static_cast<uint32_t>(std::min(sm[i] + floor, FrontEndParams::kLightReference));
			r.b[i] = q << 24 | static_cast<uint32_t>(gx[i] * gx[i] + gy[i] * gy[i]) << 2 | dir;
			for (int yy = std::max(0, y - 1); yy <= std::min(h - 1, y + 1); ++yy) {
				const size_t j = static_cast<size_t>(yy) * w + x;
				r.xx[i] += static_cast<uint32_t>(gx[j] * gx[j]);
				r.yy[i] += static_cast<uint32_t>(gy[j] * gy[j]);
				r.xy[i] += static_cast<uint32_t>(gx[j] * gy[j]);
			}
		}
	return r;
}

// Pass 1 alone: its gradient buffer against referencePlanes(); then pass 2, whose input is
// thereby the reference, against the CPU's EdgeMap (expectSame in compare()).
void comparePass1(const Img &img, float scale, unsigned seed, const std::string &what, int floor = 16)
{
	auto fe = vc4::makeFrontEnd({.emulate = true, .seed = seed, .strict = true});
	EdgeMap got;
	fe->run(img.view(), scale, params(400, 2000, 41, floor), got);
	std::vector<uint32_t> buf;
	int pitch = 0;
	ASSERT_TRUE(vc4::lastGradientBuffer(*fe, buf, pitch)) << what;
	const Planes ref = referencePlanes(img, scale, floor);
	ASSERT_EQ(got.width, ref.w);
	size_t bad = 0;
	std::string first;
	for (int y = 0; y < ref.h; ++y)
		for (int x = 0; x < ref.w; ++x) {
			const size_t i = static_cast<size_t>(y) * ref.w + x;
			const uint32_t *p = buf.data() + static_cast<size_t>(y) * pitch + vc4::kernels::gradWord(x);
			const uint32_t want[4] = {ref.b[i], ref.xx[i], ref.yy[i], ref.xy[i]};
			for (int k = 0; k < 4; ++k)
				if (p[k * pitch / 4] != want[k] && bad++ == 0)
					first = "plane " + std::to_string(k) + " at (" + std::to_string(x) + ", " + std::to_string(y) +
					        ") got " + std::to_string(p[k * pitch / 4]) + " want " + std::to_string(want[k]);
		}
	EXPECT_EQ(bad, 0u) << what << ": " << first;
}

TEST(Vc4Kernels, GradientPassMatchesCoreRows)
{
	comparePass1(scene(67, 33, 1, 1), 1.0f, 0, "67x33");
	comparePass1(scene(3, 3, 2, 0), 1.0f, 0, "3x3");
	comparePass1(scene(7, 5, 3, 0), 1.0f, 1, "7x5");
	comparePass1(scene(130, 70, 4, 2, 3), 1.0f, 2, "130x70 stride 133");
	comparePass1(scene(200, 150, 5, 2), 0.5f, 3, "200x150 scale 0.5");
	comparePass1(scene(161, 97, 6, 2), 0.7f, 4, "161x97 scale 0.7");
	for (const int floor : kFloors)
		comparePass1(dimmed(scene(130, 70, 8, 2), 1, 3), 1.0f, 5, "130x70 dim, floor " + std::to_string(floor), floor);
	comparePass1(scene(67, 33, 1, 1), 1.0f, 0, "67x33 floor 200", 200);
}

// One launch of a kernel driven without the front end (seed 0: round robin); every program
// must raise the host interrupt.
void runJobs(vc4::emu::Device &dev, const std::vector<vc4::emu::Job> &jobs, unsigned seed)
{
	vc4::emu::LaunchOptions lo;
	if (seed) {
		lo.schedule = vc4::emu::Schedule::Random;
		lo.seed = seed;
	}
	EXPECT_EQ(dev.wait(dev.launch(jobs, lo)).host_interrupts, jobs.size());
}

// Pass 2 alone, on the emulator without the front end: fed referencePlanes() (frappe-core's
// gradients), its edge bytes and tile mask against the CPU front end's EdgeMap.
void comparePass2(const Img &img, const FrontEndParams &p, unsigned seed, const std::string &what)
{
	namespace k = vc4::kernels;
	const Planes ref = referencePlanes(img, 1.0f, std::max(p.light_floor, 0));
	const int w = ref.w, h = ref.h;
	const uint32_t pw = (w + 63) / 64 * 64, ph = (h + 31) / 32 * 32, pitch = 16 * pw, margin = k::gradMargin(pitch);
	const unsigned tx = pw / 64, tiles = tx * (ph / 32), units = tx * (ph / k::kEdgeRows);
	const unsigned programs = std::min(12u, units);
	vc4::emu::Config config;
	config.strict = true;
	config.tmu_fifo_limit = vc4::kTmuDepth;
	vc4::emu::Device dev(config, 16u << 20);
	auto grad = dev.alloc(pitch * ph + 2 * margin), edge = dev.alloc(pw * ph), mask = dev.alloc(128 * tiles);
	std::fill(edge.cpu.begin(), edge.cpu.end(), uint8_t{0xEE});
	for (int y = 0; y < h; ++y)
		for (int x = 0; x < w; ++x) {
			const size_t i = static_cast<size_t>(y) * w + x;
			const uint32_t v[4] = {ref.b[i], ref.xx[i], ref.yy[i], ref.xy[i]};
			for (int q = 0; q < 4; ++q)
				std::memcpy(grad.cpu.data() + margin + y * pitch + q * pitch / 4 + 4 * k::gradWord(x), &v[q], 4);
		}
	const auto code = dev.upload(k::edgePass().program.code);
	std::vector<vc4::emu::Job> jobs;
	for (unsigned prog = 0; prog < programs; ++prog) {
		const k::EdgeUniforms e{pitch, uint32_t(std::clamp<int64_t>(p.edge_threshold_sq, 0, int64_t{1} << 22)),
		                        uint32_t(std::clamp<int64_t>(p.corner_threshold, 0, (int64_t{1} << 23) - 1)),
		                        vc4::isa::VdwStride{.stride = uint16_t(pw - 64)}.word(), 4 * pw};
		const auto *words = reinterpret_cast<const uint32_t *>(&e);
		std::vector<uint32_t> u(words, words + k::kEdgeUniforms);
		for (unsigned n = prog; n < units; n += 12) {
			const uint32_t x0 = n % tx * 64, y0 = n / tx * k::kEdgeRows, t = n / tx / 2 * tx + n % tx;
			const k::EdgeUnit unit{x0, uint32_t(w - 2), grad.bus + margin + (y0 - 1) * pitch + 4 * x0, pitch / 4,
			                       edge.bus + y0 * pw + x0, mask.bus + 128 * t + 64 * (n / tx % 2)};
			const auto *uw = reinterpret_cast<const uint32_t *>(&unit);
			u.insert(u.end(), uw, uw + k::kEdgeUnitUniforms);
			for (int r = 0; r < k::kEdgeRows; ++r)
				u.push_back(int(y0) + r >= 1 && int(y0) + r <= h - 2 ? 0xffffffffu : 0u);
			u.push_back(n + 12 < units ? 1 : 0);
		}
		jobs.push_back({dev.upload(u).bus, code.bus});
	}
	runJobs(dev, jobs, seed);
	EdgeMap want;
	makeCpuFrontEnd(1)->run(img.view(), 1.0f, p, want);
	size_t bad = 0;
	for (int y = 0; y < h; ++y)
		for (int x = 0; x < w; ++x)
			bad += edge.cpu[static_cast<size_t>(y) * pw + x] != want.at(x, y);
	EXPECT_EQ(bad, 0u) << what << ": edge bytes";
	for (int by = 0; by < want.tiles_y; ++by)
		for (int bx = 0; bx < want.tiles_x; ++bx) {
			const unsigned t = (by / 2) * tx + bx / 4;
			uint32_t word;
			std::memcpy(&word, mask.cpu.data() + 128 * t + 64 * (by % 2) + 4 * (4 * (bx % 4) + 3), 4);
			EXPECT_EQ(word != 0, !want.tileEmpty(bx, by)) << what << ": block " << bx << ", " << by;
		}
}

TEST(Vc4Kernels, EdgePassMatchesCoreOnCoreGradients)
{
	comparePass2(scene(67, 33, 1, 1), params(), 0, "67x33");
	comparePass2(scene(3, 3, 2, 0), params(0, 0), 0, "3x3");
	comparePass2(scene(7, 5, 3, 0), params(0, 0), 1, "7x5");
	comparePass2(scene(200, 150, 5, 3), params(), 2, "200x150");
	comparePass2(scene(131, 97, 6, 2), params(100, 500), 3, "131x97 low thresholds");
	// Thresholds that follow the light, on a dim scene, at each floor.
	const Img dim = dimmed(scene(200, 150, 9, 3), 2, 7);
	for (const int floor : kFloors)
		for (const auto &[edge, corner] : {std::pair<int64_t, int64_t>{4740, 12354}, {400, 2000}, {-1, 0}, {int64_t{1} << 30, 0}})
			comparePass2(dim, params(edge, corner, 41, floor), floor % 5,
			             "dim 200x150 floor " + std::to_string(floor) + " thresholds " + std::to_string(edge) + " " +
			                     std::to_string(corner));
}

// The region map's means pass alone, on the emulator without the front end: its rows of r
// against frappe-core's halveImage() of the scaled frame, and its tile words against the
// least and greatest r of each 4x4 tile (partial at the right and bottom).
void compareRegionMeans(const Img &img, float scale, unsigned seed, const std::string &what)
{
	namespace k = vc4::kernels;
	const int W = scale < 1.0f ? scaledLength(img.width, scale) : img.width;
	const int H = scale < 1.0f ? scaledLength(img.height, scale) : img.height;
	std::vector<uint8_t> scaled(static_cast<size_t>(W) * H);
	detail::scaleNearest(img.view(), W, H, scaled.data());
	const int w = W / 2, h = H / 2;
	std::vector<uint8_t> r(static_cast<size_t>(w) * h);
	detail::halveImage(ImageView(scaled.data(), W, H, W), r.data());
	const uint32_t pitch = (w + 63) / 64 * 64, bx = pitch / 64, blocks = bx * ((h + 15) / 16);
	const uint32_t stride = (img.width + 3) / 4 * 4;
	vc4::emu::Config config;
	config.strict = true;
	config.tmu_fifo_limit = 4;
	vc4::emu::Device dev(config, 16u << 20);
	auto src = dev.alloc(stride * img.height), buf = dev.alloc(20 * pitch * (blocks / bx));
	for (int y = 0; y < img.height; ++y)
		std::memcpy(src.cpu.data() + y * stride, img.view().row(y), img.width);
	const uint32_t stepX = static_cast<uint32_t>((uint64_t{uint32_t(img.width)} * 65536u + W / 2) / W);
	const uint32_t stepY = static_cast<uint32_t>((uint64_t{uint32_t(img.height)} * 65536u + H / 2) / H);
	const auto code = dev.upload(k::regionMeansPass().program.code);
	std::vector<vc4::emu::Job> jobs;
	for (unsigned prog = 0; prog < std::min(12u, blocks); ++prog) {
		std::vector<uint32_t> u;
		for (unsigned b = prog; b < blocks; b += 12) {
			const uint32_t x0 = b % bx * 64, y0 = b / bx * 16;
			const k::RegionMeansUniforms m{uint32_t(img.width - 1), stepX, uint32_t(w - 1), x0,
			                               buf.bus + 5 * (y0 / 4) * pitch + x0,
			                               vc4::isa::VdwStride{.stride = uint16_t(pitch - 64)}.word(), 5 * pitch};
			const auto *words = reinterpret_cast<const uint32_t *>(&m);
			u.insert(u.end(), words, words + k::kRegionMeansUniforms);
			u.resize(u.size() + k::kRegionSourceRows);
			k::regionSourceRows(u.data() + u.size() - k::kRegionSourceRows, src.bus, stride, img.height, stepY, h,
			                    int(y0));
			u.push_back(b + 12 < blocks ? 1 : 0);
		}
		jobs.push_back({dev.upload(u).bus, code.bus});
	}
	runJobs(dev, jobs, seed);
	size_t bad = 0;
	for (int y = 0; y < h; ++y)
		for (int x = 0; x < w; ++x)
			bad += buf.cpu[(5 * (y / 4) + y % 4) * pitch + x] != r[static_cast<size_t>(y) * w + x];
	EXPECT_EQ(bad, 0u) << what << ": means";
	for (int ty = 0; ty < (h + 3) / 4; ++ty)
		for (int tx = 0; tx < (w + 3) / 4; ++tx) {
			int lo = 255, hi = 0;
			for (int y = 4 * ty; y < std::min(h, 4 * ty + 4); ++y)
				for (int x = 4 * tx; x < std::min(w, 4 * tx + 4); ++x) {
					lo = std::min<int>(lo, r[static_cast<size_t>(y) * w + x]);
					hi = std::max<int>(hi, r[static_cast<size_t>(y) * w + x]);
				}
			const uint8_t *word = buf.cpu.data() + (5 * ty + 4) * pitch + 4 * tx;
			EXPECT_EQ(word[0], lo) << what << ": tile " << tx << ", " << ty;
			EXPECT_EQ(word[1], 255 - hi) << what << ": tile " << tx << ", " << ty;
		}
}

TEST(Vc4Kernels, RegionMeansPassMatchesCore)
{
	compareRegionMeans(scene(67, 33, 1, 1), 1.0f, 0, "67x33");
	compareRegionMeans(scene(13, 11, 2, 0), 1.0f, 1, "13x11");
	compareRegionMeans(scene(130, 70, 4, 2, 3), 1.0f, 2, "130x70 stride 133");
	compareRegionMeans(scene(200, 150, 5, 2), 0.5f, 3, "200x150 scale 0.5");
	compareRegionMeans(scene(161, 97, 6, 2), 0.7f, 4, "161x97 scale 0.7");
}

// The kernels survive a round trip through their vc4asm-syntax listings (what vc4asm
// reads), and their hazard lint is clean (finish() throws otherwise).
TEST(Vc4Kernels, ListingsRoundTrip)
{
	// The uniform structs of kernels.hpp are the programs' streams, in order, then `more`.
	namespace k = vc4::kernels;
	EXPECT_EQ(k::gradientPass().program.uniforms.size(), k::kGradientUniforms + k::kGradientUnitUniforms + 1);
	EXPECT_EQ(k::edgePass().program.uniforms.size(), k::kEdgeUniforms + k::kEdgeUnitUniforms + 1);
	EXPECT_EQ(k::gradientPass().program.uniformIndex("vdw_stride"), k::kGradientUniforms - 2);
	EXPECT_EQ(k::gradientPass().program.uniformIndex("light_floor"), k::kGradientUniforms - 1);
	EXPECT_EQ(k::gradientPass().program.uniformIndex("rows"), k::kGradientUniforms + k::kGradientUnitUniforms - 1);
	EXPECT_EQ(k::edgePass().program.uniformIndex("edge_pitch4"), k::kEdgeUniforms - 1);
	EXPECT_EQ(k::edgePass().program.uniformIndex("mask_dst"), k::kEdgeUniforms + k::kEdgeUnitUniforms - 1);
	EXPECT_EQ(k::regionMeansPass().program.uniforms.size(), k::kRegionMeansUniforms + 1);
	EXPECT_EQ(k::regionDarkPass().program.uniforms.size(), k::kRegionDarkUniforms + 1);
	EXPECT_EQ(k::regionDarkPass().program.uniformIndex("mask_dst"), 8u);
	// Every program keeps to the build's TMU depth, and the safe one always.
	for (const auto &built : {k::gradientPass(), k::edgePass(), k::regionMeansPass(), k::regionDarkPass()}) {
		EXPECT_TRUE(vc4::qasm::lint(built.program.code, vc4::kTmuDepth).empty()) << built.program.name;
		if (vc4::kTmuDepth == 4) {
			EXPECT_TRUE(vc4::qasm::lint(built.program.code, 4).empty()) << built.program.name;
		}
	}
	for (const auto &built : {k::gradientPass(), k::edgePass(), k::regionMeansPass(), k::regionDarkPass()}) {
		EXPECT_EQ(vc4::qasm::assembleText(vc4::isa::disassembleProgram(built.program.code)), built.program.code)
			<< built.program.name;
		EXPECT_EQ(built.program.uniforms.back().name, "more");
		std::printf("%s: %zu instructions, %u nops the builder could not fill\n", built.program.name.c_str(),
		            built.program.code.size(), built.nops);
	}
}

// The region map's programs keep at most four TMU requests in flight, both TMUs together
// (the hardware's reliable depth), counted along their listings (their loops are entered
// and left with the same requests in flight).
TEST(Vc4Kernels, RegionPassesTmuDepth)
{
	for (const auto &built : {vc4::kernels::regionMeansPass(), vc4::kernels::regionDarkPass()}) {
		const std::string text = vc4::isa::disassembleProgram(built.program.code, false);
		int outstanding = 0, most = 0, requests = 0;
		size_t at = 0;
		while (at < text.size()) {
			const size_t end = std::min(text.find('\n', at), text.size());
			const std::string line = text.substr(at, end - at);
			at = end + 1;
			for (const char *tmu : {" t0s,", " t1s,"})
				if (line.find(tmu) != std::string::npos)
					++outstanding, ++requests;
			most = std::max(most, outstanding);
			if (line.find("ldtmu") != std::string::npos)
				--outstanding;
			EXPECT_GE(outstanding, 0) << built.program.name << ": " << line;
		}
		EXPECT_EQ(most, 4) << built.program.name;
		EXPECT_EQ(outstanding, 0) << built.program.name;
		EXPECT_GT(requests, 8) << built.program.name;
	}
}

// Instruction and modelled-cycle counts of both passes on a 640x480 frame (README table).
TEST(Vc4Kernels, FrameCounts)
{
	const Img img = scene(640, 480, 21, 6);
	auto fe = vc4::makeFrontEnd({});
	EdgeMap got, want;
	fe->run(img.view(), 1.0f, params(4740, 12354), got);
	makeCpuFrontEnd(1)->run(img.view(), 1.0f, params(4740, 12354), want);
	expectSame(got, want, "640x480");
	vc4::FrameCounts c;
	ASSERT_TRUE(vc4::lastFrameCounts(*fe, c));
	EXPECT_EQ(c.pass[0].tiles, 150u);
	EXPECT_EQ(c.pass[1].units, 300u); // half tiles: 25 a QPU
	std::printf("TMU depth %u\n", vc4::kTmuDepth);
	for (int pass = 0; pass < 2; ++pass) {
		const auto &p = c.pass[pass];
		std::printf("pass %d: %u units on %u QPUs; %.0f instructions/tile; slowest QPU %llu cycles "
		            "= %.3f ms at 250 MHz, %.3f ms at 300 MHz; DRAM read %.2f MB, written %.2f MB\n",
		            pass + 1, p.units, p.programs, double(p.instructions) / p.tiles,
		            static_cast<unsigned long long>(p.slowest_cycles), p.slowest_cycles / 250e3,
		            p.slowest_cycles / 300e3, p.dram_read / 1e6, p.dram_written / 1e6);
		EXPECT_GT(p.instructions, 0u);
		EXPECT_GT(p.dram_read, 0u);
	}
	// Pass 1 writes the four planes of every pixel (one VDW a row a strip); pass 2 the
	// edge bytes and two mask rows a tile.
	EXPECT_EQ(c.pass[0].dram_written, 640u * 480u * 16u);
	EXPECT_EQ(c.pass[1].dram_written, 640u * 480u + 150u * 128u);
	// The region map: 64x16 blocks of the 320x240 map. DRAM: the means pass reads 4 source
	// bytes a map pixel (4 B gathered words) and writes r and the tile words; the dark pass
	// gathers 9 tile words a lane and tile row and one word of r a lane and row, and writes
	// the dark bytes and 64 mask bytes a block.
	const char *names[2] = {"region means", "region dark"};
	for (int pass = 0; pass < 2; ++pass) {
		const auto &p = c.region[pass];
		const unsigned perQpu = (p.tiles + p.programs - 1) / p.programs;
		std::printf("%s: %u blocks on %u QPUs; %.0f instructions/block; slowest QPU %llu cycles "
		            "(%u blocks) = %.3f ms at 250 MHz\n",
		            names[pass], p.tiles, p.programs, double(p.instructions) / p.tiles,
		            static_cast<unsigned long long>(p.slowest_cycles), perQpu, p.slowest_cycles / 250e3);
		EXPECT_EQ(p.tiles, 5u * 15u);
		EXPECT_GT(p.instructions, 0u);
	}
	EXPECT_EQ(got.regions.width, 320);
	// Bytes to and from memory (layout: kernels.hpp): the frame once, r and the tile words
	// written (20 rows a block) and read back, the dark bytes and mask words written; and
	// what the TMUs hand the QPUs (16 and 13 gathered words a lane, map row and tile row).
	const size_t pitch = 320, blocks = c.region[0].tiles, frame = 640 * 480;
	const size_t meansOut = 20 * pitch * blocks / 5, darkIn = meansOut, darkOut = 16 * pitch * blocks / 5 + 64 * blocks;
	std::printf("region DRAM: %zu bytes (frame %zu, means out %zu, dark in %zu, dark out %zu); TMU: %zu bytes\n",
	            frame + meansOut + darkIn + darkOut, frame, meansOut, darkIn, darkOut,
	            blocks * 16 * 16 * 16 * 4 + blocks * 4 * 13 * 16 * 4);
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

// The whole detector with its front end on the emulator ("vc4-emu"): the same markers,
// corners and edge maps as with the CPU front end, in Normal and AScale modes. Frames 3
// and 4 dimmed to a sixth (noise about 1.5 grey levels): the light floor the detector
// derives from the frame's noise (about 8 grey levels, not 16) reaches both front ends.
TEST(Vc4FrontEnd, WholeDetector)
{
	for (const Mode mode : {Mode::Normal, Mode::AScale}) {
		Config config;
		config.mode = mode;
		Detector cpu(config), qpu(config);
		qpu.setFrontEnd(vc4::makeFrontEnd({.seed = 4}));
		ASSERT_STREQ(qpu.frontEnd().name(), "vc4-emu");
		size_t found = 0;
		for (int frame = 0; frame < 5; ++frame) {
			const Img img = frame < 3 ? scene(320, 240, 40 + frame, 3)
						  : dimmed(scene(320, 240, 40 + frame, 3), 1, 6);
			const Result want = cpu.detect(img.view());
			const Result got = qpu.detect(img.view());
			expectSame(qpu.edgeMap(), cpu.edgeMap(), "detector frame " + std::to_string(frame));
			EXPECT_EQ(got.scale, want.scale);
			ASSERT_EQ(got.markers.size(), want.markers.size()) << "frame " << frame;
			for (size_t i = 0; i < want.markers.size(); ++i) {
				EXPECT_EQ(got.markers[i].id, want.markers[i].id);
				for (int c = 0; c < 4; ++c) {
					EXPECT_EQ(got.markers[i].corners[c].x, want.markers[i].corners[c].x);
					EXPECT_EQ(got.markers[i].corners[c].y, want.markers[i].corners[c].y);
				}
			}
			found += want.markers.size();
		}
		EXPECT_GT(found, 0u);
	}
}

// Off a Pi (or with the QPUs unusable) the real-GPU front end refuses with the probe's reason.
TEST(Vc4FrontEnd, RealGpuProbe)
{
	const std::string reason = vc4::probeGpu();
	if (reason.empty()) {
		EXPECT_STREQ(vc4::makeFrontEnd({.emulate = false})->name(), "vc4");
		return;
	}
	try {
		vc4::makeFrontEnd({.emulate = false});
		ADD_FAILURE() << "makeFrontEnd succeeded although the probe said: " << reason;
	} catch (const std::runtime_error &e) {
		EXPECT_EQ(std::string(e.what()), reason);
	}
}

// A flat frame with one marker: most 16x16 blocks empty, some not.
TEST(Vc4FrontEnd, SparseTileMask)
{
	for (const int w : {200, 131}) {
		Img img{w, 130, w, std::vector<uint8_t>(static_cast<size_t>(w) * 130, 128)};
		MutableImageView m{img.pixels.data(), img.width, img.height, img.stride};
		renderMarker(m, *findDictionary("aruco_mip_36h12"), 3, perspectiveSquare(w * 0.6f, 70, 40, 20, 10),
		             {.quiet_cells = 1, .supersample = 2, .black = 25, .white = 225});
		EdgeMap want, got;
		makeCpuFrontEnd(1)->run(img.view(), 1.0f, params(), want);
		vc4::makeFrontEnd({.seed = 9})->run(img.view(), 1.0f, params(), got);
		expectSame(got, want, "sparse " + std::to_string(w));
		const auto set = std::count(want.tiles.begin(), want.tiles.end(), 1);
		EXPECT_GT(set, 0);
		EXPECT_LT(set, static_cast<long>(want.tiles.size()) / 2);
	}
}

// Six threshold pairs at each light floor, on a scene and on a dim copy of it (where the
// thresholds follow the light), and floors beyond 128 (absolute) and negative (the CPU's).
TEST(Vc4FrontEnd, Thresholds)
{
	const Img img = scene(150, 90, 7, 2), dim = dimmed(img, 1, 4);
	const int floors[] = { 16, 0, 128, 1, 127, 255 };
	for (std::size_t f = 0; f < std::size(floors); ++f)
		for (const Img *frame : {&img, &dim})
			for (auto p : {params(0, 0), params(-5, -100), params(100, 500), params(2500, 20000),
			               params(int64_t{1} << 40, 0), params(400, int64_t{1} << 20), params(4740, 12354),
			               params(int64_t{1} << 22, (int64_t{1} << 23) - 1)}) {
				const int floor = floors[f];
				if (!sweeps(f, std::size(floors)))
					continue;
				p.light_floor = floor;
				compare(*frame, 1.0f, p, floor % 3,
				        std::string(frame == &dim ? "dim " : "") + "floor " + std::to_string(floor) + " thresholds " +
				                std::to_string(p.edge_threshold_sq) + " " + std::to_string(p.corner_threshold));
			}
	compare(dim, 1.0f, params(400, 2000, 41, -20), 0, "negative floor");
}

// A frame whose light falls from white to black across it: edges and dark regions where
// the thresholds are scaled down, at each floor; more edges with a lower floor.
TEST(Vc4FrontEnd, ThresholdsFollowTheLight)
{
	Img img = scene(260, 140, 17, 4);
	for (int y = 0; y < img.height; ++y)
		for (int x = 0; x < img.width; ++x) {
			uint8_t &v = img.pixels[static_cast<size_t>(y) * img.stride + x];
			v = static_cast<uint8_t>(v * (img.width - x) / img.width);
		}
	size_t edges[3] = {};
	for (int k = 0; k < 3; ++k) {
		compare(img, 1.0f, params(4740, 12354, 41, kFloors[k]), static_cast<unsigned>(k),
		        "gradient of light, floor " + std::to_string(kFloors[k]));
		edges[k] = last_edges;
	}
	EXPECT_GT(edges[1], edges[0]); // floor 0 > floor 16
	EXPECT_GT(edges[0], edges[2]); // floor 16 > absolute
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

// The region map (EdgeMap::regions) on the QPUs: every map size from 3x3 (frames 6x6 ..
// 13x11, odd sizes leave a row or column out), contrasts from 1 to beyond 255, and 0 (off:
// no map on either side).
TEST(Vc4Regions, SmallMapsAndContrasts)
{
	for (const int h : {6, 7, 11})
		for (const int w : {6, 7, 8, 9, 13})
			for (const int contrast : {1, 41})
				for (std::size_t f = 0; f < std::size(kFloors); ++f) {
					const int floor = kFloors[f];
					if (!sweeps(f, std::size(kFloors)))
						continue;
					const std::string what = std::to_string(w) + "x" + std::to_string(h) + " contrast " +
					                         std::to_string(contrast) + " floor " + std::to_string(floor);
					compare(scene(w, h, static_cast<unsigned>(w * 31 + h), 0), 1.0f, params(0, 0, contrast, floor), 0,
					        what);
				}
	const Img img = scene(150, 90, 7, 2);
	const Img dim = dimmed(img, 1, 3);
	const int floors[] = { 16, 0, 128, 7, 300 };
	for (std::size_t f = 0; f < std::size(floors); ++f)
		for (const Img *frame : {&img, &dim})
			for (const int contrast : {0, 1, 20, 41, 128, 255, 1000, 65280, 65281, 1 << 20}) {
				const int floor = floors[f];
				if (!sweeps(f, std::size(floors)))
					continue;
				const std::string what = std::string(frame == &dim ? "dim " : "") + "contrast " +
				                         std::to_string(contrast) + " floor " + std::to_string(floor);
				compare(*frame, 1.0f, params(400, 2000, contrast, floor), contrast % 3, what);
				if (contrast == 0 || contrast > 255 * 256) {
					EXPECT_EQ(last_dark, 0u) << what;
				} else if (contrast <= 128 && frame == &img) {
					EXPECT_GT(last_dark, 100u) << what;
				}
			}
	EdgeMap off;
	vc4::makeFrontEnd({})->run(img.view(), 1.0f, params(400, 2000, 0), off);
	EXPECT_EQ(off.regions.width, 0);
	EXPECT_TRUE(vc4::makeFrontEnd({})->makesRegionMap());
}

// Markers at several sizes and scales, padded strides, random QPU interleavings: dark
// regions inside the outlines, and blocks of the map's tile mask both set and clear.
TEST(Vc4Regions, ScenesScalesAndSeeds)
{
	struct Case { int w, h, pad; float scale; unsigned seed; };
	for (const Case c : {Case{256, 160, 0, 1.0f, 0}, Case{261, 177, 3, 1.0f, 7}, Case{400, 300, 1, 0.5f, 3},
	                     Case{333, 251, 2, 0.7f, 12345}, Case{640, 96, 0, 0.33f, 2}}) {
		const Img img = scene(c.w, c.h, c.w * 7 + c.h, 4, c.pad);
		const std::string what = std::to_string(c.w) + "x" + std::to_string(c.h) + " scale " +
		                         std::to_string(c.scale) + " seed " + std::to_string(c.seed);
		for (const int floor : kFloors) {
			compare(floor ? img : dimmed(img, 1, 3), c.scale, params(400, 2000, 41, floor), c.seed,
			        what + " floor " + std::to_string(floor));
			EXPECT_GT(last_dark, 20u) << what;
		}
	}
	// A flat frame with one marker: most of the map's 16x16 blocks empty.
	Img flat{300, 200, 300, std::vector<uint8_t>(300 * 200, 128)};
	MutableImageView m{flat.pixels.data(), flat.width, flat.height, flat.stride};
	renderMarker(m, *findDictionary("aruco_mip_36h12"), 5, perspectiveSquare(200, 90, 60, 15, 20),
	             {.quiet_cells = 1, .supersample = 2, .black = 25, .white = 225});
	EdgeMap want, got;
	makeCpuFrontEnd(1)->run(flat.view(), 1.0f, params(), want);
	vc4::makeFrontEnd({.seed = 4})->run(flat.view(), 1.0f, params(), got);
	expectSame(got, want, "flat");
	const auto set = std::count(want.regions.tiles.begin(), want.regions.tiles.end(), 1);
	EXPECT_GT(set, 0);
	EXPECT_LT(set, static_cast<long>(want.regions.tiles.size()) / 2);
}

} // namespace

#if FRAPPE_VC4_TEST_OPENCV
// The shared data set (../shared/data, not shipped to users): a bounded subset by default,
// every image with FRAPPE_VC4_ALL=1. Each image runs at full size and scaled to about 320
// pixels wide, under a seed that changes from image to image.
TEST(Vc4FrontEnd, SharedImages)
{
	const char *shared = std::getenv("FRAPPE_SHARED");
	const std::filesystem::path root = shared ? std::filesystem::path(shared) / "data" : std::filesystem::path();
	if (!shared)
		GTEST_SKIP() << "FRAPPE_SHARED is not set";
	if (!std::filesystem::is_directory(root)) {
		// meson's vc4-front-end-shared test: report "skipped" as meson understands it.
		std::printf("no shared data at %s: skipped\n", root.string().c_str());
		std::exit(77);
	}
	std::vector<std::filesystem::path> files;
	for (const auto &e : std::filesystem::recursive_directory_iterator(root)) {
		const auto ext = e.path().extension().string();
		if (e.is_regular_file() && (ext == ".png" || ext == ".jpg"))
			files.push_back(e.path());
	}
	std::sort(files.begin(), files.end());
	const bool all = std::getenv("FRAPPE_VC4_ALL") && std::string(std::getenv("FRAPPE_VC4_ALL")) == "1";
	const size_t limit = all ? files.size() : 10;
	const size_t step = all ? 1 : std::max<size_t>(1, files.size() / limit);
	// Config's defaults 0.27, 0.19, 0.16 and 0.063; every third image at floor 0, and at
	// 128 (the absolute thresholds), in turn.
	const FrontEndParams defaults = params(4740, 12354, 41, 16);
	size_t runs = 0, fallback = 0, frames = 0;
	auto cpu = makeCpuFrontEnd(1);
	// FRAPPE_VC4_SHARD=k/n: only images i with i % n == k (to spread a full run over cores).
	size_t shard = 0, shards = 1;
	if (const char *sh = std::getenv("FRAPPE_VC4_SHARD"))
		if (std::sscanf(sh, "%zu/%zu", &shard, &shards) != 2 || shards == 0 || shard >= shards)
			shard = 0, shards = 1;
	for (size_t i = 0; i < files.size() && frames < limit; i += step) {
		if (i % shards != shard)
			continue;
		++frames;
		const cv::Mat m = cv::imread(files[i].string(), cv::IMREAD_GRAYSCALE);
		ASSERT_FALSE(m.empty()) << files[i];
		const ImageView view(m.data, m.cols, m.rows, static_cast<int>(m.step));
		const unsigned seed = static_cast<unsigned>(i % 5); // 0: round robin
		auto fe = vc4::makeFrontEnd({.emulate = true, .seed = seed, .strict = true});
		FrontEndParams p = defaults;
		p.light_floor = kFloors[frames % 3];
		for (const float scale : {1.0f, std::min(1.0f, 320.0f / static_cast<float>(m.cols))}) {
			EdgeMap want, got;
			cpu->run(view, scale, p, want);
			fe->run(view, scale, p, got);
			expectSame(got, want, files[i].string() + " scale " + std::to_string(scale) + " seed " + std::to_string(seed) +
			                              " floor " + std::to_string(p.light_floor));
			if (want.width > vc4::kMaxQpuWidth)
				++fallback;
			++runs;
		}
		if (all && frames % 100 == 0)
			std::printf("... %zu frames\n", frames), std::fflush(stdout);
	}
	std::printf("shared images: %zu frames, %zu comparisons (%zu wider than the QPU limit, on the CPU)\n", frames, runs,
	            fallback);
}
#endif
