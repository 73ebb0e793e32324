// SPDX-License-Identifier: MIT
// The checks a decoded candidate passes before it is reported, each on
// inputs whose answer is known exactly: sample grids set by hand, markers
// rendered upright on whole pixels, quads placed by hand.
#include <bit>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "decode.h"
#include "frappe/frappe.h"
#include "frappe/render.h"
#include "scene.h"
#include "marker_set.h"
#include "verify.h"

using namespace frappe;
using frappe::test::Image;

namespace {

using Quad = std::array<Point2f, 4>;

/* A 2x2-samples-a-cell grid for a marker of `bits` bits: black border,
 * code cells from `code` (1 = white), black = 0 and white = 200. */
detail::WarpedMarker gridOf(std::uint64_t code, int bits)
{
	detail::WarpedMarker w;
	const int cells = bits + 2;
	w.side = cells * 2;
	for (int cy = 0; cy < cells; ++cy) {
		for (int cx = 0; cx < cells; ++cx) {
			float v = 0.0f;
			if (cx > 0 && cy > 0 && cx <= bits && cy <= bits) {
				const int bit = bits * bits - 1 - ((cy - 1) * bits + (cx - 1));
				v = (code >> bit) & 1 ? 200.0f : 0.0f;
			}
			for (int y = 0; y < 2; ++y)
				for (int x = 0; x < 2; ++x)
					w.samples[static_cast<std::size_t>((cy * 2 + y) * w.side + cx * 2 + x)] = v;
		}
	}
	return w;
}

void setCell(detail::WarpedMarker &w, int cx, int cy, float a, float b, float c, float d)
{
	const float v[4] = { a, b, c, d };
	for (int k = 0; k < 4; ++k)
		w.samples[static_cast<std::size_t>((cy * 2 + k / 2) * w.side + cx * 2 + k % 2)] = v[k];
}

/* Threshold 100 of contrast 200: a ring sample above 100 is light, one
 * below 70 clearly dark. */
detail::Binarised levels()
{
	detail::Binarised b;
	b.threshold = 100.0f;
	b.contrast = 200.0f;
	return b;
}

Quad square(float x, float y, float side)
{
	return { Point2f{ x, y }, { x + side, y }, { x + side, y + side }, { x, y + side } };
}

} // namespace

/* ---- the decoding policy ---- */

TEST(DecodePolicy, CarefulDefaultsPerDictionary)
{
	/* The documented rule, evaluated: 4x4 and 5x5 codes are too dense to
	 * correct a clear bit; 36-bit families correct one or two. */
	const std::pair<const char *, std::array<int, 2>> expected[] = {
		{ "4x4_50", { 0, 0 } },		 { "4x4_1000", { 0, 0 } },	 { "apriltag_16h5", { 0, 0 } },
		{ "5x5_50", { 0, 3 } },		 { "apriltag_25h9", { 0, 3 } },	 { "6x6_250", { 2, 5 } },
		{ "6x6_1000", { 1, 4 } },	 { "apriltag_36h10", { 1, 4 } }, { "apriltag_36h11", { 1, 5 } },
		{ "aruco_mip_36h12", { 2, 5 } }, { "7x7_50", { 5, 5 } },	 { "aruco_original", { 0, 0 } },
	};
	for (const auto &[name, h] : expected) {
		const Dictionary &d = *findDictionary(name);
		EXPECT_EQ(d.defaultMaxHamming(), h[0]) << name;
		EXPECT_EQ(d.weakMaxHamming(), h[1]) << name;
	}
	for (const Dictionary &d : dictionaries()) {
		EXPECT_LE(d.defaultMaxHamming(), d.weakMaxHamming()) << d.name;
		EXPECT_LE(2 * d.weakMaxHamming(), std::max(0, d.min_hamming - 1)) << d.name;
	}
}

TEST(DecodePolicy, RunnerUpIsTheNearestOtherId)
{
	const Dictionary &d = *findDictionary("aruco_mip_36h12");
	/* Id 0 with two bits flipped: 2 from id 0, and the nearest other id is
	 * where the scan says it is (at least dmin - 2). */
	const std::uint64_t seen = d.codes[0] ^ 0b101;
	const detail::Decoded got = detail::decode(d, seen, 5);
	ASSERT_EQ(got.id, 0);
	EXPECT_EQ(got.hamming, 2);
	int nearest = 99;
	for (int id = 1; id < d.size(); ++id) {
		std::uint64_t c = d.codes[static_cast<std::size_t>(id)];
		for (int r = 0; r < 4; ++r, c = rotateCode(c, d.bits))
			nearest = std::min(nearest, std::popcount(c ^ seen));
	}
	EXPECT_EQ(got.runnerUp, nearest);
	EXPECT_GE(got.runnerUp, d.min_hamming - 2);
	/* An exact read through the code book reports the dictionary's
	 * minimum distance, a lower bound. */
	const detail::CodeBook book(d);
	EXPECT_EQ(book.decode(d.codes[7], 0).runnerUp, d.min_hamming);
}

