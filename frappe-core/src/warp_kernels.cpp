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

void WarpSamples(const ImageView &image, const Homography &H, int side, bool inside, float *out)
{
#if !HWY_ARCH_X86 || HWY_TARGET > HWY_AVX2
	/* Without gather instructions (SSE4, SSSE3, NEON, ...) a gather is a
	 * load a lane: measured on SSE4 the vector form was no faster than
	 * the scalar one, on SSSE3 twice as slow. */
	warpSamplesScalar(image, H, side, inside, out);
#else
	/* The gathers below take pixels from 32-bit words by their byte
	 * offset (x86: lowest address in the low byte); images too small for
	 * a 2x2 neighbourhood, or too large for such offsets, go the scalar
	 * way. */
	const std::int64_t bytes = static_cast<std::int64_t>(image.height - 1) * image.stride + image.width;
	if (image.width < 2 || image.height < 2 || bytes > std::numeric_limits<std::int32_t>::max()) {
		warpSamplesScalar(image, H, side, inside, out);
		return;
	}
	const hn::ScalableTag<float> df;
	const hn::RebindToSigned<decltype(df)> di;
	const hn::RebindToUnsigned<decltype(df)> du;
	const hn::Half<decltype(df)> dh;
	const hn::Repartition<double, decltype(df)> dd;
	const int N = static_cast<int>(hn::Lanes(df)), M = static_cast<int>(hn::Lanes(dd));

	const auto &h = H.h;
	const double step = 1.0 / side;
	const auto vStep = hn::Set(dd, step), vSide = hn::Set(dd, side), half = hn::Set(dd, 0.5);
	struct Point {
		hn::Vec<decltype(dh)> x, y;
	};
	/* Lane l is sample k + l, in row j = floor((k + l + 0.5) / side): that
	 * quotient lies at least 1 / (2 side) from an integer, far beyond the
	 * rounding of the product below, so j and i are exact and u, v are
	 * the scalar form's. */
	auto point = [&](int k) HWY_ATTR {
		const auto kd = hn::Iota(dd, k);
		const auto j = hn::Floor(hn::Mul(hn::Add(kd, half), vStep));
		const auto i = hn::Sub(kd, hn::Mul(j, vSide));
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
	const auto stride = hn::Set(di, image.stride), nextRowLeft2 = hn::Set(di, image.stride - 2);
	const auto byte = hn::Set(du, 0xFFu);
	const auto *words = reinterpret_cast<const std::uint32_t *>(image.data);
	auto toFloat = [&](hn::Vec<decltype(du)> v) HWY_ATTR { return hn::ConvertTo(df, hn::BitCast(di, v)); };

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
		/* Row y0 from x0 on (the word's low bytes) and row y0 + 1 up to
		 * x0 + 1 (its high bytes): neither word reaches past the image,
		 * whose last row may end the buffer. */
		const auto at = hn::Add(hn::Mul(y0, stride), x0);
		const auto above = hn::GatherOffset(du, words, at);
		const auto below = hn::GatherOffset(du, words, hn::Add(at, nextRowLeft2));
		const auto p00 = toFloat(hn::And(above, byte)), p01 = toFloat(hn::And(hn::ShiftRight<8>(above), byte));
		const auto p10 = toFloat(hn::And(hn::ShiftRight<16>(below), byte)), p11 = toFloat(hn::ShiftRight<24>(below));
		const auto top = hn::Add(p00, hn::Mul(fx, hn::Sub(p01, p00)));
		const auto bottom = hn::Add(p10, hn::Mul(fx, hn::Sub(p11, p10)));
		const auto sample = hn::Add(top, hn::Mul(fy, hn::Sub(bottom, top)));
		if (k + N <= total) {
			hn::StoreU(sample, df, out + k);
		} else {
			HWY_ALIGN float lanes[HWY_MAX_BYTES / sizeof(float)];
			hn::Store(sample, df, lanes);
			std::copy(lanes, lanes + (total - k), out + k);
		}
	}
#endif
}

