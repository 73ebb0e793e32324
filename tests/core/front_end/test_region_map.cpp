// SPDX-License-Identifier: MIT
// The region map: its row kernels against their scalar references on every
// Highway target, the whole map against a slow transcription of the rule at
// the top of front_end_cpu.cpp, and what it is for: strongly blurred
// markers, whose edge ring opens, found through their dark regions.
#include <algorithm>
#include <cstdio>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "every_target.h"
#include "frappe/frappe.h"
#include "frappe/render.h"
#include "front_end_rows.h"
#include "region_map.h"
#include "scene.h"

using namespace frappe;
using frappe::test::Image;
using frappe::test::onEveryTarget;

namespace {

std::vector<std::uint8_t> randomBytes(std::size_t n, std::mt19937 &rng)
{
	std::vector<std::uint8_t> v(n);
	for (auto &b : v)
		b = static_cast<std::uint8_t>(rng() & 0xFF);
	return v;
}

/* The documented rule, pixel by pixel. */
std::vector<std::uint8_t> slowRegionMap(const Image &img, int minContrast, int lightFloor, int &w, int &h,
					bool shade = false)
{
	w = img.width / 2;
	h = img.height / 2;
	std::vector<int> r(static_cast<std::size_t>(w) * h);
	for (int y = 0; y < h; ++y)
		for (int x = 0; x < w; ++x) {
			const auto &p = img.pixels;
			const int s = img.stride;
			r[y * w + x] = (p[2 * y * s + 2 * x] + p[2 * y * s + 2 * x + 1] + p[(2 * y + 1) * s + 2 * x] +
					p[(2 * y + 1) * s + 2 * x + 1] + 2) >> 2;
		}
	const int tx = (w + 3) / 4, ty = (h + 3) / 4;
	std::vector<std::uint8_t> out(static_cast<std::size_t>(w) * h, 0);
	for (int y = 1; y < h - 1; ++y)
		for (int x = 1; x < w - 1; ++x) {
			int lo = 255, hi = 0;
			for (int j = std::max(0, y / 4 - 1); j <= std::min(ty - 1, y / 4 + 1); ++j)
				for (int i = std::max(0, x / 4 - 1); i <= std::min(tx - 1, x / 4 + 1); ++i)
					for (int yy = 4 * j; yy < std::min(h, 4 * j + 4); ++yy)
						for (int xx = 4 * i; xx < std::min(w, 4 * i + 4); ++xx) {
							lo = std::min(lo, r[yy * w + xx]);
							hi = std::max(hi, r[yy * w + xx]);
						}
			/* The contrast follows the light below mid-grey. */
			const int need = (minContrast * std::min(lo + hi + 2 * lightFloor, 256) + 255) >> 8;
			/* The region map: below the midpoint; the shade map: below the
			 * geometric mean, with 4 added. */
			const int v = r[y * w + x];
			const bool below = shade ? (v + 4) * (v + 4) < (lo + 4) * (hi + 4) : v < ((lo + hi + 1) >> 1);
			out[y * w + x] = hi - lo >= need && below ? 1 : 0;
		}
	return out;
}

} // namespace

