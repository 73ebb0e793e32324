// SPDX-License-Identifier: MIT
// Suzuki border following and candidate selection on hand-made edge maps.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include <gtest/gtest.h>

#include "contour_trace.h"
#include "every_target.h"
#include "frappe/edge_map.h"
#include "trace_kernels.h"

using namespace frappe;
using namespace frappe::detail;
using frappe::test::onEveryTarget;

namespace {

EdgeMap emptyMap(int w, int h)
{
	EdgeMap em;
	em.resize(w, h);
	std::fill(em.pixels.begin(), em.pixels.end(), 0);
	std::fill(em.tiles.begin(), em.tiles.end(), 0);
	return em;
}

void set(EdgeMap &em, int x, int y, std::uint8_t v)
{
	em.pixels[static_cast<std::size_t>(y) * em.width + x] = v;
	em.tiles[static_cast<std::size_t>(y / EdgeMap::kTile) * em.tiles_x + x / EdgeMap::kTile] = 1;
}

/* A one-pixel ring around [x0, x1] x [y0, y1] with corner flags on the four
 * corner pixels and their neighbours along the ring. */
void ring(EdgeMap &em, int x0, int y0, int x1, int y1)
{
	for (int x = x0; x <= x1; ++x) {
		set(em, x, y0, EdgeMap::kEdge);
		set(em, x, y1, EdgeMap::kEdge);
	}
	for (int y = y0; y <= y1; ++y) {
		set(em, x0, y, EdgeMap::kEdge);
		set(em, x1, y, EdgeMap::kEdge);
	}
	const int cx[4] = { x0, x1, x1, x0 }, cy[4] = { y0, y0, y1, y1 };
	for (int k = 0; k < 4; ++k) {
		for (int d = -1; d <= 1; ++d) {
			const int xs[2] = { cx[k] + d, cx[k] }, ys[2] = { cy[k], cy[k] + d };
			for (int j = 0; j < 2; ++j)
				if (xs[j] >= x0 && xs[j] <= x1 && ys[j] >= y0 && ys[j] <= y1)
					set(em, xs[j], ys[j], EdgeMap::kEdge | EdgeMap::kCorner);
		}
	}
}

} // namespace

TEST(ContourTrace, OneRingGivesOneQuadAtItsCorners)
{
	EdgeMap em = emptyMap(80, 60);
	ring(em, 20, 15, 50, 40);
	ContourTracer tracer;
	std::vector<Quad> quads;
	tracer.trace(em, TraceParams{}, quads);
	/* The outer and the hole border of the ring: both found... */
	EXPECT_EQ(quads.size(), 2u);
	EXPECT_EQ(tracer.bordersFollowed(), 2);
	/* ...and one survives de-duplication. */
	removeDuplicateQuads(quads, 2.5f);
	ASSERT_EQ(quads.size(), 1u);
	const Quad &q = quads[0];
	/* Clockwise on screen: positive signed area in y-down coordinates. */
	float area = 0;
	for (int i = 0; i < 4; ++i)
		area += q.corners[i].x * q.corners[(i + 1) & 3].y - q.corners[(i + 1) & 3].x * q.corners[i].y;
	EXPECT_GT(area, 0.0f);
	const float ex[4] = { 20, 50, 50, 20 }, ey[4] = { 15, 15, 40, 40 };
	for (const Point2f &c : q.corners) {
		bool near = false;
		for (int k = 0; k < 4; ++k)
			near = near || (std::abs(c.x - ex[k]) <= 1.0f && std::abs(c.y - ey[k]) <= 1.0f);
		EXPECT_TRUE(near) << c.x << "," << c.y;
	}
}

TEST(ContourTrace, WithoutHolesOnlyTheOuterBorderIsFollowed)
{
	EdgeMap em = emptyMap(80, 60);
	ring(em, 20, 15, 50, 40);
	ContourTracer tracer;
	std::vector<Quad> quads;
	TraceParams params;
	params.holes = false;
	tracer.trace(em, params, quads);
	EXPECT_EQ(tracer.bordersFollowed(), 1);
	ASSERT_EQ(quads.size(), 1u);
	/* The outer border runs on the ring itself: its corners. */
	const float ex[4] = { 20, 50, 50, 20 }, ey[4] = { 15, 15, 40, 40 };
	for (const Point2f &c : quads[0].corners) {
		bool near = false;
		for (int k = 0; k < 4; ++k)
			near = near || (std::abs(c.x - ex[k]) <= 1.0f && std::abs(c.y - ey[k]) <= 1.0f);
		EXPECT_TRUE(near) << c.x << "," << c.y;
	}
}

