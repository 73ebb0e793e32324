// SPDX-License-Identifier: MIT
// The contour tracer's data-parallel kernels (see trace_kernels.h),
// vectorised with Highway where it is built in, else plain loops. With
// Highway the library is built with -ffp-contract=off, so that the float
// kernels give the scalar ones' results exactly.

#include "trace_kernels.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#ifdef FRAPPE_HAVE_HWY
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "trace_kernels.cpp"
#include <hwy/foreach_target.h> // IWYU pragma: keep

#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace frappe::detail {
namespace HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

/* v << bits, lane by lane. Highway 1.0.3 (Debian 12) spells it Shl on the
 * scalable targets (SVE, RVV: no operators on sizeless types) and
 * operator<< elsewhere. */
template <class V>
HWY_INLINE V ShiftLeftBy(V v, V bits)
{
#if HWY_HAVE_SCALABLE
	return hn::Shl(v, bits);
#else
	return hn::operator<<(v, bits);
#endif
}

void LabelsFromEdges(const std::uint8_t *edges, std::size_t n, std::uint8_t *labels)
{
	const hn::ScalableTag<std::uint8_t> d8;
	const std::size_t N = hn::Lanes(d8);
	const auto one = hn::Set(d8, kUnfollowed);
	std::size_t i = 0;
	for (; i + N <= n; i += N)
		hn::StoreU(hn::And(hn::LoadU(d8, edges + i), one), d8, labels + i);
	for (; i < n; ++i)
		labels[i] = edges[i] & kUnfollowed;
}

void NeighbourMaskRow(const std::uint8_t *row, std::ptrdiff_t stride, int x0, int x1, std::uint8_t *out)
{
#if HWY_TARGET == HWY_SCALAR
	/* One-lane vectors have no 16-bit view. */
	neighbourMasksScalar(row, stride, x0, x1, out);
#else
	const hn::ScalableTag<std::uint8_t> d8;
	const hn::Repartition<std::uint16_t, decltype(d8)> d16;
	const int N = static_cast<int>(hn::Lanes(d8));
	const std::uint8_t *up = row - stride, *down = row + stride;
	/* Bit 0 of a neighbour's byte moved to bit k: a 16-bit shift moves
	 * both bytes of a lane alike and no bit crosses into the next byte,
	 * since k < 8; the AND keeps bit k only. */
	auto add = [&](auto acc, const std::uint8_t *p, auto shift) HWY_ATTR {
		constexpr int k = decltype(shift)::value;
		const auto v = hn::BitCast(d8, hn::ShiftLeft<k>(hn::BitCast(d16, hn::LoadU(d8, p))));
		return hn::OrAnd(acc, v, hn::Set(d8, static_cast<std::uint8_t>(1u << k)));
	};
	using S1 = std::integral_constant<int, 1>;
	using S2 = std::integral_constant<int, 2>;
	using S3 = std::integral_constant<int, 3>;
	using S4 = std::integral_constant<int, 4>;
	using S5 = std::integral_constant<int, 5>;
	using S6 = std::integral_constant<int, 6>;
	using S7 = std::integral_constant<int, 7>;
	auto masks = [&](int x) HWY_ATTR {
		auto acc = hn::And(hn::LoadU(d8, row + x + 1), hn::Set(d8, 1));
		acc = add(acc, up + x + 1, S1{});
		acc = add(acc, up + x, S2{});
		acc = add(acc, up + x - 1, S3{});
		acc = add(acc, row + x - 1, S4{});
		acc = add(acc, down + x - 1, S5{});
		acc = add(acc, down + x, S6{});
		acc = add(acc, down + x + 1, S7{});
		hn::StoreU(acc, d8, out + x);
	};
	int x = x0;
	for (; x + N <= x1; x += N)
		masks(x);
	if (x == x1)
		return;
	/* The tail as one vector ending at x1, recomputing some masks on its
	 * left (the stretches are short: a scalar tail cost as much as the
	 * rest), when that vector starts inside the row. */
	if (x1 - N >= 1)
		masks(x1 - N);
	else
		neighbourMasksScalar(row, stride, x, x1, out);
#endif
}