TEST(RegionMap, RowKernelsMatchTheirScalarReferences)
{
	onEveryTarget([](const char *target) {
		std::mt19937 rng(7);
		for (int w : { 1, 2, 15, 16, 17, 63, 64, 65, 320, 333 }) {
			const auto a0 = randomBytes(2 * w + 1, rng), a1 = randomBytes(2 * w + 1, rng);
			std::vector<std::uint8_t> got(w + 1, 0xAA), want(w + 1, 0xAA);
			detail::decimateRow(a0.data(), a1.data(), w, got.data());
			detail::decimateRowScalar(a0.data(), a1.data(), w, want.data());
			EXPECT_EQ(got, want) << target << " decimate, w " << w;
			for (bool least : { true, false }) {
				detail::extremePairs(a0.data(), a1.data(), w, got.data(), least);
				detail::extremePairsScalar(a0.data(), a1.data(), w, want.data(), least);
				EXPECT_EQ(got, want) << target << (least ? " min" : " max") << " pairs, w " << w;
			}
			bool anyGot = detail::darkRow(a0.data(), a1.data(), w, got.data());
			bool anyWant = detail::darkRowScalar(a0.data(), a1.data(), w, want.data());
			EXPECT_EQ(got, want) << target << " dark row, w " << w;
			EXPECT_EQ(anyGot, anyWant) << target;
			/* A row with nothing dark says so. */
			const std::vector<std::uint8_t> zeros(w, 0);
			EXPECT_FALSE(detail::darkRow(a0.data(), zeros.data(), w, got.data())) << target;
		}
#ifdef FRAPPE_HAVE_HWY
		/* The 3 x 3 spread of the tile extremes, rows of every length. */
		for (auto [tx, ty] : { std::pair{ 1, 1 }, { 2, 3 }, { 15, 4 }, { 16, 2 }, { 17, 5 }, { 63, 3 }, { 80, 60 }, { 131, 7 } }) {
			const std::size_t nt = static_cast<std::size_t>(tx) * ty;
			auto mn = randomBytes(nt, rng), mx = randomBytes(nt, rng);
			auto mn2 = mn, mx2 = mx;
			std::vector<std::uint8_t> work(4 * static_cast<std::size_t>(tx) + 4);
			detail::spreadTiles(mn.data(), mx.data(), tx, ty, work.data());
			detail::spreadTilesScalar(mn2.data(), mx2.data(), tx, ty, work.data());
			EXPECT_EQ(mn, mn2) << target << " spread min " << tx << "x" << ty;
			EXPECT_EQ(mx, mx2) << target << " spread max " << tx << "x" << ty;
		}
#endif
		/* The tiles' thresholds: every pair of extremes (hi below lo
		 * too), in rows of every length, at each light floor. */
		for (int lightFloor : { 0, 16, 100, FrontEndParams::kLightReference })
			for (int contrast : { 1, 41, 255 })
				for (int tx : { 1, 7, 16, 17, 80, 256 }) {
					FrontEndParams params;
					params.region_contrast = contrast;
					params.light_floor = lightFloor;
					for (int start = 0; start < 65536; start += tx < 16 ? 61 * tx : tx) {
						const int n = std::min(tx, 65536 - start);
						std::vector<std::uint8_t> lo(n), hi(n);
						for (int i = 0; i < n; ++i) {
							lo[i] = static_cast<std::uint8_t>((start + i) >> 8);
							hi[i] = static_cast<std::uint8_t>(start + i);
						}
						std::vector<std::uint8_t> mid(4 * n + 1, 0xAA), mid2 = mid, shade = mid,
												shade2 = mid;
						detail::tileThresholds(lo.data(), hi.data(), n, params, true,
								       mid.data(), shade.data());
						detail::tileThresholdsScalar(lo.data(), hi.data(), n, params, true,
									     mid2.data(), shade2.data());
						ASSERT_EQ(mid, mid2) << target << " tile midpoints from " << start;
						ASSERT_EQ(shade, shade2)
							<< target << " shade thresholds from " << start;
						std::vector<std::uint8_t> alone(4 * n + 1, 0xAA);
						detail::tileThresholds(lo.data(), hi.data(), n, params, false,
								       alone.data(), nullptr);
						ASSERT_EQ(alone, mid2)
							<< target << " midpoints without shades from " << start;
					}
				}
	});
}

/* The one-pass references of the ARMv6 kernels (tests/armv6 compares the
 * kernels with them): a tile's extremes over its rows and columns that
 * exist, and the dark row marking its 16-pixel tiles. */
TEST(RegionMap, OnePassReferences)
{
	std::mt19937 rng(5);
	for (int w : { 1, 3, 4, 5, 8, 17, 33, 320 })
		for (int n = 1; n <= 4; ++n) {
			const int stride = w + 3;
			const auto rows = randomBytes(static_cast<std::size_t>(4) * stride, rng);
			const int tx = (w + 3) / 4;
			std::vector<std::uint8_t> mn(tx + 1, 0xAA), mx(tx + 1, 0xAA);
			detail::tileExtremesScalar(rows.data(), stride, n, w, mn.data(), mx.data());
			for (int i = 0; i < tx; ++i) {
				int lo = 255, hi = 0;
				for (int y = 0; y < n; ++y)
					for (int x = 4 * i; x < std::min(w, 4 * i + 4); ++x) {
						lo = std::min<int>(lo, rows[y * stride + x]);
						hi = std::max<int>(hi, rows[y * stride + x]);
					}
				EXPECT_EQ(mn[i], lo) << "w " << w << " n " << n << " tile " << i;
				EXPECT_EQ(mx[i], hi) << "w " << w << " n " << n << " tile " << i;
			}
			EXPECT_EQ(mn[tx], 0xAA);
			EXPECT_EQ(mx[tx], 0xAA);

			const auto d = randomBytes(w, rng), mid = randomBytes(w, rng);
			const int nt = (w + 15) / 16;
			std::vector<std::uint8_t> tiles(nt), want(w), got(w);
			for (auto &t : tiles)
				t = static_cast<std::uint8_t>(rng() & 1);
			auto wantTiles = tiles;
			const bool anyWant = detail::darkRowScalar(d.data(), mid.data(), w, want.data());
			for (int x = 0; x < w; ++x)
				wantTiles[x / 16] |= want[x];
			EXPECT_EQ(detail::darkRowTilesScalar(d.data(), mid.data(), w, got.data(), tiles.data()), anyWant);
			EXPECT_EQ(got, want);
			EXPECT_EQ(tiles, wantTiles);
		}
}

