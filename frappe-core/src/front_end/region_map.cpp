// SPDX-License-Identifier: MIT
// The region map (region_map.h): half-resolution block means, the darkest
// and brightest over 3 x 3 tiles of 4 x 4 pixels around each pixel, and the
// midpoint threshold between them.

#include "region_map.h"

#include <algorithm>
#include <cstring>

#ifdef FRAPPE_HAVE_HWY
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "region_map.cpp"
#include <hwy/foreach_target.h> // IWYU pragma: keep

#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace frappe::detail {
namespace HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

/* Each output pixel from the 2 x 2 pixels a0[2x], a0[2x + 1], a1[2x],
 * a1[2x + 1]. A 16-bit lane holds two neighbouring pixels of a row: the
 * low byte and the high one, whatever the byte order (every reduction here
 * is symmetric). The result (< 256) is narrowed from signed lanes, which
 * this Highway can. `reduce` takes the four pixels as 16-bit lanes; the
 * scalar form does the tail and the scalar target. */
template <class Reduce>
void Of2x2(const std::uint8_t *a0, const std::uint8_t *a1, int w, std::uint8_t *out, Reduce reduce,
	   void (*scalar)(const std::uint8_t *, const std::uint8_t *, int, std::uint8_t *))
{
#if HWY_TARGET == HWY_SCALAR
	(void)reduce;
	scalar(a0, a1, w, out);
#else
	const hn::ScalableTag<std::uint16_t> d16;
	const hn::RebindToSigned<decltype(d16)> di16;
	const hn::Repartition<std::uint8_t, decltype(d16)> d8;
	const hn::Rebind<std::uint8_t, decltype(d16)> d8h;
	const int N = static_cast<int>(hn::Lanes(d16));
	const auto low = hn::Set(d16, 0xFF);
	int x = 0;
	for (; x + N <= w; x += N) {
		const auto a = hn::BitCast(d16, hn::LoadU(d8, a0 + 2 * x));
		const auto b = hn::BitCast(d16, hn::LoadU(d8, a1 + 2 * x));
		const auto r = reduce(d16, hn::And(a, low), hn::ShiftRight<8>(a), hn::And(b, low), hn::ShiftRight<8>(b));
		hn::StoreU(hn::DemoteTo(d8h, hn::BitCast(di16, r)), d8h, out + x);
	}
	if (x < w)
		scalar(a0 + 2 * x, a1 + 2 * x, w - x, out + x);
#endif
}

void DecimateRow(const std::uint8_t *r0, const std::uint8_t *r1, int w, std::uint8_t *out)
{
	Of2x2(r0, r1, w, out, [](auto d, auto p, auto q, auto r, auto t) {
		return hn::ShiftRight<2>(hn::Add(hn::Add(hn::Add(p, q), hn::Add(r, t)), hn::Set(d, 2)));
	}, decimateRowScalar);
}

void MinPairs(const std::uint8_t *a0, const std::uint8_t *a1, int w, std::uint8_t *out)
{
	Of2x2(a0, a1, w, out, [](auto, auto p, auto q, auto r, auto t) {
		return hn::Min(hn::Min(p, q), hn::Min(r, t));
	}, [](const std::uint8_t *b0, const std::uint8_t *b1, int n, std::uint8_t *o) {
		extremePairsScalar(b0, b1, n, o, true);
	});
}

void MaxPairs(const std::uint8_t *a0, const std::uint8_t *a1, int w, std::uint8_t *out)
{
	Of2x2(a0, a1, w, out, [](auto, auto p, auto q, auto r, auto t) {
		return hn::Max(hn::Max(p, q), hn::Max(r, t));
	}, [](const std::uint8_t *b0, const std::uint8_t *b1, int n, std::uint8_t *o) {
		extremePairsScalar(b0, b1, n, o, false);
	});
}

bool DarkRow(const std::uint8_t *d, const std::uint8_t *mid, int w, std::uint8_t *out)
{
	const hn::ScalableTag<std::uint8_t> d8;
	const int N = static_cast<int>(hn::Lanes(d8));
	const auto one = hn::Set(d8, 1);
	auto any = hn::Zero(d8);
	int x = 0;
	for (; x + N <= w; x += N) {
		const auto dark = hn::IfThenElseZero(hn::Lt(hn::LoadU(d8, d + x), hn::LoadU(d8, mid + x)), one);
		hn::StoreU(dark, d8, out + x);
		any = hn::Or(any, dark);
	}
	bool found = !hn::AllTrue(d8, hn::Eq(any, hn::Zero(d8)));
	if (x < w)
		found = darkRowScalar(d + x, mid + x, w - x, out + x) || found;
	return found;
}