TEST(DecodePolicy, AmbiguityGap)
{
	const Dictionary &d = *findDictionary("aruco_mip_36h12");
	detail::Decoded x;
	x.id = 3;
	x.hamming = 4;
	x.runnerUp = 6;
	EXPECT_TRUE(detail::unambiguous(x, d));
	x.runnerUp = 5;
	EXPECT_FALSE(detail::unambiguous(x, d));
	/* With codes one bit apart (aruco_original), only a tie is ambiguous. */
	const Dictionary &o = *findDictionary("aruco_original");
	x.hamming = 0;
	x.runnerUp = 1;
	EXPECT_TRUE(detail::unambiguous(x, o));
	x.runnerUp = 0;
	EXPECT_FALSE(detail::unambiguous(x, o));
}

TEST(DecodePolicy, ClearErrorsLeaveOutWeakCellsInEveryRotation)
{
	const Dictionary &d = *findDictionary("aruco_mip_36h12");
	const std::uint64_t flips = (1ull << 35) | (1ull << 20) | (1ull << 3); /* three cells */
	const std::uint64_t weak = (1ull << 35) | (1ull << 3);		      /* two of them weak */
	std::uint64_t seen = d.codes[11] ^ flips, weakSeen = weak;
	for (int turn = 0; turn < 4; ++turn) {
		const detail::Decoded got = detail::decode(d, seen, 5);
		ASSERT_EQ(got.id, 11) << "turn " << turn;
		EXPECT_EQ(got.hamming, 3);
		EXPECT_EQ(detail::clearErrors(d, seen, weakSeen, got), 1) << "turn " << turn;
		EXPECT_EQ(detail::clearErrors(d, seen, 0, got), 3) << "turn " << turn;
		seen = rotateCode(seen, d.bits);
		weakSeen = rotateCode(weakSeen, d.bits);
	}
}

/* ---- the cells ---- */

TEST(CellRead, MarginIsTheWeakestCodeCell)
{
	const Dictionary &d = *findDictionary("aruco_mip_36h12");
	detail::WarpedMarker w = gridOf(d.codes[5], d.bits);
	detail::Binarised b = detail::binarise(w, d.bits);
	ASSERT_EQ(b.code, d.codes[5]);
	EXPECT_FLOAT_EQ(b.threshold, 100.0f);
	detail::CellRead c = detail::readCells(w, d.bits, b, 0.3f);
	EXPECT_FLOAT_EQ(c.margin, 1.0f);
	EXPECT_EQ(c.weak, 0u);
	EXPECT_EQ(c.straddling, 0);

	/* Code cell (row 2, column 3) at mean 130: 30 above the threshold, of a
	 * half contrast of 100. Border cells do not count. */
	setCell(w, 3, 2, 130, 130, 130, 130);
	setCell(w, 0, 4, 90, 90, 90, 90);
	b = detail::binarise(w, d.bits);
	c = detail::readCells(w, d.bits, b, 0.31f);
	EXPECT_NEAR(c.margin, 0.3f, 1e-6f);
	const int bit = d.bits * d.bits - 1 - ((2 - 1) * d.bits + (3 - 1));
	EXPECT_EQ(c.weak, 1ull << bit);
	EXPECT_EQ(detail::readCells(w, d.bits, b, 0.29f).weak, 0u);
}

/* Glare: where a border cell (black ink) clips, a clipped code cell may be
 * black under the glare: it is unknown (weak, margin 0). Without glare on
 * the border a clipped white cell is read as white. */
