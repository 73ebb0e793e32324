// SPDX-License-Identifier: MIT
// The front end's row kernels vectorised with Highway, compiled for every
// x86/ARM target Highway knows and chosen at run time. They compute exactly
// what the scalar kernels of front_end_rows.cpp compute (the tests compare
// the two byte for byte); only the first and last columns, whose edge
// replication does not vectorise, are left to scalar code.
//
// Lane types: smoothing and Sobel in int16 (|gx|, |gy| <= 1020), the squared
// magnitude and the non-maximum suppression in int32 (m <= 2 * 1020^2).

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "front_end_simd.cpp"
#include <hwy/foreach_target.h> // IWYU pragma: keep

#include <hwy/highway.h>

#include "front_end_rows.h"

HWY_BEFORE_NAMESPACE();
namespace frappe::detail {
namespace HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

void SmoothRow(const std::uint8_t *a, const std::uint8_t *b, const std::uint8_t *c, int w,
	       std::uint8_t *out, std::uint16_t *tmpU)
{
	const hn::ScalableTag<std::int16_t> d16;
	const hn::Rebind<std::uint8_t, decltype(d16)> d8;
	const int N = static_cast<int>(hn::Lanes(d16));
	auto *tmp = reinterpret_cast<std::int16_t *>(tmpU);

	int x = 0;
	for (; x + N <= w; x += N) {
		const auto va = hn::PromoteTo(d16, hn::LoadU(d8, a + x));
		const auto vb = hn::PromoteTo(d16, hn::LoadU(d8, b + x));
		const auto vc = hn::PromoteTo(d16, hn::LoadU(d8, c + x));
		hn::StoreU(hn::Add(hn::Add(va, vc), hn::Add(vb, vb)), d16, tmp + x);
	}
	for (; x < w; ++x)
		tmp[x] = static_cast<std::int16_t>(a[x] + 2 * b[x] + c[x]);
	if (w < 2) {
		smoothRow(a, b, c, w, out, tmpU);
		return;
	}

	const auto round = hn::Set(d16, 8);
	x = 1;
	for (; x + N <= w - 1; x += N) {
		const auto l = hn::LoadU(d16, tmp + x - 1);
		const auto m = hn::LoadU(d16, tmp + x);
		const auto r = hn::LoadU(d16, tmp + x + 1);
		const auto s = hn::ShiftRight<4>(hn::Add(hn::Add(l, r), hn::Add(hn::Add(m, m), round)));
		hn::StoreU(hn::DemoteTo(d8, s), d8, out + x);
	}
	for (; x < w - 1; ++x)
		out[x] = static_cast<std::uint8_t>((tmp[x - 1] + 2 * tmp[x] + tmp[x + 1] + 8) >> 4);
	out[0] = static_cast<std::uint8_t>((3 * tmp[0] + tmp[1] + 8) >> 4);
	out[w - 1] = static_cast<std::uint8_t>((tmp[w - 2] + 3 * tmp[w - 1] + 8) >> 4);
}

void GradientRow(const std::uint8_t *a, const std::uint8_t *b, const std::uint8_t *c, int w,
		 std::int16_t *gx, std::int16_t *gy, std::int32_t *mag, std::int16_t *tmp,
		 TensorRow tensor)
{
	const hn::ScalableTag<std::int16_t> d16;
	const hn::Rebind<std::uint8_t, decltype(d16)> d8;
	const hn::ScalableTag<std::int32_t> d32;
	const hn::Rebind<std::int16_t, decltype(d32)> d16h;
	const int N = static_cast<int>(hn::Lanes(d16));
	const int N32 = static_cast<int>(hn::Lanes(d32));
	std::int16_t *vs = tmp, *vd = tmp + w;

	int x = 0;
	for (; x + N <= w; x += N) {
		const auto va = hn::PromoteTo(d16, hn::LoadU(d8, a + x));
		const auto vb = hn::PromoteTo(d16, hn::LoadU(d8, b + x));
		const auto vc = hn::PromoteTo(d16, hn::LoadU(d8, c + x));
		hn::StoreU(hn::Add(hn::Add(va, vc), hn::Add(vb, vb)), d16, vs + x);
		hn::StoreU(hn::Sub(vc, va), d16, vd + x);
	}
	for (; x < w; ++x) {
		vs[x] = static_cast<std::int16_t>(a[x] + 2 * b[x] + c[x]);
		vd[x] = static_cast<std::int16_t>(c[x] - a[x]);
	}

	gx[0] = gy[0] = 0;
	gx[w - 1] = gy[w - 1] = 0;
	x = 1;
	for (; x + N <= w - 1; x += N) {
		const auto sx = hn::Sub(hn::LoadU(d16, vs + x + 1), hn::LoadU(d16, vs + x - 1));
		const auto m = hn::LoadU(d16, vd + x);
		const auto sy = hn::Add(hn::Add(hn::LoadU(d16, vd + x - 1), hn::LoadU(d16, vd + x + 1)),
					hn::Add(m, m));
		hn::StoreU(sx, d16, gx + x);
		hn::StoreU(sy, d16, gy + x);
	}
	for (; x < w - 1; ++x) {
		gx[x] = static_cast<std::int16_t>(vs[x + 1] - vs[x - 1]);
		gy[x] = static_cast<std::int16_t>(vd[x - 1] + 2 * vd[x] + vd[x + 1]);
	}

	/* The squared magnitude, and the tensor products summed over x-1..x+1
	 * for the corner test: each product once, then the sums. gx and gy are
	 * 0 in the end columns. */
	std::int32_t *pxx = tensor.scratch, *pyy = pxx + w, *pxy = pyy + w;
	x = 0;
	for (; x + N32 <= w; x += N32) {
		const auto vx = hn::PromoteTo(d32, hn::LoadU(d16h, gx + x));
		const auto vy = hn::PromoteTo(d32, hn::LoadU(d16h, gy + x));
		const auto xx = hn::Mul(vx, vx), yy = hn::Mul(vy, vy);
		hn::StoreU(hn::Add(xx, yy), d32, mag + x);
		hn::StoreU(xx, d32, pxx + x);
		hn::StoreU(yy, d32, pyy + x);
		hn::StoreU(hn::Mul(vx, vy), d32, pxy + x);
	}
	for (; x < w; ++x) {
		pxx[x] = gx[x] * gx[x];
		pyy[x] = gy[x] * gy[x];
		pxy[x] = gx[x] * gy[x];
		mag[x] = pxx[x] + pyy[x];
	}
	std::int32_t *txx = tensor.xx, *tyy = tensor.yy, *txy = tensor.xy;
	txx[0] = tyy[0] = txy[0] = 0;
	txx[w - 1] = tyy[w - 1] = txy[w - 1] = 0;
	auto sum3 = [&](const std::int32_t *p) {
		return hn::Add(hn::Add(hn::LoadU(d32, p - 1), hn::LoadU(d32, p)), hn::LoadU(d32, p + 1));
	};
	x = 1;
	for (; x + N32 <= w - 1; x += N32) {
		hn::StoreU(sum3(pxx + x), d32, txx + x);
		hn::StoreU(sum3(pyy + x), d32, tyy + x);
		hn::StoreU(sum3(pxy + x), d32, txy + x);
	}
	for (; x < w - 1; ++x) {
		txx[x] = pxx[x - 1] + pxx[x] + pxx[x + 1];
		tyy[x] = pyy[x - 1] + pyy[x] + pyy[x + 1];
		txy[x] = pxy[x - 1] + pxy[x] + pxy[x + 1];
	}
}

bool EdgeRow(const GradRows &rows, int w, const FrontEndParams &params, std::uint8_t *out)
{
	const hn::ScalableTag<std::int32_t> d32;
	const hn::Rebind<std::int16_t, decltype(d32)> d16h;
	const hn::Rebind<std::uint8_t, decltype(d32)> d8;
	const int N = static_cast<int>(hn::Lanes(d32));
	const std::int32_t *up = rows.mag[0];
	const std::int32_t *mid = rows.mag[1];
	const std::int32_t *down = rows.mag[2];
	const std::int16_t *gxr = rows.gx[1];
	const std::int16_t *gyr = rows.gy[1];
	/* Thresholds beyond the largest magnitude can never pass. */
	const auto thr = hn::Set(d32, static_cast<std::int32_t>(
					      std::min<std::int64_t>(params.edge_threshold_sq, 1 << 30)));
	const auto k256 = hn::Set(d32, 256);
	const auto k106 = hn::Set(d32, 106);
	const auto zero = hn::Zero(d32);
	const auto one = hn::Set(d32, EdgeMap::kEdge);
	const auto two = hn::Set(d32, EdgeMap::kCorner);
	const auto twoT = hn::Set(d32, 2 * static_cast<std::int32_t>(params.corner_threshold));

	bool any = false;
	out[0] = 0;
	out[w - 1] = 0;
	int x = 1;
	for (; x + N <= w - 1; x += N) {
		const auto m = hn::LoadU(d32, mid + x);
		const auto strong = hn::Lt(thr, m);
		if (hn::AllFalse(d32, strong)) {
			hn::StoreU(hn::DemoteTo(d8, zero), d8, out + x);
			continue;
		}
		const auto gx = hn::PromoteTo(d32, hn::LoadU(d16h, gxr + x));
		const auto gy = hn::PromoteTo(d32, hn::LoadU(d16h, gyr + x));
		const auto ax = hn::Abs(gx), ay = hn::Abs(gy);
		/* Same precedence as the scalar if/else chain: horizontal first. */
		const auto horizontal = hn::Not(hn::Lt(hn::Mul(k106, ax), hn::Mul(k256, ay)));
		const auto vertical = hn::Not(hn::Lt(hn::Mul(k106, ay), hn::Mul(k256, ax)));
		const auto diagSame = hn::Eq(hn::VecFromMask(d32, hn::Lt(zero, gx)),
					     hn::VecFromMask(d32, hn::Lt(zero, gy)));
		auto prev = hn::IfThenElse(diagSame, hn::LoadU(d32, up + x - 1), hn::LoadU(d32, up + x + 1));
		auto next = hn::IfThenElse(diagSame, hn::LoadU(d32, down + x + 1), hn::LoadU(d32, down + x - 1));
		prev = hn::IfThenElse(vertical, hn::LoadU(d32, up + x), prev);
		next = hn::IfThenElse(vertical, hn::LoadU(d32, down + x), next);
		prev = hn::IfThenElse(horizontal, hn::LoadU(d32, mid + x - 1), prev);
		next = hn::IfThenElse(horizontal, hn::LoadU(d32, mid + x + 1), next);
		const auto edge = hn::And(hn::And(strong, hn::Lt(prev, m)), hn::Not(hn::Lt(m, next)));
		if (hn::AllFalse(d32, edge)) {
			hn::StoreU(hn::DemoteTo(d8, zero), d8, out + x);
			continue;
		}
		any = true;
		/* Shi-Tomasi in the scalar kernel's int32 form (see isCorner). */
		const auto sxx = hn::Add(hn::Add(hn::LoadU(d32, rows.txx[0] + x), hn::LoadU(d32, rows.txx[1] + x)),
					 hn::LoadU(d32, rows.txx[2] + x));
		const auto syy = hn::Add(hn::Add(hn::LoadU(d32, rows.tyy[0] + x), hn::LoadU(d32, rows.tyy[1] + x)),
					 hn::LoadU(d32, rows.tyy[2] + x));
		const auto sxy = hn::Add(hn::Add(hn::LoadU(d32, rows.txy[0] + x), hn::LoadU(d32, rows.txy[1] + x)),
					 hn::LoadU(d32, rows.txy[2] + x));
		const auto c = hn::ShiftRight<9>(hn::Sub(hn::Add(sxx, syy), twoT));
		const auto ad = hn::ShiftRight<9>(hn::Abs(hn::Sub(sxx, syy)));
		const auto bd = hn::ShiftRight<8>(hn::Abs(sxy));
		const auto corner = hn::And(hn::Lt(zero, c),
					    hn::Lt(hn::Add(hn::Mul(ad, ad), hn::Mul(bd, bd)), hn::Mul(c, c)));
		const auto v = hn::Or(hn::IfThenElseZero(edge, one), hn::IfThenElseZero(hn::And(edge, corner), two));
		hn::StoreU(hn::DemoteTo(d8, v), d8, out + x);
	}
	/* The last few columns: the scalar rule. */
	if (x < w - 1 && edgeSpan(rows, x, w - 1, params, out))
		any = true;
	return any;
}

} // namespace HWY_NAMESPACE
} // namespace frappe::detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace frappe::detail {