/* tileThresholdsScalar on whole vectors of tiles, one int32 lane a tile:
 * the lane's four bytes are the tile's four columns of mid. Returns how
 * many tiles it did; the float root is the scalar one's (IEEE, exact below
 * 2^24), its integer corrections too. */
int TileThresholds(const std::uint8_t *tmin, const std::uint8_t *tmax, int tx, int contrast, int lightFloor,
		   bool shaded, std::uint8_t *mid, std::uint8_t *shadeMid)
{
	const hn::ScalableTag<std::int32_t> d;
	const hn::RebindToUnsigned<decltype(d)> du;
	const hn::Rebind<float, decltype(d)> df;
	const hn::Rebind<std::uint8_t, decltype(d)> d8;
	const int N = static_cast<int>(hn::Lanes(d));
	const auto floor2 = hn::Set(d, 2 * lightFloor), cap = hn::Set(d, 2 * FrontEndParams::kLightReference);
	const auto c = hn::Set(d, contrast), round = hn::Set(d, 255), one = hn::Set(d, 1);
	const auto four = hn::Set(d, FrontEndParams::kShadeFloor), zero = hn::Zero(d);
	const auto bytes = hn::Set(du, 0x01010101u);
	auto replicate = [&](hn::Vec<decltype(d)> v) HWY_ATTR { return hn::Mul(hn::BitCast(du, v), bytes); };
	int i = 0;
	for (; i + N <= tx; i += N) {
		const auto lo = hn::PromoteTo(d, hn::LoadU(d8, tmin + i));
		const auto hi = hn::PromoteTo(d, hn::LoadU(d8, tmax + i));
		const auto sum = hn::Add(lo, hi);
		const auto need = hn::ShiftRight<8>(hn::Add(hn::Mul(c, hn::Min(hn::Add(sum, floor2), cap)), round));
		const auto pass = hn::Not(hn::Lt(hn::Sub(hi, lo), need));
		const auto m = hn::IfThenElseZero(pass, hn::ShiftRight<1>(hn::Add(sum, one)));
		hn::StoreU(replicate(m), du, reinterpret_cast<std::uint32_t *>(mid + 4 * i));
		if (!shaded)
			continue;
		const auto p = hn::Mul(hn::Add(lo, four), hn::Add(hi, four));
		auto r = hn::ConvertTo(d, hn::Sqrt(hn::ConvertTo(df, p)));
		r = hn::Add(r, hn::VecFromMask(d, hn::Lt(p, hn::Mul(r, r)))); /* s -= s^2 > p */
		const auto r1 = hn::Add(r, one);
		r = hn::Sub(r, hn::VecFromMask(d, hn::Not(hn::Lt(p, hn::Mul(r1, r1))))); /* s += (s+1)^2 <= p */
		r = hn::Sub(r, hn::VecFromMask(d, hn::Lt(hn::Mul(r, r), p)));            /* the least root */
		const auto g = hn::IfThenElseZero(hn::Not(hn::Eq(m, zero)), hn::Sub(r, four));
		hn::StoreU(replicate(g), du, reinterpret_cast<std::uint32_t *>(shadeMid + 4 * i));
	}
	return i;
}

