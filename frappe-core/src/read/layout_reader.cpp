// SPDX-License-Identifier: MIT
#include "layout_reader.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "frappe/homography.h"

namespace frappe::detail {

bool layoutGrid(const std::array<Point2f, 4> &square, const MarkerLayout &layout, std::array<Point2f, 4> &grid)
{
	const auto H = Homography::fromUnitSquare(square);
	if (!H)
		return false;
	/* The grid spans cells -1 .. size of the layout; the square spans
	 * square_start .. square_start + square_cells, the unit square. */
	const double w = layout.square_cells;
	const double lo = (-1.0 - layout.square_start) / w, hi = (layout.size + 1.0 - layout.square_start) / w;
	grid = { H->map(lo, lo), H->map(hi, lo), H->map(hi, hi), H->map(lo, hi) };
	return true;
}

namespace {

/* A plane v = a + bx x + by y over a ring of cells centred on the layout's
 * centre: over a whole ring x, y and x y sum to 0, so least squares
 * separate into three means. */
struct Plane {
	float a = 0.0f, bx = 0.0f, by = 0.0f;
	float at(float x, float y) const { return a + bx * x + by * y; }
};

/* The grid position (x, y) of each cell of a ring, in order. */
template<typename F>
void forRing(const MarkerLayout &l, int ring, F &&f)
{
	const int lo = ring, hi = l.size - 1 - ring;
	for (int y = lo; y <= hi; ++y)
		for (int x = lo; x <= hi; ++x)
			if (x == lo || x == hi || y == lo || y == hi)
				f(x, y);
}

/* Under glare (`unknown` says which cells clip) a ring's clipped cells
 * take its other cells' mean: the fit then follows the light on the
 * marker, not on the glare. */
template<typename Unknown>
Plane fitRing(const WarpedMarker &g, const MarkerLayout &l, int ring, bool glare, Unknown &&unknown)
{
	float known = 0.0f;
	int nKnown = 0;
	if (glare)
		forRing(l, ring, [&](int x, int y) {
			if (!unknown(x, y)) {
				known += g.at(x + 1, y + 1);
				++nKnown;
			}
		});
	const float fill = nKnown ? known / static_cast<float>(nKnown) : 0.0f;
	const float c = 0.5f * static_cast<float>(l.size - 1);
	float s = 0.0f, sx = 0.0f, sy = 0.0f, xx = 0.0f, yy = 0.0f;
	int n = 0;
	forRing(l, ring, [&](int x, int y) {
		const float v = nKnown && unknown(x, y) ? fill : g.at(x + 1, y + 1);
		const float dx = static_cast<float>(x) - c, dy = static_cast<float>(y) - c;
		s += v;
		sx += dx * v;
		sy += dy * v;
		xx += dx * dx;
		yy += dy * dy;
		++n;
	});
	Plane p;
	p.a = s / static_cast<float>(n);
	p.bx = xx > 0.0f ? sx / xx : 0.0f;
	p.by = yy > 0.0f ? sy / yy : 0.0f;
	return p;
}

/* Each cell's sample against its four neighbours: c + k (4 c - their sum).
 * Blur of a cell's width (small or blurred markers) spreads each cell over
 * its neighbours; this takes most of it back, as warpCellCentres() does
 * for today's markers. The grid's outer ring stays as sampled. */
constexpr float kSharpening = 0.25f;

void sharpen(const WarpedMarker &in, WarpedMarker &out)
{
	const int n = in.side;
	out.side = n;
	for (int y = 0; y < n; ++y) {
		for (int x = 0; x < n; ++x) {
			const float c = in.at(x, y);
			float v = c;
			if (x > 0 && y > 0 && x < n - 1 && y < n - 1)
				v = c + kSharpening * (4.0f * c - in.at(x - 1, y) - in.at(x + 1, y) - in.at(x, y - 1) - in.at(x, y + 1));
			out.samples[static_cast<std::size_t>(y * n + x)] = v;
		}
	}
}

} // namespace

bool ringsNearlyWhole(const WarpedMarker &sampled, const MarkerLayout &l)
{
	const int outer = l.square_start - 1, inner = l.square_start;
	auto none = [](int, int) { return false; }; /* no glare: every cell known */
	const Plane po = fitRing(sampled, l, outer, false, none), pi = fitRing(sampled, l, inner, false, none);
	const Plane &dark = l.reversed ? po : pi, &light = l.reversed ? pi : po;
	if (light.a - dark.a < 10.0f)
		return false;
	const float c = 0.5f * static_cast<float>(l.size - 1);
	int errors = 0, cells = 0;
	for (const int ring : { outer, inner })
		forRing(l, ring, [&](int x, int y) {
			const float dx = static_cast<float>(x) - c, dy = static_cast<float>(y) - c;
			const float thr = 0.5f * (dark.at(dx, dy) + light.at(dx, dy));
			const float v = sampled.at(x + 1, y + 1);
			errors += (ring == outer) == l.reversed ? v > thr : v < thr;
			++cells;
		});
	return 4 * errors <= cells;
}

LayoutCells readLayoutCells(const WarpedMarker &sampled, const MarkerLayout &l, float weakMargin, float clip)
{
	WarpedMarker g;
	sharpen(sampled, g);
	/* The ring just outside the square and the one just inside it; the
	 * outer one may be the quiet zone, a ring of the grid beyond the layout. */
	const int outer = l.square_start - 1, inner = l.square_start;
	const int darkRing = l.reversed ? outer : inner;
	auto ringOf = [&](int x, int y) { return std::min(std::min(x, y), std::min(l.size - 1 - x, l.size - 1 - y)); };
	/* Glare, as verify.cpp's readCells() judges it: a cell that must be
	 * black (the dark ring, a black cell) at the sensor's ceiling. Every
	 * cell that clips is then unknown: black ink may lie under it. (The
	 * clip is judged on the samples as warped: sharpening lifts a light
	 * cell beside dark ones.) */
	auto clips = [&](int x, int y) { return sampled.at(x + 1, y + 1) >= clip; };
	auto darkClips = [&] {
		const int n = sampled.side * sampled.side;
		int i = 0;
		while (i < n && sampled.samples[static_cast<std::size_t>(i)] < clip)
			++i;
		if (i == n) /* nothing clips: the common case, one pass */
			return false;
		for (int y = -1; y <= l.size; ++y)
			for (int x = -1; x <= l.size; ++x) {
				const bool inside = x >= 0 && y >= 0 && x < l.size && y < l.size;
				if (clips(x, y) &&
				    (ringOf(x, y) == darkRing || (inside && l.at(x, y) == MarkerLayout::kBlack)))
					return true;
			}
		return false;
	};
	const bool glare = darkClips();
	auto unknown = [&](int x, int y) { return glare && clips(x, y); };
	const Plane po = fitRing(g, l, outer, glare, unknown), pi = fitRing(g, l, inner, glare, unknown);
	const Plane &dark = l.reversed ? po : pi, &light = l.reversed ? pi : po;
	const float c = 0.5f * static_cast<float>(l.size - 1);
	LayoutCells out;
	out.contrast = light.a - dark.a;
	const float half = std::max(0.5f * out.contrast, 1.0f);
	out.margin = 1.0f;
	std::array<std::uint8_t, 64> value{};
	std::array<float, 64> margin{};
	for (int y = -1; y <= l.size; ++y) {
		for (int x = -1; x <= l.size; ++x) {
			const float dx = static_cast<float>(x) - c, dy = static_cast<float>(y) - c;
			const float thr = 0.5f * (dark.at(dx, dy) + light.at(dx, dy));
			const float v = g.at(x + 1, y + 1);
			const int ring = ringOf(x, y);
			const bool inside = x >= 0 && y >= 0 && x < l.size && y < l.size;
			const int bit = inside ? l.at(x, y) : MarkerLayout::kAny;
			const bool isRing = ring == outer || ring == inner || bit == MarkerLayout::kWhite;
			if (!inside && !isRing)
				continue;
			/* A clipped cell under glare is no evidence either way; a
			 * bit there is read, and weak (margin 0). */
			if (unknown(x, y) && bit < 0) {
				out.ringUnknown += isRing;
				continue;
			}
			if (isRing) {
				const bool isDark = bit != MarkerLayout::kWhite && (ring == outer) == l.reversed;
				out.ringErrors += isDark ? v > thr : v < thr;
				++out.ringCells;
				continue;
			}
			if (bit < 0) {
				/* A plain cell counts only where it reads clearly: at
				 * cells of 2 px blur mixes a circle's corner cells with
				 * their neighbours (4 light, 16 dark on one exact read). */
				if (std::abs(v - thr) / half >= weakMargin) {
					++out.plainCells;
					out.plainLight += v > thr;
				}
				continue;
			}
			value[static_cast<std::size_t>(bit)] = v > thr;
			margin[static_cast<std::size_t>(bit)] =
				unknown(x, y) ? 0.0f : std::min(std::abs(v - thr) / half, 1.0f);
		}
	}
	for (int k = 0; k < l.code_bits; ++k) {
		const auto i = static_cast<std::size_t>(k);
		out.code = out.code << 1 | value[i];
		out.weak = out.weak << 1 | (margin[i] < weakMargin ? 1u : 0u);
		out.margin = std::min(out.margin, margin[i]);
	}
	return out;
}

MarkerRead decodeLayout(const LayoutCells &cells, const CodeBook &codes, const DecodePolicy &policy)
{
	MarkerRead read;
	const Dictionary &dict = codes.dictionary();
	/* A square of real contrast, its two rings whole but for a cell in 16
	 * (blur at the corners, a corner covered), and at most half of them
	 * under glare (unknown cells count as neither). */
	const int ring = cells.ringCells + cells.ringUnknown;
	if (cells.contrast < 10.0f || 16 * cells.ringErrors > ring || 2 * cells.ringUnknown > ring) {
		read.rejection = Rejection::BorderNotBlack;
		return read;
	}
	/* A circle family's corners carry nothing, but they are one colour
	 * (drawn black, or the paper around a printed circle); another
	 * layout's bits there are a mixture. (Only the cells read clearly
	 * count: blur mixes small corner cells with their neighbours.) (A tagStandard41h12 marker read
	 * as a tagCircle21h7 code, exactly, on 1 in 360 rendered markers.) */
	if (8 * std::min(cells.plainLight, cells.plainCells - cells.plainLight) > cells.plainCells) {
		read.rejection = Rejection::BorderNotBlack;
		return read;
	}
	const Decoded d = codes.decode(cells.code, policy.maxTotal);
	read.decoded = d;
	if (d.id < 0)
		return read;
	/* The bits corrected that were read clearly. */
	std::uint64_t want = dict.codes[static_cast<std::size_t>(d.id)];
	/* rotation r: read with corner r as the top-left, i.e. the code turned
	 * (4 - r) quarter turns clockwise from the read. */
	std::uint64_t read4 = cells.code, weak4 = cells.weak;
	for (int k = 0; k < (4 - d.rotation) % 4; ++k) {
		read4 = dict.rotate(read4);
		weak4 = dict.rotate(weak4);
	}
	const int clear = std::popcount((read4 ^ want) & ~weak4);
	if (clear > policy.maxHamming) {
		read.rejection = Rejection::TooManyClearErrors;
		return read;
	}
	/* The nearest other id at least twice as far as this one, beyond
	 * what correction spends. */
	if (d.runnerUp <= 2 * d.hamming) {
		read.rejection = Rejection::Ambiguous;
		return read;
	}
	read.rejection = Rejection::None;
	read.margin = cells.margin;
	return read;
}

} // namespace frappe::detail
