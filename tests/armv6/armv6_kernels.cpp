// SPDX-License-Identifier: MIT
// The ARMv6 SIMD32 row kernels (frappe-core/src/front_end/front_end_armv6.cpp) against
// the scalar reference, byte for byte. Built for the ARM1176 by the cross
// compiler and run under `qemu-arm -cpu arm1176` (see meson.build here), so
// an ARMv7 or NEON instruction would also fail it (SIGILL).
//
// usage: armv6-kernels [--quick] [image.pgm ...]
// Checks smoothRow and gradientRow on random rows (all widths 1..96 and
// some large ones, unaligned inputs, extreme values), then the whole CPU
// front end (EdgeMap pixels and tiles) on constructed images with several
// thresholds, and on each binary PGM (P5) given.
#include <algorithm>
#include <bit>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "contour_trace.h"
#include "frappe/edge_map.h"
#include "front_end_rows.h"
#include "region_map.h"
#include "trace_kernels.h"

using namespace frappe;
using namespace frappe::detail;

#if !defined(FRAPPE_HAVE_ARMV6_KERNELS) || !defined(FRAPPE_HAVE_ARMV6_REGION) || !defined(FRAPPE_HAVE_ARMV6_TRACE)
int main()
{
	std::puts("armv6-kernels: not an ARMv6 SIMD32 build; skipped");
	return 77;
}
#else

