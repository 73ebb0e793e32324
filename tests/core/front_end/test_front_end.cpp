// SPDX-License-Identifier: MIT
// The CPU front end on small constructed images: where the edges and the
// corners of a square fall, the tile mask, and independence from stride,
// threads and padding.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "every_target.h"
#include "frappe/frappe.h"
#include "front_end_rows.h"
#include "scene.h"

using namespace frappe;
using frappe::test::Image;

namespace {

FrontEndParams defaultParams()
{
	return Detector(Config{}).frontEndParams();
}

/* A bright axis-aligned square [x0, x1) x [y0, y1) on a dark ground. */
Image square(int w, int h, int x0, int y0, int x1, int y1, int padding = 0)
{
	Image img(w, h, 30, padding);
	for (int y = y0; y < y1; ++y)
		for (int x = x0; x < x1; ++x)
			img.at(x, y) = 220;
	return img;
}

/* The front end's contract (front_end_cpu.cpp) written out literally, one
 * pixel at a time, without the kernels' row rings or shortcuts: the edge
 * map bytes of the interior of `img` (the outermost rows and columns are
 * zero). */
std::vector<std::uint8_t> contractEdgeMap(const Image &src, const FrontEndParams &prm)
{
	const int w = src.width, h = src.height;
	auto px = [&](int x, int y) {
		x = std::clamp(x, 0, w - 1);
		y = std::clamp(y, 0, h - 1);
		return static_cast<int>(src.pixels[static_cast<std::size_t>(y) * src.stride + x]);
	};
	std::vector<int> p(static_cast<std::size_t>(w) * h), gx(p.size()), gy(p.size());
	std::vector<std::int64_t> m(p.size(), 0);
	for (int y = 0; y < h; ++y)
		for (int x = 0; x < w; ++x) {
			int s = 0;
			for (int dy = -1; dy <= 1; ++dy)
				for (int dx = -1; dx <= 1; ++dx)
					s += (2 - std::abs(dx)) * (2 - std::abs(dy)) * px(x + dx, y + dy);
			p[static_cast<std::size_t>(y) * w + x] = (s + 8) >> 4;
		}
	auto P = [&](int x, int y) { return p[static_cast<std::size_t>(y) * w + x]; };
	for (int y = 1; y < h - 1; ++y)
		for (int x = 1; x < w - 1; ++x) {
			const std::size_t i = static_cast<std::size_t>(y) * w + x;
			gx[i] = (P(x + 1, y - 1) + 2 * P(x + 1, y) + P(x + 1, y + 1)) - (P(x - 1, y - 1) + 2 * P(x - 1, y) + P(x - 1, y + 1));
			gy[i] = (P(x - 1, y + 1) + 2 * P(x, y + 1) + P(x + 1, y + 1)) - (P(x - 1, y - 1) + 2 * P(x, y - 1) + P(x + 1, y - 1));
			m[i] = static_cast<std::int64_t>(gx[i]) * gx[i] + static_cast<std::int64_t>(gy[i]) * gy[i];
		}
	auto M = [&](int x, int y) { return m[static_cast<std::size_t>(y) * w + x]; };
	/* The thresholds at brightness p: t (min(p + floor, 128) / 128)^2 in
	 * the contract's two truncating steps. */
	auto scaled = [&](std::int64_t t, int b) {
		const std::int64_t q = std::min(b + prm.light_floor, 128);
		return (((t * q) >> 7) * q) >> 7;
	};
	const std::int64_t E = std::min<std::int64_t>(prm.edge_threshold_sq, std::int64_t{ 1 } << 22);
	std::vector<std::uint8_t> out(p.size(), 0);
	for (int y = 2; y < h - 2; ++y)
		for (int x = 2; x < w - 2; ++x) {
			const std::size_t i = static_cast<std::size_t>(y) * w + x;
			if (!(m[i] > scaled(E, P(x, y))))
				continue;
			const int ax = std::abs(gx[i]), ay = std::abs(gy[i]);
			std::int64_t prev, next;
			if (256 * ay <= 106 * ax) {
				prev = M(x - 1, y);
				next = M(x + 1, y);
			} else if (256 * ax <= 106 * ay) {
				prev = M(x, y - 1);
				next = M(x, y + 1);
			} else if ((gx[i] > 0) == (gy[i] > 0)) {
				prev = M(x - 1, y - 1);
				next = M(x + 1, y + 1);
			} else {
				prev = M(x + 1, y - 1);
				next = M(x - 1, y + 1);
			}
			if (!(m[i] > prev && m[i] >= next))
				continue;
			out[i] = EdgeMap::kEdge;
			std::int64_t sxx = 0, syy = 0, sxy = 0;
			for (int dy = -1; dy <= 1; ++dy)
				for (int dx = -1; dx <= 1; ++dx) {
					const std::size_t j = static_cast<std::size_t>(y + dy) * w + x + dx;
					sxx += gx[j] * gx[j];
					syy += gy[j] * gy[j];
					sxy += gx[j] * gy[j];
				}
			const std::int64_t T = scaled(prm.corner_threshold, P(x, y));
			const std::int64_t c = (sxx + syy - 2 * T) >> 9, a = std::abs(sxx - syy) >> 9, b = std::abs(sxy) >> 8;
			if (c > 0 && c * c > a * a + b * b)
				out[i] |= EdgeMap::kCorner;
		}
	return out;
}

} // namespace