TEST(ContourTrace, OpenCurveIsNotACandidate)
{
	EdgeMap em = emptyMap(80, 60);
	ring(em, 20, 15, 50, 40);
	/* Remove the bottom side: a U is three sides, not a marker outline. */
	for (int x = 21; x <= 49; ++x)
		em.pixels[static_cast<std::size_t>(40) * em.width + x] = 0;
	ContourTracer tracer;
	std::vector<Quad> quads;
	tracer.trace(em, TraceParams{}, quads);
	EXPECT_TRUE(quads.empty());
}

TEST(ContourTrace, OutlineWithAGapIsStillACandidate)
{
	/* Blur breaks outlines; a border that runs along all four sides is
	 * kept even when it slips through a gap. */
	EdgeMap em = emptyMap(80, 60);
	ring(em, 20, 15, 50, 40);
	for (int x = 33; x <= 36; ++x)
		em.pixels[static_cast<std::size_t>(40) * em.width + x] = 0;
	ContourTracer tracer;
	std::vector<Quad> quads;
	tracer.trace(em, TraceParams{}, quads);
	removeDuplicateQuads(quads, 2.5f);
	ASSERT_EQ(quads.size(), 1u);
}

TEST(ContourTrace, TooSmallAndTouchingTheFrameAreDropped)
{
	EdgeMap em = emptyMap(80, 60);
	ring(em, 10, 10, 15, 15); /* 5 px sides < min_side 8 */
	ring(em, 1, 20, 30, 50);  /* corner on the frame margin */
	ContourTracer tracer;
	std::vector<Quad> quads;
	TraceParams p;
	p.border_margin = 2.0f;
	tracer.trace(em, p, quads);
	EXPECT_TRUE(quads.empty());
}

TEST(ContourTrace, StrayCornerOnASideIsIgnored)
{
	EdgeMap em = emptyMap(80, 60);
	ring(em, 20, 15, 50, 40);
	set(em, 35, 15, EdgeMap::kEdge | EdgeMap::kCorner); /* noise half-way along the top */
	ContourTracer tracer;
	std::vector<Quad> quads;
	tracer.trace(em, TraceParams{}, quads);
	removeDuplicateQuads(quads, 2.5f);
	ASSERT_EQ(quads.size(), 1u);
	for (const Point2f &c : quads[0].corners)
		EXPECT_GT(std::abs(c.x - 35.0f), 5.0f) << "the stray cluster became a corner";
}

TEST(ContourTrace, EmptyTilesAreSkippedWithoutLosingContours)
{
	EdgeMap em = emptyMap(96, 96);
	ring(em, 40, 40, 70, 70);
	ContourTracer tracer;
	std::vector<Quad> quads;
	tracer.trace(em, TraceParams{}, quads);
	EXPECT_EQ(quads.size(), 2u);
	/* Marking its tiles empty hides the ring from the scan entirely. */
	std::fill(em.tiles.begin(), em.tiles.end(), 0);
	tracer.trace(em, TraceParams{}, quads);
	EXPECT_TRUE(quads.empty());
	EXPECT_EQ(tracer.bordersFollowed(), 0);
}

namespace {

/* Calls the quads it is shown markers when their top-left corner is in a
 * given box, and counts the calls. */
struct BoxProbe final : MarkerProbe {
	float x0, y0, x1, y1;
	int calls = 0;
	BoxProbe(float ax, float ay, float bx, float by) : x0(ax), y0(ay), x1(bx), y1(by) {}
	bool isMarker(Quad &quad) override
	{
		quad.probeRead = calls++; /* the order it was asked in */
		float minX = 1e9f, minY = 1e9f;
		for (const Point2f &c : quad.corners) {
			minX = std::min(minX, c.x);
			minY = std::min(minY, c.y);
		}
		return minX >= x0 && minX <= x1 && minY >= y0 && minY <= y1;
	}
};

/* A marker-like edge map: an outline ring holding a second ring (the inner
 * edge of its black frame) and two code cells. */
void markerLike(EdgeMap &em, int x0, int y0, int side)
{
	ring(em, x0, y0, x0 + side, y0 + side);
	const int c = side / 8;
	ring(em, x0 + c, y0 + c, x0 + side - c, y0 + side - c);
	ring(em, x0 + 2 * c, y0 + 2 * c, x0 + 4 * c, y0 + 4 * c);
	ring(em, x0 + 4 * c + 2, y0 + 4 * c + 2, x0 + 6 * c, y0 + 6 * c);
}

} // namespace

/* The inside of a quad the probe calls a marker is never followed: not the
 * hole border of its outline, not its code's cells. */
