// SPDX-License-Identifier: MIT
// The perspective warp's sampling (see warp_kernels.h): the fixed-point
// form and the float fallback, each vectorised with Highway where it is
// built in, else a plain loop. With Highway the library is built with
// -ffp-contract=off, so that both float forms give the same bits; the
// fixed-point forms compute exact integers.

#include "warp_kernels.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "sampling.h"

#ifdef FRAPPE_HAVE_HWY
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "warp_kernels.cpp"
#include <hwy/foreach_target.h> // IWYU pragma: keep

#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace frappe::detail {
namespace HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

#if HWY_ARCH_X86 && HWY_TARGET <= HWY_AVX2
/* Lanes k, k + 1, ... of a side x side grid as (i, j), in doubles. Row
 * j = floor((k + l + 0.5) / side): that quotient lies at least 1 / (2 side)
 * from an integer, far beyond the rounding of the product below, so i and j
 * are exact. */
template <class DD>
HWY_INLINE void gridLanes(DD dd, int k, int side, hn::Vec<DD> &i, hn::Vec<DD> &j)
{
	const auto kd = hn::Iota(dd, k);
	j = hn::Floor(hn::Mul(hn::Add(kd, hn::Set(dd, 0.5)), hn::Set(dd, 1.0 / side)));
	i = hn::Sub(kd, hn::Mul(j, hn::Set(dd, side)));
}

/* The 2x2 neighbourhoods at (x0, y0), x0 <= width - 2, y0 <= height - 2,
 * by two 32-bit gathers a lane that take pixels by byte offset (x86: lowest
 * address in the low byte): row y0 from x0 on (the word's low bytes) and
 * row y0 + 1 up to x0 + 1 (its high bytes), so that neither word reaches
 * past the image, whose last row may end the buffer. */
template <class DI>
struct Neighbours {
	hn::Vec<DI> p00, p01, p10, p11;
};
template <class DI>
HWY_INLINE Neighbours<DI> gatherNeighbours(DI di, const ImageView &image, hn::Vec<DI> x0, hn::Vec<DI> y0)
{
	const hn::RebindToUnsigned<DI> du;
	const auto *words = reinterpret_cast<const std::uint32_t *>(image.data);
	const auto byte = hn::Set(du, 0xFFu);
	const auto at = hn::Add(hn::Mul(y0, hn::Set(di, image.stride)), x0);
	const auto above = hn::GatherOffset(du, words, at);
	const auto below = hn::GatherOffset(du, words, hn::Add(at, hn::Set(di, image.stride - 2)));
	return { hn::BitCast(di, hn::And(above, byte)), hn::BitCast(di, hn::And(hn::ShiftRight<8>(above), byte)),
		 hn::BitCast(di, hn::And(hn::ShiftRight<16>(below), byte)), hn::BitCast(di, hn::ShiftRight<24>(below)) };
}

/* Stores lanes k .. min(k + N, total) - 1 of the grid. */
template <class DF>
HWY_INLINE void storeSamples(DF df, hn::Vec<DF> sample, int k, int total, float *out)
{
	if (k + static_cast<int>(hn::Lanes(df)) <= total) {
		hn::StoreU(sample, df, out + k);
	} else {
		HWY_ALIGN float lanes[HWY_MAX_BYTES / sizeof(float)];
		hn::Store(sample, df, lanes);
		std::copy(lanes, lanes + (total - k), out + k);
	}
}

/* Images too large for 32-bit byte offsets go the scalar way. */
inline bool offsetsFit(const ImageView &image)
{
	const std::int64_t bytes = static_cast<std::int64_t>(image.height - 1) * image.stride + image.width;
	return bytes <= std::numeric_limits<std::int32_t>::max();
}
#endif

