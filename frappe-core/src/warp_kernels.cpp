// SPDX-License-Identifier: MIT
// The perspective warp's sampling (see warp_kernels.h), vectorised with
// Highway where it is built in, else a plain loop. With Highway the library
// is built with -ffp-contract=off, so that both forms give the same bits.

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
