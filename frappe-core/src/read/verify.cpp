// SPDX-License-Identifier: MIT
#include "verify.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <optional>

#include "frappe/homography.h"
#include "quad_geometry.h"
#include "sampling.h"

namespace frappe::detail {

namespace {

/* A cell straddles when its darkest sample is this fraction of the contrast
 * below the threshold and its brightest as far above: blur alone moves a
 * true cell's quarter-point samples apart by less. */
constexpr float kStraddle = 0.15f;

/* The nearest other id must be this many bits further than the decoded one
 * (fewer where the dictionary's own codes are closer): one bit more is a
 * coin toss between two ids. */
constexpr int kAmbiguityGap = 2;

/* AprilTag's sharpening of the cell centres (decode_sharpening): enough to
 * take back what a blur of about a cell spreads into the neighbours. */
constexpr float kSharpening = 0.25f;

/* On the log scale a light grey beside black ink reads as white: a quiet
 * zone read there must also hold a cell at least half as light, in grey
 * levels, as the code's lightest (paper under the same light within a
 * factor of two; a panel on a mid-grey wall is no marker). */
constexpr float kPaperWhite = 0.5f;

/* A cell whose mean is at least this grey level clips: what lies under it
 * may be black ink under glare. */
constexpr float kClipped = kClippedGrey;

/* A plain codeword (plainCode(): a hollow square, a bar) must be read at
 * least this clearly, on cells of at least this many pixels: letters and
 * strokes of text make those shapes, and read them with margins up to 0.45
 * on cells of 2 pixels or more, and up to 0.54 on smaller ones
 * (tests/bench/frappe_text.cpp). */
constexpr float kPlainMargin = 0.5f;
constexpr float kPlainCellPx = 2.0f;

/* A candidate's payload must span at least this many grey levels (the
 * detector's rule for every read). */
constexpr float kMinContrast = 10.0f;

/* A read that a random pattern would match with at most this chance is
 * strong evidence on its own (a 6x6 code read exactly: 1e-8). */
constexpr double kStrongRead = 1e-4;

/* A centre read is believed only when a random pattern would match some
 * code on its clearly read cells with at most this chance: a tenth, as
 * every other check must also pass. Reads of the cells of another family's
 * marker, sampled on the wrong grid, leave a quarter or more. */
constexpr double kWeakReadChance = 0.1;

/* The chance that a random pattern matches some code of `dict`, in some
 * rotation, on `clear` given cells within `errors` of them (the other
 * cells free): 4 codes C(clear, <= errors) / 2^clear. */
double clearCellsChance(const Dictionary &dict, int clear, int errors)
{
	double within = 0.0, choose = 1.0;
	for (int i = 0; i <= errors && i <= clear; ++i) {
		within += choose;
		choose = choose * (clear - i) / (i + 1);
	}
	return 4.0 * dict.size() * within / std::ldexp(1.0, clear);
}

} // namespace

bool quietZoneIsPaper(const QuietZone &q, const Binarised &b, Tone tone)
{
	if (tone.linear() || q.seen < 8)
		return true;
	/* Sharpened cell centres overshoot the code's white: on the log scale
	 * by a factor of two or more in grey levels. */
	const float white = tone.invert(b.lightest >= 0.0f ? b.lightest : b.threshold + 0.5f * b.contrast);
	return q.brightest >= kPaperWhite * white;
}

CellRead readCells(const WarpedMarker &w, int bits, const Binarised &b, float weakMargin, Tone tone)
{
	const int cells = bits + 2;
	const int k = std::max(1, w.side / cells);
	const float thr = b.threshold;
	const float clear = kStraddle * b.contrast;
	const float half = 0.5f * b.contrast;
	auto mean = [&](int cx, int cy) { return cellMean(w, k, cx, cy); };
	/* Glare: a black border cell at the sensor's ceiling. */
	const float clip = tone.apply(kClipped);
	bool glare = false;
	for (int c = 0; c < cells && !glare; ++c)
		glare = mean(c, 0) >= clip || mean(c, cells - 1) >= clip || mean(0, c) >= clip || mean(cells - 1, c) >= clip;
	CellRead out;
	out.margin = 1.0f;
	for (int cy = 0; cy < cells; ++cy) {
		for (int cx = 0; cx < cells; ++cx) {
			float lo = 1e9f, hi = -1e9f, sum = 0.0f;
			for (int y = 0; y < k; ++y) {
				for (int x = 0; x < k; ++x) {
					const float v = w.at(cx * k + x, cy * k + y);
					lo = std::min(lo, v);
					hi = std::max(hi, v);
					sum += v;
				}
			}
			out.straddling += lo < thr - clear && hi > thr + clear;
			if (cx == 0 || cy == 0 || cx > bits || cy > bits)
				continue;
			const float mean = sum / static_cast<float>(k * k);
			const float margin = glare && mean >= clip ? 0.0f
				: half > 0.0f ? std::min(std::abs(mean - thr) / half, 1.0f) : 0.0f;
			out.margin = std::min(out.margin, margin);
			out.weak = (out.weak << 1) | (margin < weakMargin ? 1u : 0u);
		}
	}
	return out;
}

int clearErrors(const Dictionary &dict, std::uint64_t code, std::uint64_t weak, const Decoded &d)
{
	/* Turn the read and its weak cells as decode() turned the read for
	 * the codeword: rotation r is three quarter turns per step. */
	for (int r = 0; r < (4 - d.rotation) % 4; ++r) {
		code = rotateCode(code, dict.bits);
		weak = rotateCode(weak, dict.bits);
	}
	return std::popcount((code ^ dict.codes[static_cast<std::size_t>(d.id)]) & ~weak);
}

QuietZone readQuietZone(const ImageView &image, const std::array<Point2f, 4> &corners, int bits,
			const Binarised &b, Tone tone)
{
	const float threshold = b.threshold, black = b.threshold - kStraddle * b.contrast;
	QuietZone out;
	const auto H = Homography::fromUnitSquare(corners);
	if (!H)
		return out;
	const int cells = bits + 2;
	const double step = 1.0 / cells;
	const float maxX = static_cast<float>(image.width - 1), maxY = static_cast<float>(image.height - 1);
	auto sample = [&](int cx, int cy) {
		const Point2f p = H->map((cx + 0.5) * step, (cy + 0.5) * step);
		if (!(p.x >= 0.0f && p.y >= 0.0f && p.x <= maxX && p.y <= maxY))
			return;
		++out.seen;
		const float grey = sampleBilinear(image, p.x, p.y);
		out.brightest = std::max(out.brightest, grey);
		const float v = tone.apply(grey);
		out.light += v > threshold;
		out.dark += v < black;
	};
	/* Cells -1 and bits + 2 on each side, corners once. */
	for (int c = -1; c <= cells; ++c) {
		sample(c, -1);
		sample(c, cells);
	}
	for (int c = 0; c < cells; ++c) {
		sample(-1, c);
		sample(cells, c);
	}
	return out;
}

namespace {

/* Least squares of v = a + b x + c y: the sums of the normal equations. */
struct PlaneFit {
	double m[6] = {}; /* n, x, y, xx, xy, yy */
	double r[3] = {}; /* v, x v, y v */
	void add(double x, double y, double v)
	{
		m[0] += 1.0;
		m[1] += x;
		m[2] += y;
		m[3] += x * x;
		m[4] += x * y;
		m[5] += y * y;
		r[0] += v;
		r[1] += x * v;
		r[2] += y * v;
	}
	/* The plane's a, b, c; false when the points do not span one. */
	bool solve(double (&p)[3]) const
	{
		const double a = m[0], b = m[1], c = m[2], d = m[3], e = m[4], f = m[5];
		const double i00 = d * f - e * e, i01 = c * e - b * f, i02 = b * e - c * d;
		const double det = a * i00 + b * i01 + c * i02;
		if (!(std::abs(det) > 1e-9))
			return false;
		const double i11 = a * f - c * c, i12 = b * c - a * e, i22 = a * d - b * b;
		p[0] = (i00 * r[0] + i01 * r[1] + i02 * r[2]) / det;
		p[1] = (i01 * r[0] + i11 * r[1] + i12 * r[2]) / det;
		p[2] = (i02 * r[0] + i12 * r[1] + i22 * r[2]) / det;
		return true;
	}
};

} // namespace

Binarised binariseInLight(const ImageView &image, const std::array<Point2f, 4> &corners, const WarpedMarker &w,
			  int bits, Tone tone)
{
	Binarised out = binarise(w, bits);
	const int cells = bits + 2;
	const int k = std::max(1, w.side / cells);
	const auto H = Homography::fromUnitSquare(corners);
	PlaneFit black, white;
	for (int c = 0; c < cells; ++c)
		for (int e : { 0, cells - 1 }) {
			black.add(c + 0.5, e + 0.5, cellMean(w, k, c, e));
			if (c > 0 && c < cells - 1)
				black.add(e + 0.5, c + 0.5, cellMean(w, k, e, c));
		}
	const float maxX = static_cast<float>(image.width - 1), maxY = static_cast<float>(image.height - 1);
	auto ring = [&](int cx, int cy) {
		const Point2f p = H->map((cx + 0.5) / cells, (cy + 0.5) / cells);
		if (p.x >= 0.0f && p.y >= 0.0f && p.x <= maxX && p.y <= maxY)
			white.add(cx + 0.5, cy + 0.5, tone.apply(sampleBilinear(image, p.x, p.y)));
	};
	if (H)
		for (int c = -1; c <= cells; ++c) {
			ring(c, -1);
			ring(c, cells);
			if (c >= 0 && c < cells) {
				ring(-1, c);
				ring(cells, c);
			}
		}
	double pb[3], pw[3];
	/* A ring mostly in the image: three sides' worth. */
	if (white.m[0] < 3.0 * cells || !black.solve(pb) || !white.solve(pw)) {
		out.contrast = 0.0f;
		return out;
	}
	out.code = 0;
	out.border_errors = 0;
	for (int cy = 0; cy < cells; ++cy) {
		for (int cx = 0; cx < cells; ++cx) {
			const double x = cx + 0.5, y = cy + 0.5;
			const double lo = pb[0] + pb[1] * x + pb[2] * y, hi = pw[0] + pw[1] * x + pw[2] * y;
			const bool code = cx > 0 && cy > 0 && cx <= bits && cy <= bits;
			if (code && !(hi - lo >= kMinContrast)) {
				out.contrast = 0.0f;
				return out;
			}
			const bool light = cellMean(w, k, cx, cy) > 0.5 * (lo + hi);
			if (code)
				out.code = (out.code << 1) | (light ? 1u : 0u);
			else
				out.border_errors += light;
		}
	}
	return out;
}

int allowedBorderErrors(int bits)
{
	return (4 * (bits + 1)) / 8;
}

bool borderIsBlack(const Binarised &b, int bits)
{
	return b.border_errors <= allowedBorderErrors(bits);
}

bool readable(const Binarised &b, int bits)
{
	return b.contrast >= kMinContrast && borderIsBlack(b, bits);
}

Scrutiny scrutinyFor(const Dictionary &dict, int hamming)
{
	return dict.randomDecodeChance(hamming) > kStrongRead ? Scrutiny::Strict : Scrutiny::Tolerant;
}

bool quietZoneIsLight(const QuietZone &q, Scrutiny scrutiny)
{
	if (q.seen < 8)
		return true;
	if (scrutiny == Scrutiny::Tolerant)
		return 3 * q.light >= 2 * q.seen;
	return 4 * q.light >= 3 * q.seen && 16 * q.dark <= q.seen;
}

bool cellsAgree(const CellRead &c, int bits, Scrutiny scrutiny)
{
	return (scrutiny == Scrutiny::Tolerant ? 4 : 8) * c.straddling <= bits * bits;
}

bool unambiguous(const Decoded &d, const Dictionary &dict)
{
	const int gap = std::clamp(dict.min_hamming, 1, kAmbiguityGap);
	return d.runnerUp - d.hamming >= gap;
}

namespace {

/* The marker's unit square (inverse of its homography), for testing where
 * other quads lie in it. */
std::optional<Homography> unitSquareOf(const std::array<Point2f, 4> &marker)
{
	const auto H = Homography::fromUnitSquare(marker);
	return H ? H->inverse() : std::nullopt;
}

bool insideWith(const Homography &toUnit, const std::array<Point2f, 4> &inner, int bits)
{
	/* The code area is [1, bits + 1] cells; corners within half a cell of
	 * the border count as inside. */
	const double lo = 0.5 / (bits + 2), hi = 1.0 - lo;
	for (const Point2f &p : inner) {
		const Point2f u = toUnit.map(p.x, p.y);
		if (!(u.x >= lo && u.x <= hi && u.y >= lo && u.y <= hi))
			return false;
	}
	return true;
}

} // namespace

bool insideCodeArea(const std::array<Point2f, 4> &inner, const std::array<Point2f, 4> &marker, int bits)
{
	const auto toUnit = unitSquareOf(marker);
	return toUnit && insideWith(*toUnit, inner, bits);
}

void dropNestedMarkers(std::vector<Marker> &markers, int bits, PointGrid &grid)
{
	if (markers.size() < 2)
		return;
	/* Each marker filed under its first corner, in cells as wide as the
	 * markers' mean first side: a marker nested in another has all four
	 * corners inside that one's outline, so its first corner in that
	 * outline's box (padded: the test maps corners in floats). */
	double sides = 0.0;
	for (const Marker &m : markers)
		sides += std::hypot(m.corners[1].x - m.corners[0].x, m.corners[1].y - m.corners[0].y);
	const double mean = sides / static_cast<double>(markers.size());
	grid.reset(markers.size(), std::isfinite(mean) ? static_cast<float>(std::max(mean, 4.0)) : 4.0f);
	for (std::size_t i = 0; i < markers.size(); ++i)
		grid.add(static_cast<int>(i), 0, markers[i].corners[0]);
	/* Marks by id = -1 first: a marker inside one that is itself nested
	 * still shows where the outer one's code is. */
	std::size_t dropped = 0;
	for (const Marker &outer : markers) {
		const auto toUnit = unitSquareOf(outer.corners);
		if (!toUnit)
			continue;
		auto mark = [&](int i, int) {
			Marker &m = markers[static_cast<std::size_t>(i)];
			if (&m != &outer && m.id >= 0 && insideWith(*toUnit, m.corners, bits)) {
				m.id = -1;
				++dropped;
			}
			return false; /* every one */
		};
		/* Only a convex outline holds what maps into its unit square;
		 * otherwise (never for a verified marker) every marker is tested. */
		const QuadBox b = quadBox(outer.corners);
		const float pad = 1.0f + 1e-3f * std::max(b.x1 - b.x0, b.y1 - b.y0);
		if (convexQuad(outer.corners) && std::isfinite(pad))
			grid.anyIn(b.x0 - pad, b.y0 - pad, b.x1 + pad, b.y1 + pad, mark);
		else
			for (std::size_t i = 0; i < markers.size(); ++i)
				mark(static_cast<int>(i), 0);
	}
	if (dropped)
		std::erase_if(markers, [](const Marker &m) { return m.id < 0; });
}

void dropNestedMarkers(std::vector<Marker> &markers, int bits)
{
	PointGrid grid;
	dropNestedMarkers(markers, bits, grid);
}

MarkerRead readMarker(const ImageView &image, const std::array<Point2f, 4> &corners, const CodeBook &codes,
		      const DecodePolicy &policy, const WarpedMarker &w, const Binarised &b)
{
	const Dictionary &dict = codes.dictionary();
	MarkerRead out;
	out.decoded = policy.decodes ? policy.decodes->decode(codes, b.code, policy.maxTotal)
				     : codes.decode(b.code, policy.maxTotal);
	if (out.decoded.id < 0)
		return out;
	if (!unambiguous(out.decoded, dict)) {
		out.rejection = Rejection::Ambiguous;
		return out;
	}
	if (!borderIsBlack(b, dict.bits)) {
		out.rejection = Rejection::BorderNotBlack;
		return out;
	}
	const CellRead cells = readCells(w, dict.bits, b, policy.weakMargin, policy.tone);
	out.margin = cells.margin;
	if (out.decoded.hamming > policy.maxHamming &&
	    clearErrors(dict, b.code, cells.weak, out.decoded) > policy.maxHamming) {
		out.rejection = Rejection::TooManyClearErrors;
		return out;
	}
	const Scrutiny scrutiny = scrutinyFor(dict, out.decoded.hamming);
	CellRead agreement = cells;
	if (w.side < 2 * (dict.bits + 2) && scrutiny == Scrutiny::Strict) {
		/* One sample per cell (warpCellCentres) cannot straddle; a code
		 * that chance reads often must still sit on real cells, as judged
		 * by samples a quarter cell from their edges. */
		WarpedMarker quarters;
		if (!warpMarker(image, corners, dict.bits, quarters, policy.tone, policy.memo)) {
			out.rejection = Rejection::CellsDisagree;
			return out;
		}
		agreement = readCells(quarters, dict.bits, binarise(quarters, dict.bits), policy.weakMargin, policy.tone);
	}
	if (!cellsAgree(agreement, dict.bits, scrutiny)) {
		out.rejection = Rejection::CellsDisagree;
		return out;
	}
	const QuietZone quiet = readQuietZone(image, corners, dict.bits, b, policy.tone);
	if (!quietZoneIsLight(quiet, scrutiny) || !quietZoneIsPaper(quiet, b, policy.tone)) {
		out.rejection = Rejection::NoQuietZone;
		return out;
	}
	if (codes.plain(out.decoded.id) &&
	    (cells.margin < kPlainMargin || !sidesAtLeast(corners, kPlainCellPx * static_cast<float>(dict.bits + 2)))) {
		out.rejection = Rejection::PlainShape;
		return out;
	}
	out.rejection = Rejection::None;
	return out;
}

MarkerRead readCellCentres(const ImageView &image, const std::array<Point2f, 4> &corners, const CodeBook &codes,
			   const DecodePolicy &policy, WarpedMarker &scratch)
{
	const int bits = codes.dictionary().bits;
	float reference = 0.0f, lightest = 0.0f;
	if (!warpCellCentres(image, corners, bits, kSharpening, scratch, &reference, policy.tone, policy.memo,
			     &lightest))
		return {};
	Binarised b = binarise(scratch, bits);
	b.lightest = lightest;
	const float lo = b.threshold - 0.5f * b.contrast, hi = b.threshold + 0.5f * b.contrast;
	if (!readable(b, bits) || !(lo < reference && hi > reference))
		return {};
	MarkerRead r = readMarker(image, corners, codes, policy, scratch, b);
	if (!r.ok())
		return r;
	/* Sharpened centres of blurred cells read weakly more often than the
	 * quarter-cell samples of large ones; the clearly read cells alone
	 * must still single out a code. */
	const Dictionary &dict = codes.dictionary();
	const std::uint64_t weak = readCells(scratch, bits, b, policy.weakMargin, policy.tone).weak;
	const int clear = bits * bits - std::popcount(weak);
	if (clearCellsChance(dict, clear, clearErrors(dict, b.code, weak, r.decoded)) > kWeakReadChance)
		r.rejection = Rejection::WeakRead;
	return r;
}

} // namespace frappe::detail