TEST(CellRead, ClippedCellsUnderGlareAreUnknown)
{
	const Dictionary &d = *findDictionary("aruco_mip_36h12");
	detail::WarpedMarker w = gridOf(d.codes[5], d.bits);
	setCell(w, 3, 2, 255, 255, 255, 255); /* a clipped code cell */
	detail::Binarised b = detail::binarise(w, d.bits);
	detail::CellRead c = detail::readCells(w, d.bits, b, 0.3f);
	const int bit = d.bits * d.bits - 1 - ((2 - 1) * d.bits + (3 - 1));
	EXPECT_EQ(c.weak & (1ull << bit), 0u) << "no glare on the border: a white cell";
	setCell(w, 0, 4, 252, 255, 253, 255); /* glare on the border */
	b = detail::binarise(w, d.bits);
	c = detail::readCells(w, d.bits, b, 0.3f);
	EXPECT_NE(c.weak & (1ull << bit), 0u);
	EXPECT_FLOAT_EQ(c.margin, 0.0f);
	/* The same on the log scale. */
	const detail::Tone tone{ 16.0f };
	for (float &v : w.samples)
		v = tone.apply(v);
	b = detail::binarise(w, d.bits);
	EXPECT_NE(detail::readCells(w, d.bits, b, 0.3f, tone).weak & (1ull << bit), 0u);
}

TEST(CellRead, SamplesOnBothSidesOfTheThresholdStraddle)
{
	const Dictionary &d = *findDictionary("aruco_mip_36h12");
	detail::WarpedMarker w = gridOf(d.codes[9], d.bits);
	/* Threshold 100, contrast 200: a cell straddles when a sample is below
	 * 70 and another above 130. */
	setCell(w, 2, 2, 0, 200, 0, 200);   /* straddles */
	setCell(w, 4, 3, 60, 140, 60, 140); /* straddles */
	setCell(w, 5, 5, 80, 140, 80, 140); /* one side only clearly */
	setCell(w, 0, 3, 0, 200, 200, 200); /* border cells count too */
	const detail::Binarised b = detail::binarise(w, d.bits);
	const detail::CellRead c = detail::readCells(w, d.bits, b, 0.3f);
	EXPECT_EQ(c.straddling, 3);
	/* One cell in eight may straddle: 4 of 36 for 6x6, 2 of 16 for 4x4. */
	detail::CellRead r;
	r.straddling = 4;
	EXPECT_TRUE(detail::cellsAgree(r, 6));
	r.straddling = 5;
	EXPECT_FALSE(detail::cellsAgree(r, 6));
	r.straddling = 2;
	EXPECT_TRUE(detail::cellsAgree(r, 4));
	r.straddling = 3;
	EXPECT_FALSE(detail::cellsAgree(r, 4));
}

TEST(CellRead, BorderWithWhiteCells)
{
	const Dictionary &d = *findDictionary("aruco_mip_36h12");
	detail::WarpedMarker w = gridOf(d.codes[2], d.bits);
	for (int c = 0; c < 3; ++c)
		setCell(w, c, 0, 200, 200, 200, 200);
	detail::Binarised b = detail::binarise(w, d.bits);
	EXPECT_EQ(b.border_errors, 3);
	EXPECT_TRUE(detail::borderIsBlack(b, d.bits));
	setCell(w, 7, 7, 200, 200, 200, 200);
	b = detail::binarise(w, d.bits);
	EXPECT_EQ(b.border_errors, 4);
	EXPECT_FALSE(detail::borderIsBlack(b, d.bits));
	/* 4x4: two of the 20 border cells. */
	b.border_errors = 2;
	EXPECT_TRUE(detail::borderIsBlack(b, 4));
	b.border_errors = 3;
	EXPECT_FALSE(detail::borderIsBlack(b, 4));
}

/* ---- the quiet zone ---- */

TEST(QuietZone, RingOutsideTheBorder)
{
	const Dictionary &d = *findDictionary("aruco_mip_36h12");
	/* 8 px cells, one cell of quiet zone, on black: the ring is exactly
	 * the quiet zone, the cells beyond it black. */
	Image img(120, 120, 0);
	const Quad q = square(19.5f, 19.5f, 64.0f);
	RenderOptions opt;
	opt.supersample = 1;
	renderMarker(img.mut(), d, 4, q, opt);
	const detail::QuietZone z = detail::readQuietZone(img.view(), q, d.bits, levels());
	EXPECT_EQ(z.seen, 4 * (d.bits + 3));
	EXPECT_EQ(z.light, 4 * (d.bits + 3));
	EXPECT_TRUE(detail::quietZoneIsLight(z));

	/* Without a quiet zone, on black: nothing light. */
	Image dark(120, 120, 0);
	opt.quiet_cells = 0;
	renderMarker(dark.mut(), d, 4, q, opt);
	const detail::QuietZone none = detail::readQuietZone(dark.view(), q, d.bits, levels());
	EXPECT_EQ(none.seen, 36);
	EXPECT_EQ(none.light, 0);
	EXPECT_EQ(none.dark, 36);
	EXPECT_FALSE(detail::quietZoneIsLight(none));

	/* The same quad read as a 4x4 marker: the ring is a cell of 64 / 6 px
	 * outside, still the quiet zone. */
	EXPECT_EQ(detail::readQuietZone(img.view(), q, 4, levels()).light, 28);
}