/* spreadTilesScalar's two passes with whole vectors of tiles. */
void SpreadTiles(std::uint8_t *tileMin, std::uint8_t *tileMax, int tx, int ty, std::uint8_t *work)
{
	const hn::ScalableTag<std::uint8_t> d;
	const int N = static_cast<int>(hn::Lanes(d));
	auto across = [&](const std::uint8_t *a, const std::uint8_t *b, std::uint8_t *tmin, std::uint8_t *tmax,
			  int n) HWY_ATTR {
		int i = 0;
		for (; i + N <= n; i += N) {
			hn::StoreU(hn::Min(hn::Min(hn::LoadU(d, a + i), hn::LoadU(d, a + i + 1)), hn::LoadU(d, a + i + 2)), d,
				   tmin + i);
			hn::StoreU(hn::Max(hn::Max(hn::LoadU(d, b + i), hn::LoadU(d, b + i + 1)), hn::LoadU(d, b + i + 2)), d,
				   tmax + i);
		}
		return i;
	};
	auto down = [&](std::uint8_t *upMin, std::uint8_t *upMax, const std::uint8_t *dnMin,
			const std::uint8_t *dnMax, std::uint8_t *tmin, std::uint8_t *tmax, int n) HWY_ATTR {
		int i = 0;
		for (; i + N <= n; i += N) {
			const auto m = hn::LoadU(d, tmin + i), x = hn::LoadU(d, tmax + i);
			hn::StoreU(hn::Min(hn::Min(hn::LoadU(d, upMin + i), m), hn::LoadU(d, dnMin + i)), d, tmin + i);
			hn::StoreU(hn::Max(hn::Max(hn::LoadU(d, upMax + i), x), hn::LoadU(d, dnMax + i)), d, tmax + i);
			hn::StoreU(m, d, upMin + i);
			hn::StoreU(x, d, upMax + i);
		}
		return i;
	};
	spreadTilesWith(tileMin, tileMax, tx, ty, work, across, down);
}

} // namespace HWY_NAMESPACE
} // namespace frappe::detail
HWY_AFTER_NAMESPACE();
#endif