void BorderStartBits(const std::uint8_t *labels, int x0, int x1, std::uint64_t *bits)
{
#if HWY_TARGET == HWY_SCALAR
	borderStartBitsScalar(labels, x0, x1, bits);
#else
	const hn::ScalableTag<std::uint8_t> d8;
	const int N = static_cast<int>(hn::Lanes(d8)); /* a multiple of 16 */
	const auto zero = hn::Zero(d8), unfollowed = hn::Set(d8, kUnfollowed);
	const auto one = hn::Set(d8, 1), rightBg = hn::Set(d8, kFollowedRightBg ^ kFollowed);
	auto *out = reinterpret_cast<std::uint8_t *>(bits);
	int x = x0;
	for (; x < x1; x += N) {
		const auto here = hn::LoadU(d8, labels + x);
		const auto left = hn::LoadU(d8, labels + x - 1), right = hn::LoadU(d8, labels + x + 1);
		const auto outer = hn::And(hn::Eq(here, unfollowed), hn::Eq(left, zero));
		const auto hole = hn::And(hn::And(hn::TestBit(here, one), hn::Not(hn::TestBit(here, rightBg))),
					  hn::Eq(right, zero));
		auto starts = hn::Or(outer, hole);
		if (x + N > x1)
			starts = hn::And(starts, hn::FirstN(d8, static_cast<std::size_t>(x1 - x)));
		hn::StoreMaskBits(d8, starts, out + (x - x0) / 8);
	}
	/* Clear the rest of the last word. */
	const int done = (x - x0) / 8, end = ((x1 - x0 + 63) / 64) * 8;
	if (done < end)
		std::memset(out + done, 0, static_cast<std::size_t>(end - done));
#endif
}

std::uint32_t SideCoverage(const std::uint32_t *pts, std::size_t n, const SideLine &side, float tol)
{
#if HWY_TARGET == HWY_SCALAR
	return sideCoverageScalar(pts, n, side, tol);
#else
	const hn::ScalableTag<std::uint32_t> du;
	const hn::Rebind<std::int32_t, decltype(du)> di;
	const hn::Rebind<float, decltype(du)> df;
	const std::size_t N = hn::Lanes(du);
	const auto nx = hn::Set(df, side.nx), ny = hn::Set(df, side.ny), nc = hn::Set(df, side.nc);
	const auto ux = hn::Set(df, side.ux), uy = hn::Set(df, side.uy), t0 = hn::Set(df, side.t0);
	const auto vTol = hn::Set(df, tol), zero = hn::Zero(df), bins = hn::Set(df, static_cast<float>(kSideBins));
	const auto low16 = hn::Set(du, 0xFFFFu), one = hn::Set(du, 1u);
	auto covered = hn::Zero(du);
	for (std::size_t k = 0; k < n; k += N) {
		const auto v = hn::LoadU(du, pts + k);
		const auto x = hn::ConvertTo(df, hn::BitCast(di, hn::And(v, low16)));
		const auto y = hn::ConvertTo(df, hn::BitCast(di, hn::ShiftRight<16>(v)));
		const auto d = hn::Abs(hn::Sub(hn::Add(hn::Mul(nx, x), hn::Mul(ny, y)), nc));
		const auto t = hn::Sub(hn::Add(hn::Mul(ux, x), hn::Mul(uy, y)), t0);
		auto hit = hn::And(hn::Not(hn::Gt(d, vTol)), hn::And(hn::Ge(t, zero), hn::Lt(t, bins)));
		if (k + N > n)
			hit = hn::And(hit, hn::FirstN(df, n - k));
		/* t is in [0, 16) where it counts: the shift never exceeds 15. */
		const auto bin = hn::BitCast(du, hn::ConvertTo(di, hn::IfThenElseZero(hit, t)));
		covered = hn::Or(covered, hn::IfThenElseZero(hn::RebindMask(du, hit), ShiftLeftBy(one, bin)));
	}
	HWY_ALIGN std::uint32_t lanes[HWY_MAX_BYTES / 4];
	hn::Store(covered, du, lanes);
	std::uint32_t all = 0;
	for (std::size_t i = 0; i < N; ++i)
		all |= lanes[i];
	return all;
#endif
}