TEST(QuietZone, OutsideTheImageIsUnknown)
{
	const Dictionary &d = *findDictionary("aruco_mip_36h12");
	/* A marker whose left quiet zone is cut off by the frame's edge: the
	 * ring's left column is not seen, the rest is light. */
	Image img(90, 90, 0);
	const Quad q = square(2.5f, 12.5f, 64.0f);
	RenderOptions opt;
	opt.supersample = 1;
	renderMarker(img.mut(), d, 4, q, opt);
	const detail::QuietZone z = detail::readQuietZone(img.view(), q, d.bits, levels());
	EXPECT_EQ(z.seen, 4 * (d.bits + 3) - (d.bits + 4));
	EXPECT_EQ(z.light, z.seen);
	EXPECT_TRUE(detail::quietZoneIsLight(z));
}

TEST(Scrutiny, WeakCodesNeedACleanFrame)
{
	const Dictionary &mip = *findDictionary("aruco_mip_36h12");
	EXPECT_EQ(detail::scrutinyFor(mip, 0), detail::Scrutiny::Tolerant);
	EXPECT_EQ(detail::scrutinyFor(mip, 2), detail::Scrutiny::Tolerant);
	EXPECT_EQ(detail::scrutinyFor(mip, 3), detail::Scrutiny::Strict);
	EXPECT_EQ(detail::scrutinyFor(*findDictionary("4x4_50"), 0), detail::Scrutiny::Strict);
	EXPECT_EQ(detail::scrutinyFor(*findDictionary("apriltag_25h9"), 0), detail::Scrutiny::Tolerant);
	/* The chance behind it: 4 x 250 codes / 2^36 for an exact read. */
	EXPECT_NEAR(mip.randomDecodeChance(0), 1000.0 / 68719476736.0, 1e-15);
	EXPECT_NEAR(mip.randomDecodeChance(1), 37 * 1000.0 / 68719476736.0, 1e-14);

	/* One side of the ring missing (a card's edge): tolerated only for
	 * strong reads. 26 of 36 light, 10 dark. */
	const detail::QuietZone cut{ 26, 10, 36 };
	EXPECT_TRUE(detail::quietZoneIsLight(cut, detail::Scrutiny::Tolerant));
	EXPECT_FALSE(detail::quietZoneIsLight(cut, detail::Scrutiny::Strict));
	EXPECT_FALSE(detail::quietZoneIsLight({ 23, 13, 36 }, detail::Scrutiny::Tolerant));
	detail::CellRead c;
	c.straddling = 9;
	EXPECT_TRUE(detail::cellsAgree(c, 6, detail::Scrutiny::Tolerant));
	EXPECT_FALSE(detail::cellsAgree(c, 6, detail::Scrutiny::Strict));
	c.straddling = 10;
	EXPECT_FALSE(detail::cellsAgree(c, 6, detail::Scrutiny::Tolerant));
}

TEST(QuietZone, ThreeQuartersLightFewClearlyDark)
{
	detail::QuietZone z{ 27, 0, 36 };
	EXPECT_TRUE(detail::quietZoneIsLight(z));
	z.light = 26;
	EXPECT_FALSE(detail::quietZoneIsLight(z));
	/* Grey cells (blur on a one-cell zone) are tolerated, black ones
	 * (the cells around a block of code) only one in sixteen. */
	z = { 30, 2, 36 };
	EXPECT_TRUE(detail::quietZoneIsLight(z));
	z = { 30, 3, 36 };
	EXPECT_FALSE(detail::quietZoneIsLight(z));
	z = { 26, 1, 28 };
	EXPECT_TRUE(detail::quietZoneIsLight(z));
	z = { 26, 2, 28 };
	EXPECT_FALSE(detail::quietZoneIsLight(z));
	/* Too little of the ring in the image to judge. */
	z = { 0, 7, 7 };
	EXPECT_TRUE(detail::quietZoneIsLight(z));
}