TEST(ContourTrace, InsideOfAProbedMarkerIsSkipped)
{
	EdgeMap em = emptyMap(160, 120);
	markerLike(em, 20, 20, 80);
	ContourTracer tracer;
	std::vector<Quad> quads;
	tracer.trace(em, TraceParams{}, quads);
	/* Each of the four rings gives an outer and a hole border. */
	EXPECT_EQ(tracer.bordersFollowed(), 8);
	EXPECT_EQ(quads.size(), 8u);

	BoxProbe yes(18, 18, 22, 22);
	tracer.trace(em, TraceParams{}, quads, &yes);
	EXPECT_EQ(tracer.bordersFollowed(), 1);
	ASSERT_EQ(quads.size(), 1u);
	EXPECT_EQ(yes.calls, 1);

	/* A probe that says no changes nothing. */
	BoxProbe no(-10, -10, -5, -5);
	tracer.trace(em, TraceParams{}, quads, &no);
	EXPECT_EQ(tracer.bordersFollowed(), 8);
	EXPECT_EQ(quads.size(), 8u);
	EXPECT_EQ(no.calls, 8);
	/* What the probe noted stays with each quad. */
	for (std::size_t k = 0; k < quads.size(); ++k)
		EXPECT_EQ(quads[k].probeRead, static_cast<int>(k));
}

/* The seal stays inside the probed outline: a ring two pixels beside it,
 * and one just below it, are still found whole. */
TEST(ContourTrace, SealDoesNotReachNeighbours)
{
	EdgeMap em = emptyMap(200, 160);
	markerLike(em, 20, 20, 64);
	ring(em, 87, 20, 140, 84);  /* two background pixels right of x = 84 */
	ring(em, 20, 87, 84, 140);  /* and below y = 84 */
	BoxProbe probe(18, 18, 22, 22);
	ContourTracer tracer;
	std::vector<Quad> quads;
	tracer.trace(em, TraceParams{}, quads, &probe);
	/* The marker's outline, then both borders of each neighbour. */
	EXPECT_EQ(tracer.bordersFollowed(), 5);
	removeDuplicateQuads(quads, 2.5f);
	EXPECT_EQ(quads.size(), 3u);
}

/* A border longer than the tracer's first point buffer (1024 steps) is
 * followed whole, and the tracer gives the same answer on its next frame
 * of the same size (its label image and step table are reused). */
TEST(ContourTrace, LongBorderAndReuseGiveTheSameQuad)
{
	EdgeMap em = emptyMap(640, 480);
	ring(em, 30, 20, 600, 450);
	ContourTracer tracer;
	std::vector<Quad> first, second;
	tracer.trace(em, TraceParams{}, first);
	EXPECT_EQ(tracer.bordersFollowed(), 2);
	tracer.trace(em, TraceParams{}, second);
	ASSERT_EQ(first.size(), 2u);
	ASSERT_EQ(second.size(), 2u);
	for (std::size_t k = 0; k < 2; ++k)
		for (int i = 0; i < 4; ++i) {
			EXPECT_EQ(first[k].corners[i].x, second[k].corners[i].x);
			EXPECT_EQ(first[k].corners[i].y, second[k].corners[i].y);
		}
	const float ex[4] = { 30, 600, 600, 30 }, ey[4] = { 20, 20, 450, 450 };
	for (const Point2f &c : first[0].corners) {
		bool near = false;
		for (int k = 0; k < 4; ++k)
			near = near || (std::abs(c.x - ex[k]) <= 1.0f && std::abs(c.y - ey[k]) <= 1.0f);
		EXPECT_TRUE(near) << c.x << "," << c.y;
	}
}

/* Each bit of a neighbour mask names one direction, counter-clockwise on
 * screen from the right; only bit 0 of a neighbour counts (labels 9 and 25
 * and the corner bit are all "non-zero" or ignored alike). */
TEST(NeighbourMasks, BitsNameTheDirections)
{
	const int w = 8;
	const int dx[8] = { 1, 1, 0, -1, -1, -1, 0, 1 }, dy[8] = { 0, -1, -1, -1, 0, 1, 1, 1 };
	const std::uint8_t values[8] = { 1, 9, 25, 3, 1, 9, 25, 3 };
	for (int d = 0; d < 8; ++d) {
		std::vector<std::uint8_t> img(w * 3, 0), out(w, 0xAA);
		img[(1 + dy[d]) * w + 3 + dx[d]] = values[d];
		img[1 * w + 5] = EdgeMap::kCorner; /* bit 0 clear: not a neighbour */
		neighbourMasksScalar(img.data() + w, w, 2, 5, out.data());
		EXPECT_EQ(out[3], 1u << d) << "direction " << d;
		EXPECT_EQ(out[4] & 1, 0) << "the corner bit counted as an edge";
		EXPECT_EQ(out[1], 0xAAu) << "written outside [x0, x1)";
		EXPECT_EQ(out[5], 0xAAu) << "written outside [x0, x1)";
		neighbourMasks(img.data() + w, w, 2, 5, out.data());
		EXPECT_EQ(out[3], 1u << d) << "direction " << d;
	}
}

