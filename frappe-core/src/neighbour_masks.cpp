// SPDX-License-Identifier: MIT
// Eight-neighbour masks for the contour tracer (see neighbour_masks.h),
// vectorised with Highway where it is built in, else a plain loop.

#include "neighbour_masks.h"

#ifdef FRAPPE_HAVE_HWY
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "neighbour_masks.cpp"
#include <hwy/foreach_target.h> // IWYU pragma: keep

#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace frappe::detail {
namespace HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

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

#ifdef FRAPPE_HAVE_HWY
HWY_EXPORT(NeighbourMaskRow);

void neighbourMasks(const std::uint8_t *row, std::ptrdiff_t stride, int x0, int x1, std::uint8_t *out)
{
	HWY_DYNAMIC_DISPATCH(NeighbourMaskRow)(row, stride, x0, x1, out);
}
#else
void neighbourMasks(const std::uint8_t *row, std::ptrdiff_t stride, int x0, int x1, std::uint8_t *out)
{
	neighbourMasksScalar(row, stride, x0, x1, out);
}
#endif

} // namespace frappe::detail
#endif