/* The CPU front end (this CPU's best kernels and the scalar ones) against
 * the contract written out literally, at every light floor: absolute
 * thresholds (128), the default (16) and none (0), on frames from dim to
 * bright. The outermost two rows and columns of the frame are left out:
 * the literal form does not replicate smoothed rows there. */
TEST(FrontEnd, FollowsTheDocumentedContractInAnyLight)
{
	std::mt19937 rng(29);
	int edges = 0, corners = 0, relative = 0;
	for (int lightFloor : { 128, 16, 0 }) {
		FrontEndParams prm = defaultParams();
		prm.light_floor = lightFloor;
		for (int gain : { 255, 60, 12 }) {
			/* Squares of random grey on a ramp, with noise: edges of every
			 * strength and direction, at every brightness. */
			Image img(97, 61, 0, 3);
			std::uniform_int_distribution<int> noise(-3, 3);
			for (int y = 0; y < img.height; ++y)
				for (int x = 0; x < img.width; ++x) {
					const int block = ((x / 9) * 7 + (y / 7) * 13) % 17;
					const int v = (block * 15 + x) * gain / 300 + noise(rng);
					img.at(x, y) = static_cast<std::uint8_t>(std::clamp(v, 0, 255));
				}
			const auto want = contractEdgeMap(img, prm);
			for (const detail::BandKernels *k : { &detail::bestBandKernels(), &detail::scalarBandKernels() }) {
				EdgeMap em;
				detail::makeCpuFrontEnd(1, *k)->run(img.view(), 1.0f, prm, em);
				for (int y = 2; y < img.height - 2; ++y)
					for (int x = 2; x < img.width - 2; ++x) {
						const std::size_t i = static_cast<std::size_t>(y) * img.width + x;
						ASSERT_EQ(em.at(x, y), want[i]) << k->name << " at " << x << "," << y << " floor "
										<< lightFloor << " gain " << gain;
					}
			}
			for (std::size_t i = 0; i < want.size(); ++i) {
				edges += want[i] & EdgeMap::kEdge;
				corners += (want[i] & EdgeMap::kCorner) != 0;
			}
			if (lightFloor < 128 && gain == 12)
				relative += static_cast<int>(std::count(want.begin(), want.end(), EdgeMap::kEdge));
		}
	}
	EXPECT_GT(edges, 3000);
	EXPECT_GT(corners, 100);
	/* The dim frames have edges only because the thresholds follow the light. */
	EXPECT_GT(relative, 200);
}

/* A square whose black and white differ by 12 grey levels in a dim frame
 * (black 6, white 18): edges all round at the default light floor, none
 * where the thresholds are absolute (the paper's). */
TEST(FrontEnd, ADimSquareKeepsItsEdges)
{
	Image img(64, 48, 6);
	for (int y = 12; y < 36; ++y)
		for (int x = 16; x < 48; ++x)
			img.at(x, y) = 18;
	auto count = [&](int lightFloor) {
		FrontEndParams prm = defaultParams();
		prm.light_floor = lightFloor;
		EdgeMap em;
		makeCpuFrontEnd(1)->run(img.view(), 1.0f, prm, em);
		int n = 0;
		for (std::uint8_t v : em.pixels)
			n += v & EdgeMap::kEdge;
		return n;
	};
	EXPECT_EQ(count(128), 0);
	EXPECT_GE(count(defaultParams().light_floor), 2 * (32 + 24) - 8);
}