namespace {

void expectVectorMasksMatchScalar(const char *target)
{
	/* Rows of random labels (0, 1, 9, 25, with corner bits), spans of
	 * every length and start up to a few vectors, so that every tail and
	 * misalignment is met. */
	const int w = 301;
	std::mt19937 rng(5);
	std::vector<std::uint8_t> img(static_cast<std::size_t>(w) * 3);
	const std::uint8_t pick[6] = { 0, 0, 1, 9, 25, 3 };
	for (std::uint8_t &v : img)
		v = pick[rng() % 6];
	std::vector<std::uint8_t> all(w), a(w);
	neighbourMasksScalar(img.data() + w, w, 1, w - 1, all.data());
	int compared = 0;
	for (int x0 = 1; x0 < 40; x0 += 3)
		for (int x1 = x0; x1 <= w - 1; x1 += 7) {
			std::fill(a.begin(), a.end(), 0x55);
			neighbourMasks(img.data() + w, w, x0, x1, a.data());
			for (int x = 0; x < w; ++x) {
				const bool mustWrite = x >= x0 && x < x1;
				const bool mayWrite = x >= std::max(1, x1 - 64) && x < x1;
				if (mustWrite || (mayWrite && a[x] != 0x55))
					ASSERT_EQ(a[x], all[x]) << target << ": x = " << x << " in [" << x0 << ", " << x1 << ")";
				else
					ASSERT_EQ(a[x], 0x55) << target << ": x = " << x << " written, outside [" << x0 << ", " << x1 << ")";
			}
			++compared;
		}
	EXPECT_GT(compared, 500);
}

void expectVectorStartsMatchScalar(const char *target)
{
	const int w = 301;
	std::mt19937 rng(9);
	std::vector<std::uint8_t> row(w + 128);
	const std::uint8_t pick[6] = { 0, 0, 1, 9, 25, 1 };
	for (std::uint8_t &v : row)
		v = pick[rng() % 6];
	std::vector<std::uint64_t> a(8), b(8);
	int compared = 0;
	for (int x0 = 1; x0 < 70; x0 += 3)
		for (int x1 = x0; x1 <= w - 1; x1 += 5) {
			std::fill(a.begin(), a.end(), ~std::uint64_t{ 0 });
			std::fill(b.begin(), b.end(), ~std::uint64_t{ 0 });
			borderStartBits(row.data(), x0, x1, a.data());
			borderStartBitsScalar(row.data(), x0, x1, b.data());
			const int words = (x1 - x0 + 63) / 64;
			for (int k = 0; k < words; ++k)
				ASSERT_EQ(a[k], b[k]) << target << ": x in [" << x0 << ", " << x1 << "), word " << k;
			ASSERT_EQ(a[words], ~std::uint64_t{ 0 }) << target << ": wrote past the last word";
			++compared;
		}
	EXPECT_GT(compared, 1000);
}

void expectVectorCoverageMatchesScalar(const char *target)
{
	/* Points scattered about a side of a random quad, many within the
	 * tolerance and on bin edges (whole-pixel corners), counts covering
	 * every tail length. */
	std::mt19937 rng(21);
	std::uniform_real_distribution<float> coord(20.0f, 200.0f);
	int compared = 0, nonzero = 0;
	for (int trial = 0; trial < 300; ++trial) {
		const Point2f a{ std::floor(coord(rng)), std::floor(coord(rng)) };
		const Point2f b{ std::floor(coord(rng)), std::floor(coord(rng)) };
		if (std::hypot(b.x - a.x, b.y - a.y) < 8.0f)
			continue;
		const SideLine side = SideLine::between(a, b);
		const int n = trial % 70;
		std::vector<std::uint32_t> pts(n + kPointsPadding, 0xFFFFFFFFu);
		for (int k = 0; k < n; ++k) {
			const float s = std::uniform_real_distribution<float>(-0.1f, 1.1f)(rng);
			const float off = std::uniform_real_distribution<float>(-3.0f, 3.0f)(rng);
			const int x = static_cast<int>(std::lround(a.x + s * (b.x - a.x) + off * side.nx));
			const int y = static_cast<int>(std::lround(a.y + s * (b.y - a.y) + off * side.ny));
			pts[k] = static_cast<std::uint32_t>(x) | static_cast<std::uint32_t>(y) << 16;
		}
		const float tol = 1.5f + static_cast<float>(trial % 3);
		const std::uint32_t want = sideCoverageScalar(pts.data(), n, side, tol);
		ASSERT_EQ(sideCoverage(pts.data(), n, side, tol), want) << target << ": trial " << trial << " n " << n;
		++compared;
		nonzero += want != 0;
	}
	EXPECT_GT(compared, 250);
	EXPECT_GT(nonzero, 200);
}

void expectVectorExtremesMatchScalar(const char *target)
{
	/* Borders of small integer shapes, so that distances tie often: rings
	 * of a square (four farthest corners), random walks, and collinear
	 * points (an empty side). */
	std::mt19937 rng(31);
	int compared = 0;
	for (int trial = 0; trial < 400; ++trial) {
		const int n = 1 + trial % 90;
		std::vector<std::uint32_t> pts(n + kPointsPadding, 0x00010001u);
		int x = 100, y = 100;
		for (int k = 0; k < n; ++k) {
			switch (trial % 3) {
			case 0: { /* around a square of side 10 */
				const int s = k % 40, side = s / 10, t = s % 10;
				x = 100 + (side == 0 ? t : side == 1 ? 10 : side == 2 ? 10 - t : 0);
				y = 100 + (side == 0 ? 0 : side == 1 ? t : side == 2 ? 10 : 10 - t);
				break;
			}
			case 1: /* a random walk */
				x += static_cast<int>(rng() % 3) - 1;
				y += static_cast<int>(rng() % 3) - 1;
				break;
			default: /* a line */
				x = 50 + k;
				y = 60 + k / 2;
			}
			pts[k] = static_cast<std::uint32_t>(x) | static_cast<std::uint32_t>(y) << 16;
		}
		const OutlineExtremes a = outlineExtremes(pts.data(), n), b = outlineExtremesScalar(pts.data(), n);
		ASSERT_EQ(a.i0, b.i0) << target << ": trial " << trial;
		ASSERT_EQ(a.i1, b.i1) << target << ": trial " << trial;
		ASSERT_EQ(a.i2, b.i2) << target << ": trial " << trial;
		ASSERT_EQ(a.i3, b.i3) << target << ": trial " << trial;
		ASSERT_EQ(a.most, b.most) << target << ": trial " << trial;
		ASSERT_EQ(a.least, b.least) << target << ": trial " << trial;
		++compared;
	}
	EXPECT_EQ(compared, 400);
}

} // namespace