OutlineExtremes OutlineExtremesV(const std::uint32_t *pts, std::size_t n)
{
#if HWY_TARGET == HWY_SCALAR
	return outlineExtremesScalar(pts, n);
#else
	const hn::ScalableTag<std::uint32_t> du;
	const hn::Rebind<std::int32_t, decltype(du)> di;
	const std::size_t N = hn::Lanes(du);
	const auto low16 = hn::Set(du, 0xFFFFu);
	auto X = [&](hn::Vec<decltype(du)> v) HWY_ATTR { return hn::BitCast(di, hn::And(v, low16)); };
	auto Y = [&](hn::Vec<decltype(du)> v) HWY_ATTR { return hn::BitCast(di, hn::ShiftRight<16>(v)); };

	/* The centroid: sums in 32-bit lanes, emptied before they could
	 * overflow (2^15 vectors of 16-bit values). */
	std::uint64_t sx = 0, sy = 0;
	for (std::size_t k = 0; k < n;) {
		const std::size_t end = std::min(n, k + N * 32768);
		auto ax = hn::Zero(du), ay = hn::Zero(du);
		for (; k < end; k += N) {
			auto v = hn::LoadU(du, pts + k);
			if (k + N > n)
				v = hn::IfThenElseZero(hn::FirstN(du, n - k), v);
			ax = hn::Add(ax, hn::And(v, low16));
			ay = hn::Add(ay, hn::ShiftRight<16>(v));
		}
		sx += hn::GetLane(hn::SumOfLanes(du, ax));
		sy += hn::GetLane(hn::SumOfLanes(du, ay));
	}
	OutlineExtremes e;

	/* i0 in double, as the scalar form: the largest distance, then the
	 * first point at it. */
	{
		const hn::ScalableTag<double> dd;
		const hn::Rebind<std::uint32_t, decltype(dd)> duh;
		const hn::Rebind<std::int32_t, decltype(dd)> dih;
		const std::size_t M = hn::Lanes(dd);
		const auto mx = hn::Set(dd, static_cast<double>(sx) / static_cast<double>(n));
		const auto my = hn::Set(dd, static_cast<double>(sy) / static_cast<double>(n));
		const auto low16h = hn::Set(duh, 0xFFFFu);
		const auto none = hn::Set(dd, -1.0);
		auto dist = [&](std::size_t k) HWY_ATTR {
			const auto v = hn::LoadU(duh, pts + k);
			const auto dx = hn::Sub(hn::PromoteTo(dd, hn::BitCast(dih, hn::And(v, low16h))), mx);
			const auto dy = hn::Sub(hn::PromoteTo(dd, hn::BitCast(dih, hn::ShiftRight<16>(v))), my);
			const auto d = hn::Add(hn::Mul(dx, dx), hn::Mul(dy, dy));
			return k + M > n ? hn::IfThenElse(hn::FirstN(dd, n - k), d, none) : d;
		};
		auto best = none;
		for (std::size_t k = 0; k < n; k += M)
			best = hn::Max(best, dist(k));
		const auto top = hn::MaxOfLanes(dd, best);
		for (std::size_t k = 0; k < n; k += M) {
			const intptr_t at = hn::FindFirstTrue(dd, hn::Eq(dist(k), top));
			if (at >= 0) {
				e.i0 = k + static_cast<std::size_t>(at);
				break;
			}
		}
	}

	/* The rest in int32, like the scalar form. */
	const auto x0 = hn::Set(di, static_cast<std::int32_t>(pts[e.i0] & 0xFFFFu));
	const auto y0 = hn::Set(di, static_cast<std::int32_t>(pts[e.i0] >> 16));
	auto firstWhere = [&](auto value, hn::Vec<decltype(di)> target) HWY_ATTR {
		for (std::size_t k = 0; k < n; k += N) {
			auto m = hn::Eq(value(k), target);
			if (k + N > n)
				m = hn::And(m, hn::FirstN(di, n - k));
			const intptr_t at = hn::FindFirstTrue(di, m);
			if (at >= 0)
				return k + static_cast<std::size_t>(at);
		}
		return std::size_t{ 0 };
	};
	{
		auto dist = [&](std::size_t k) HWY_ATTR {
			const auto v = hn::LoadU(du, pts + k);
			const auto dx = hn::Sub(X(v), x0), dy = hn::Sub(Y(v), y0);
			return hn::Add(hn::Mul(dx, dx), hn::Mul(dy, dy));
		};
		auto best = hn::Set(di, -1);
		for (std::size_t k = 0; k < n; k += N) {
			auto d = dist(k);
			if (k + N > n)
				d = hn::IfThenElse(hn::FirstN(di, n - k), d, hn::Set(di, -1));
			best = hn::Max(best, d);
		}
		e.i2 = firstWhere(dist, hn::MaxOfLanes(di, best));
	}
	{
		const auto ex = hn::Sub(hn::Set(di, static_cast<std::int32_t>(pts[e.i2] & 0xFFFFu)), x0);
		const auto ey = hn::Sub(hn::Set(di, static_cast<std::int32_t>(pts[e.i2] >> 16)), y0);
		auto cross = [&](std::size_t k) HWY_ATTR {
			const auto v = hn::LoadU(du, pts + k);
			return hn::Sub(hn::Mul(ex, hn::Sub(Y(v), y0)), hn::Mul(ey, hn::Sub(X(v), x0)));
		};
		auto most = hn::Zero(di), least = hn::Zero(di);
		for (std::size_t k = 0; k < n; k += N) {
			auto c = cross(k);
			if (k + N > n)
				c = hn::IfThenElseZero(hn::FirstN(di, n - k), c);
			most = hn::Max(most, c);
			least = hn::Min(least, c);
		}
		const auto mostV = hn::MaxOfLanes(di, most), leastV = hn::MinOfLanes(di, least);
		e.most = hn::GetLane(mostV);
		e.least = hn::GetLane(leastV);
		if (e.most > 0)
			e.i1 = firstWhere(cross, mostV);
		if (e.least < 0)
			e.i3 = firstWhere(cross, leastV);
	}
	return e;
#endif
}