HWY_EXPORT(SmoothRow);
HWY_EXPORT(GradientRow);
HWY_EXPORT(EdgeRow);

namespace {

void smoothDispatch(const std::uint8_t *a, const std::uint8_t *b, const std::uint8_t *c, int w,
		    std::uint8_t *out, std::uint16_t *tmp)
{
	HWY_DYNAMIC_DISPATCH(SmoothRow)(a, b, c, w, out, tmp);
}

void gradientDispatch(const std::uint8_t *a, const std::uint8_t *b, const std::uint8_t *c, int w,
		      std::int16_t *gx, std::int16_t *gy, std::int32_t *mag, std::int16_t *tmp,
		      TensorRow tensor)
{
	HWY_DYNAMIC_DISPATCH(GradientRow)(a, b, c, w, gx, gy, mag, tmp, tensor);
}

bool edgeDispatch(const GradRows &rows, int w, const FrontEndParams &params, std::uint8_t *out)
{
	return HWY_DYNAMIC_DISPATCH(EdgeRow)(rows, w, params, out);
}

} // namespace

const RowKernels &bestRowKernels()
{
	static constexpr RowKernels kSimd{ "highway", smoothDispatch, gradientDispatch, edgeDispatch };
	return kSimd;
}

} // namespace frappe::detail
#endif // HWY_ONCE