namespace {

int failures = 0;

#define CHECK(cond, ...)                                                     \
	do {                                                                 \
		if (!(cond)) {                                               \
			std::printf("FAIL %s:%d: ", __FILE__, __LINE__);   \
			std::printf(__VA_ARGS__);                            \
			std::printf("\n");                                   \
			if (++failures > 20)                                 \
				std::exit(1);                                \
		}                                                            \
	} while (0)

std::mt19937 rng(12345);

/* A row of random bytes: uniform, or only the extremes, or a smooth ramp
 * with noise (the realistic case). */
void fillRow(std::uint8_t *p, int w, int kind)
{
	std::uniform_int_distribution<int> u(0, 255);
	int v = u(rng);
	for (int x = 0; x < w; ++x) {
		switch (kind) {
		case 0: p[x] = static_cast<std::uint8_t>(u(rng)); break;
		case 1: p[x] = (u(rng) & 1) ? 255 : 0; break;
		default:
			v = std::clamp(v + u(rng) % 9 - 4, 0, 255);
			p[x] = static_cast<std::uint8_t>(v);
		}
	}
}

void checkRows(const RowKernels &ref, const RowKernels &k, int w, int kind, int misalign)
{
	/* Three input rows at an unaligned offset, with guard bytes. */
	std::vector<std::uint8_t> buf(3 * (w + 16));
	std::uint8_t *a = buf.data() + misalign;
	std::uint8_t *b = a + w + 16 - misalign;
	std::uint8_t *c = b + w + 16;
	fillRow(a, w, kind);
	fillRow(b, w, kind);
	fillRow(c, w, kind);
	std::vector<std::uint16_t> tmp(w);
	/* The ARMv6 smoothing stores its row lane-split (armv6SmoothedOffset). */
	const std::size_t s16 = 2 * static_cast<std::size_t>(w) + 8;
	std::vector<std::uint8_t> o1(w, 0xAB), o2(s16 + 8, 0xAB);
	ref.smooth(a, b, c, w, o1.data(), tmp.data());
	k.smooth(a, b, c, w, o2.data(), tmp.data());
	for (int x = 0; x < w; ++x) {
		std::uint16_t v;
		std::memcpy(&v, o2.data() + armv6SmoothedOffset(x), 2);
		CHECK(o1[x] == v, "smoothRow w=%d kind=%d x=%d: %d vs %d", w, kind, x, o1[x], v);
	}
	for (std::size_t i = s16; i < s16 + 8; ++i)
		CHECK(o2[i] == 0xAB, "smoothRow w=%d wrote past its row", w);
	if (w < 3)
		return;
	/* The gradient kernels take the rows in their smoothing's layout. */
	std::vector<std::uint8_t> la(s16, 0), lb(s16, 0), lc(s16, 0);
	for (int x = 0; x < w; ++x) {
		const std::uint16_t va = a[x], vb = b[x], vc = c[x];
		std::memcpy(la.data() + armv6SmoothedOffset(x), &va, 2);
		std::memcpy(lb.data() + armv6SmoothedOffset(x), &vb, 2);
		std::memcpy(lc.data() + armv6SmoothedOffset(x), &vc, 2);
	}

	std::vector<std::int16_t> gx(2 * w + 8, 0x5555), gy(2 * w + 8, 0x5555), rgx(w), rgy(w), sep(2 * w + 16);
	std::vector<std::int32_t> mag(w + 4, 0x55555555), rmag(w);
	ref.gradient(a, b, c, w, rgx.data(), rgy.data(), rmag.data(), sep.data());
	k.gradient(la.data(), lb.data(), lc.data(), w, gx.data(), gy.data(), mag.data(), sep.data());
	for (int x = 0; x < w; ++x) {
		/* The ARMv6 kernel stores (gx, gy) pairs in the gx buffer. */
		CHECK(gx[2 * x] == rgx[x] && gx[2 * x + 1] == rgy[x] && mag[x] == rmag[x],
		      "gradientRow w=%d kind=%d x=%d: (%d,%d,%" PRId32 ") vs (%d,%d,%" PRId32 ")", w, kind, x,
		      gx[2 * x], gx[2 * x + 1], mag[x], rgx[x], rgy[x], rmag[x]);
	}
	for (int i = 2 * w; i < 2 * w + 8; ++i)
		CHECK(gx[i] == 0x5555, "gradientRow w=%d wrote past the row", w);
	for (int x = w; x < w + 4; ++x)
		CHECK(mag[x] == 0x55555555, "gradientRow w=%d wrote past mag", w);
}

/* The tile marking of an edge row (both front ends call markTiles, so the
 * front-end comparisons cannot tell it apart from its reference). */
void checkMarkTiles(int w, int misalign)
{
	std::vector<std::uint8_t> row(w + 8, 0);
	for (int x = 0; x < w; ++x)
		row[misalign + x] = rng() % 23 == 0 ? static_cast<std::uint8_t>(1 + rng() % 3) : 0;
	const int nt = (w + 15) / 16;
	std::vector<std::uint8_t> t1(nt + 2), t2;
	for (auto &t : t1)
		t = static_cast<std::uint8_t>(rng() % 5 == 0);
	t2 = t1;
	markTilesScalar(row.data() + misalign, w, t1.data());
	markTilesV6(row.data() + misalign, w, t2.data());
	CHECK(t1 == t2, "markTiles w=%d misalign=%d", w, misalign);
}

struct Gray {
	int w = 0, h = 0;
	std::vector<std::uint8_t> px;
};

/* Blurred bright and dark rectangles, a checkerboard patch and noise: edges
 * in every direction, corners, flat areas. */
Gray constructed(int w, int h, int noise, unsigned seed)
{
	std::mt19937 r(seed);
	Gray g{ w, h, std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h) };
	std::vector<float> f(g.px.size(), 128.0f);
	std::uniform_int_distribution<int> ux(0, w - 1), uy(0, h - 1), uv(0, 255);
	for (int n = 0; n < 12; ++n) {
		const int x0 = ux(r), y0 = uy(r), x1 = std::min(w, x0 + 8 + ux(r) / 3), y1 = std::min(h, y0 + 8 + uy(r) / 3);
		const float v = static_cast<float>(uv(r));
		for (int y = y0; y < y1; ++y)
			for (int x = x0; x < x1; ++x)
				f[static_cast<std::size_t>(y) * w + x] = v;
	}
	for (int y = h / 3; y < std::min(h, h / 3 + 40); ++y)
		for (int x = w / 2; x < std::min(w, w / 2 + 40); ++x)
			f[static_cast<std::size_t>(y) * w + x] = (((x / 7) + (y / 5)) & 1) ? 230.0f : 20.0f;
	/* A diagonal edge. */
	for (int y = 0; y < h; ++y)
		for (int x = 0; x < w / 4; ++x)
			if (x + y < w / 4)
				f[static_cast<std::size_t>(y) * w + x] = 250.0f;
	std::normal_distribution<float> nd(0.0f, static_cast<float>(noise));
	for (std::size_t i = 0; i < f.size(); ++i)
		g.px[i] = static_cast<std::uint8_t>(std::clamp(f[i] + (noise ? nd(r) : 0.0f), 0.0f, 255.0f));
	return g;
}