TEST(NeighbourMasks, VectorFormMatchesTheScalarOne)
{
	onEveryTarget(expectVectorMasksMatchScalar);
}

/* Outer borders start at an unfollowed pixel after background, hole
 * borders at any edge pixel not marked "right is background" before
 * background. */
TEST(BorderStarts, BitsMarkOuterAndHoleStarts)
{
	/*                     x: 0  1  2  3   4  5  6  7  8   9 10 */
	const std::uint8_t row[11 + 128] = { 0, 1, 1, 0, 9, 0, 25, 0, 1, 25, 9 };
	std::uint64_t bits[2] = { 0, 0 };
	borderStartBitsScalar(row, 1, 10, bits);
	/* 1: outer (0 on its left); 2: hole (0 on its right); 4: followed,
	 * 0 on its right: hole; 6: right-bg marked: none; 8: outer, and its
	 * right is 25, so no hole; 9: none (marked, and 9 on its right). */
	const std::uint64_t expect = (1u << (1 - 1)) | (1u << (2 - 1)) | (1u << (4 - 1)) | (1u << (8 - 1));
	EXPECT_EQ(bits[0], expect);
	std::uint64_t vbits[2] = { 0, 0 };
	borderStartBits(row, 1, 10, vbits);
	EXPECT_EQ(vbits[0], expect);
}

TEST(BorderStarts, VectorFormMatchesTheScalarOne)
{
	onEveryTarget(expectVectorStartsMatchScalar);
}

/* A side's sixteen bins: a point on the line in each bin sets that bit,
 * one beyond the tolerance or past either end sets none. */
TEST(SideCoverage, BinsAlongTheSide)
{
	/* The side from (10, 20) to (42, 20): 2 px a bin. */
	SideLine side{ 0.0f, 1.0f, 20.0f, 0.5f, 0.0f, 5.0f };
	std::vector<std::uint32_t> pts(kPointsPadding + 8, 0);
	auto at = [](int x, int y) { return static_cast<std::uint32_t>(x) | static_cast<std::uint32_t>(y) << 16; };
	pts[0] = at(10, 20);   /* bin 0 */
	pts[1] = at(13, 21);   /* bin 1, 1 px off the line */
	pts[2] = at(41, 19);   /* bin 15 */
	pts[3] = at(20, 23);   /* 3 px off: outside a tolerance of 1.5 */
	pts[4] = at(9, 20);    /* before the start */
	pts[5] = at(42, 20);   /* at the end: t = 16, outside */
	EXPECT_EQ(sideCoverageScalar(pts.data(), 6, side, 1.5f), (1u << 0) | (1u << 1) | (1u << 15));
	EXPECT_EQ(sideCoverage(pts.data(), 6, side, 1.5f), (1u << 0) | (1u << 1) | (1u << 15));
	EXPECT_EQ(sideCoverage(pts.data(), 6, side, 3.0f), (1u << 0) | (1u << 1) | (1u << 5) | (1u << 15));
	EXPECT_EQ(sideCoverage(pts.data(), 0, side, 3.0f), 0u);
}