void WarpSamples(const ImageView &image, const Homography &H, int side, bool inside, float *out)
{
#if !HWY_ARCH_X86 || HWY_TARGET > HWY_AVX2
	/* Without gather instructions (SSE4, SSSE3, NEON, ...) a gather is a
	 * load a lane: measured on SSE4 the vector form was no faster than
	 * the scalar one, on SSSE3 twice as slow. */
	warpSamplesScalar(image, H, side, inside, out);
#else
	if (image.width < 2 || image.height < 2 || !offsetsFit(image)) {
		warpSamplesScalar(image, H, side, inside, out);
		return;
	}
	const hn::ScalableTag<float> df;
	const hn::RebindToSigned<decltype(df)> di;
	const hn::Half<decltype(df)> dh;
	const hn::Repartition<double, decltype(df)> dd;
	const int N = static_cast<int>(hn::Lanes(df)), M = static_cast<int>(hn::Lanes(dd));

	const auto &h = H.h;
	const auto vStep = hn::Set(dd, 1.0 / side), half = hn::Set(dd, 0.5);
	struct Point {
		hn::Vec<decltype(dh)> x, y;
	};
	/* u, v are the scalar form's (gridLanes is exact). */
	auto point = [&](int k) HWY_ATTR {
		hn::Vec<decltype(dd)> i, j;
		gridLanes(dd, k, side, i, j);
		const auto u = hn::Mul(hn::Add(i, half), vStep), v = hn::Mul(hn::Add(j, half), vStep);
		auto line = [&](int row) HWY_ATTR {
			const auto c = hn::Add(hn::Mul(hn::Set(dd, h[3 * row + 1]), v), hn::Set(dd, h[3 * row + 2]));
			return hn::Add(hn::Mul(hn::Set(dd, h[3 * row]), u), c);
		};
		const auto r = hn::Div(hn::Set(dd, 1.0), line(2));
		return Point{ hn::DemoteTo(dh, hn::Mul(line(0), r)), hn::DemoteTo(dh, hn::Mul(line(1), r)) };
	};

	const auto zero = hn::Zero(df);
	const auto xMax = hn::Set(df, static_cast<float>(image.width - 1));
	const auto yMax = hn::Set(df, static_cast<float>(image.height - 1));
	const auto x0Max = hn::Set(di, image.width - 2), y0Max = hn::Set(di, image.height - 2);

	const int total = side * side;
	for (int k = 0; k < total; k += N) {
		const Point lo = point(k), hi = point(k + M);
		/* sampleBilinear's clamps, NaN (a quad whose homography
		 * crosses infinity) to 0. */
		auto x = hn::Combine(df, hi.x, lo.x), y = hn::Combine(df, hi.y, lo.y);
		x = hn::IfThenElseZero(hn::Ge(x, zero), hn::Min(x, xMax));
		y = hn::IfThenElseZero(hn::Ge(y, zero), hn::Min(y, yMax));
		const auto x0 = hn::Min(hn::ConvertTo(di, x), x0Max), y0 = hn::Min(hn::ConvertTo(di, y), y0Max);
		const auto fx = hn::Sub(x, hn::ConvertTo(df, x0)), fy = hn::Sub(y, hn::ConvertTo(df, y0));
		const auto p = gatherNeighbours(di, image, x0, y0);
		const auto p00 = hn::ConvertTo(df, p.p00), p01 = hn::ConvertTo(df, p.p01);
		const auto p10 = hn::ConvertTo(df, p.p10), p11 = hn::ConvertTo(df, p.p11);
		const auto top = hn::Add(p00, hn::Mul(fx, hn::Sub(p01, p00)));
		const auto bottom = hn::Add(p10, hn::Mul(fx, hn::Sub(p11, p10)));
		storeSamples(df, hn::Add(top, hn::Mul(fy, hn::Sub(bottom, top))), k, total, out);
	}
#endif
}