bool readPgm(const char *path, Gray &g)
{
	FILE *f = std::fopen(path, "rb");
	if (!f)
		return false;
	int maxv = 0;
	const bool ok = std::fscanf(f, "P5 %d %d %d", &g.w, &g.h, &maxv) == 3 && maxv == 255 && g.w > 0 && g.h > 0 &&
			std::fgetc(f) != EOF;
	if (ok) {
		g.px.resize(static_cast<std::size_t>(g.w) * g.h);
		if (std::fread(g.px.data(), 1, g.px.size(), f) != g.px.size()) {
			std::fclose(f);
			return false;
		}
	}
	std::fclose(f);
	return ok;
}

/* Calls every other accepted quad a marker, so that sealing runs too. */
class EveryOtherProbe : public MarkerProbe
{
public:
	bool isMarker(Quad &) override { return (n_++ & 1) != 0; }

private:
	int n_ = 0;
};

/* The tracer with the ARMv6 walk and with the portable one: the same
 * quads, bit for bit, and as many borders; as an edge map and as a region
 * map is traced, each with and without a probe, and with and without the
 * corner pixels (the walk without them, frappe_armv6_follow_bare). */
void compareTracers(const TraceMap &map, const char *what)
{
	if (map.width < 3 || map.height < 3)
		return;
	for (int kind = 0; kind < 8; ++kind) {
		TraceParams params;
		if (kind & 1) {
			params.min_clusters = 0;
			params.max_winding = 2.0f;
			params.min_side = 4.0f;
		}
		params.corners = (kind & 4) == 0;
		ContourTracer asmWalk, portable;
		portable.usePortableWalk(true);
		EveryOtherProbe probe1, probe2;
		std::vector<Quad> q1, q2;
		asmWalk.trace(map, params, q1, (kind & 2) ? &probe1 : nullptr);
		portable.trace(map, params, q2, (kind & 2) ? &probe2 : nullptr);
		bool same = q1.size() == q2.size() && asmWalk.bordersFollowed() == portable.bordersFollowed();
		for (std::size_t i = 0; same && i < q1.size(); ++i)
			same = std::memcmp(q1[i].corners.data(), q2[i].corners.data(), sizeof(q1[i].corners)) == 0;
		CHECK(same, "%s: tracer kind %d: %zu quads, %d borders vs %zu, %d", what, kind, q1.size(),
		      asmWalk.bordersFollowed(), q2.size(), portable.bordersFollowed());
	}
}

std::size_t compareFrontEnds(const Gray &g, const FrontEndParams &params, float scale, const char *what)
{
	auto ref = makeCpuFrontEnd(1, scalarBandKernels());
	auto v6 = makeCpuFrontEnd(1, armv6BandKernels());
	EdgeMap e1, e2;
	const ImageView view(g.px.data(), g.w, g.h, g.w);
	ref->run(view, scale, params, e1);
	v6->run(view, scale, params, e2);
	CHECK(e1.width == e2.width && e1.height == e2.height, "%s: sizes differ", what);
	std::size_t edges = 0, diff = 0;
	for (std::size_t i = 0; i < e1.pixels.size(); ++i) {
		edges += e1.pixels[i] != 0;
		if (e1.pixels[i] != e2.pixels[i] && diff++ < 3)
			CHECK(false, "%s: pixel (%zu, %zu): %d vs %d", what, i % e1.width, i / e1.width, e1.pixels[i],
			      e2.pixels[i]);
	}
	CHECK(diff == 0, "%s: %zu pixels differ", what, diff);
	CHECK(e1.tiles == e2.tiles, "%s: tile masks differ", what);
	compareTracers(e2, what);
	return edges;
}

/* The region map's row kernels on rows of width w: inputs and outputs at
 * unaligned offsets, guard bytes after every output. */