PointsBox PointsBoxV(const std::uint32_t *pts, std::size_t n)
{
#if HWY_TARGET == HWY_SCALAR
	return pointsBoxScalar(pts, n);
#else
	const hn::ScalableTag<std::uint32_t> du;
	const std::size_t N = hn::Lanes(du);
	const auto low16 = hn::Set(du, 0xFFFFu);
	/* The tail repeats the first point, which changes no extreme. */
	const auto first = hn::Set(du, pts[0]);
	auto lo = first, hi = first, loX = hn::And(first, low16), hiX = loX;
	for (std::size_t k = 0; k < n; k += N) {
		auto v = hn::LoadU(du, pts + k);
		if (k + N > n)
			v = hn::IfThenElse(hn::FirstN(du, n - k), v, first);
		/* y is the high half: the extreme words give its extremes. */
		lo = hn::Min(lo, v);
		hi = hn::Max(hi, v);
		const auto x = hn::And(v, low16);
		loX = hn::Min(loX, x);
		hiX = hn::Max(hiX, x);
	}
	return { hn::GetLane(hn::MinOfLanes(du, loX)), hn::GetLane(hn::MaxOfLanes(du, hiX)),
		 hn::GetLane(hn::MinOfLanes(du, lo)) >> 16, hn::GetLane(hn::MaxOfLanes(du, hi)) >> 16 };
#endif
}

} // namespace HWY_NAMESPACE
} // namespace frappe::detail
HWY_AFTER_NAMESPACE();
#endif // FRAPPE_HAVE_HWY