void WarpFixedSamples(const ImageView &image, const FixedWarp &w, bool fine, float *out)
{
#if !HWY_ARCH_X86 || HWY_TARGET > HWY_AVX2
	/* No gathers: as WarpSamples. */
	warpFixedSamplesScalar(image, w, fine, out);
#else
	if (!offsetsFit(image)) {
		warpFixedSamplesScalar(image, w, fine, out);
		return;
	}
	const hn::ScalableTag<std::int32_t> di;
	const hn::RebindToFloat<decltype(di)> df;
	const hn::Repartition<double, decltype(di)> dd;
	const hn::Rebind<std::int32_t, decltype(dd)> dh; /* half of di */
	const int N = static_cast<int>(hn::Lanes(di)), M = static_cast<int>(hn::Lanes(dd));
	const int side = w.side;

	using VD = hn::Vec<decltype(dd)>;
	const auto zero = hn::Zero(dd), one = hn::Set(dd, 1.0), k1024 = hn::Set(dd, 1024.0), k2048 = hn::Set(dd, 2048.0);
	const auto xMax = hn::Set(dd, 1024.0 * (image.width - 1)), yMax = hn::Set(dd, 1024.0 * (image.height - 1));
	const auto xOrigin = hn::Set(dd, 1024.0 * w.ox), yOrigin = hn::Set(dd, 1024.0 * w.oy);
	auto form = [&](const FixedWarpForm &f, VD i, VD j) HWY_ATTR {
		return hn::Add(hn::Add(hn::Set(dd, f.at00), hn::Mul(hn::Set(dd, f.di), i)), hn::Mul(hn::Set(dd, f.dj), j));
	};
	/* The contract's position in double, where every value is an exact
	 * integer and the quotient's floor exact (warpFixedSamplesScalar).
	 * The clamp also takes the lanes past the grid, whose forms may be out
	 * of range (NaN included), into the image. */
	auto position = [&](VD n, VD d, VD origin, VD max) HWY_ATTR {
		const auto nc = hn::Min(hn::Max(n, zero), hn::Sub(hn::Mul(d, k2048), one));
		const auto p = hn::Add(origin, hn::Floor(hn::Div(hn::Mul(nc, k1024), d)));
		return hn::DemoteTo(dh, hn::IfThenElseZero(hn::Ge(p, zero), hn::Min(p, max)));
	};
	struct Point {
		hn::Vec<decltype(dh)> x, y;
	};
	auto point = [&](int k) HWY_ATTR {
		VD i, j;
		gridLanes(dd, k, side, i, j);
		const auto d = form(w.d, i, j);
		return Point{ position(form(w.x, i, j), d, xOrigin, xMax), position(form(w.y, i, j), d, yOrigin, yMax) };
	};

	const auto x0Max = hn::Set(di, image.width - 2), y0Max = hn::Set(di, image.height - 2);
	const auto one1024 = hn::Set(di, 1024), round = hn::Set(di, fine ? 0 : 1 << 19);
	const auto unit = hn::Set(df, 1.0f / 1048576.0f);
	const int total = side * side;
	for (int k = 0; k < total; k += N) {
		const Point lo = point(k), hi = point(k + M);
		const auto X = hn::Combine(di, hi.x, lo.x), Y = hn::Combine(di, hi.y, lo.y);
		const auto x0 = hn::Min(hn::ShiftRight<10>(X), x0Max), y0 = hn::Min(hn::ShiftRight<10>(Y), y0Max);
		const auto fx = hn::Sub(X, hn::ShiftLeft<10>(x0)), fy = hn::Sub(Y, hn::ShiftLeft<10>(y0));
		const auto p = gatherNeighbours(di, image, x0, y0);
		const auto gx = hn::Sub(one1024, fx), gy = hn::Sub(one1024, fy);
		const auto top = hn::Add(hn::Mul(p.p00, gx), hn::Mul(p.p01, fx));
		const auto bottom = hn::Add(hn::Mul(p.p10, gx), hn::Mul(p.p11, fx));
		const auto v = hn::Add(hn::Add(hn::Mul(top, gy), hn::Mul(bottom, fy)), round);
		storeSamples(df, fine ? hn::Mul(hn::ConvertTo(df, v), unit) : hn::ConvertTo(df, hn::ShiftRight<20>(v)), k,
			     total, out);
	}
#endif
}

} // namespace HWY_NAMESPACE
} // namespace frappe::detail
HWY_AFTER_NAMESPACE();
#endif // FRAPPE_HAVE_HWY