void checkRegionRows(int w, int kind, int misalign)
{
	const int W = 2 * w + 8;
	std::vector<std::uint8_t> buf(2 * W + 8);
	std::uint8_t *r0 = buf.data() + misalign, *r1 = r0 + W;
	fillRow(r0, 2 * w + 4, kind);
	fillRow(r1, 2 * w + 4, kind);
	/* Outputs at the inputs' offset: misalign 0 is the word-aligned case
	 * (the LDM loops). */
	std::vector<std::uint8_t> o1(w + 8, 0xAB), o2(w + 12, 0xAB);
	decimateRowScalar(r0, r1, w, o1.data());
	decimateRowV6(r0, r1, w, o2.data() + misalign);
	for (int x = 0; x < w + 7; ++x)
		CHECK(o1[x] == o2[x + misalign], "decimateRow w=%d kind=%d mis=%d x=%d: %d vs %d", w, kind, misalign, x,
		      o1[x], o2[x + misalign]);

	/* Tile extremes of 1..4 rows, stride W. */
	const int tx = (w + 3) / 4;
	for (int n = 1; n <= 4; ++n) {
		std::vector<std::uint8_t> rows(static_cast<std::size_t>(4) * W + 8);
		for (int y = 0; y < 4; ++y)
			fillRow(rows.data() + misalign + y * W, w, kind);
		std::vector<std::uint8_t> mn1(tx + 4, 0xAB), mx1(tx + 4, 0xAB), mn2(tx + 4, 0xAB), mx2(tx + 4, 0xAB);
		tileExtremesScalar(rows.data() + misalign, W, n, w, mn1.data(), mx1.data());
		tileExtremesV6(rows.data() + misalign, W, n, w, mn2.data(), mx2.data());
		CHECK(mn1 == mn2 && mx1 == mx2, "tileExtremes w=%d n=%d kind=%d mis=%d", w, n, kind, misalign);
	}

	/* The dark test, with thresholds per pixel (the map's are per tile)
	 * and tiles already marked or not. */
	const int ntiles = (w + 15) / 16;
	std::vector<std::uint8_t> d(w + 8), mid(w + 8);
	std::uint8_t *pmid = mid.data() + misalign;
	fillRow(d.data() + misalign, w, kind);
	fillRow(pmid, w, (kind + 1) % 3);
	std::vector<std::uint8_t> tiles1(ntiles + 2), tiles2;
	for (auto &t : tiles1)
		t = static_cast<std::uint8_t>(rng() % 4 == 0);
	tiles2 = tiles1;
	std::vector<std::uint8_t> dk1(w + 8, 0xAB), dk2(w + 8, 0xAB);
	darkRowTilesScalar(d.data() + misalign, pmid, w, dk1.data() + misalign, tiles1.data());
	darkRowV6(d.data() + misalign, pmid, w, dk2.data() + misalign, tiles2.data());
	CHECK(dk1 == dk2 && tiles1 == tiles2, "darkRow w=%d kind=%d mis=%d", w, kind, misalign);
}

/* The 3 x 3 spread of tx x ty tiles' extremes. */
void checkSpread(int tx, int ty, int kind)
{
	const std::size_t n = static_cast<std::size_t>(tx) * ty;
	std::vector<std::uint8_t> mn(n), mx(n);
	fillRow(mn.data(), static_cast<int>(n), kind);
	fillRow(mx.data(), static_cast<int>(n), (kind + 1) % 3);
	auto mn2 = mn, mx2 = mx;
	std::vector<std::uint8_t> w1(4 * static_cast<std::size_t>(tx) + 4), w2(w1.size());
	spreadTilesScalar(mn.data(), mx.data(), tx, ty, w1.data());
	spreadTilesV6(mn2.data(), mx2.data(), tx, ty, w2.data());
	CHECK(mn == mn2 && mx == mx2, "spreadTiles %dx%d kind=%d", tx, ty, kind);
}

/* n points (x | y << 16): a closed-ish 8-connected walk (a border), or
 * scattered points, or points at the extremes of the coordinate range. */
std::vector<std::uint32_t> randomPoints(std::size_t n, int kind)
{
	std::vector<std::uint32_t> pts(n + kPointsPadding);
	std::uniform_int_distribution<int> u(0, 32767), step(-1, 1);
	int x = u(rng), y = u(rng);
	for (std::size_t i = 0; i < n; ++i) {
		if (kind == 0) {
			x = std::clamp(x + step(rng), 0, 32767);
			y = std::clamp(y + step(rng), 0, 32767);
		} else if (kind == 1) {
			x = u(rng);
			y = u(rng);
		} else {
			x = (rng() & 1) ? 32767 : 0;
			y = (rng() & 1) ? 32767 : 0;
		}
		pts[i] = static_cast<std::uint32_t>(x) | static_cast<std::uint32_t>(y) << 16;
	}
	return pts;
}