/* frappe::simdTarget() names the kernels that really run: on aarch64 NEON
 * even where Highway's run-time check would not offer it (Debian 12's
 * Highway 1.0.3 asks for AES, which the Pi Zero 2 W's Cortex-A53 lacks; CI
 * also runs this test with AES hidden from the CPU). */
TEST(FrontEnd, SimdTargetNamesTheKernelsThatRun)
{
	const std::string target = simdTarget();
	std::printf("kernels: %s\n", target.c_str());
#if defined(FRAPPE_TEST_HWY_TARGETS)
	std::string offered;
	for (const std::int64_t t : hwy::SupportedAndGeneratedTargets())
		offered += std::string(offered.empty() ? "" : ", ") + hwy::TargetName(t);
	std::printf("Highway's run-time check offers: %s\n", offered.c_str());
#endif
#if defined(__aarch64__) && defined(FRAPPE_TEST_HWY_TARGETS)
	EXPECT_EQ(target, "NEON");
	/* tests/cross/hide_aes.cpp took effect: Highway's check declines NEON. */
	if (std::getenv("FRAPPE_TEST_NO_AES")) {
		EXPECT_EQ(offered.find("NEON"), std::string::npos) << offered;
	}
#elif defined(FRAPPE_TEST_HWY_TARGETS)
	/* Dynamic dispatch: the best target built that this CPU has. */
	EXPECT_EQ(target, hwy::TargetName(hwy::SupportedAndGeneratedTargets().front()));
#elif defined(FRAPPE_HAVE_ARMV6_KERNELS)
	EXPECT_EQ(target, "ARMv6 SIMD32");
#else
	EXPECT_EQ(target, "scalar");
#endif
}

TEST(FrontEnd, ParamsFollowTheConfig)
{
	const FrontEndParams p = defaultParams();
	/* (0.27 * 255)^2 = 4740.2 and 0.19 * 255^2 = 12354.75 */
	EXPECT_EQ(p.edge_threshold_sq, 4740);
	EXPECT_EQ(p.corner_threshold, 12354);
	/* 0.063 * 255 = 16.07 */
	EXPECT_EQ(p.light_floor, 16);
	Config absolute;
	absolute.light_floor = 0.9f;
	EXPECT_EQ(Detector(absolute).frontEndParams().light_floor, FrontEndParams::kLightReference);
}

TEST(FrontEnd, EdgesOfASquareLieOnItsBoundary)
{
	const Image img = square(64, 48, 16, 12, 48, 36);
	EdgeMap em;
	makeCpuFrontEnd(1)->run(img.view(), 1.0f, defaultParams(), em);
	ASSERT_EQ(em.width, 64);
	ASSERT_EQ(em.height, 48);
	int edges = 0;
	for (int y = 0; y < 48; ++y) {
		for (int x = 0; x < 64; ++x) {
			if (!(em.at(x, y) & EdgeMap::kEdge))
				continue;
			++edges;
			/* Within a pixel of the step between columns 15|16, 47|48 or rows 11|12, 35|36. */
			const bool nearV = (x >= 15 && x <= 16) || (x >= 47 && x <= 48);
			const bool nearH = (y >= 11 && y <= 12) || (y >= 35 && y <= 36);
			EXPECT_TRUE((nearV && y >= 10 && y <= 37) || (nearH && x >= 14 && x <= 49))
				<< "edge at " << x << "," << y;
		}
	}
	/* One line per side: about the perimeter, not a double line. */
	EXPECT_GE(edges, 2 * (32 + 24) - 8);
	EXPECT_LE(edges, 2 * (32 + 24) + 8);
	/* Every side is present. */
	for (int y = 14; y < 34; ++y) {
		EXPECT_TRUE((em.at(15, y) | em.at(16, y)) & EdgeMap::kEdge) << y;
		EXPECT_TRUE((em.at(47, y) | em.at(48, y)) & EdgeMap::kEdge) << y;
	}
}