TEST(SideCoverage, VectorFormMatchesTheScalarOne)
{
	onEveryTarget(expectVectorCoverageMatchesScalar);
}

/* The extremes of a square's outline: its corners, the first of each tie. */
TEST(OutlineExtremes, SquareGivesItsCorners)
{
	std::vector<std::uint32_t> pts;
	auto at = [](int x, int y) { return static_cast<std::uint32_t>(x) | static_cast<std::uint32_t>(y) << 16; };
	for (int t = 0; t < 20; ++t)
		pts.push_back(at(10 + t, 10)); /* top, left to right */
	for (int t = 0; t < 20; ++t)
		pts.push_back(at(30, 10 + t)); /* right, downwards */
	for (int t = 0; t < 20; ++t)
		pts.push_back(at(30 - t, 30)); /* bottom */
	for (int t = 0; t < 20; ++t)
		pts.push_back(at(10, 30 - t)); /* left */
	const std::size_t n = pts.size();
	pts.resize(n + kPointsPadding, 0);
	for (const OutlineExtremes e : { outlineExtremes(pts.data(), n), outlineExtremesScalar(pts.data(), n) }) {
		EXPECT_EQ(pts[e.i0], at(10, 10)); /* first of the four at the same distance */
		EXPECT_EQ(pts[e.i2], at(30, 30));
		EXPECT_EQ(pts[e.i1], at(10, 30)); /* most > 0: left of i0 -> i2 on screen */
		EXPECT_EQ(pts[e.i3], at(30, 10));
		EXPECT_EQ(e.most, 400);
		EXPECT_EQ(e.least, -400);
	}
}

TEST(OutlineExtremes, VectorFormMatchesTheScalarOne)
{
	onEveryTarget(expectVectorExtremesMatchScalar);
}

/* The bounding box of points, every count and tail, extremes anywhere (the
 * packed word's order is y's, not x's: x needs its own pass). */
TEST(PointsBox, VectorFormMatchesTheScalarOne)
{
	onEveryTarget([](const char *target) {
		std::mt19937 rng(41);
		for (int n = 1; n < 80; ++n) {
			std::vector<std::uint32_t> pts(n + kPointsPadding, 0xFFFFFFFFu);
			for (int k = 0; k < n; ++k) {
				/* One draw a statement, in the order x86 has drawn
				 * them: the operands of | are evaluated in an
				 * unspecified order. */
				const std::uint32_t x = rng() % 600;
				const std::uint32_t y = rng() % 400;
				pts[k] = x | y << 16;
			}
			const PointsBox a = pointsBox(pts.data(), n), b = pointsBoxScalar(pts.data(), n);
			ASSERT_EQ(a.minX, b.minX) << target << " n " << n;
			ASSERT_EQ(a.maxX, b.maxX) << target << " n " << n;
			ASSERT_EQ(a.minY, b.minY) << target << " n " << n;
			ASSERT_EQ(a.maxY, b.maxY) << target << " n " << n;
		}
		const std::uint32_t two[2 + kPointsPadding] = { 5u | 9u << 16, 7u | 3u << 16 };
		const PointsBox box = pointsBox(two, 2);
		EXPECT_EQ(box.minX, 5u);
		EXPECT_EQ(box.maxX, 7u);
		EXPECT_EQ(box.minY, 3u);
		EXPECT_EQ(box.maxY, 9u);
	});
}

/* Frames wider than 16-bit moves reach follow the neighbourhood from three
 * label rows at every step (the 32-bit targets' walk) rather than from the
 * neighbour masks. Both walks must give the same borders and quads: the same
 * clutter, rings and probed marker placed in a narrow and a very wide frame. */