#if !defined(FRAPPE_HAVE_HWY) || HWY_ONCE
namespace frappe::detail {

void decimateRowScalar(const std::uint8_t *r0, const std::uint8_t *r1, int w, std::uint8_t *out)
{
	for (int x = 0; x < w; ++x)
		out[x] = static_cast<std::uint8_t>((r0[2 * x] + r0[2 * x + 1] + r1[2 * x] + r1[2 * x + 1] + 2) >> 2);
}

void extremePairsScalar(const std::uint8_t *a0, const std::uint8_t *a1, int w, std::uint8_t *out, bool least)
{
	for (int x = 0; x < w; ++x) {
		const std::uint8_t p = least ? std::min(a0[2 * x], a0[2 * x + 1]) : std::max(a0[2 * x], a0[2 * x + 1]);
		const std::uint8_t q = least ? std::min(a1[2 * x], a1[2 * x + 1]) : std::max(a1[2 * x], a1[2 * x + 1]);
		out[x] = least ? std::min(p, q) : std::max(p, q);
	}
}

bool darkRowScalar(const std::uint8_t *d, const std::uint8_t *mid, int w, std::uint8_t *out)
{
	std::uint8_t any = 0;
	for (int x = 0; x < w; ++x) {
		out[x] = d[x] < mid[x] ? TraceMap::kEdge : 0;
		any |= out[x];
	}
	return any != 0;
}

void tileExtremesScalar(const std::uint8_t *rows, std::ptrdiff_t stride, int n, int w, std::uint8_t *tmin,
			std::uint8_t *tmax)
{
	for (int i = 0; i * kRegionTile < w; ++i) {
		std::uint8_t lo = 255, hi = 0;
		for (int y = 0; y < n; ++y)
			for (int x = i * kRegionTile; x < std::min(w, (i + 1) * kRegionTile); ++x) {
				lo = std::min(lo, rows[y * stride + x]);
				hi = std::max(hi, rows[y * stride + x]);
			}
		tmin[i] = lo;
		tmax[i] = hi;
	}
}

void spreadTilesScalar(std::uint8_t *tileMin, std::uint8_t *tileMax, int tx, int ty, std::uint8_t *work)
{
	auto none = [](auto &&...) { return 0; };
	spreadTilesWith(tileMin, tileMax, tx, ty, work, none, none);
}

void tileThresholdsScalar(const std::uint8_t *tmin, const std::uint8_t *tmax, int tx, const FrontEndParams &params,
			  bool shaded, std::uint8_t *mid, std::uint8_t *shadeMid)
{
	for (int i = 0; i < tx; ++i) {
		const int lo = tmin[i], hi = tmax[i];
		const std::uint32_t m = hi - lo >= params.relativeRegionContrast(lo, hi)
						? static_cast<std::uint32_t>((lo + hi + 1) >> 1)
						: 0u;
		const std::uint32_t word = m * 0x01010101u;
		std::memcpy(mid + i * kRegionTile, &word, 4);
		if (shaded) {
			const std::uint32_t g =
				m ? static_cast<std::uint32_t>(FrontEndParams::shadeThreshold(lo, hi)) : 0u;
			const std::uint32_t gword = g * 0x01010101u;
			std::memcpy(shadeMid + i * kRegionTile, &gword, 4);
		}
	}
}

bool darkRowTilesScalar(const std::uint8_t *d, const std::uint8_t *mid, int w, std::uint8_t *out,
			std::uint8_t *tiles)
{
	if (!darkRowScalar(d, mid, w, out))
		return false;
	for (int x = 0; x < w; ++x)
		tiles[x / TraceMap::kTile] |= out[x];
	return true;
}

#ifdef FRAPPE_HAVE_HWY
HWY_EXPORT(SpreadTiles);
HWY_EXPORT(DecimateRow);
HWY_EXPORT(DarkRow);
HWY_EXPORT(MinPairs);
HWY_EXPORT(MaxPairs);
HWY_EXPORT(TileThresholds);

void tileThresholds(const std::uint8_t *tmin, const std::uint8_t *tmax, int tx, const FrontEndParams &params,
		    bool shaded, std::uint8_t *mid, std::uint8_t *shadeMid)
{
	const int done = HWY_DYNAMIC_DISPATCH(TileThresholds)(tmin, tmax, tx, params.region_contrast,
							      params.light_floor, shaded, mid, shadeMid);
	tileThresholdsScalar(tmin + done, tmax + done, tx - done, params, shaded, mid + kRegionTile * done,
			     shaded ? shadeMid + kRegionTile * done : shadeMid);
}

void extremePairs(const std::uint8_t *a0, const std::uint8_t *a1, int w, std::uint8_t *out, bool least)
{
	if (least)
		HWY_DYNAMIC_DISPATCH(MinPairs)(a0, a1, w, out);
	else
		HWY_DYNAMIC_DISPATCH(MaxPairs)(a0, a1, w, out);
}

void decimateRow(const std::uint8_t *r0, const std::uint8_t *r1, int w, std::uint8_t *out)
{
	HWY_DYNAMIC_DISPATCH(DecimateRow)(r0, r1, w, out);
}

void spreadTiles(std::uint8_t *tileMin, std::uint8_t *tileMax, int tx, int ty, std::uint8_t *work)
{
	HWY_DYNAMIC_DISPATCH(SpreadTiles)(tileMin, tileMax, tx, ty, work);
}

bool darkRow(const std::uint8_t *d, const std::uint8_t *mid, int w, std::uint8_t *out)
{
	return HWY_DYNAMIC_DISPATCH(DarkRow)(d, mid, w, out);
}
#else
void tileThresholds(const std::uint8_t *tmin, const std::uint8_t *tmax, int tx, const FrontEndParams &params,
		    bool shaded, std::uint8_t *mid, std::uint8_t *shadeMid)
{
	tileThresholdsScalar(tmin, tmax, tx, params, shaded, mid, shadeMid);
}

void decimateRow(const std::uint8_t *r0, const std::uint8_t *r1, int w, std::uint8_t *out)
{
#ifdef FRAPPE_HAVE_ARMV6_REGION
	decimateRowV6(r0, r1, w, out);
#else
	decimateRowScalar(r0, r1, w, out);
#endif
}

void extremePairs(const std::uint8_t *a0, const std::uint8_t *a1, int w, std::uint8_t *out, bool least)
{
	extremePairsScalar(a0, a1, w, out, least);
}

bool darkRow(const std::uint8_t *d, const std::uint8_t *mid, int w, std::uint8_t *out)
{
	return darkRowScalar(d, mid, w, out);
}
#endif

void halveImage(const ImageView &src, std::uint8_t *out)
{
	const int w = src.width / 2, h = src.height / 2;
	for (int y = 0; y < h; ++y)
		decimateRow(src.row(2 * y), src.row(2 * y + 1), w, out + static_cast<std::size_t>(y) * w);
}

void regionMap(const ImageView &src, float srcScale, const FrontEndParams &params, TraceMap &out, TraceMap &shades,
	       RegionScratch &s, bool withShades)
{
	if (!makesRegionMap(src.width, src.height, params.region_contrast)) {
		out.resize(0, 0);
		shades.resize(0, 0);
		return;
	}
	s.decimated.resize(static_cast<std::size_t>(src.width / 2) * (src.height / 2));
	halveImage(src, s.decimated.data());
	regionMapFromMeans(src.width, src.height, srcScale, params, out, shades, s, withShades);
}

void regionMapFromMeans(int width, int height, float srcScale, const FrontEndParams &params, TraceMap &out,
			TraceMap &shades, RegionScratch &s, bool withShades)
{
	const int w = width / 2, h = height / 2;
	if (!makesRegionMap(width, height, params.region_contrast)) {
		out.resize(0, 0);
		shades.resize(0, 0);
		return;
	}
	out.resize(w, h);
	out.scale = srcScale / 2.0f;
	const bool shaded = withShades && params.makesShades();
	if (shaded) {
		shades.resize(w, h);
		shades.scale = out.scale;
	} else {
		shades.resize(0, 0);
	}
	constexpr int T = kRegionTile;
	const int tx = (w + T - 1) / T, ty = (h + T - 1) / T;
	const std::size_t nt = static_cast<std::size_t>(tx) * ty;
	s.tileMin.resize(nt);
	s.tileMax.resize(nt);
	s.lo.resize(w);
	s.mid.resize(std::max(tx * T, 2 * tx));
	const std::uint8_t *dec = s.decimated.data();

#ifdef FRAPPE_HAVE_ARMV6_REGION
	/* Each tile's darkest and brightest in one pass over its rows: a
	 * tile's row is one word. */
	for (int j = 0; j < ty; ++j)
		tileExtremesV6(dec + static_cast<std::size_t>(T * j) * w, w, std::min(T, h - T * j), w,
			       s.tileMin.data() + static_cast<std::size_t>(j) * tx,
			       s.tileMax.data() + static_cast<std::size_t>(j) * tx);
#else
	/* Each tile's darkest and brightest, by two halvings of the
	 * decimated image: extremes of 2 x 2 pixels, then of 2 x 2 of those.
	 * A row or column left over at the bottom or right (odd sizes) is
	 * taken with the one before it, by replicating it. */
	const int w1 = (w + 1) / 2, h1 = (h + 1) / 2; /* after the first halving */
	static_assert(T == 4);
	s.level.resize(4 * (static_cast<std::size_t>(w1) + 2) * 2 + 4 * static_cast<std::size_t>(w) + 8);
	std::uint8_t *pad0 = s.level.data(), *pad1 = pad0 + 2 * w1 + 2; /* rows of w padded to even */
	std::uint8_t *l1min = pad1 + 2 * w1 + 2, *l1max = l1min + 2 * w1 + 4;
	std::uint8_t *l1min2 = l1max + 2 * w1 + 4, *l1max2 = l1min2 + 2 * w1 + 4;
	auto paddedRow = [&](int y, std::uint8_t *buf) {
		const std::uint8_t *r = dec + static_cast<std::size_t>(std::min(y, h - 1)) * w;
		if (!(w & 1))
			return r;
		std::memcpy(buf, r, w);
		buf[w] = r[w - 1];
		return static_cast<const std::uint8_t *>(buf);
	};
	/* level-1 rows 2j and 2j + 1 (each padded to an even count) give tile row j */
	for (int j = 0; j < ty; ++j) {
		for (int k = 0; k < 2; ++k) {
			const int y1 = std::min(2 * j + k, h1 - 1);
			const std::uint8_t *r0 = paddedRow(2 * y1, pad0), *r1 = paddedRow(2 * y1 + 1, pad1);
			std::uint8_t *mn = k ? l1min2 : l1min, *mx = k ? l1max2 : l1max;
			extremePairs(r0, r1, w1, mn, true);
			extremePairs(r0, r1, w1, mx, false);
			if (w1 & 1) {
				mn[w1] = mn[w1 - 1];
				mx[w1] = mx[w1 - 1];
			}
		}
		extremePairs(l1min, l1min2, tx, s.tileMin.data() + static_cast<std::size_t>(j) * tx, true);
		extremePairs(l1max, l1max2, tx, s.tileMax.data() + static_cast<std::size_t>(j) * tx, false);
	}
#endif
	/* Then over the 3 x 3 tiles around each. */
	s.spread.resize(4 * static_cast<std::size_t>(tx) + 4);
#ifdef FRAPPE_HAVE_ARMV6_REGION
	spreadTilesV6(s.tileMin.data(), s.tileMax.data(), tx, ty, s.spread.data());
#elif defined(FRAPPE_HAVE_HWY)
	spreadTiles(s.tileMin.data(), s.tileMax.data(), tx, ty, s.spread.data());
#else
	spreadTilesScalar(s.tileMin.data(), s.tileMax.data(), tx, ty, s.spread.data());
#endif

	for (TraceMap *map : { &out, &shades }) {
		if (map->width == 0)
			continue;
		std::fill(map->tiles.begin(), map->tiles.end(), 0);
		std::fill_n(map->pixels.data(), w, 0);
		std::fill_n(map->pixels.data() + static_cast<std::size_t>(h - 1) * w, w, 0);
	}
	constexpr int ET = TraceMap::kTile;
	std::uint8_t *mid = s.mid.data();
	if (shaded)
		s.shadeMid.resize(s.mid.size());
	std::uint8_t *shadeMid = s.shadeMid.data();
#ifndef FRAPPE_HAVE_ARMV6_REGION
	std::uint8_t *acc = s.lo.data(); /* the OR of a tile row's dark rows */
	bool accAny = false, shadeAny = false;
	std::fill_n(acc, w, 0);
	if (shaded)
		s.shadeAcc.assign(static_cast<std::size_t>(w), 0);
	std::uint8_t *shadeAcc = s.shadeAcc.data();
	/* Each tile row's tile mask from the OR of its dark rows. */
	auto markTileRow = [&](TraceMap &map, std::uint8_t *rowOr, int y) {
		std::uint8_t *tileRow = map.tiles.data() + static_cast<std::size_t>(y / ET) * map.tiles_x;
		static_assert(ET == 16);
		for (int t = 0; t < map.tiles_x; ++t) {
			const int x0 = t * ET, x1 = std::min(w, x0 + ET);
			std::uint8_t any = 0;
			if (x1 - x0 == ET) {
				/* A whole tile's bytes ORed as two words, folded. */
				std::uint64_t a, b;
				std::memcpy(&a, rowOr + x0, 8);
				std::memcpy(&b, rowOr + x0 + 8, 8);
				a |= b;
				a |= a >> 32;
				a |= a >> 16;
				a |= a >> 8;
				any = static_cast<std::uint8_t>(a);
			} else {
				for (int x = x0; x < x1; ++x)
					any |= rowOr[x];
			}
			tileRow[t] = any;
		}
		std::fill_n(rowOr, w, 0);
	};
#endif
	for (int j = 0; j < ty; ++j) {
		/* The threshold of each tile of this row: the midpoint, rounded
		 * up, of the extremes around it, or 0 (no pixel is dark) where
		 * they are too close. */
		const std::uint8_t *tmin = s.tileMin.data() + static_cast<std::size_t>(j) * tx;
		const std::uint8_t *tmax = s.tileMax.data() + static_cast<std::size_t>(j) * tx;
		tileThresholds(tmin, tmax, tx, params, shaded, mid, shadeMid); /* mid has room for whole tiles */
		mid[0] = mid[w - 1] = 0; /* the outermost columns are never dark */
		if (shaded)
			shadeMid[0] = shadeMid[w - 1] = 0;
		for (int y = std::max(1, j * T); y < std::min(h - 1, (j + 1) * T); ++y) {
			std::uint8_t *o = out.pixels.data() + static_cast<std::size_t>(y) * w;
#ifdef FRAPPE_HAVE_ARMV6_REGION
			/* Each row marks its tiles itself: no row of ORs. */
			darkRowV6(dec + static_cast<std::size_t>(y) * w, mid, w, o,
				  out.tiles.data() + static_cast<std::size_t>(y / ET) * out.tiles_x);
			if (shaded)
				darkRowV6(dec + static_cast<std::size_t>(y) * w, shadeMid, w,
					  shades.pixels.data() + static_cast<std::size_t>(y) * w,
					  shades.tiles.data() + static_cast<std::size_t>(y / ET) * shades.tiles_x);
#else
			if (darkRow(dec + static_cast<std::size_t>(y) * w, mid, w, o)) {
				for (int x = 0; x < w; ++x)
					acc[x] |= o[x];
				accAny = true;
			}
			if (shaded) {
				std::uint8_t *so = shades.pixels.data() + static_cast<std::size_t>(y) * w;
				if (darkRow(dec + static_cast<std::size_t>(y) * w, shadeMid, w, so)) {
					for (int x = 0; x < w; ++x)
						shadeAcc[x] |= so[x];
					shadeAny = true;
				}
			}
			const bool tileRowEnds = (y + 1) % ET == 0 || y + 1 == h - 1;
			if (accAny && tileRowEnds) {
				markTileRow(out, acc, y);
				accAny = false;
			}
			if (shadeAny && tileRowEnds) {
				markTileRow(shades, shadeAcc, y);
				shadeAny = false;
			}
#endif
		}
	}
}

} // namespace frappe::detail
#endif
