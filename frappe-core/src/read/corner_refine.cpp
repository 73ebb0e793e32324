// SPDX-License-Identifier: MIT
// CORNER_REFINE: sub-pixel corners from straight-line fits to the four sides.
//
// Each side is measured along image columns (sides nearer horizontal) or rows
// (nearer vertical), at whole pixels: no interpolation, and integer arithmetic
// from the pixels to the line's sums. Call u the axis along the side (x for a
// flat side) and v the axis across it. At a column u, the pixels along v
// cross the side's light-to-dark step; the centroid of the falls between
// consecutive pixels lies exactly where the column crosses the edge line, for
// any sub-pixel phase and any symmetric blur: pixels integrate over their
// area, so the falls sum the edge's profile exactly, and across a slanted
// edge the pixel's footprint only widens that profile symmetrically. The
// crossings (u, v) are fitted by weighted least squares of v on u (u is
// exact, v carries the error), and the corners are the intersections of
// adjacent lines.
//
// The falls are cut to a window, since neighbouring edges (code cells, the
// quiet zone's outer edge) lie a cell away on small markers. A window placed
// on the steepest pixel would pull every crossing towards the pixel grid,
// so the window is centred on a first centroid, with fractional weights at
// its ends.
//
// Two passes: a wide one from the tracer's corners with few columns, then a
// narrow one with more columns from corners that are now within a fraction of
// a pixel, so its columns stay clear of the corners exactly.
//
// With Highway, the columns of a side are measured together, one per lane:
// their pixels are gathered into rows, and measureColumn's searches become
// masked passes over the rows. They compute the same integers, so the
// corners are the same to the bit as the scalar code's (ARMv6 builds).

#if FRAPPE_HAVE_HWY
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "corner_refine.cpp"
#include <hwy/foreach_target.h> // IWYU pragma: keep

#include <hwy/highway.h>
#endif

/* Once, not per Highway target. */
#ifndef FRAPPE_CORNER_REFINE_COMMON
#define FRAPPE_CORNER_REFINE_COMMON

#include "corner_refine.h"
#include "rounding.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace frappe::detail {

namespace {

struct Line {
	/* Points p with n . p = c, |n| = 1. */
	double nx, ny, c;
};

constexpr int kCoarsePoints = 12; /* columns per side, first pass */
constexpr int kFinePoints = 48;  /* columns per side, second pass */
/* RefineWindow's run (how far, pixels along the column, the falls may
 * extend beyond the two differences at the steepest point: a blurred edge
 * spreads over a few pixels, but more lets noise and neighbouring edges in)
 * is at most this. Its window16 is half the final window, in 1/16 pixel,
 * plus half a pixel (32: 1.5 px either side of the first centroid); a
 * difference, a pixel wide, counts by how much of it lies inside. */
constexpr int kMaxRun = 8;
constexpr int kMaxReach = 23; /* search window, pixels either side */
constexpr int kMaxProfile = 2 * (kMaxReach + kMaxRun + 1) + 1;
/* Steepest fall over two pixels below which a column is noise, not edge. */
constexpr int kMinDrop = 6;
/* The centroid moment2 / (2 mass) pixels in 1/16 pixel, rounded half away
 * from zero; mass > 0. */
inline int centroid16(int moment2, int mass)
{
	/* (8 moment2 +- mass / 2) / mass, truncated. ARMv6 has no integer
	 * divide (libgcc's costs ~40 instructions, twice or more a column):
	 * the quotient in floats, off by at most one, corrected by the
	 * remainder, as the vector kernel computes it. */
	const int num = 8 * std::abs(moment2) + mass / 2;
	int q = static_cast<int>(static_cast<float>(num) / static_cast<float>(mass));
	const int rem = num - q * mass;
	if (rem >= mass)
		++q;
	else if (rem < 0)
		--q;
	return moment2 < 0 ? -q : q;
}

/* A profile clips when its bright end is at least kSaturated: past it the
 * sensor tells nothing. (Not at the dark end: a dim frame's blacks lie
 * near 0 with noise, and cutting their falls only adds noise.) */
constexpr int kSaturated = 250;
inline bool clippedProfile(int bright)
{
	return bright >= kSaturated;
}

constexpr int kMinWindow16 = 32;
/* RefineWindow::symmetric's window (window16: a fall at 16 k + 8 counts
 * min(16, window16 - its distance from c16) / 16) for falls spanning
 * pixels lo..hi: at most window16, and reaching (window16 - 8) no further
 * from c16 than the nearer end of the falls; at least a pixel (or
 * window16 when that is less). */
inline int symmetricWindow16(int window16, int c16, int lo, int hi)
{
	return std::max(std::min(window16, kMinWindow16), std::min(window16, std::min(c16 - 16 * lo, 16 * hi - c16) + 8));
}

/* A side's columns for the vector kernel: p[r][i] is column i's pixel
 * j = kLoMin - kRun - 1 + r steps inwards, r < kHiMax - kLoMin + 2 kRun + 3;
 * the kernel returns each column's measureColumn() in mass and moment2. */
struct Columns {
	/* Columns a row holds: a fine pass's, padded to whole vectors. */
	static constexpr int kLanes = 64;
	/* Vectors hold at most this many columns (int32 lanes of AVX-512):
	 * columns n..roundUp(n, kPad) are filled with empty searches. */
	static constexpr int kPad = 16;
	int n;
	int kLoMin, kHiMax;
	int run, window16, passes; /* RefineWindow's */
	bool symmetric;
	alignas(64) std::uint8_t p[kMaxProfile][kLanes];
	alignas(64) std::int32_t kLo[kLanes];
	alignas(64) std::int32_t kHi[kLanes];
	alignas(64) std::int32_t mass[kLanes];
	alignas(64) std::int32_t moment2[kLanes];
};

static_assert(kFinePoints <= Columns::kLanes && Columns::kLanes % Columns::kPad == 0);

} // namespace

} // namespace frappe::detail