TEST(ContourTrace, BothWalksGiveTheSameQuads)
{
	auto scene = [](int w) {
		EdgeMap em = emptyMap(w, 200);
		markerLike(em, 20, 20, 64);
		ring(em, 87, 20, 140, 84);
		ring(em, 150, 30, 230, 110);
		/* Clutter: random edge pixels, some with corner bits, and a
		 * second ring through it. */
		std::mt19937 rng(11);
		for (int k = 0; k < 2500; ++k) {
			const int x = 10 + static_cast<int>(rng() % 280), y = 120 + static_cast<int>(rng() % 70);
			set(em, x, y, (rng() % 5 == 0) ? EdgeMap::kEdge | EdgeMap::kCorner : EdgeMap::kEdge);
		}
		ring(em, 40, 125, 120, 185);
		/* Clutter touching the probed marker's outline from outside
		 * and inside: borders that run beside its sealed inside. */
		for (int k = 0; k < 400; ++k) {
			const int x = 14 + static_cast<int>(rng() % 70), y = 76 + static_cast<int>(rng() % 16);
			set(em, x, y, EdgeMap::kEdge);
		}
		for (int k = 0; k < 200; ++k) {
			const int x = 76 + static_cast<int>(rng() % 9), y = 14 + static_cast<int>(rng() % 70);
			set(em, x, y, EdgeMap::kEdge);
		}
		return em;
	};
	const EdgeMap narrow = scene(320), wide = scene(33000);
	BoxProbe p1(18, 18, 22, 22), p2(18, 18, 22, 22);
	ContourTracer a, b;
	std::vector<Quad> qa, qb;
	a.trace(narrow, TraceParams{}, qa, &p1);
	b.trace(wide, TraceParams{}, qb, &p2);
	EXPECT_GT(a.bordersFollowed(), 100);
	EXPECT_EQ(a.bordersFollowed(), b.bordersFollowed());
	EXPECT_EQ(p1.calls, p2.calls);
	ASSERT_EQ(qa.size(), qb.size());
	EXPECT_GE(qa.size(), 4u);
	for (std::size_t k = 0; k < qa.size(); ++k)
		for (int i = 0; i < 4; ++i) {
			EXPECT_EQ(qa[k].corners[i].x, qb[k].corners[i].x);
			EXPECT_EQ(qa[k].corners[i].y, qb[k].corners[i].y);
		}
}

/* TraceParams::corners = false (region and shade maps) walks as if the map
 * had no corner pixels: the same borders and quads as the map with its
 * kCorner bits cleared, in both walks (narrow: the masks' on 64-bit targets;
 * wide: the rows'). */
TEST(ContourTrace, WithoutCornersTheMapsCornerPixelsAreIgnored)
{
	for (const int w : { 320, 33000 }) {
		EdgeMap em = emptyMap(w, 200);
		ring(em, 20, 20, 80, 84);
		ring(em, 87, 20, 140, 84);
		std::mt19937 rng(5);
		for (int k = 0; k < 2500; ++k) {
			const int x = 10 + static_cast<int>(rng() % 280), y = 120 + static_cast<int>(rng() % 70);
			set(em, x, y, (rng() % 5 == 0) ? EdgeMap::kEdge | EdgeMap::kCorner : EdgeMap::kEdge);
		}
		ring(em, 150, 100, 230, 185);
		EdgeMap plain = em;
		for (std::uint8_t &p : plain.pixels)
			p &= EdgeMap::kEdge;
		TraceParams params; /* as the region maps are traced */
		params.min_clusters = 0;
		params.max_winding = 2.0f;
		params.holes = false;
		ContourTracer a, b;
		std::vector<Quad> qa, qb;
		params.corners = false;
		a.trace(em, params, qa);
		params.corners = true;
		b.trace(plain, params, qb);
		EXPECT_EQ(a.bordersFollowed(), b.bordersFollowed()) << w;
		ASSERT_EQ(qa.size(), qb.size()) << w;
		EXPECT_GE(qa.size(), 3u) << w; /* the three rings' outer borders at least */
		for (std::size_t k = 0; k < qa.size(); ++k)
			EXPECT_EQ(std::memcmp(qa[k].corners.data(), qb[k].corners.data(), sizeof qa[k].corners), 0)
				<< w;
	}
}

namespace {

/* The rule removeDuplicateQuads() keeps, as it was first written: each quad
 * compared with every kept one. */
std::vector<Quad> duplicatesRemovedPairwise(std::vector<Quad> quads, float tolerance)
{
	std::vector<Quad> kept;
	for (const Quad &q : quads) {
		bool repeat = false;
		for (const Quad &k : kept)
			for (int shift = 0; shift < 4 && !repeat; ++shift) {
				bool all = true;
				for (int c = 0; c < 4 && all; ++c) {
					const float dx = q.corners[c].x - k.corners[(c + shift) & 3].x;
					const float dy = q.corners[c].y - k.corners[(c + shift) & 3].y;
					all = dx * dx + dy * dy <= tolerance * tolerance;
				}
				repeat = all;
			}
		if (!repeat)
			kept.push_back(q);
	}
	return kept;
}

} // namespace

/* Quads around a few hundred places, each repeated with its corners moved
 * by up to 1.5 px each way (mostly repeats, some not), its start turned,
 * or its corners out of order: the grid keeps exactly the quads, in the
 * order, that comparing with every kept quad keeps. */