void checkTraceKernels(std::size_t n, int kind)
{
	const auto pts = randomPoints(n, kind);
	const OutlineExtremes a = outlineExtremesScalar(pts.data(), n), b = outlineExtremesV6(pts.data(), n);
	CHECK(a.i0 == b.i0 && a.i1 == b.i1 && a.i2 == b.i2 && a.i3 == b.i3 && a.most == b.most && a.least == b.least,
	      "outlineExtremes n=%zu kind=%d: (%zu %zu %zu %zu %ld %ld) vs (%zu %zu %zu %zu %ld %ld)", n, kind, a.i0,
	      a.i1, a.i2, a.i3, static_cast<long>(a.most), static_cast<long>(a.least), b.i0, b.i1, b.i2, b.i3,
	      static_cast<long>(b.most), static_cast<long>(b.least));
	const PointsBox p = pointsBoxScalar(pts.data(), n), q = pointsBoxV6(pts.data(), n);
	CHECK(p.minX == q.minX && p.maxX == q.maxX && p.minY == q.minY && p.maxY == q.maxY, "pointsBox n=%zu kind=%d",
	      n, kind);
}

/* sideCoverage's integer pre-test: sides between random points of a w x h
 * map, points strewn within a few pixels of the side's line (so that many
 * lie near the tolerance) and anywhere. */
void checkSideCoverage(int w, int h, int trials)
{
	std::uniform_real_distribution<float> ux(0.0f, static_cast<float>(w - 1)), uy(0.0f, static_cast<float>(h - 1));
	std::uniform_real_distribution<float> ut(-0.2f, 1.2f), ud(-1.0f, 1.0f), utol(0.0f, 12.0f);
	for (int k = 0; k < trials; ++k) {
		const Point2f a{ ux(rng), uy(rng) }, b{ ux(rng), uy(rng) };
		if (a.x == b.x && a.y == b.y)
			continue;
		const SideLine side = SideLine::between(a, b);
		const float tol = (k & 3) ? 1.5f + 0.06f * utol(rng) * 5.0f : utol(rng);
		const std::size_t n = 1 + rng() % 300;
		std::vector<std::uint32_t> pts(n + kPointsPadding);
		for (std::size_t i = 0; i < n; ++i) {
			float x, y;
			if (i % 5 == 4) {
				x = ux(rng);
				y = uy(rng);
			} else {
				const float t = ut(rng), d = (tol + 0.5f) * ud(rng);
				x = a.x + t * (b.x - a.x) + d * side.nx;
				y = a.y + t * (b.y - a.y) + d * side.ny;
			}
			const int xi = std::clamp(static_cast<int>(std::lround(x)), 0, w - 1);
			const int yi = std::clamp(static_cast<int>(std::lround(y)), 0, h - 1);
			pts[i] = static_cast<std::uint32_t>(xi) | static_cast<std::uint32_t>(yi) << 16;
		}
		const std::uint32_t want = sideCoverageScalar(pts.data(), n, side, tol);
		const std::uint32_t got = sideCoverageV6(pts.data(), n, side, tol, w + h);
		CHECK(want == got, "sideCoverage %dx%d trial %d: %08x vs %08x", w, h, k, want, got);
		/* From any first point, stopping at `need` bins: a subset of at
		 * least need bits, or all of them when there are fewer. */
		for (const std::size_t first : { std::size_t{ 0 }, n / 3, n - 1, n }) {
			CHECK(sideCoverageV6(pts.data(), n, side, tol, w + h, 0, first) == want,
			      "sideCoverage %dx%d trial %d from %zu", w, h, k, first);
			for (const int need : { 1, 7, 16 }) {
				const std::uint32_t part = sideCoverageV6(pts.data(), n, side, tol, w + h, need, first);
				const bool fine = std::popcount(want) < need
							  ? part == want
							  : std::popcount(part) >= need && (part & ~want) == 0;
				CHECK(fine, "sideCoverage %dx%d trial %d need %d from %zu: %08x vs %08x", w, h, k, need,
				      first, want, part);
			}
		}
	}
}