#if !defined(FRAPPE_HAVE_HWY) || HWY_ONCE
namespace frappe::detail {

void warpSamplesScalar(const ImageView &image, const Homography &H, int side, bool inside, float *out)
{
	const auto &h = H.h;
	const double step = 1.0 / side;
	for (int j = 0; j < side; ++j) {
		const double v = (j + 0.5) * step;
		const double cx = h[1] * v + h[2], cy = h[4] * v + h[5], cd = h[7] * v + h[8];
		float *row = out + static_cast<std::size_t>(j) * side;
		for (int i = 0; i < side; ++i) {
			const double u = (i + 0.5) * step;
			const double r = 1.0 / (h[6] * u + cd);
			const float x = static_cast<float>((h[0] * u + cx) * r);
			const float y = static_cast<float>((h[3] * u + cy) * r);
			row[i] = inside ? sampleInside(image, x, y) : sampleBilinear(image, x, y);
		}
	}
}

namespace {

/* One axis of the contract's position, for a 32-bit core: 0 < d < 2^20 on
 * the grid, so the clamped numerator is below 2^31 and the quotient below
 * 2^21, and both go between int32 and double, one VFP instruction each on
 * a Pi Zero (int64 conversions are libgcc calls there). The quotient is the
 * contract's: nc 2^10 is exact in double and the division correctly rounded.
 * `origin` is the origin times 2^10, below 2^30 in magnitude (the caller
 * checks), so origin + q cannot overflow. */
inline std::int32_t fixedAxis(std::int64_t n, std::int32_t d, std::int32_t origin, std::int32_t max)
{
	const std::int64_t limit = (std::int64_t{ d } << kFixedWarpIntBits) - 1;
	const auto nc = static_cast<std::int32_t>(n < 0 ? 0 : (n > limit ? limit : n));
	const auto q = static_cast<std::int32_t>(static_cast<double>(nc) * (1 << kFixedWarpFracBits) /
						 static_cast<double>(d));
	const std::int32_t p = origin + q;
	return p < 0 ? 0 : (p > max ? max : p);
}

/* Whether none of the contract's clamps acts on any sample of the grid. Each
 * clamp is the sign of a linear form over (i, j): with a = 2^10 n and d > 0,
 * 0 <= n <= 2^11 d - 1 for the numerator, and for the position
 * origin + floor(a / d) >= 0  <=>  a + origin d >= 0 and
 * origin + floor(a / d) <= max  <=>  a + origin d < (max + 1) d,
 * so the grid's four corners decide for all its samples. */
bool clampsIdle(const FixedWarp &w, int width, int height)
{
	const int last = w.side - 1;
	const std::int64_t ox = std::int64_t{ w.ox } << kFixedWarpFracBits;
	const std::int64_t oy = std::int64_t{ w.oy } << kFixedWarpFracBits;
	const std::int64_t xMax = std::int64_t{ width - 1 } << kFixedWarpFracBits;
	const std::int64_t yMax = std::int64_t{ height - 1 } << kFixedWarpFracBits;
	auto idle = [](std::int64_t n, std::int64_t d, std::int64_t origin, std::int64_t max) {
		if (n < 0 || n > (d << kFixedWarpIntBits) - 1)
			return false;
		const std::int64_t a = (n << kFixedWarpFracBits) + origin * d;
		return a >= 0 && a < (max + 1) * d;
	};
	for (int j : { 0, last })
		for (int i : { 0, last }) {
			const std::int64_t d = w.d.at(i, j);
			if (!idle(w.x.at(i, j), d, ox, xMax) || !idle(w.y.at(i, j), d, oy, yMax))
				return false;
		}
	return true;
}

/* The grid when no clamp acts: 2^10 n and d stepped along each row in
 * double (integers below 2^48, so exact), one correctly rounded division a
 * position, whose truncation is the contract's floor (a >= 0, and a
 * quotient below 2^21 that is not an integer is at least 2^-20 below the
 * next one, far more than its rounding). */
template <bool Fine>
void warpFixedInside(const ImageView &image, const FixedWarp &w, float *out)
{
	const auto ox = static_cast<std::int32_t>(w.ox * (1 << kFixedWarpFracBits));
	const auto oy = static_cast<std::int32_t>(w.oy * (1 << kFixedWarpFracBits));
	constexpr double kUnit = 1 << kFixedWarpFracBits;
	const double sx = kUnit * w.x.di, sy = kUnit * w.y.di, sd = w.d.di;
	/* Each row's start from the int32 coefficients (int64 to double is a
	 * libgcc call on a Pi Zero, int32 to double one instruction). */
	auto start = [](const FixedWarpForm &f, int j) {
		return static_cast<double>(f.at00) + static_cast<double>(f.dj) * j;
	};
	for (int j = 0; j < w.side; ++j) {
		double ax = kUnit * start(w.x, j);
		double ay = kUnit * start(w.y, j);
		double d = start(w.d, j);
		float *row = out + static_cast<std::size_t>(j) * w.side;
		for (int i = 0; i < w.side; ++i) {
			const std::int32_t X = ox + static_cast<std::int32_t>(ax / d);
			const std::int32_t Y = oy + static_cast<std::int32_t>(ay / d);
			row[i] = fixedSample(fixedBilinear(image, X, Y), Fine);
			ax += sx;
			ay += sy;
			d += sd;
		}
	}
}

} // namespace

void warpFixedSamplesScalar(const ImageView &image, const FixedWarp &w, bool fine, float *out)
{
	if (clampsIdle(w, image.width, image.height)) {
		/* Most candidates: inside the frame, nowhere near the ranges. */
		if (fine)
			warpFixedInside<true>(image, w, out);
		else
			warpFixedInside<false>(image, w, out);
		return;
	}
	const std::int64_t ox = std::int64_t{ w.ox } << kFixedWarpFracBits;
	const std::int64_t oy = std::int64_t{ w.oy } << kFixedWarpFracBits;
	constexpr std::int64_t kOriginLimit = std::int64_t{ 1 } << 30;
	if (ox <= -kOriginLimit || ox >= kOriginLimit || oy <= -kOriginLimit || oy >= kOriginLimit) {
		/* An origin a million pixels away: the contract verbatim. */
		for (int j = 0; j < w.side; ++j)
			for (int i = 0; i < w.side; ++i)
				out[static_cast<std::size_t>(j) * w.side + i] =
					fixedSample(fixedWarpValue(image, w, i, j), fine);
		return;
	}
	const auto xMax = static_cast<std::int32_t>((image.width - 1) << kFixedWarpFracBits);
	const auto yMax = static_cast<std::int32_t>((image.height - 1) << kFixedWarpFracBits);
	/* The forms stepped along each row: the same integers as at(i, j). */
	for (int j = 0; j < w.side; ++j) {
		std::int64_t nx = w.x.at(0, j), ny = w.y.at(0, j);
		std::int64_t d = w.d.at(0, j); /* in (0, 2^20) at every sample, not past the row */
		float *row = out + static_cast<std::size_t>(j) * w.side;
		for (int i = 0; i < w.side; ++i) {
			const auto d32 = static_cast<std::int32_t>(d);
			const std::int32_t X = fixedAxis(nx, d32, static_cast<std::int32_t>(ox), xMax);
			const std::int32_t Y = fixedAxis(ny, d32, static_cast<std::int32_t>(oy), yMax);
			row[i] = fixedSample(fixedBilinear(image, X, Y), fine);
			nx += w.x.di;
			ny += w.y.di;
			d += w.d.di;
		}
	}
}

#ifdef FRAPPE_HAVE_HWY
HWY_EXPORT(WarpFixedSamples);

void warpFixedSamples(const ImageView &image, const FixedWarp &w, bool fine, float *out)
{
	HWY_DYNAMIC_DISPATCH(WarpFixedSamples)(image, w, fine, out);
}
#else
void warpFixedSamples(const ImageView &image, const FixedWarp &w, bool fine, float *out)
{
	warpFixedSamplesScalar(image, w, fine, out);
}
#endif

#ifdef FRAPPE_HAVE_HWY
HWY_EXPORT(WarpSamples);

void warpSamples(const ImageView &image, const Homography &H, int side, bool inside, float *out)
{
	HWY_DYNAMIC_DISPATCH(WarpSamples)(image, H, side, inside, out);
}
#else
void warpSamples(const ImageView &image, const Homography &H, int side, bool inside, float *out)
{
	warpSamplesScalar(image, H, side, inside, out);
}
#endif

} // namespace frappe::detail
#endif