TEST(FrontEnd, CornersOnlyNearTheFourCorners)
{
	const Image img = square(64, 48, 16, 12, 48, 36);
	EdgeMap em;
	makeCpuFrontEnd(1)->run(img.view(), 1.0f, defaultParams(), em);
	const int cx[4] = { 16, 47, 47, 16 }, cy[4] = { 12, 12, 35, 35 };
	int near[4] = {};
	for (int y = 0; y < 48; ++y) {
		for (int x = 0; x < 64; ++x) {
			if (!(em.at(x, y) & EdgeMap::kCorner))
				continue;
			EXPECT_TRUE(em.at(x, y) & EdgeMap::kEdge) << "corners are edge pixels";
			bool ok = false;
			for (int k = 0; k < 4; ++k) {
				if (std::abs(x - cx[k]) <= 3 && std::abs(y - cy[k]) <= 3) {
					++near[k];
					ok = true;
				}
			}
			EXPECT_TRUE(ok) << "corner pixel at " << x << "," << y << " far from every corner";
		}
	}
	for (int k = 0; k < 4; ++k)
		EXPECT_GE(near[k], 1) << "corner " << k << " not marked";
}

TEST(FrontEnd, OuterFrameIsAlwaysClear)
{
	/* A pattern that would put edges everywhere. */
	Image img(40, 30);
	for (int y = 0; y < 30; ++y)
		for (int x = 0; x < 40; ++x)
			img.at(x, y) = ((x / 2 + y / 2) & 1) ? 250 : 5;
	EdgeMap em;
	makeCpuFrontEnd(1)->run(img.view(), 1.0f, defaultParams(), em);
	for (int x = 0; x < 40; ++x) {
		EXPECT_EQ(em.at(x, 0), 0);
		EXPECT_EQ(em.at(x, 29), 0);
	}
	for (int y = 0; y < 30; ++y) {
		EXPECT_EQ(em.at(0, y), 0);
		EXPECT_EQ(em.at(39, y), 0);
	}
}

TEST(FrontEnd, TileMaskMarksExactlyTheTilesWithEdges)
{
	/* A flat image has no edges and no occupied tiles. */
	Image flat(100, 70, 77);
	EdgeMap em;
	makeCpuFrontEnd(1)->run(flat.view(), 1.0f, defaultParams(), em);
	EXPECT_EQ(em.tiles_x, 7);
	EXPECT_EQ(em.tiles_y, 5);
	for (std::uint8_t t : em.tiles)
		EXPECT_EQ(t, 0);

	const Image img = square(100, 70, 40, 40, 60, 60);
	makeCpuFrontEnd(1)->run(img.view(), 1.0f, defaultParams(), em);
	for (int ty = 0; ty < em.tiles_y; ++ty) {
		for (int tx = 0; tx < em.tiles_x; ++tx) {
			bool any = false;
			for (int y = ty * 16; y < std::min(70, ty * 16 + 16); ++y)
				for (int x = tx * 16; x < std::min(100, tx * 16 + 16); ++x)
					any = any || (em.at(x, y) & EdgeMap::kEdge);
			EXPECT_EQ(em.tileEmpty(tx, ty), !any) << tx << "," << ty;
		}
	}
}

TEST(FrontEnd, SameEdgesForAnyStrideAndThreadCount)
{
	Image tight(203, 157);
	Image padded(203, 157, 128, 37);
	std::mt19937 rng(5);
	test::addNoise(tight, 40.0f, rng);
	for (int y = 0; y < 157; ++y)
		for (int x = 0; x < 203; ++x)
			padded.at(x, y) = tight.at(x, y);
	/* Garbage in the padding must not matter. */
	for (int y = 0; y < 157; ++y)
		for (int x = 203; x < 240; ++x)
			padded.pixels[static_cast<std::size_t>(y) * padded.stride + x] = static_cast<std::uint8_t>(x * 7);
	EdgeMap a, b, c;
	makeCpuFrontEnd(1)->run(tight.view(), 1.0f, defaultParams(), a);
	makeCpuFrontEnd(1)->run(padded.view(), 1.0f, defaultParams(), b);
	makeCpuFrontEnd(3)->run(tight.view(), 1.0f, defaultParams(), c);
	EXPECT_EQ(a.pixels, b.pixels);
	EXPECT_EQ(a.pixels, c.pixels);
	EXPECT_EQ(a.tiles, c.tiles);
}