#endif // FRAPPE_CORNER_REFINE_COMMON

#if FRAPPE_HAVE_HWY
HWY_BEFORE_NAMESPACE();
namespace frappe::detail {
namespace HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

/* measureColumn() for every column, one per lane, over rows of the profile:
 * at each row a lane acts only where the scalar loop would have reached. */
void MeasureColumns(Columns &c)
{
	const hn::ScalableTag<std::int32_t> d;
	const hn::Rebind<std::uint8_t, decltype(d)> d8;
	const hn::Rebind<float, decltype(d)> df;
	const int N = static_cast<int>(hn::Lanes(d));
	/* The differences p(m) - p(m + 1), m = m0..m1 (as far as falls reach). */
	const int m0 = c.kLoMin - c.run - 1, m1 = c.kHiMax + c.run;
	HWY_ALIGN std::int32_t diff[(kMaxProfile - 1) * HWY_LANES(std::int32_t)];
	HWY_ALIGN std::int32_t falls[(kMaxProfile - 1) * HWY_LANES(std::int32_t)];
	const auto zero = hn::Zero(d), one = hn::Set(d, 1);

	for (int i = 0; i < c.n; i += N) {
		auto prev = hn::PromoteTo(d, hn::LoadU(d8, &c.p[0][i]));
		for (int m = m0; m <= m1; ++m) {
			const auto next = hn::PromoteTo(d, hn::LoadU(d8, &c.p[m - m0 + 1][i]));
			hn::Store(hn::Sub(prev, next), d, diff + (m - m0) * N);
			prev = next;
		}
		auto at = [&](int m) { return hn::Load(d, diff + (m - m0) * N); };

		/* The strongest fall in kLo..kHi, the first of equals. */
		/* (No integer >= or <= in this Highway.) */
		const auto kLo1 = hn::Sub(hn::Load(d, c.kLo + i), one), kHi1 = hn::Add(hn::Load(d, c.kHi + i), one);
		auto best = zero, bestDrop = zero;
		for (int k = c.kLoMin; k <= c.kHiMax; ++k) {
			const auto kv = hn::Set(d, k);
			const auto drop = hn::Add(at(k - 1), at(k));
			const auto take = hn::And(hn::And(hn::Gt(kv, kLo1), hn::Lt(kv, kHi1)), hn::Gt(drop, bestDrop));
			bestDrop = hn::IfThenElse(take, drop, bestDrop);
			best = hn::IfThenElse(take, kv, best);
		}
		const auto valid = hn::Gt(bestDrop, hn::Set(d, kMinDrop - 1));

		/* The run down from best - 1 stops after the last non-fall
		 * below best - 1, the run up from best + 1 at the first above,
		 * each at most kRun further. */
		const auto loStop = hn::Sub(best, one);
		auto lo = hn::Set(d, m0);
		for (int m = m0; m <= c.kHiMax - 2; ++m) {
			const auto mv = hn::Set(d, m);
			const auto stop = hn::And(hn::Lt(at(m), one), hn::Lt(mv, loStop));
			lo = hn::IfThenElse(stop, hn::Add(mv, one), lo);
		}
		lo = hn::Max(lo, hn::Sub(best, hn::Set(d, c.run + 1)));
		auto hi = hn::Set(d, m1 + 1);
		for (int m = m1; m >= c.kLoMin + 1; --m) {
			const auto mv = hn::Set(d, m);
			const auto stop = hn::And(hn::Lt(at(m), one), hn::Gt(mv, best));
			hi = hn::IfThenElse(stop, mv, hi);
		}
		hi = hn::Min(hi, hn::Add(best, hn::Set(d, c.run + 1)));
		/* clippedProfile(p(lo)): both sides cut to the shorter. */
		{
			auto pLo = zero;
			for (int m = m0; m <= m1; ++m)
				pLo = hn::IfThenElse(hn::Eq(hn::Set(d, m), lo), hn::PromoteTo(d, hn::LoadU(d8, &c.p[m - m0][i])), pLo);
			const auto clipped = hn::Gt(pLo, hn::Set(d, kSaturated - 1));
			const auto reach = hn::Min(hn::Sub(best, lo), hn::Sub(hi, best));
			lo = hn::IfThenElse(clipped, hn::Sub(best, reach), lo);
			hi = hn::IfThenElse(clipped, hn::Add(best, reach), hi);
		}

		/* The falls from lo to hi, and their centroid in 1/16 pixel. */
		const auto lo1 = hn::Sub(lo, one);
		auto mass = zero, moment2 = zero;
		for (int m = m0; m <= m1; ++m) {
			const auto mv = hn::Set(d, m);
			const auto in = hn::And(hn::Gt(mv, lo1), hn::Lt(mv, hi));
			const auto fall = hn::IfThenElseZero(in, hn::Max(at(m), zero));
			hn::Store(fall, d, falls + (m - m0) * N);
			mass = hn::Add(mass, fall);
			moment2 = hn::Add(moment2, hn::Mul(fall, hn::Set(d, 2 * m + 1)));
		}
		/* centroid16(): (8 moment2 +- mass / 2) / mass, truncated: the
		 * quotient of |numerator| < 2^21 by mass in floats is off by at
		 * most one, which the remainder corrects. */
		auto centroid16V = [&](decltype(zero) mom2, decltype(zero) m, decltype(valid) ok) {
			const auto num = hn::Add(hn::ShiftLeft<3>(hn::Abs(mom2)), hn::ShiftRight<1>(m));
			const auto den = hn::IfThenElse(ok, m, one);
			auto q = hn::ConvertTo(d, hn::Div(hn::ConvertTo(df, num), hn::ConvertTo(df, den)));
			const auto rem = hn::Sub(num, hn::Mul(q, den));
			q = hn::Add(q, hn::IfThenElseZero(hn::Gt(rem, hn::Sub(den, one)), one));
			q = hn::Sub(q, hn::IfThenElseZero(hn::Lt(rem, zero), one));
			return hn::IfThenElse(hn::Lt(mom2, zero), hn::Neg(q), q);
		};
		auto c16 = centroid16V(moment2, mass, valid);

		/* The falls weighted by how much of each lies in the window,
		 * symmetricWindow16() wide if asked, c.passes times. */
		auto wMass = zero, wMoment2 = zero;
		auto live = valid;
		const auto full = hn::Set(d, 16), eight = hn::Set(d, 8);
		const auto lo16 = hn::ShiftLeft<4>(lo), hi16 = hn::ShiftLeft<4>(hi);
		for (int pass = 0; pass < c.passes; ++pass) {
			const auto reach = hn::Min(hn::Sub(c16, lo16), hn::Sub(hi16, c16));
			const auto window16 =
				c.symmetric ? hn::Max(hn::Set(d, std::min(c.window16, kMinWindow16)),
						      hn::Min(hn::Set(d, c.window16), hn::Add(reach, eight)))
					    : hn::Set(d, c.window16);
			auto pm = zero, pm2 = zero;
			for (int m = m0; m <= m1; ++m) {
				const auto dist = hn::Abs(hn::Sub(hn::Set(d, 16 * m + 8), c16));
				const auto f16 = hn::Min(hn::Max(hn::Sub(window16, dist), zero), full);
				const auto wf = hn::Mul(f16, hn::Load(d, falls + (m - m0) * N));
				pm = hn::Add(pm, wf);
				pm2 = hn::Add(pm2, hn::Mul(wf, hn::Set(d, 2 * m + 1)));
			}
			/* A lane whose window holds no fall keeps its last sums
			 * (the scalar loop stops there). */
			wMass = hn::IfThenElse(live, pm, wMass);
			wMoment2 = hn::IfThenElse(live, pm2, wMoment2);
			live = hn::And(live, hn::Gt(pm, zero));
			const auto next = hn::IfThenElse(live, centroid16V(pm2, pm, live), c16);
			/* Converged in every lane: another pass would give the
			 * same sums (the scalar loop stops lane by lane). */
			if (hn::AllTrue(d, hn::Eq(next, c16)))
				break;
			c16 = next;
		}
		hn::Store(hn::IfThenElseZero(valid, wMass), d, c.mass + i);
		hn::Store(hn::IfThenElseZero(valid, wMoment2), d, c.moment2 + i);
	}
}

} // namespace HWY_NAMESPACE
} // namespace frappe::detail
HWY_AFTER_NAMESPACE();
#endif // FRAPPE_HAVE_HWY