TEST(RemoveDuplicateQuads, KeepsWhatComparingEveryPairKeeps)
{
	std::mt19937 rng(16);
	std::uniform_real_distribution<float> place(-50.0f, 2000.0f), side(8.0f, 60.0f), jitter(-1.5f, 1.5f);
	std::uniform_int_distribution<int> turn(0, 3), copies(1, 6);
	std::vector<Quad> quads;
	for (int p = 0; p < 300; ++p) {
		const float x = place(rng), y = place(rng), s = side(rng);
		const std::array<Point2f, 4> base{ Point2f{ x, y }, { x + s, y }, { x + s, y + s }, { x, y + s } };
		for (int c = copies(rng); c > 0; --c) {
			Quad q;
			const int t = turn(rng);
			for (int k = 0; k < 4; ++k)
				q.corners[k] = { base[(k + t) & 3].x + jitter(rng), base[(k + t) & 3].y + jitter(rng) };
			if (c == 2)
				std::swap(q.corners[1], q.corners[3]); /* the other way round: not a repeat */
			q.probeRead = static_cast<int>(quads.size()); /* which one it was */
			quads.push_back(q);
		}
	}
	std::shuffle(quads.begin(), quads.end(), rng);
	/* A corner exactly at the tolerance is a repeat; just beyond, not. */
	Quad edge = quads[0], beyond = quads[0];
	edge.corners[2].x += 2.5f;
	beyond.corners[2].x += 2.5f + 1e-3f;
	edge.probeRead = -2;
	beyond.probeRead = -3;
	quads.push_back(edge);
	quads.push_back(beyond);

	const std::vector<Quad> expected = duplicatesRemovedPairwise(quads, 2.5f);
	PointGrid grid;
	for (int frame = 0; frame < 2; ++frame) { /* a reused grid gives the same */
		std::vector<Quad> got = quads;
		removeDuplicateQuads(got, 2.5f, grid);
		ASSERT_EQ(got.size(), expected.size());
		for (std::size_t i = 0; i < got.size(); ++i)
			EXPECT_EQ(got[i].probeRead, expected[i].probeRead) << "kept quad " << i;
	}
	EXPECT_LT(expected.size(), quads.size() * 2 / 3); /* many were repeats */
	EXPECT_GT(expected.size(), 300u);		   /* and some not */
	EXPECT_TRUE(std::none_of(expected.begin(), expected.end(), [](const Quad &q) { return q.probeRead == -2; }));
	EXPECT_TRUE(std::any_of(expected.begin(), expected.end(), [](const Quad &q) { return q.probeRead == -3; }));
}

/* Over the cap: the probe's markers first, then the others from the front,
 * each kept in its place; the count of the dropped returned. */
TEST(CapCandidates, KeepsTheProbesMarkersThenTheFirst)
{
	std::vector<Quad> quads(10);
	for (int i = 0; i < 10; ++i) {
		quads[i].probeRead = i;
		quads[i].probeDecoded = i == 7 || i == 9;
	}
	std::vector<Quad> under = quads;
	EXPECT_EQ(capCandidates(under, 10), 0);
	EXPECT_EQ(under.size(), 10u);

	EXPECT_EQ(capCandidates(quads, 5), 5);
	std::vector<int> kept;
	for (const Quad &q : quads)
		kept.push_back(q.probeRead);
	EXPECT_EQ(kept, (std::vector<int>{ 0, 1, 2, 7, 9 }));

	std::vector<Quad> one = quads;
	EXPECT_EQ(capCandidates(one, 1), 4);
	ASSERT_EQ(one.size(), 1u);
	EXPECT_EQ(one[0].probeRead, 7);
}

/* Issue 34: over the cap, the ranks the probe gives: markers, then near
 * codewords (a damaged marker), then readable frames, then the rest, each
 * rank from the front, the kept ones in their order. */
TEST(CapCandidates, RanksNearCodesThenReadableFramesBeforeTheRest)
{
	std::vector<Quad> quads(12);
	for (int i = 0; i < 12; ++i) {
		quads[i].probeRead = i;
		quads[i].probeDecoded = i == 11;
		quads[i].probeNearCode = i == 9 || i == 10;
		quads[i].probeReadable = i >= 6;
	}
	std::vector<Quad> four = quads;
	EXPECT_EQ(capCandidates(four, 4), 8);
	std::vector<int> kept;
	for (const Quad &q : four)
		kept.push_back(q.probeRead);
	EXPECT_EQ(kept, (std::vector<int>{ 6, 9, 10, 11 }));

	std::vector<Quad> two = quads;
	EXPECT_EQ(capCandidates(two, 2), 10);
	kept.clear();
	for (const Quad &q : two)
		kept.push_back(q.probeRead);
	EXPECT_EQ(kept, (std::vector<int>{ 9, 11 }));

	std::vector<Quad> eight = quads;
	EXPECT_EQ(capCandidates(eight, 8), 4);
	kept.clear();
	for (const Quad &q : eight)
		kept.push_back(q.probeRead);
	EXPECT_EQ(kept, (std::vector<int>{ 0, 1, 6, 7, 8, 9, 10, 11 }));
}