TEST(RegionMap, FollowsTheDocumentedRuleAtOddSizesAndStrides)
{
	onEveryTarget([](const char *target) {
		std::mt19937 rng(11);
		for (auto [W, H, pad] : { std::tuple{ 640, 480, 0 }, { 37, 29, 5 }, { 6, 6, 0 }, { 101, 67, 3 }, { 250, 9, 1 } }) {
			Image img(W, H, 0, pad);
			/* Blocks of random grey with noise: every kind of tile. */
			for (int y = 0; y < H; ++y)
				for (int x = 0; x < W; ++x)
					img.at(x, y) = static_cast<std::uint8_t>(((x / 7 + y / 5) * 53 + rng() % 40) & 0xFF);
			for (auto [contrast, lightFloor] : { std::pair{ 1, 128 }, { 40, 128 }, { 200, 128 }, { 40, 16 }, { 200, 0 }, { 41, 16 } }) {
				int w, h;
				TraceMap map, shades;
				detail::RegionScratch scratch;
				FrontEndParams params;
				params.region_contrast = contrast;
				params.light_floor = lightFloor;
				detail::regionMap(img.view(), 1.0f, params, map, shades, scratch);
				/* The shade map exactly when the thresholds follow the light. */
				EXPECT_EQ(shades.width > 0, lightFloor < 128);
				for (bool shade : { false, true }) {
					const TraceMap &got = shade ? shades : map;
					if (shade && lightFloor >= 128)
						continue;
					const auto want = slowRegionMap(img, contrast, lightFloor, w, h, shade);
					ASSERT_EQ(got.width, w);
					ASSERT_EQ(got.height, h);
					EXPECT_EQ(got.pixels, want) << target << " " << W << "x" << H << " contrast " << contrast
								    << " light floor " << lightFloor << (shade ? " shades" : "");
					EXPECT_FLOAT_EQ(got.scale, 0.5f);
					for (int ty = 0; ty < got.tiles_y; ++ty)
						for (int tx = 0; tx < got.tiles_x; ++tx) {
							bool any = false;
							for (int y = ty * 16; y < std::min(h, ty * 16 + 16); ++y)
								for (int x = tx * 16; x < std::min(w, tx * 16 + 16); ++x)
									any = any || want[y * w + x];
							EXPECT_EQ(!got.tileEmpty(tx, ty), any) << target << " tile " << tx << "," << ty;
						}
				}
			}
		}
	});
}

/* The shade map's threshold is its definition, the least r with (r + 4)^2 >=
 * (lo + 4)(hi + 4), for every pair of tile extremes. */
TEST(RegionMap, ShadeThresholdIsTheLeastRootForEveryPair)
{
	int wrong = 0;
	for (int lo = 0; lo < 256; ++lo)
		for (int hi = 0; hi < 256; ++hi) {
			const int p = (lo + 4) * (hi + 4);
			int want = 0;
			while ((want + 4) * (want + 4) < p)
				++want;
			const int got = FrontEndParams::shadeThreshold(lo, hi);
			if (got != want && ++wrong <= 5)
				ADD_FAILURE() << "lo " << lo << " hi " << hi << ": " << got << ", want " << want;
		}
	EXPECT_EQ(wrong, 0);
	/* The extremes: a black tile, a white one. */
	EXPECT_EQ(FrontEndParams::shadeThreshold(0, 0), 0);
	EXPECT_EQ(FrontEndParams::shadeThreshold(255, 255), 255);
	EXPECT_EQ(FrontEndParams::shadeThreshold(0, 255), 29); /* 32^2 = 1024 < 1036 <= 33^2 = (29 + 4)^2 */
}