#if !FRAPPE_HAVE_HWY || HWY_ONCE
namespace frappe::detail {

#if FRAPPE_HAVE_HWY
HWY_EXPORT(MeasureColumns);
#endif

namespace {

/* The edge's crossing of one column. p(j) is the pixel j steps inwards of
 * the side's nearest pixel, for |j| <= kLo/kHi's reach + kRun + 1; the
 * steepest fall is looked for at kLo..kHi. Returns the windowed falls' total
 * w (0: no edge) and their moment2, so that the crossing is at
 * moment2 / (2 w) steps, both in sixteenths of the falls. */
template <typename Pixel>
inline int measureColumn(Pixel p, int kLo, int kHi, const RefineWindow &win, int &moment2Out)
{
	/* Strongest fall in intensity going inwards (white border outside,
	 * black frame inside); rises belong to other edges. */
	int best = 0, bestDrop = 0;
	for (int k = kLo; k <= kHi; ++k) {
		const int drop = p(k - 1) - p(k + 1);
		if (drop > bestDrop) {
			bestDrop = drop;
			best = k;
		}
	}
	if (bestDrop < kMinDrop)
		return 0;
	/* The falls around it: the two differences at the peak, extended while
	 * the intensity keeps falling, at most kRun pixels. The difference
	 * p(k) - p(k + 1) lies at k + 1/2. */
	int lo = best - 1, hi = best + 1;
	int prev = p(lo);
	const int kRun = win.run;
	for (int next; lo > best - 1 - kRun && (next = p(lo - 1)) > prev; prev = next)
		--lo;
	prev = p(hi);
	for (int next; hi <= best + kRun && prev > (next = p(hi + 1)); prev = next)
		++hi;
	/* Where the light clips (a white at the sensor's ceiling) the
	 * profile's falls end early on the bright side and their centroid
	 * leans to the dark: both sides cut to the shorter one, symmetric
	 * about the steepest pair (clippedProfile()). */
	if (clippedProfile(p(lo))) {
		const int reach = std::min(best - lo, hi - best);
		lo = best - reach;
		hi = best + reach;
	}
	/* falls[i] at lo + i; hi is one past the last. */
	int falls[2 * kMaxRun + 2];
	int mass = 0, moment2 = 0;
	prev = p(lo);
	for (int k = lo; k < hi; ++k) {
		const int next = p(k + 1);
		const int fall = std::max(prev - next, 0);
		prev = next;
		falls[k - lo] = fall;
		mass += fall;
		moment2 += fall * (2 * k + 1);
	}
	/* Their centroid, in 1/16 pixel (rounded), centres the window. */
	int c16 = centroid16(moment2, mass);
	int wMass = 0, wMoment2 = 0;
	for (int pass = 0; pass < win.passes; ++pass) {
		const int window16 = win.symmetric ? symmetricWindow16(win.window16, c16, lo, hi) : win.window16;
		wMass = 0;
		wMoment2 = 0;
		for (int k = lo; k < hi; ++k) {
			const int f16 = std::clamp(window16 - std::abs(16 * k + 8 - c16), 0, 16);
			const int wf = f16 * falls[k - lo];
			wMass += wf;
			wMoment2 += wf * (2 * k + 1);
		}
		if (wMass <= 0)
			break;
		/* Converged: another pass would give the same sums. */
		const int next = centroid16(wMoment2, wMass);
		if (next == c16)
			break;
		c16 = next;
	}
	moment2Out = wMoment2;
	return wMass;
}

/* Column U of a side: where the side crosses it (vFix, 16.16, and the
 * nearest pixel vc) and the range kLo..kHi of steps inwards from vc where
 * the edge's fall is looked for. */
struct ColumnAt {
	int U;
	std::int32_t vFix;
	int vc, kLo, kHi;
};

inline ColumnAt columnAt(int U, std::int32_t vFix0, std::int32_t slopeFix, int dir, std::int32_t peakFix)
{
	ColumnAt c;
	c.U = U;
	c.vFix = vFix0 + slopeFix * U;
	c.vc = (c.vFix + 32768) >> 16;
	const std::int32_t frac = dir * (c.vFix - (c.vc << 16)); /* the side at p[frac], |frac| <= 1/2 */
	c.kLo = (frac - peakFix + 65535) >> 16;
	c.kHi = (frac + peakFix) >> 16;
	return c;
}

/* Weighted sums over the crossings, weight = the windowed falls' total w;
 * with U = u - u0 and q = 2 w (v - vRef) they are all integers. */
struct Sums {
	std::int64_t sw = 0, su = 0, suu = 0, sq = 0, suq = 0;
	int used = 0;
};

/* Adds column U's crossing, at vc + dir * wMoment2 / (2 wMass) when wMass > 0,
 * if it lies within reachFix (16.16) of the side's vFix, less `shift` px
 * (SideOffsets', along v). */
inline void addCrossing(Sums &s, int U, std::int32_t vFix, int vc, int wMass, int wMoment2, int dir, int vRef,
			std::int64_t reachFix, float shift = 0.0f)
{
	if (wMass <= 0)
		return;
	/* Both sides of the test times 2 wMass 2^16. */
	const std::int64_t m2 = 2 * static_cast<std::int64_t>(wMass);
	const std::int64_t off = m2 * ((static_cast<std::int64_t>(vc) << 16) - vFix) +
				 static_cast<std::int64_t>(dir * wMoment2) * 65536;
	if ((off < 0 ? -off : off) > m2 * reachFix)
		return;
	const std::int64_t q =
		m2 * (vc - vRef) + dir * wMoment2 - (shift != 0.0f ? std::llround(static_cast<double>(m2) * shift) : 0);
	s.sw += wMass;
	s.su += static_cast<std::int64_t>(wMass) * U;
	s.suu += static_cast<std::int64_t>(wMass) * U * U;
	s.sq += q;
	s.suq += q * U;
	++s.used;
}

#if FRAPPE_HAVE_HWY
/* Out of line: inside fitSide the sums stay in memory. */
[[gnu::noinline]] void addColumns(Sums &s, const Columns &c, int n, const int *Us, const std::int32_t *vFixes, int dir,
				  int vRef, std::int64_t reachFix, const float *shifts)
{
	for (int i = 0; i < n; ++i)
		addCrossing(s, Us[i], vFixes[i], (vFixes[i] + 32768) >> 16, c.mass[i], c.moment2[i], dir, vRef,
			    reachFix, shifts ? shifts[i] : 0.0f);
}
#endif

/* Measures one side from a to b (clockwise quad, so the marker interior is
 * on the right of a->b on screen); with `side`, its columns' crossings
 * moved back by it (SideOffsets). */
bool fitSide(const ImageView &img, Point2f a, Point2f b, float search, int maxPoints, const RefineWindow &win,
	     RefineKernels kernels, Line &line, const float *side = nullptr)
{
	const int kRun = win.run;
	const float dx = b.x - a.x, dy = b.y - a.y;
	const float len = std::sqrt(dx * dx + dy * dy);
	if (len < 2.0f || img.width < 1 || img.height < 1)
		return false;
	/* u along the side's dominant axis, v across it. */
	const bool flat = std::abs(dx) >= std::abs(dy);
	const float au = flat ? a.x : a.y, av = flat ? a.y : a.x;
	const float du = flat ? dx : dy, dv = flat ? dy : dx;
	/* The inward normal is (-dy, dx) / len; its v component says which way
	 * along the column is inwards, its size how much of the normal one pixel
	 * of column covers (at least 1/sqrt(2)). */
	const float nv = (flat ? dx : -dy) / len;
	const int dir = nv > 0.0f ? 1 : -1;
	const float cosV = std::abs(nv);
	const int uDim = flat ? img.width : img.height, vDim = flat ? img.height : img.width;
	/* One step along u or v, in bytes; along v inwards. */
	const std::ptrdiff_t uStep = flat ? 1 : img.stride, vStep = flat ? img.stride : 1;
	const std::ptrdiff_t step = dir * vStep;

	/* Stay clear of the corners, where the neighbouring side interferes. */
	const float margin = std::max(1.5f, 0.12f * len);
	if (len <= 2.0f * margin)
		return false;
	const float marginU = margin * cosV;
	const int u0 = ceilInt(std::min(au, au + du) + marginU);
	const int u1 = floorInt(std::max(au, au + du) - marginU);
	const int count = u1 - u0 + 1;
	if (count < 3)
		return false;
	const int nPoints = std::min(count, maxPoints);

	/* The side's v at column u, in 16.16 fixed point: it only places the
	 * window and checks the search distance, so its rounding is harmless. */
	const float slope = dv / du;
	const std::int32_t vFix0 = floorInt((av + (static_cast<float>(u0) - au) * slope) * 65536.0f + 0.5f);
	const std::int32_t slopeFix = floorInt(slope * 65536.0f + 0.5f);
	const int vRef = (vFix0 + 32768) >> 16;
	/* The steepest fall may lie up to search - 1/2 from the side along its
	 * normal (as when profiles were sampled along it in half pixels), its
	 * centroid up to search; in pixels along the column, 16.16. */
	const float peakV = std::max(0.0f, search - 0.5f) / cosV;
	const std::int32_t peakFix = floorInt(std::min(peakV, static_cast<float>(kMaxReach) - 0.5f) * 65536.0f);
	const std::int64_t reachFix = static_cast<std::int64_t>(search / cosV * 65536.0f);
	const int reach = ceilInt(std::min(peakV, static_cast<float>(kMaxReach) - 0.5f) + 0.5f);
	const int half = reach + kRun + 1; /* the profile: -half..half */

	/* Columns spread evenly, in 16.16 steps (one division per side). */
	const std::int32_t stepFix = (count << 16) / nPoints;
	std::int32_t accFix = stepFix >> 1;
	/* Each column's shift from `side`, by its fraction along a->b: along
	 * v, an inward normal offset is 1 / cosV as long, `dir` signed. */
	float shifts[kFinePoints];
	if (side) {
		for (int i = 0; i < nPoints; ++i) {
			const int U = (accFix + i * stepFix) >> 16;
			const float t = (static_cast<float>(u0 + U) - au) / du;
			const int bin = std::clamp(floorInt(t * SideOffsets::kSteps), 0, SideOffsets::kSteps - 1);
			shifts[i] = static_cast<float>(dir) * side[bin] / cosV;
		}
	}

	Sums sums;
#if FRAPPE_HAVE_HWY
	if (kernels == RefineKernels::Best) {
		/* The columns' geometry and search ranges first, for the rows of
		 * pixels to gather; then all of them measured at once. */
		Columns cols;
		int Us[kFinePoints];
		std::int32_t vFixes[kFinePoints];
		cols.run = kRun;
		cols.window16 = win.window16;
		cols.symmetric = win.symmetric;
		cols.passes = win.passes;
		cols.kLoMin = kMaxReach;
		cols.kHiMax = -kMaxReach;
		for (int i = 0; i < nPoints; ++i, accFix += stepFix) {
			const ColumnAt c = columnAt(accFix >> 16, vFix0, slopeFix, dir, peakFix);
			Us[i] = c.U;
			vFixes[i] = c.vFix;
			cols.kLo[i] = c.kLo;
			cols.kHi[i] = c.kHi;
			cols.kLoMin = std::min(cols.kLoMin, c.kLo);
			cols.kHiMax = std::max(cols.kHiMax, c.kHi);
		}
		/* No column has a step to look for. */
		if (cols.kLoMin > cols.kHiMax)
			return false;
		const int j0 = cols.kLoMin - kRun - 1, rows = cols.kHiMax + kRun + 2 - j0;
		for (int i = 0; i < nPoints; ++i) {
			const int u = u0 + Us[i];
			const int vc = (vFixes[i] + 32768) >> 16;
			if (u >= 0 && u < uDim && vc - half >= 0 && vc + half < vDim) {
				const std::uint8_t *px = img.data + u * uStep + vc * vStep + j0 * step;
				/* Four at a time: the copy is a fifth of the time. */
				int r = 0;
				for (; r + 4 <= rows; r += 4, px += 4 * step) {
					cols.p[r][i] = px[0];
					cols.p[r + 1][i] = px[step];
					cols.p[r + 2][i] = px[2 * step];
					cols.p[r + 3][i] = px[3 * step];
				}
				for (; r < rows; ++r, px += step)
					cols.p[r][i] = *px;
			} else {
				/* Clamped to the image, as a bilinear sampler would. */
				const int uc = std::clamp(u, 0, uDim - 1);
				for (int r = 0; r < rows; ++r)
					cols.p[r][i] = img.data[uc * uStep + std::clamp(vc + dir * (j0 + r), 0, vDim - 1) * vStep];
			}
		}
		/* Empty searches to whole vectors. */
		cols.n = (nPoints + Columns::kPad - 1) / Columns::kPad * Columns::kPad;
		for (int i = nPoints; i < cols.n; ++i) {
			cols.kLo[i] = 1;
			cols.kHi[i] = 0;
		}
		static_assert(kFinePoints + Columns::kPad <= Columns::kLanes);
		for (int r = 0; r < rows; ++r)
			std::memset(&cols.p[r][nPoints], 0, Columns::kPad);
		HWY_DYNAMIC_DISPATCH(MeasureColumns)(cols);
		addColumns(sums, cols, nPoints, Us, vFixes, dir, vRef, reachFix, side ? shifts : nullptr);
	} else
#else
	(void)kernels;
#endif
	{
		/* The scalar reference, one column at a time (the ARMv6 build's path;
		 * with Highway, what the tests hold the vector kernel to). */
		int buf[kMaxProfile];
		int *const p = buf + half; /* near the image border: p[j], the pixel j steps inwards of the side, clamped */
		for (int i = 0; i < nPoints; ++i, accFix += stepFix) {
			const auto [U, vFix, vc, kLo, kHi] = columnAt(accFix >> 16, vFix0, slopeFix, dir, peakFix);
			const int u = u0 + U;
			int wMass, wMoment2 = 0;
			if (u >= 0 && u < uDim && vc - half >= 0 && vc + half < vDim) {
				const std::uint8_t *px = img.data + u * uStep + vc * vStep;
				wMass = measureColumn([px, step](int j) { return static_cast<int>(px[j * step]); }, kLo, kHi,
						      win, wMoment2);
			} else {
				/* Clamped to the image, as a bilinear sampler would. */
				const int uc = std::clamp(u, 0, uDim - 1);
				for (int j = -half; j <= half; ++j)
					p[j] = img.data[uc * uStep + std::clamp(vc + dir * j, 0, vDim - 1) * vStep];
				wMass = measureColumn([p](int j) { return p[j]; }, kLo, kHi, win, wMoment2);
			}
			addCrossing(sums, U, vFix, vc, wMass, wMoment2, dir, vRef, reachFix, side ? shifts[i] : 0.0f);
		}
	}
	const std::int64_t sw = sums.sw, su = sums.su, suu = sums.suu, sq = sums.sq, suq = sums.suq;
	if (sums.used < 3 || sums.used * 2 < nPoints)
		return false;
	/* v = vRef + meanV + m (u - u0 - meanU), by weighted least squares. */
	const double w = static_cast<double>(sw);
	const double den = w * static_cast<double>(suu) - static_cast<double>(su) * static_cast<double>(su);
	if (den <= 0.0)
		return false;
	const double m = (w * static_cast<double>(suq) - static_cast<double>(su) * static_cast<double>(sq)) / (2.0 * den);
	const double meanU = static_cast<double>(su) / w, meanV = static_cast<double>(sq) / (2.0 * w);
	/* As n . (u, v) = c with n = (-m, 1) / |(-m, 1)|, then back to (x, y). */
	const double norm = 1.0 / std::sqrt(1.0 + m * m);
	const double nu = -m * norm;
	line.c = (static_cast<double>(vRef) + meanV - m * (static_cast<double>(u0) + meanU)) * norm;
	line.nx = flat ? nu : norm;
	line.ny = flat ? norm : nu;
	return true;
}

bool intersect(const Line &l1, const Line &l2, Point2f &p)
{
	const double det = l1.nx * l2.ny - l1.ny * l2.nx;
	if (std::abs(det) < 1e-6)
		return false;
	p.x = static_cast<float>((l1.c * l2.ny - l1.ny * l2.c) / det);
	p.y = static_cast<float>((l1.nx * l2.c - l1.c * l2.nx) / det);
	return true;
}

bool refineOnce(const ImageView &img, std::array<Point2f, 4> &q, float search, int maxPoints, const RefineWindow &win,
		RefineKernels kernels, const SideOffsets *offsets = nullptr)
{
	Line lines[4];
	for (int i = 0; i < 4; ++i) {
		if (!fitSide(img, q[i], q[(i + 1) & 3], search, maxPoints, win, kernels, lines[i],
			     offsets ? offsets->d[static_cast<std::size_t>(i)].data() : nullptr))
			return false;
	}
	std::array<Point2f, 4> r;
	for (int i = 0; i < 4; ++i) {
		/* Corner i joins side i-1 (ending at it) and side i (starting at it). */
		if (!intersect(lines[(i + 3) & 3], lines[i], r[i]))
			return false;
		const float dx = r[i].x - q[i].x, dy = r[i].y - q[i].y;
		if (dx * dx + dy * dy > 4.0f * search * search + 4.0f)
			return false;
	}
	q = r;
	return true;
}

} // namespace

bool refineCorners(const ImageView &image, std::array<Point2f, 4> &corners, float search, const RefineWindow &window,
		   RefineKernels kernels)
{
	RefineWindow win = window;
	win.run = std::clamp(win.run, 1, kMaxRun);
	win.window16 = std::clamp(win.window16, 8, 16 * kMaxRun);
	win.passes = std::clamp(win.passes, 1, 4);
	std::array<Point2f, 4> q = corners;
	/* The wide first pass only has to place the sides roughly: few points. */
	if (!refineOnce(image, q, search, kCoarsePoints, win, kernels))
		return false;
	/* A second, narrow pass: the sides are now well placed, so the
	 * measurement points avoid the corners exactly and the window shrinks. */
	refineOnce(image, q, std::min(search, 1.5f), kFinePoints, win, kernels);
	corners = q;
	return true;
}

bool refineCornersOffset(const ImageView &image, std::array<Point2f, 4> &corners, float search,
			 const SideOffsets &offsets, RefineKernels kernels)
{
	return refineOnce(image, corners, search, kFinePoints, RefineWindow{}, kernels, &offsets);
}

} // namespace frappe::detail
#endif // !FRAPPE_HAVE_HWY || HWY_ONCE