#if !defined(FRAPPE_HAVE_HWY) || HWY_ONCE
namespace frappe::detail {

void neighbourMasksScalar(const std::uint8_t *row, std::ptrdiff_t stride, int x0, int x1, std::uint8_t *out)
{
	const std::uint8_t *up = row - stride, *down = row + stride;
	for (int x = x0; x < x1; ++x)
		out[x] = static_cast<std::uint8_t>(
			(row[x + 1] & 1) | (up[x + 1] & 1) << 1 | (up[x] & 1) << 2 | (up[x - 1] & 1) << 3 |
			(row[x - 1] & 1) << 4 | (down[x - 1] & 1) << 5 | (down[x] & 1) << 6 | (down[x + 1] & 1) << 7);
}

void borderStartBitsScalar(const std::uint8_t *labels, int x0, int x1, std::uint64_t *bits)
{
	const int words = (x1 - x0 + 63) / 64;
	for (int k = 0; k < words; ++k)
		bits[k] = 0;
	for (int x = x0; x < x1; ++x) {
		const std::uint8_t f = labels[x];
		const bool outer = f == kUnfollowed && labels[x - 1] == 0;
		const bool hole = (f & 1) && !(f & (kFollowedRightBg ^ kFollowed)) && labels[x + 1] == 0;
		if (outer || hole)
			bits[(x - x0) / 64] |= std::uint64_t{ 1 } << ((x - x0) % 64);
	}
}

std::uint32_t sideCoverageScalar(const std::uint32_t *pts, std::size_t n, const SideLine &side, float tol)
{
	std::uint32_t covered = 0;
	for (std::size_t k = 0; k < n; ++k) {
		const float px = static_cast<float>(pts[k] & 0xFFFFu), py = static_cast<float>(pts[k] >> 16);
		if (std::abs(side.nx * px + side.ny * py - side.nc) > tol)
			continue;
		const float t = side.ux * px + side.uy * py - side.t0;
		if (t >= 0.0f && t < static_cast<float>(kSideBins))
			covered |= 1u << static_cast<int>(t);
	}
	return covered;
}

OutlineExtremes outlineExtremesScalar(const std::uint32_t *pts, std::size_t n)
{
	auto X = [pts](std::size_t i) { return static_cast<std::int32_t>(pts[i] & 0xFFFFu); };
	auto Y = [pts](std::size_t i) { return static_cast<std::int32_t>(pts[i] >> 16); };
	std::int64_t sx = 0, sy = 0;
	for (std::size_t i = 0; i < n; ++i) {
		sx += X(i);
		sy += Y(i);
	}
	const double mx = static_cast<double>(sx) / static_cast<double>(n);
	const double my = static_cast<double>(sy) / static_cast<double>(n);
	OutlineExtremes e;
	double bd = -1;
	for (std::size_t i = 0; i < n; ++i) {
		const double dx = X(i) - mx, dy = Y(i) - my;
		if (dx * dx + dy * dy > bd) {
			bd = dx * dx + dy * dy;
			e.i0 = i;
		}
	}
	/* The rest in integers (coordinates below 2^15, so squares and cross
	 * products fit an int32). */
	const std::int32_t x0 = X(e.i0), y0 = Y(e.i0);
	std::int32_t bd2 = -1;
	for (std::size_t i = 0; i < n; ++i) {
		const std::int32_t dx = X(i) - x0, dy = Y(i) - y0;
		if (dx * dx + dy * dy > bd2) {
			bd2 = dx * dx + dy * dy;
			e.i2 = i;
		}
	}
	const std::int32_t ex = X(e.i2) - x0, ey = Y(e.i2) - y0;
	for (std::size_t i = 0; i < n; ++i) {
		/* cross(p0, p2, p) */
		const std::int32_t c = ex * (Y(i) - y0) - ey * (X(i) - x0);
		if (c > e.most) {
			e.most = c;
			e.i1 = i;
		} else if (c < e.least) {
			e.least = c;
			e.i3 = i;
		}
	}
	return e;
}

void labelsFromEdgesScalar(const std::uint8_t *edges, std::size_t n, std::uint8_t *labels)
{
	for (std::size_t i = 0; i < n; ++i)
		labels[i] = edges[i] & kUnfollowed;
}

PointsBox pointsBoxScalar(const std::uint32_t *pts, std::size_t n)
{
	std::uint32_t lo = pts[0], hi = lo, minX = lo & 0xFFFFu, maxX = minX;
	for (std::size_t i = 0; i < n; ++i) {
		const std::uint32_t v = pts[i], x = v & 0xFFFFu;
		lo = std::min(lo, v);
		hi = std::max(hi, v);
		minX = std::min(minX, x);
		maxX = std::max(maxX, x);
	}
	return { minX, maxX, lo >> 16, hi >> 16 };
}

#ifdef FRAPPE_HAVE_HWY
HWY_EXPORT(LabelsFromEdges);
HWY_EXPORT(NeighbourMaskRow);

void labelsFromEdges(const std::uint8_t *edges, std::size_t n, std::uint8_t *labels)
{
	HWY_DYNAMIC_DISPATCH(LabelsFromEdges)(edges, n, labels);
}
HWY_EXPORT(BorderStartBits);
HWY_EXPORT(SideCoverage);
HWY_EXPORT(OutlineExtremesV);
HWY_EXPORT(PointsBoxV);

PointsBox pointsBox(const std::uint32_t *pts, std::size_t n)
{
	return HWY_DYNAMIC_DISPATCH(PointsBoxV)(pts, n);
}

OutlineExtremes outlineExtremes(const std::uint32_t *pts, std::size_t n)
{
	return HWY_DYNAMIC_DISPATCH(OutlineExtremesV)(pts, n);
}

std::uint32_t sideCoverage(const std::uint32_t *pts, std::size_t n, const SideLine &side, float tol)
{
	return HWY_DYNAMIC_DISPATCH(SideCoverage)(pts, n, side, tol);
}

void neighbourMasks(const std::uint8_t *row, std::ptrdiff_t stride, int x0, int x1, std::uint8_t *out)
{
	HWY_DYNAMIC_DISPATCH(NeighbourMaskRow)(row, stride, x0, x1, out);
}

void borderStartBits(const std::uint8_t *labels, int x0, int x1, std::uint64_t *bits)
{
	HWY_DYNAMIC_DISPATCH(BorderStartBits)(labels, x0, x1, bits);
}
#else
void labelsFromEdges(const std::uint8_t *edges, std::size_t n, std::uint8_t *labels)
{
#ifdef FRAPPE_HAVE_ARMV6_TRACE
	labelsFromEdgesV6(edges, n, labels);
#else
	labelsFromEdgesScalar(edges, n, labels); /* the compiler's word loop */
#endif
}

void neighbourMasks(const std::uint8_t *row, std::ptrdiff_t stride, int x0, int x1, std::uint8_t *out)
{
	neighbourMasksScalar(row, stride, x0, x1, out);
}

void borderStartBits(const std::uint8_t *labels, int x0, int x1, std::uint64_t *bits)
{
	borderStartBitsScalar(labels, x0, x1, bits);
}

std::uint32_t sideCoverage(const std::uint32_t *pts, std::size_t n, const SideLine &side, float tol)
{
	return sideCoverageScalar(pts, n, side, tol);
}

OutlineExtremes outlineExtremes(const std::uint32_t *pts, std::size_t n)
{
#ifdef FRAPPE_HAVE_ARMV6_TRACE
	return outlineExtremesV6(pts, n);
#else
	return outlineExtremesScalar(pts, n);
#endif
}

PointsBox pointsBox(const std::uint32_t *pts, std::size_t n)
{
#ifdef FRAPPE_HAVE_ARMV6_TRACE
	return pointsBoxV6(pts, n);
#else
	return pointsBoxScalar(pts, n);
#endif
}
#endif

} // namespace frappe::detail
#endif