/* ---- nesting ---- */

TEST(Nesting, InsideTheCodeArea)
{
	/* A 6x6 marker of 80 px: 10 px cells, code area [10, 70] from its
	 * corner; corners within half a cell of the border count. */
	const Quad marker = square(100, 100, 80);
	EXPECT_TRUE(detail::insideCodeArea(square(110, 110, 60), marker, 6));
	EXPECT_TRUE(detail::insideCodeArea(square(106, 130, 20), marker, 6));
	EXPECT_FALSE(detail::insideCodeArea(square(104, 130, 20), marker, 6));
	EXPECT_FALSE(detail::insideCodeArea(square(160, 160, 20), marker, 6));
	EXPECT_FALSE(detail::insideCodeArea(marker, marker, 6));
	EXPECT_FALSE(detail::insideCodeArea(square(90, 90, 100), marker, 6));
}

TEST(Nesting, DropsMarkersInsideOthers)
{
	std::vector<Marker> found(4);
	found[0].id = 7;
	found[0].corners = square(120, 120, 30); /* inside [1] */
	found[1].id = 3;
	found[1].corners = square(100, 100, 80);
	found[2].id = 9;
	found[2].corners = square(300, 100, 80); /* beside */
	found[3].id = 4;
	found[3].corners = square(315, 115, 20); /* inside [2] */
	detail::dropNestedMarkers(found, 6);
	ASSERT_EQ(found.size(), 2u);
	EXPECT_EQ(found[0].id, 3);
	EXPECT_EQ(found[1].id, 9);
}

/* Hundreds of markers of all sizes, many nested in others (some two deep),
 * some tilted: the grid drops exactly the markers, and keeps the rest in
 * their order, that testing every pair does. */
TEST(Nesting, GridDropsWhatTestingEveryPairDrops)
{
	std::mt19937 rng(16);
	std::uniform_real_distribution<float> place(0.0f, 3000.0f), side(10.0f, 300.0f), frac(0.0f, 1.0f);
	std::vector<Marker> found;
	for (int i = 0; i < 600; ++i) {
		Marker m;
		m.id = i;
		if (!found.empty() && frac(rng) < 0.4f) {
			/* Within (or straddling) an earlier one. */
			const Marker &o = found[static_cast<std::size_t>(rng() % found.size())];
			const float os = o.corners[1].x - o.corners[0].x, s = os * (0.1f + 0.5f * frac(rng));
			/* One draw a statement, in the order x86 has drawn them: a call's
			 * arguments are evaluated in an unspecified order (GCC for ARM
			 * draws them in another, rendering other scenes). */
			const float fy = frac(rng);
			const float fx = frac(rng);
			m.corners = square(o.corners[0].x + (os - s) * fx, o.corners[0].y + (os - s) * fy, s);
		} else {
			const float roll = 90.0f * frac(rng);
			const float sd = side(rng);
			const float y = place(rng);
			const float x = place(rng);
			m.corners = test::squarePose(x, y, sd, roll, 0.0f);
		}
		found.push_back(m);
	}
	std::vector<int> expected;
	for (const Marker &m : found) {
		bool nested = false;
		for (const Marker &outer : found)
			nested = nested || (&outer != &m && detail::insideCodeArea(m.corners, outer.corners, 6));
		if (!nested)
			expected.push_back(m.id);
	}
	detail::PointGrid grid;
	for (int frame = 0; frame < 2; ++frame) {
		std::vector<Marker> got = found;
		detail::dropNestedMarkers(got, 6, grid);
		std::vector<int> ids;
		for (const Marker &m : got)
			ids.push_back(m.id);
		EXPECT_EQ(ids, expected);
	}
	EXPECT_LT(expected.size(), 550u); /* many were nested */
}

/* Candidates around markers of all sizes: looking only at the markers
 * whose centre is filed near a candidate's finds the quiet-zone outlines
 * that testing every marker finds, and no others. */