/* Label rows: word-aligned buffers (as the tracer's), or not. */
void checkLabels(std::size_t n, int misalign)
{
	std::vector<std::uint8_t> edges(n + 8), l1(n + 8, 0xAB), l2(n + 8, 0xAB);
	for (auto &e : edges)
		e = static_cast<std::uint8_t>(rng() % 4 == 0 ? rng() & 3 : 0);
	labelsFromEdgesScalar(edges.data() + misalign, n, l1.data() + misalign);
	labelsFromEdgesV6(edges.data() + misalign, n, l2.data() + misalign);
	CHECK(l1 == l2, "labelsFromEdges n=%zu misalign=%d", n, misalign);
}

/* The documented rule of the region map, pixel by pixel. */
std::vector<std::uint8_t> slowRegionMap(const Gray &g, int minContrast, int lightFloor, int &w, int &h,
					bool shade = false)
{
	w = g.w / 2;
	h = g.h / 2;
	std::vector<int> r(static_cast<std::size_t>(w) * h);
	for (int y = 0; y < h; ++y)
		for (int x = 0; x < w; ++x) {
			auto p = [&](int xx, int yy) { return static_cast<int>(g.px[static_cast<std::size_t>(yy) * g.w + xx]); };
			r[static_cast<std::size_t>(y) * w + x] =
				(p(2 * x, 2 * y) + p(2 * x + 1, 2 * y) + p(2 * x, 2 * y + 1) + p(2 * x + 1, 2 * y + 1) + 2) >> 2;
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
							lo = std::min(lo, r[static_cast<std::size_t>(yy) * w + xx]);
							hi = std::max(hi, r[static_cast<std::size_t>(yy) * w + xx]);
						}
			out[static_cast<std::size_t>(y) * w + x] =
				hi - lo >= ((minContrast * std::min(lo + hi + 2 * lightFloor, 256) + 255) >> 8) &&
				(shade ? (r[static_cast<std::size_t>(y) * w + x] + 4) * (r[static_cast<std::size_t>(y) * w + x] + 4) <
						 (lo + 4) * (hi + 4)
				       : r[static_cast<std::size_t>(y) * w + x] < ((lo + hi + 1) >> 1));
		}
	return out;
}

/* A map's tile mask against the pixels it should mark: a tile is set
 * exactly when one of its 16 x 16 pixels is. */
void compareTileMask(const TraceMap &map, const std::vector<std::uint8_t> &want, int w, int h, const char *what,
		     const char *kind)
{
	for (int ty = 0; ty < map.tiles_y; ++ty)
		for (int tx = 0; tx < map.tiles_x; ++tx) {
			bool any = false;
			for (int y = ty * 16; y < std::min(h, ty * 16 + 16); ++y)
				for (int x = tx * 16; x < std::min(w, tx * 16 + 16); ++x)
					any = any || want[static_cast<std::size_t>(y) * w + x];
			CHECK(!map.tileEmpty(tx, ty) == any, "%s: %s tile %d,%d", what, kind, tx, ty);
		}
}

/* The whole region map (this build's: the ARMv6 kernels) against the rule,
 * pixels and tile mask; the number of dark pixels. */
std::size_t compareRegionMap(const Gray &g, int contrast, const char *what, int lightFloor = 16)
{
	int w, h;
	const auto want = slowRegionMap(g, contrast, lightFloor, w, h);
	const auto wantShades = slowRegionMap(g, contrast, lightFloor, w, h, true);
	TraceMap map, shades;
	RegionScratch scratch;
	frappe::FrontEndParams params;
	params.region_contrast = contrast;
	params.light_floor = lightFloor;
	regionMap(ImageView(g.px.data(), g.w, g.h, g.w), 1.0f, params, map, shades, scratch);
	if (w >= 3 && h >= 3 && lightFloor < 128) {
		CHECK(shades.pixels == wantShades, "%s: shade map pixels", what);
		compareTileMask(shades, wantShades, w, h, what, "shade");
	}
	if (w < 3 || h < 3) {
		CHECK(map.width == 0, "%s: a map of a frame too small", what);
		return 0;
	}
	CHECK(map.width == w && map.height == h, "%s: region map size", what);
	if (map.width != w || map.height != h)
		return 0;
	std::size_t dark = 0, diff = 0;
	for (std::size_t i = 0; i < want.size(); ++i) {
		dark += want[i];
		if (map.pixels[i] != want[i] && diff++ < 3)
			CHECK(false, "%s: region pixel (%zu, %zu): %d vs %d", what, i % w, i / w, map.pixels[i], want[i]);
	}
	CHECK(diff == 0, "%s: %zu region pixels differ", what, diff);
	compareTracers(map, what);
	compareTileMask(map, want, w, h, what, "region");
	return dark;
}

} // namespace