void WarpFixedSamples(const ImageView &image, const FixedWarp &w, float *out)
{
#if !HWY_ARCH_X86 || HWY_TARGET > HWY_AVX2
	/* No gathers: as WarpSamples. */
	warpFixedSamplesScalar(image, w, out);
#else
	const std::int64_t bytes = static_cast<std::int64_t>(image.height - 1) * image.stride + image.width;
	if (bytes > std::numeric_limits<std::int32_t>::max()) {
		warpFixedSamplesScalar(image, w, out);
		return;
	}
	const hn::ScalableTag<std::int32_t> di;
	const hn::RebindToUnsigned<decltype(di)> du;
	const hn::RebindToFloat<decltype(di)> df;
	const hn::Repartition<double, decltype(di)> dd;
	const hn::Rebind<std::int32_t, decltype(dd)> dh; /* half of di */
	const int N = static_cast<int>(hn::Lanes(di)), M = static_cast<int>(hn::Lanes(dd));
	const int side = w.side;

	const auto vStep = hn::Set(dd, 1.0 / side), vSide = hn::Set(dd, side), half = hn::Set(dd, 0.5);
	const auto zero = hn::Zero(dd), one = hn::Set(dd, 1.0), k1024 = hn::Set(dd, 1024.0), k2048 = hn::Set(dd, 2048.0);
	const auto xMax = hn::Set(dd, 1024.0 * (image.width - 1)), yMax = hn::Set(dd, 1024.0 * (image.height - 1));
	const auto xOrigin = hn::Set(dd, 1024.0 * w.ox), yOrigin = hn::Set(dd, 1024.0 * w.oy);
	auto form = [&](const FixedWarpForm &f, decltype(zero) i, decltype(zero) j) HWY_ATTR {
		return hn::Add(hn::Add(hn::Set(dd, f.at00), hn::Mul(hn::Set(dd, f.di), i)), hn::Mul(hn::Set(dd, f.dj), j));
	};
	/* The contract's position in double, where every value is an exact
	 * integer and the quotient's floor exact (warpFixedSamplesScalar).
	 * The clamp also takes the lanes past the grid, whose forms may be out
	 * of range (NaN included), into the image. */
	auto position = [&](decltype(zero) n, decltype(zero) d, decltype(zero) origin, decltype(zero) max) HWY_ATTR {
		const auto nc = hn::Min(hn::Max(n, zero), hn::Sub(hn::Mul(d, k2048), one));
		const auto p = hn::Add(origin, hn::Floor(hn::Div(hn::Mul(nc, k1024), d)));
		return hn::DemoteTo(dh, hn::IfThenElseZero(hn::Ge(p, zero), hn::Min(p, max)));
	};
	struct Point {
		hn::Vec<decltype(dh)> x, y;
	};
	/* Lane l is sample k + l, in row j = floor((k + l + 0.5) / side) (exact:
	 * see WarpSamples). */
	auto point = [&](int k) HWY_ATTR {
		const auto kd = hn::Iota(dd, k);
		const auto j = hn::Floor(hn::Mul(hn::Add(kd, half), vStep));
		const auto i = hn::Sub(kd, hn::Mul(j, vSide));
		const auto d = form(w.d, i, j);
		return Point{ position(form(w.x, i, j), d, xOrigin, xMax), position(form(w.y, i, j), d, yOrigin, yMax) };
	};

	const auto x0Max = hn::Set(di, image.width - 2), y0Max = hn::Set(di, image.height - 2);
	const auto stride = hn::Set(di, image.stride), nextRowLeft2 = hn::Set(di, image.stride - 2);
	const auto byte = hn::Set(du, 0xFFu);
	const auto one1024 = hn::Set(di, 1024), round = hn::Set(di, 1 << 19);
	const auto *words = reinterpret_cast<const std::uint32_t *>(image.data);
	auto pixel = [&](hn::Vec<decltype(du)> v) HWY_ATTR { return hn::BitCast(di, v); };

	const int total = side * side;
	for (int k = 0; k < total; k += N) {
		const Point lo = point(k), hi = point(k + M);
		const auto X = hn::Combine(di, hi.x, lo.x), Y = hn::Combine(di, hi.y, lo.y);
		const auto x0 = hn::Min(hn::ShiftRight<10>(X), x0Max), y0 = hn::Min(hn::ShiftRight<10>(Y), y0Max);
		const auto fx = hn::Sub(X, hn::ShiftLeft<10>(x0)), fy = hn::Sub(Y, hn::ShiftLeft<10>(y0));
		/* The gathers of WarpSamples. */
		const auto at = hn::Add(hn::Mul(y0, stride), x0);
		const auto above = hn::GatherOffset(du, words, at);
		const auto below = hn::GatherOffset(du, words, hn::Add(at, nextRowLeft2));
		const auto p00 = pixel(hn::And(above, byte)), p01 = pixel(hn::And(hn::ShiftRight<8>(above), byte));
		const auto p10 = pixel(hn::And(hn::ShiftRight<16>(below), byte)), p11 = pixel(hn::ShiftRight<24>(below));
		const auto gx = hn::Sub(one1024, fx), gy = hn::Sub(one1024, fy);
		const auto top = hn::Add(hn::Mul(p00, gx), hn::Mul(p01, fx));
		const auto bottom = hn::Add(hn::Mul(p10, gx), hn::Mul(p11, fx));
		const auto v = hn::Add(hn::Add(hn::Mul(top, gy), hn::Mul(bottom, fy)), round);
		const auto sample = hn::ConvertTo(df, hn::ShiftRight<20>(v));
		if (k + N <= total) {
			hn::StoreU(sample, df, out + k);
		} else {
			HWY_ALIGN float lanes[HWY_MAX_BYTES / sizeof(float)];
			hn::Store(sample, df, lanes);
			std::copy(lanes, lanes + (total - k), out + k);
		}
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

void warpFixedSamplesScalar(const ImageView &image, const FixedWarp &w, float *out)
{
	for (int j = 0; j < w.side; ++j) {
		for (int i = 0; i < w.side; ++i) {
			const std::int64_t d = w.d.at(i, j);
			auto quotient = [d](std::int64_t n) {
				const std::int64_t nc = std::clamp<std::int64_t>(n, 0, (d << kFixedWarpIntBits) - 1);
				return static_cast<std::int64_t>(static_cast<double>(nc << kFixedWarpFracBits) /
								 static_cast<double>(d));
			};
			const std::int32_t X = fixedPosition(quotient(w.x.at(i, j)), w.ox, image.width);
			const std::int32_t Y = fixedPosition(quotient(w.y.at(i, j)), w.oy, image.height);
			out[static_cast<std::size_t>(j) * w.side + i] = fixedBilinear(image, X, Y);
		}
	}
}

#ifdef FRAPPE_HAVE_HWY
HWY_EXPORT(WarpFixedSamples);

void warpFixedSamples(const ImageView &image, const FixedWarp &w, float *out)
{
	HWY_DYNAMIC_DISPATCH(WarpFixedSamples)(image, w, out);
}
#else
void warpFixedSamples(const ImageView &image, const FixedWarp &w, float *out)
{
	warpFixedSamplesScalar(image, w, out);
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