TEST(Nesting, SurroundsMarkerThroughTheGridAsThroughAll)
{
	std::mt19937 rng(17);
	std::uniform_real_distribution<float> place(0.0f, 2000.0f), side(10.0f, 200.0f), frac(0.0f, 1.0f);
	std::vector<Marker> found(300);
	detail::PointGrid centres;
	centres.reset(found.size(), 32.0f);
	for (std::size_t i = 0; i < found.size(); ++i) {
		found[i].id = static_cast<int>(i);
		/* One draw a statement, in x86's order (see above). */
		const float sd = side(rng);
		const float y = place(rng);
		const float x = place(rng);
		found[i].corners = square(x, y, sd);
		centres.add(static_cast<int>(i), 0, detail::quadCentre(found[i].corners));
	}
	const detail::PointGrid none = [] {
		detail::PointGrid g;
		g.reset(0, 32.0f);
		return g;
	}();
	int surrounding = 0;
	for (int k = 0; k < 2000; ++k) {
		const Marker &m = found[rng() % found.size()];
		const float ms = m.corners[1].x - m.corners[0].x, grow = ms * (2.0f * frac(rng) - 0.3f);
		const float shift = ms * (0.6f * frac(rng) - 0.3f);
		const Quad q = square(m.corners[0].x - grow / 2 + shift, m.corners[0].y - grow / 2, ms + grow);
		/* The rule, on every marker: about its size, centred on it. */
		const float area = detail::quadArea(q);
		const Point2f c = detail::quadCentre(q);
		bool all = false;
		for (const Marker &f : found) {
			const float am = detail::quadArea(f.corners);
			const Point2f cm = detail::quadCentre(f.corners);
			const float dx = c.x - cm.x, dy = c.y - cm.y;
			all = all || (area <= 3.0f * am && am <= 3.0f * area && dx * dx + dy * dy < 0.12f * am);
		}
		const bool grid = detail::surroundsMarker(q, detail::quadArea(q), -1, 6, found, centres);
		EXPECT_EQ(grid, all) << "candidate " << k;
		EXPECT_FALSE(detail::surroundsMarker(q, detail::quadArea(q), -1, 6, found, none));
		surrounding += grid;
	}
	EXPECT_GT(surrounding, 200); /* both answers were asked */
	EXPECT_LT(surrounding, 1800);
}

/* ---- all of it, on one candidate ---- */

TEST(ReadMarker, EachRejectionOnItsOwn)
{
	const Dictionary &d = *findDictionary("aruco_mip_36h12");
	const detail::CodeBook book(d);
	detail::DecodePolicy policy{ 2, 5, 0.3f, {} };
	Image img(120, 120, 255);
	const Quad q = square(19.5f, 19.5f, 64.0f);
	RenderOptions opt;
	opt.supersample = 1;
	renderMarker(img.mut(), d, 4, q, opt);
	detail::WarpedMarker w;
	ASSERT_TRUE(detail::warpMarker(img.view(), q, d.bits, w));
	detail::Binarised b = detail::binarise(w, d.bits);
	detail::MarkerRead r = detail::readMarker(img.view(), q, book, policy, w, b);
	ASSERT_TRUE(r.ok());
	EXPECT_EQ(r.decoded.id, 4);
	EXPECT_FLOAT_EQ(r.margin, 1.0f);

	/* Three clearly wrong cells: beyond max_hamming 2. */
	detail::WarpedMarker bad = w;
	const float hi = 255.0f;
	for (int k = 1; k <= 3; ++k) {
		const bool white = (d.codes[4] >> (35 - (k - 1))) & 1;
		const float v = white ? 0.0f : hi;
		setCell(bad, k, 1, v, v, v, v);
	}
	b = detail::binarise(bad, d.bits);
	r = detail::readMarker(img.view(), q, book, policy, bad, b);
	EXPECT_EQ(r.rejection, detail::Rejection::TooManyClearErrors);
	/* The same three cells read weakly (near the threshold): corrected. */
	for (int k = 1; k <= 3; ++k) {
		const bool white = (d.codes[4] >> (35 - (k - 1))) & 1;
		const float v = white ? 120.0f : 135.0f;
		setCell(bad, k, 1, v, v, v, v);
	}
	b = detail::binarise(bad, d.bits);
	r = detail::readMarker(img.view(), q, book, policy, bad, b);
	ASSERT_TRUE(r.ok()) << static_cast<int>(r.rejection);
	EXPECT_EQ(r.decoded.hamming, 3);
	EXPECT_NEAR(r.margin, 7.5f / 127.5f, 1e-5f);

	/* Four white border cells. */
	detail::WarpedMarker frame = w;
	for (int c = 2; c < 6; ++c)
		setCell(frame, c, 0, hi, hi, hi, hi);
	b = detail::binarise(frame, d.bits);
	EXPECT_EQ(detail::readMarker(img.view(), q, book, policy, frame, b).rejection,
		  detail::Rejection::BorderNotBlack);

	/* Ten split cells, each still read as its bit: more than the quarter
	 * of 36 an exact read may have. */
	detail::WarpedMarker split = w;
	for (int k = 0; k < 10; ++k) {
		const int cx = 1 + k % 6, cy = 5 + k / 6;
		const bool white = (d.codes[4] >> (35 - ((cy - 1) * 6 + cx - 1))) & 1;
		if (white)
			setCell(split, cx, cy, 60, hi, hi, hi);
		else
			setCell(split, cx, cy, 0, 0, 0, 200);
	}
	b = detail::binarise(split, d.bits);
	ASSERT_EQ(b.code, d.codes[4]);
	EXPECT_EQ(detail::readMarker(img.view(), q, book, policy, split, b).rejection,
		  detail::Rejection::CellsDisagree);

	/* The same marker on black, without a quiet zone. */
	Image dark(120, 120, 0);
	opt.quiet_cells = 0;
	renderMarker(dark.mut(), d, 4, q, opt);
	b = detail::binarise(w, d.bits);
	EXPECT_EQ(detail::readMarker(dark.view(), q, book, policy, w, b).rejection, detail::Rejection::NoQuietZone);
}