int main(int argc, char **argv)
{
	int first = 1;
	bool quick = false;
	if (argc > 1 && std::strcmp(argv[1], "--quick") == 0) {
		quick = true;
		first = 2;
	}
	const RowKernels &ref = scalarRowKernels();
	const RowKernels &k = armv6RowKernels();
	CHECK(&bestBandKernels() == &armv6BandKernels(), "bestBandKernels() is not the ARMv6 set on this build");

	int rowCases = 0;
	for (int w = 1; w <= 96; ++w)
		for (int kind = 0; kind < 3; ++kind)
			for (int mis = 0; mis < 4; ++mis, ++rowCases)
				checkRows(ref, k, w, kind, mis);
	for (int w : { 127, 128, 129, 320, 639, 640, 641, 1283 })
		for (int rep = 0; rep < (quick ? 3 : 30); ++rep, ++rowCases)
			checkRows(ref, k, w, rep % 3, rep % 4);
	for (int w = 1; w <= 100; ++w)
		for (int mis = 0; mis < 4; ++mis)
			for (int rep = 0; rep < 4; ++rep, ++rowCases)
				checkMarkTiles(w, mis);
	for (int w : { 320, 640, 641, 1920 })
		for (int rep = 0; rep < 20; ++rep, ++rowCases)
			checkMarkTiles(w, rep % 4);
	std::printf("rows: %d random cases\n", rowCases);

	/* Thresholds: the defaults (edge 0.27, corner 0.19), none, tiny, huge,
	 * negative. */
	const FrontEndParams params[] = {
		{ 4740, 12354 }, { 0, 0 }, { 1, 1 }, { 400, 1000 }, { 40000, 200000 },
		{ -5, -7 }, { INT64_C(1) << 40, INT64_C(1) << 40 }, { 2080799, 12354 },
	};
	/* Light floors: absolute thresholds (128), the Detector's default
	 * (16), none (0); the thresholds of dark pixels follow their light. */
	const int lightFloors[] = { FrontEndParams::kLightReference, 16, 0 };
	int imageCases = 0;
	for (const auto &[w, h] : { std::pair{ 640, 480 }, std::pair{ 37, 23 }, std::pair{ 3, 3 }, std::pair{ 4, 17 },
				   std::pair{ 17, 5 }, std::pair{ 161, 97 } }) {
		for (int noise : { 0, 3, 12 }) {
			/* The frame, and the frame in a dim room (a sixth of its light). */
			for (int gain : { 255, 40 }) {
				Gray g = constructed(w, h, noise, static_cast<unsigned>(w * 131 + h * 7 + noise));
				for (auto &v : g.px)
					v = static_cast<std::uint8_t>(v * gain / 255);
				for (FrontEndParams p : params)
					for (int lightFloor : lightFloors) {
						if (gain != 255 && lightFloor == FrontEndParams::kLightReference)
							continue;
						p.light_floor = lightFloor;
						char what[128];
						std::snprintf(what, sizeof what,
							      "constructed %dx%d noise %d gain %d thr %" PRId64 "/%" PRId64
							      " floor %d",
							      w, h, noise, gain, p.edge_threshold_sq, p.corner_threshold,
							      lightFloor);
						compareFrontEnds(g, p, 1.0f, what);
						++imageCases;
					}
				if (w == 640 && gain == 255) {
					FrontEndParams p = params[0];
					p.light_floor = 16;
					compareFrontEnds(g, p, 0.5f, "constructed 640x480 at scale 0.5");
					compareFrontEnds(g, p, 0.37f, "constructed 640x480 at scale 0.37");
					imageCases += 2;
				}
			}
		}
	}
	std::printf("front end: %d constructed images\n", imageCases);

	int regionRows = 0;
	for (int w = 1; w <= 70; ++w)
		for (int kind = 0; kind < 3; ++kind)
			for (int mis = 0; mis < 4; ++mis, ++regionRows)
				checkRegionRows(w, kind, mis);
	for (int w : { 127, 128, 129, 319, 320, 321, 641 })
		for (int rep = 0; rep < (quick ? 3 : 12); ++rep, ++regionRows)
			checkRegionRows(w, rep % 3, rep % 4);
	for (int tx = 1; tx <= 13; ++tx)
		for (int ty = 1; ty <= 6; ++ty)
			for (int kind = 0; kind < 3; ++kind, ++regionRows)
				checkSpread(tx, ty, kind);
	for (int kind = 0; kind < 3; ++kind, ++regionRows)
		checkSpread(80, 60, kind);
	std::printf("region rows and tile spreads: %d random cases\n", regionRows);
	int regionCases = 0;
	for (const auto &[w, h] : { std::pair{ 640, 480 }, std::pair{ 37, 23 }, std::pair{ 6, 6 }, std::pair{ 7, 5 },
				   std::pair{ 5, 100 }, std::pair{ 101, 67 }, std::pair{ 250, 9 }, std::pair{ 161, 97 } }) {
		for (int noise : { 0, 12 }) {
			const Gray g = constructed(w, h, noise, static_cast<unsigned>(w * 17 + h * 3 + noise));
			for (int contrast : { 1, 40, 200, 256 }) {
				char what[96];
				std::snprintf(what, sizeof what, "region map %dx%d noise %d contrast %d", w, h, noise, contrast);
				compareRegionMap(g, contrast, what);
				++regionCases;
			}
		}
	}
	std::printf("region map: %d constructed images\n", regionCases);
	{
		TraceMap ring;
		ring.resize(640, 480);
		std::fill(ring.pixels.begin(), ring.pixels.end(), 0);
		for (int y = 20; y < 460; ++y)
			for (int x = 20; x < 620; ++x)
				if (y < 22 || y >= 458 || x < 22 || x >= 618)
					ring.pixels[static_cast<std::size_t>(y) * 640 + x] =
						(x == 20 || x == 619) && (y == 20 || y == 459) ? 3 : 1;
		std::fill(ring.tiles.begin(), ring.tiles.end(), 1);
		compareTracers(ring, "a ring of 2000 pixels a border");
	}

	int traceCases = 0;
	for (std::size_t n = 1; n <= 80; ++n)
		for (int kind = 0; kind < 3; ++kind, ++traceCases)
			checkTraceKernels(n, kind);
	for (std::size_t n : { 255, 256, 1000, 4099, 32767, 32768, 40000 })
		for (int kind = 0; kind < 3; ++kind, ++traceCases)
			checkTraceKernels(n, kind);
	for (std::size_t n : { 0, 1, 31, 32, 33, 63, 64, 100, 1000, 307200 })
		for (int mis = 0; mis < 4; ++mis, ++traceCases)
			checkLabels(n, mis);
	for (const auto &[w, h] : { std::pair{ 640, 480 }, std::pair{ 320, 240 }, std::pair{ 7, 5 }, std::pair{ 1920, 1080 },
				   std::pair{ 16000, 16000 }, std::pair{ 30000, 2767 } }) {
		checkSideCoverage(w, h, quick ? 300 : 3000);
		traceCases += quick ? 300 : 3000;
	}
	std::printf("trace kernels: %d random cases\n", traceCases);

	std::size_t files = 0, edges = 0, dark = 0;
	for (int i = first; i < argc; ++i) {
		Gray g;
		if (!readPgm(argv[i], g)) {
			CHECK(false, "cannot read %s (binary PGM, maxval 255)", argv[i]);
			continue;
		}
		for (int lightFloor : lightFloors) {
			FrontEndParams p = params[0];
			p.light_floor = lightFloor;
			char what[320];
			std::snprintf(what, sizeof what, "%s floor %d", argv[i], lightFloor);
			const std::size_t n = compareFrontEnds(g, p, 1.0f, what);
			if (lightFloor == 16)
				edges += n;
		}
		dark += compareRegionMap(g, 41, argv[i]); /* Config's default 0.16, as an intensity */
		++files;
	}
	if (files)
		std::printf("front end: %zu images, %zu edge pixels, %zu dark region pixels\n", files, edges, dark);
	std::printf("%s\n", failures ? "FAILED" : "ok: the ARMv6 kernels equal the scalar ones, the region map its rule");
	return failures ? 1 : 0;
}

#endif