/* The CPU front end makes the map's 2x2 means in its bands, as it reads the
 * frame: the same map as regionMap() at every size and stride, with one band
 * or several, and of the scaled frame when it scales. */
TEST(RegionMap, FrontEndBandsMakeTheSameMap)
{
	std::mt19937 rng(5);
	for (auto [W, H, pad] : { std::tuple{ 640, 480, 0 }, { 37, 29, 5 }, { 6, 6, 0 }, { 101, 67, 3 }, { 250, 49, 1 } }) {
		Image img(W, H, 0, pad);
		for (int y = 0; y < H; ++y)
			for (int x = 0; x < W; ++x)
				img.at(x, y) = static_cast<std::uint8_t>(((x / 7 + y / 5) * 53 + rng() % 40) & 0xFF);
		for (int threads : { 1, 2, 3 })
			for (float scale : { 1.0f, 0.6f }) {
				FrontEndParams params;
				params.region_contrast = 40;
				params.light_floor = 16;
				EdgeMap edges;
				makeCpuFrontEnd(threads)->run(img.view(), scale, params, edges);
				/* The reference, from the frame the front end traced. */
				Image src(edges.width, edges.height, 0);
				if (scale < 1.0f)
					detail::scaleNearest(img.view(), edges.width, edges.height, src.pixels.data());
				else
					src = img;
				TraceMap want, wantShades;
				detail::RegionScratch scratch;
				detail::regionMap(src.view(), edges.scale, params, want, wantShades, scratch);
				EXPECT_EQ(edges.regions.width, want.width) << W << "x" << H;
				EXPECT_EQ(edges.regions.pixels, want.pixels)
					<< W << "x" << H << " threads " << threads << " scale " << scale;
				EXPECT_EQ(edges.regions.tiles, want.tiles) << W << "x" << H;
				EXPECT_FLOAT_EQ(edges.regions.scale, want.scale);
				EXPECT_EQ(edges.shades.pixels, wantShades.pixels) << W << "x" << H << " shades";
				EXPECT_EQ(edges.shades.tiles, wantShades.tiles) << W << "x" << H << " shades";
			}
	}
}

TEST(RegionMap, EmptyWhenOffOrTooSmall)
{
	Image img(5, 100, 0);
	TraceMap map;
	detail::RegionScratch scratch;
	FrontEndParams params;
	params.region_contrast = 40;
	params.light_floor = 16;
	TraceMap shades;
	detail::regionMap(img.view(), 1.0f, params, map, shades, scratch);
	EXPECT_EQ(map.width, 0);
	EXPECT_EQ(shades.width, 0);
	Image big(64, 64, 0);
	params.region_contrast = 0;
	detail::regionMap(big.view(), 1.0f, params, map, shades, scratch);
	EXPECT_EQ(shades.width, 0);
	EXPECT_EQ(map.width, 0);
}

/* A marker smeared by a 12 px motion blur and a defocus: its edges spread
 * over more than a cell and the edge ring opens. The region candidates find
 * it, with its corners; without them it is lost. */
TEST(RegionCandidates, FindAStronglyBlurredMarker)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	int found = 0, foundWithout = 0, tried = 0;
	for (int k = 0; k < 6; ++k) {
		Image img(320, 240, 110);
		const float side = 90.0f + 8.0f * k;
		const auto corners = test::squarePose(160.0f, 120.0f, side, 10.0f + 13.0f * k, 20.0f);
		renderMarker(img.mut(), dict, 7 + k, corners);
		test::motionBlur(img, 12.0f, 0.2f * k);
		test::blur(img, 1.5f);
		std::mt19937 rng(k);
		test::addNoise(img, 3.0f, rng);
		Config on, off;
		off.region_contrast = 0.0f;
		Detector withRegions(on), without(off);
		const Marker *m = test::findMarker(withRegions.detect(img.view()).markers, 7 + k);
		++tried;
		if (m && test::meanCornerError(m->corners, corners) < 1.0f)
			++found;
		if (test::findMarker(without.detect(img.view()).markers, 7 + k))
			++foundWithout;
	}
	std::printf("found %d of %d with region candidates, %d without\n", found, tried, foundWithout);
	EXPECT_EQ(found, tried);
	EXPECT_LT(foundWithout, tried / 2);
}