/* The margin reaches the caller: a sharp marker reads near 1, the same
 * marker under blur and noise lower, never outside [0, 1]. */
TEST(ReadMarker, MarginOfDetectedMarkers)
{
	const Dictionary &d = *findDictionary("aruco_mip_36h12");
	Detector det(Config{});
	Image img(200, 200, 255);
	const Quad q = square(50.5f, 50.5f, 96.0f);
	renderMarker(img.mut(), d, 21, q, RenderOptions{});
	const Result sharp = det.detect(img.view());
	ASSERT_EQ(sharp.markers.size(), 1u);
	EXPECT_GT(sharp.markers[0].margin, 0.95f);
	frappe::test::blur(img, 2.5f);
	const Result &soft = det.detect(img.view());
	ASSERT_EQ(soft.markers.size(), 1u);
	EXPECT_LT(soft.markers[0].margin, sharp.markers[0].margin);
	EXPECT_GE(soft.markers[0].margin, 0.0f);
}

/* ---- small cells, read at their centres ---- */

/* A small, blurred marker reads at its cell centres; a black square of the
 * same size, whose inside is noise, does not (its payload never reaches the
 * level between the border and the white around it). */
TEST(ReadCellCentres, SmallMarkerYesDarkSquareNo)
{
	const Dictionary &d = *findDictionary("aruco_mip_36h12");
	const detail::CodeBook book(d);
	const detail::DecodePolicy policy{ 2, 5, 0.3f, {} };
	const Quad q = square(20.5f, 20.5f, 17.0f); /* 8 cells of 2.1 px */
	Image img(60, 60, 220);
	RenderOptions opt;
	opt.black = 30;
	opt.white = 220;
	renderMarker(img.mut(), d, 77, q, opt);
	frappe::test::blur(img, 0.7f);
	detail::WarpedMarker w;
	const detail::MarkerRead r = detail::readCellCentres(img.view(), q, book, policy, w);
	ASSERT_TRUE(r.ok()) << static_cast<int>(r.rejection);
	EXPECT_EQ(r.decoded.id, 77);

	std::mt19937 rng(5);
	for (int k = 0; k < 20; ++k) {
		Image dark(60, 60, 220);
		for (int y = 21; y < 38; ++y)
			for (int x = 21; x < 38; ++x)
				dark.at(x, y) = 30;
		frappe::test::addNoise(dark, 3.0f, rng);
		EXPECT_FALSE(detail::readCellCentres(dark.view(), q, book, policy, w).ok()) << k;
	}
}

/* Markers of another family, small, read at their own outline by a 4x4
 * dictionary: the grid does not sit on their cells. One of all 4x4
 * patterns in sixteen is a 4x4_1000 code; the checks for a read that chance makes
 * often (the cells' agreement on a quarter-cell grid, the clearly read
 * cells) must turn almost all of them away. */