TEST(FrontEnd, ScalingSamplesTheNearestPixel)
{
	EXPECT_EQ(scaledLength(640, 0.5f), 320);
	EXPECT_EQ(scaledLength(640, 1.0f), 640);
	EXPECT_EQ(scaledLength(3, 0.1f), 1);
	const Image img = square(128, 96, 32, 32, 96, 64);
	EdgeMap em;
	makeCpuFrontEnd(1)->run(img.view(), 0.5f, defaultParams(), em);
	EXPECT_EQ(em.width, 64);
	EXPECT_EQ(em.height, 48);
	EXPECT_FLOAT_EQ(em.scale, 0.5f);
	/* The square maps to [16, 48) x [16, 32): its left side is at 15|16. */
	EXPECT_TRUE((em.at(15, 24) | em.at(16, 24)) & EdgeMap::kEdge);
	EXPECT_FALSE(em.at(30, 24) & EdgeMap::kEdge);
}

/* The vectorised kernels must give the scalar kernels' bytes on every
 * width (vector bodies, tails, both), on saturated gradients and on dense
 * corners: on every instruction set Highway compiled them for and this CPU
 * runs (AVX-512, AVX2, SSE4, SSSE3... each has its own code paths, and
 * Highway 1.0.3 has had a wrong operation on one of them). */
void expectVectorKernelsMatchScalar(const char *target)
{
	const detail::BandKernels &best = detail::bestBandKernels();
	const detail::BandKernels &scalar = detail::scalarBandKernels();
	auto scalarFe = detail::makeCpuFrontEnd(1, scalar);
	auto bestFe = detail::makeCpuFrontEnd(1, best);
	SCOPED_TRACE(target);

	FrontEndParams loose = defaultParams();
	loose.edge_threshold_sq = 10;
	loose.corner_threshold = 0;
	FrontEndParams absolute = defaultParams(), dark = defaultParams();
	absolute.light_floor = FrontEndParams::kLightReference;
	dark.light_floor = 0;
	const FrontEndParams paramsList[] = { defaultParams(), loose, absolute, dark };

	std::mt19937 rng(11);
	int compared = 0, edges = 0, corners = 0;
	for (int w : { 1, 2, 3, 4, 5, 7, 9, 15, 16, 17, 31, 33, 47, 64, 65, 100, 257, 641 }) {
		for (int kind = 0; kind < 3; ++kind) {
			const int h = 3 + (w * 7 + kind * 5) % 41;
			Image img(w, h, 0, kind == 1 ? 13 : 0);
			std::uniform_int_distribution<int> any(0, 255), coin(0, 1);
			for (int y = 0; y < h; ++y)
				for (int x = 0; x < w; ++x) {
					if (kind == 0) /* noise: edges everywhere */
						img.at(x, y) = static_cast<std::uint8_t>(any(rng));
					else if (kind == 1) /* 0/255 blocks: the largest gradients */
						img.at(x, y) = ((x / 3 + y / 2) & 1) ? 255 : 0;
					else /* smooth ramps with sparse spikes */
						img.at(x, y) = static_cast<std::uint8_t>(
							(x * 5 + y * 3) % 256 ^ (coin(rng) && coin(rng) ? 255 : 0));
				}
			for (const FrontEndParams &p : paramsList) {
				EdgeMap a, b;
				scalarFe->run(img.view(), 1.0f, p, a);
				bestFe->run(img.view(), 1.0f, p, b);
				ASSERT_EQ(a.pixels, b.pixels) << "width " << w << " kind " << kind;
				ASSERT_EQ(a.tiles, b.tiles) << "width " << w << " kind " << kind;
				for (std::uint8_t v : a.pixels) {
					edges += v & EdgeMap::kEdge;
					corners += (v & EdgeMap::kCorner) != 0;
				}
				++compared;
			}
		}
	}
	/* The comparison must have covered edges and corners, not blank maps. */
	EXPECT_GT(edges, 10000);
	EXPECT_GT(corners, 1000);
	EXPECT_EQ(compared, 18 * 3 * 4);
}

TEST(FrontEnd, VectorKernelsMatchTheScalarOnesByteForByte)
{
	if (&detail::bestBandKernels() == &detail::scalarBandKernels())
		GTEST_SKIP() << "built without Highway: only the scalar kernels exist";
	test::onEveryTarget(expectVectorKernelsMatchScalar);
}