TEST(ReadCellCentres, AnotherFamilyOnTheWrongGrid)
{
	const Dictionary &mip = *findDictionary("aruco_mip_36h12");
	const Dictionary &d = *findDictionary("4x4_1000");
	const detail::CodeBook book(d);
	const detail::DecodePolicy policy{ d.defaultMaxHamming(), d.weakMaxHamming(), 0.3f, {} };
	const Quad q = square(20.5f, 20.5f, 18.0f);
	int read = 0;
	for (int id = 0; id < 100; ++id) {
		Image img(60, 60, 220);
		RenderOptions opt;
		opt.black = 30;
		opt.white = 220;
		renderMarker(img.mut(), mip, id, q, opt);
		frappe::test::blur(img, 0.6f);
		detail::WarpedMarker w;
		read += detail::readCellCentres(img.view(), q, book, policy, w).ok();
	}
	EXPECT_LE(read, 2);
}

/* ---- plain codewords (the shapes of letters) ---- */

/* The plain codes of each built-in dictionary, counted by hand from the
 * rule (at most 0.6 n (n + 1) black-white changes, border included): ArUco's
 * original dictionary's hollow rectangle (id 1023, every row 01110) is one,
 * a code of changes everywhere is not; AprilTag's families, made to avoid
 * simple shapes, have none. */
TEST(PlainCode, HollowShapesAndBarsArePlain)
{
	const Dictionary &original = *findDictionary("aruco_original");
	const detail::CodeBook book(original);
	EXPECT_TRUE(book.plain(1023));
	EXPECT_TRUE(detail::plainCode(0, 4));                   /* all black: no change at all */
	EXPECT_FALSE(detail::plainCode(0b1010'0101'1010'0101u, 4)); /* a checkerboard: 32 changes */
	EXPECT_TRUE(detail::plainCode(0b0110'0110'0110'0110u, 4));  /* a bar, 2 wide: 12 of 20 */
	EXPECT_FALSE(detail::plainCode(0b0110'1111'0110'0000u, 4)); /* a plus, 13 changes */
	auto count = [](const char *name) {
		const Dictionary &d = *findDictionary(name);
		const detail::CodeBook b(d);
		int n = 0;
		for (int id = 0; id < d.size(); ++id)
			n += b.plain(id);
		return n;
	};
	EXPECT_EQ(count("aruco_original"), 12);
	EXPECT_EQ(count("4x4_1000"), 29);
	EXPECT_EQ(count("4x4_50"), 1);
	EXPECT_EQ(count("5x5_1000"), 3);
	for (const char *name : { "apriltag_16h5", "apriltag_25h9", "apriltag_36h10", "apriltag_36h11", "aruco_mip_36h12",
				  "6x6_250", "7x7_1000" })
		EXPECT_EQ(count(name), 0) << name;
}

/* A plain code must be read clearly: with one code cell read at margin 0.2
 * the plain id 17 of 4x4_50 is refused as a plain shape, a code of many
 * changes read the same way is not; read clearly, both are markers. */
TEST(PlainCode, ReadOnlyClearly)
{
	const Dictionary &d = *findDictionary("4x4_50");
	const detail::CodeBook book(d);
	ASSERT_TRUE(book.plain(17));
	int busy = -1;
	for (int id = 0; id < d.size() && busy < 0; ++id)
		if (!book.plain(id))
			busy = id;
	/* Corners far outside the 1 x 1 image: the quiet zone is unknown, so it
	 * passes; every other check is the grid's. */
	const Image img(1, 1, 0);
	const Quad far = square(1000.0f, 1000.0f, 60.0f);
	detail::DecodePolicy policy;
	policy.maxHamming = policy.maxTotal = 0;
	for (int id : { 17, busy }) {
		detail::WarpedMarker w = gridOf(d.codes[static_cast<std::size_t>(id)], d.bits);
		detail::Binarised b = detail::binarise(w, d.bits);
		EXPECT_TRUE(detail::readMarker(img.view(), far, book, policy, w, b).ok()) << id;
		/* A white code cell at 120: 20 above the threshold of 100. */
		int white = -1;
		for (int bit = 0; bit < d.bits * d.bits && white < 0; ++bit)
			if ((d.codes[static_cast<std::size_t>(id)] >> (d.bits * d.bits - 1 - bit)) & 1u)
				white = bit;
		ASSERT_GE(white, 0);
		setCell(w, 1 + white % d.bits, 1 + white / d.bits, 120, 120, 120, 120);
		b = detail::binarise(w, d.bits);
		const detail::MarkerRead r = detail::readMarker(img.view(), far, book, policy, w, b);
		EXPECT_NEAR(r.margin, 0.2f, 1e-5f) << id;
		EXPECT_EQ(r.rejection, id == 17 ? detail::Rejection::PlainShape : detail::Rejection::None) << id;
	}
}
