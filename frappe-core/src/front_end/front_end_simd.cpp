// SPDX-License-Identifier: MIT
// The front end's row kernels vectorised with Highway, compiled for every
// x86/ARM target Highway knows and chosen at run time. They compute exactly
// what the scalar kernels of front_end_rows.cpp compute (the tests compare
// the two byte for byte); only the first and last columns, whose edge
// replication does not vectorise, are left to scalar code.
//
// Lane types: smoothing and Sobel in int16 (|gx|, |gy| <= 1020), the squared
// magnitude and the non-maximum suppression in int32 (m <= 2 * 1020^2); the
// gradient row holds (gx, gy) int16 pairs (see UsePairs), and the corner
// test's sums are computed from them only where a vector holds an edge.

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "front_end_simd.cpp"
#include <hwy/foreach_target.h> // IWYU pragma: keep

#include <hwy/highway.h>

#include <algorithm>

#include "front_end_rows.h"

/* The row loops call their per-vector lambdas from two places; inlined,
 * their constants stay in registers. */
#define FRAPPE_INLINE_LAMBDA __attribute__((always_inline))

HWY_BEFORE_NAMESPACE();
namespace frappe::detail {
namespace HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

/* Internal: the band loop calls its target's kernels without the PLT. */
namespace {

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
#if HWY_ARCH_X86 && HWY_TARGET <= HWY_AVX3
		/* s <= 255: truncation is exact, one instruction. */
		hn::StoreU(hn::Vec<decltype(d8)>{ _mm512_cvtepi16_epi8(s.raw) }, d8, out + x);
#else
		hn::StoreU(hn::DemoteTo(d8, s), d8, out + x);
#endif
	}
	for (; x < w - 1; ++x)
		out[x] = static_cast<std::uint8_t>((tmp[x - 1] + 2 * tmp[x] + tmp[x + 1] + 8) >> 4);
	out[0] = static_cast<std::uint8_t>((3 * tmp[0] + tmp[1] + 8) >> 4);
	out[w - 1] = static_cast<std::uint8_t>((tmp[w - 2] + 3 * tmp[w - 1] + 8) >> 4);
}

void OrRow(const std::uint8_t *row, int w, std::uint8_t *acc)
{
	const hn::ScalableTag<std::uint8_t> d8;
	const int N = static_cast<int>(hn::Lanes(d8));
	int x = 0;
	for (; x + N <= w; x += N)
		hn::StoreU(hn::Or(hn::LoadU(d8, row + x), hn::LoadU(d8, acc + x)), d8, acc + x);
	for (; x < w; ++x)
		acc[x] |= row[x];
}

#if HWY_TARGET != HWY_SCALAR

/* The gradient row layout of these kernels (like the ARMv6 ones): per pixel
 * one int32 "pair" P = gx | gy << 16 in the gx buffer (2w int16 values), gy
 * unused. On pairs one int16 pair-multiply-add gives gx^2 + gy^2, gx^2 or
 * 2 gx gy per pixel, so the corner test needs no tensor rows and no 32-bit
 * multiplies. Rows narrower than a vector take the scalar kernels and their
 * layout; GradientRow and EdgeRow make the same choice from w. */
template <class D16>
bool UsePairs(D16 d16, int w)
{
	return w >= static_cast<int>(hn::Lanes(d16)) + 2;
}

/* a0*b0 + a1*b1 for the int16 pair of each int32 lane (madd on x86). */
template <class D32, class V16>
hn::Vec<D32> PairDot(D32 d32, V16 a, V16 b)
{
	auto odd = hn::Zero(d32);
	return hn::RearrangeToOddPlusEven(hn::ReorderWidenMulAccumulate(d32, a, b, hn::Zero(d32), odd), odd);
}

/* The int32 vector one column to the right of lo (lanes 1.. of lo, then
 * lane 0 of the next vector hi), and one column to the left of cur. */
template <class D>
hn::Vec<D> NextColumn(D d, hn::Vec<D> lo, hn::Vec<D> hi)
{
#if HWY_ARCH_X86 && HWY_TARGET <= HWY_AVX3
	(void)d;
	return hn::Vec<D>{ _mm512_alignr_epi32(hi.raw, lo.raw, 1) };
#elif HWY_ARCH_X86 && HWY_TARGET == HWY_AVX2
	(void)d;
	return hn::Vec<D>{ _mm256_alignr_epi8(_mm256_permute2x128_si256(lo.raw, hi.raw, 0x21), lo.raw, 4) };
#else
	if constexpr (HWY_MAX_BYTES == 16 && hn::MaxLanes(d) == 4)
		return hn::CombineShiftRightBytes<4>(d, hi, lo);
	HWY_ALIGN std::int32_t buf[2 * HWY_MAX_BYTES / 4];
	const std::size_t n = hn::Lanes(d);
	hn::Store(lo, d, buf);
	hn::Store(hi, d, buf + n);
	return hn::LoadU(d, buf + 1);
#endif
}

template <class D>
hn::Vec<D> PrevColumn(D d, hn::Vec<D> prev, hn::Vec<D> cur)
{
#if HWY_ARCH_X86 && HWY_TARGET <= HWY_AVX3
	(void)d;
	return hn::Vec<D>{ _mm512_alignr_epi32(cur.raw, prev.raw, 15) };
#elif HWY_ARCH_X86 && HWY_TARGET == HWY_AVX2
	(void)d;
	return hn::Vec<D>{ _mm256_alignr_epi8(cur.raw, _mm256_permute2x128_si256(prev.raw, cur.raw, 0x21), 12) };
#else
	if constexpr (HWY_MAX_BYTES == 16 && hn::MaxLanes(d) == 4)
		return hn::CombineShiftRightBytes<12>(d, cur, prev);
	HWY_ALIGN std::int32_t buf[2 * HWY_MAX_BYTES / 4];
	const std::size_t n = hn::Lanes(d);
	hn::Store(prev, d, buf);
	hn::Store(cur, d, buf + n);
	return hn::LoadU(d, buf + n - 1);
#endif
}

/* The EdgeMap bytes of an int32 vector's lanes: kEdge, plus kCorner. */
template <class D32, class D8>
hn::Vec<D8> EdgeBytes(D32 d32, D8 d8, hn::Mask<D32> edge, hn::Mask<D32> corner)
{
#if HWY_ARCH_X86 && HWY_TARGET <= HWY_AVX3
	/* Byte-masked moves straight from the lane masks, no demotion. */
	(void)d32;
	(void)d8;
	const __m128i e = _mm_maskz_mov_epi8(edge.raw, _mm_set1_epi8(EdgeMap::kEdge));
	return hn::Vec<D8>{ _mm_mask_mov_epi8(e, hn::And(edge, corner).raw,
					     _mm_set1_epi8(EdgeMap::kEdge | EdgeMap::kCorner)) };
#else
	const auto v = hn::IfThenElseZero(edge, hn::IfThenElse(corner, hn::Set(d32, EdgeMap::kEdge | EdgeMap::kCorner),
							       hn::Set(d32, EdgeMap::kEdge)));
	return hn::DemoteTo(d8, v);
#endif
}

void GradientRow(const std::uint8_t *a, const std::uint8_t *b, const std::uint8_t *c, int w,
		 std::int16_t *gx, std::int16_t *gy, std::int32_t *mag, std::int16_t *tmp)
{
	const hn::ScalableTag<std::int16_t> d16;
	const hn::Rebind<std::uint8_t, decltype(d16)> d8;
	const hn::Half<decltype(d16)> d16h;
	const hn::Repartition<std::int32_t, decltype(d16)> d32;
	const hn::Repartition<std::uint32_t, decltype(d16)> du32;
	const hn::Rebind<std::uint16_t, decltype(d32)> du16h;
	const int N = static_cast<int>(hn::Lanes(d16));
	if (!UsePairs(d16, w)) {
		gradientRow(a, b, c, w, gx, gy, mag, tmp);
		return;
	}
	auto *pairs = reinterpret_cast<std::int32_t *>(gx);
	auto load = [&](const std::uint8_t *p) { return hn::PromoteTo(d16, hn::LoadU(d8, p)); };
	/* One pass, no column buffers: the 3x3 Sobel straight from the rows.
	 * The last vector overlaps the previous one instead of a scalar tail. */
	for (int x = 1;; x += N) {
		x = std::min(x, w - 1 - N);
		const auto al = load(a + x - 1), am = load(a + x), ar = load(a + x + 1);
		const auto cl = load(c + x - 1), cm = load(c + x), cr = load(c + x + 1);
		const auto bl = load(b + x - 1), br = load(b + x + 1);
		const auto sx = hn::Sub(hn::Add(hn::Add(ar, cr), hn::Add(br, br)),
					hn::Add(hn::Add(al, cl), hn::Add(bl, bl)));
		const auto dm = hn::Sub(cm, am);
		const auto sy = hn::Add(hn::Add(hn::Sub(cl, al), hn::Sub(cr, ar)), hn::Add(dm, dm));
		auto store = [&](int x0, hn::Vec<decltype(d32)> p) {
			hn::StoreU(p, d32, pairs + x0);
			hn::StoreU(PairDot(d32, hn::BitCast(d16, p), hn::BitCast(d16, p)), d32, mag + x0);
		};
#if HWY_ARCH_X86 && HWY_TARGET <= HWY_AVX3
		/* Interleave gx and gy into pixel order by a two-table permute. */
		alignas(64) static constexpr std::int16_t kLo[32] = { 0, 32, 1, 33, 2, 34, 3, 35, 4, 36, 5, 37, 6, 38, 7, 39,
			8, 40, 9, 41, 10, 42, 11, 43, 12, 44, 13, 45, 14, 46, 15, 47 };
		alignas(64) static constexpr std::int16_t kHi[32] = { 16, 48, 17, 49, 18, 50, 19, 51, 20, 52, 21, 53, 22, 54, 23, 55,
			24, 56, 25, 57, 26, 58, 27, 59, 28, 60, 29, 61, 30, 62, 31, 63 };
		store(x, hn::Vec<decltype(d32)>{ _mm512_permutex2var_epi16(sx.raw, _mm512_load_si512(kLo), sy.raw) });
		store(x + N / 2, hn::Vec<decltype(d32)>{ _mm512_permutex2var_epi16(sx.raw, _mm512_load_si512(kHi), sy.raw) });
#elif HWY_ARCH_X86 && HWY_TARGET == HWY_AVX2
		/* Interleave within 128-bit blocks, after putting the 64-bit
		 * chunks in the order 0, 2, 1, 3: four instructions, not ten. */
		const __m256i px = _mm256_permute4x64_epi64(sx.raw, 0xD8), py = _mm256_permute4x64_epi64(sy.raw, 0xD8);
		store(x, hn::Vec<decltype(d32)>{ _mm256_unpacklo_epi16(px, py) });
		store(x + N / 2, hn::Vec<decltype(d32)>{ _mm256_unpackhi_epi16(px, py) });
#else
		/* Widen each half into pairs: gx zero-extended, gy in the top. */
		auto widen = [&](hn::Vec<decltype(d16h)> vx, hn::Vec<decltype(d16h)> vy) {
			return hn::BitCast(d32, hn::Or(hn::PromoteTo(du32, hn::BitCast(du16h, vx)),
						       hn::ShiftLeft<16>(hn::PromoteTo(du32, hn::BitCast(du16h, vy)))));
		};
		store(x, widen(hn::LowerHalf(d16h, sx), hn::LowerHalf(d16h, sy)));
		store(x + N / 2, widen(hn::UpperHalf(d16h, sx), hn::UpperHalf(d16h, sy)));
#endif
		if (x == w - 1 - N)
			break;
	}
	pairs[0] = pairs[w - 1] = 0;
	mag[0] = mag[w - 1] = 0;
}

bool EdgeRow(const GradRows &rows, int w, const FrontEndParams &params, std::uint8_t *out)
{
	const hn::ScalableTag<std::int16_t> d16;
	const hn::Repartition<std::int32_t, decltype(d16)> d32;
	const hn::Repartition<std::uint32_t, decltype(d16)> du32;
	const hn::Rebind<std::uint8_t, decltype(d32)> d8;
	const int N = static_cast<int>(hn::Lanes(d32));
	if (!UsePairs(d16, w))
		return edgeRow(rows, w, params, out);
	const std::int32_t *up = rows.mag[0];
	const std::int32_t *mid = rows.mag[1];
	const std::int32_t *down = rows.mag[2];
	const std::int16_t *pr[3] = { rows.gx[0], rows.gx[1], rows.gx[2] };
	auto pairs = [&](int r, int x) { return hn::LoadU(d16, pr[r] + 2 * x); };
	/* The thresholds of each pixel follow its smoothed brightness
	 * (FrontEndParams::relativeThreshold); none is below a black pixel's. */
	const std::uint8_t *bright = rows.smooth;
	const auto least = hn::Set(d32, leastEdgeThreshold(params));
	const auto edgeT = hn::Set(d32, edgeThreshold(params));
	const auto cornerT = hn::Set(d32, cornerThreshold(params));
	const auto floor = hn::Set(d32, params.light_floor);
	const auto reference = hn::Set(d32, FrontEndParams::kLightReference);
	auto relative = [&](const auto &t, const auto &q) FRAPPE_INLINE_LAMBDA {
		return hn::ShiftRight<7>(hn::Mul(hn::ShiftRight<7>(hn::Mul(t, q)), q));
	};
	/* As pairs: 106|gx| - 256|gy| >= 0 is horizontal, 106|gy| - 256|gx|
	 * >= 0 vertical (the scalar rule's 256|gy| <= 106|gx| and so on). */
	auto pair = [&](std::int16_t lo, std::int16_t hi) {
		return hn::BitCast(d16, hn::Set(du32, static_cast<std::uint16_t>(lo) |
							      static_cast<std::uint32_t>(static_cast<std::uint16_t>(hi)) << 16));
	};
	const auto kHorizontal = pair(106, -256);
	const auto kVertical = pair(-256, 106);
	const auto lowHalf = hn::BitCast(d16, hn::Set(d32, 0xFFFF));
	const auto zero = hn::Zero(d32);
	const auto gyPositive = hn::Set(d32, 0xFFFF); /* P > 0xFFFF exactly when gy > 0 */

	bool any = false;
	out[0] = 0;
	out[w - 1] = 0;
	/* Per column x, over rows y-1..y+1: the sums of gx^2 (xx) and of
	 * 2 gx gy (xy2). Pairs of variables, not a struct: SVE's sizeless
	 * vectors cannot be members. */
	using V32 = hn::Vec<decltype(d32)>;
#if HWY_ARCH_X86 && HWY_TARGET == HWY_AVX2
	const __m256i swapHalves = _mm256_setr_epi8(2, 3, 0, 1, 6, 7, 4, 5, 10, 11, 8, 9, 14, 15, 12, 13, 2, 3, 0, 1, 6,
						    7, 4, 5, 10, 11, 8, 9, 14, 15, 12, 13);
#endif
	auto columnSums = [&](int x, V32 &xx, V32 &xy2) FRAPPE_INLINE_LAMBDA {
		xx = zero;
		xy2 = zero;
		for (int r = 0; r < 3; ++r) {
			const auto t = pairs(r, x);
#if HWY_ARCH_X86 && HWY_TARGET == HWY_AVX2
			/* (gy, gx): one byte shuffle; AVX2's 32-bit rotate is three. */
			const auto swapped = hn::Vec<decltype(d16)>{ _mm256_shuffle_epi8(t.raw, swapHalves) };
#else
			const auto swapped = hn::BitCast(d16, hn::RotateRight<16>(hn::BitCast(du32, t)));
#endif
			xx = hn::Add(xx, PairDot(d32, t, hn::And(t, lowHalf)));
			xy2 = hn::Add(xy2, PairDot(d32, t, swapped));
		}
	};
	V32 cachedXx = zero, cachedXy2 = zero, cachedPrevXx = zero, cachedPrevXy2 = zero;
	int cachedAt = -1; /* cached* hold the column sums from here on */

	/* Classifies the N pixels from x. */
	auto edgeVector = [&](int x) FRAPPE_INLINE_LAMBDA {
		const auto m = hn::LoadU(d32, mid + x);
		auto bytes = hn::Zero(d8);
		/* Each pixel's own threshold only where some magnitude passes a
		 * black pixel's; the suppression and corner test only where one
		 * passes its own. */
		const bool some = !hn::AllFalse(d32, hn::Lt(least, m));
		const auto q = hn::Min(hn::Add(hn::PromoteTo(d32, hn::LoadU(d8, bright + x)), floor), reference);
		const auto strong = hn::Lt(relative(edgeT, q), m);
		if (some && !hn::AllFalse(d32, strong)) {
			const auto twoT = hn::ShiftLeft<1>(relative(cornerT, q));
			const auto p = pairs(1, x);
			const auto absP = hn::Abs(p);
			const auto horizontal = PairDot(d32, absP, kHorizontal);
			const auto vertical = PairDot(d32, absP, kVertical);
			const auto p32 = hn::BitCast(d32, p);
			const auto diagFlip = hn::Xor(hn::Lt(zero, hn::ShiftLeft<16>(p32)), hn::Lt(gyPositive, p32));
			const auto ul = hn::LoadU(d32, up + x - 1), um = hn::LoadU(d32, up + x),
				   ur = hn::LoadU(d32, up + x + 1);
			const auto dl = hn::LoadU(d32, down + x - 1), dm = hn::LoadU(d32, down + x),
				   dr = hn::LoadU(d32, down + x + 1);
			const auto ml = hn::LoadU(d32, mid + x - 1), mr = hn::LoadU(d32, mid + x + 1);
			/* Same precedence as the scalar if/else chain: horizontal first. */
			auto prev = hn::IfThenElse(diagFlip, ur, ul);
			auto next = hn::IfThenElse(diagFlip, dl, dr);
			/* Not IfNegativeThenElse: Highway 1.0's SSSE3 one is wrong. */
			const auto notVertical = hn::Lt(vertical, zero), notHorizontal = hn::Lt(horizontal, zero);
			prev = hn::IfThenElse(notVertical, prev, um);
			next = hn::IfThenElse(notVertical, next, dm);
			prev = hn::IfThenElse(notHorizontal, prev, ml);
			next = hn::IfThenElse(notHorizontal, next, mr);
			const auto edge = hn::And(hn::And(strong, hn::Lt(prev, m)), hn::Not(hn::Lt(m, next)));
			/* A strong vector with no edge left after the suppression
			 * (about a quarter on synth/images) skips the corner
			 * test: some 60 instructions of its ~130. */
			if (hn::AllFalse(d32, edge)) {
				hn::StoreU(bytes, d8, out + x);
				return;
			}
			any = true;
			/* Shi-Tomasi in isCorner's int32 form, summed here from the
			 * pairs. Sxx + Syy is the sum of the nine magnitudes. */
			const auto s = hn::Add(hn::Add(hn::Add(hn::Add(ul, um), hn::Add(ur, dl)),
						       hn::Add(hn::Add(dm, dr), hn::Add(ml, mr))), m);
			/* The 3x3 sums as column sums over the three rows,
			 * then across; the next vector's column sums are kept,
			 * as edges run along rows. */
			V32 leftXx = zero, leftXy2 = zero, curXx = zero, curXy2 = zero, rightXx = zero, rightXy2 = zero;
			if (x == cachedAt) {
				curXx = cachedXx;
				curXy2 = cachedXy2;
				leftXx = PrevColumn(d32, cachedPrevXx, curXx);
				leftXy2 = PrevColumn(d32, cachedPrevXy2, curXy2);
			} else {
				columnSums(x, curXx, curXy2);
				columnSums(x - 1, leftXx, leftXy2);
			}
			if (x + 2 * N <= w) {
				V32 nextXx = zero, nextXy2 = zero;
				columnSums(x + N, nextXx, nextXy2);
				rightXx = NextColumn(d32, curXx, nextXx);
				rightXy2 = NextColumn(d32, curXy2, nextXy2);
				cachedPrevXx = curXx;
				cachedPrevXy2 = curXy2;
				cachedXx = nextXx;
				cachedXy2 = nextXy2;
				cachedAt = x + N;
			} else {
				columnSums(x + 1, rightXx, rightXy2);
			}
			const auto sxx = hn::Add(hn::Add(leftXx, curXx), rightXx);
			const auto sxy2 = hn::Add(hn::Add(leftXy2, curXy2), rightXy2);
			/* Sxx - Syy = 2 Sxx - S; |Sxy| >> 8 = |2 Sxy| >> 9. */
			const auto c = hn::ShiftRight<9>(hn::Sub(s, twoT));
			const auto ad = hn::ShiftRight<9>(hn::Abs(hn::Sub(hn::Add(sxx, sxx), s)));
			const auto bd = hn::ShiftRight<9>(hn::Abs(sxy2));
			const auto corner = hn::And(hn::Lt(zero, c),
						    hn::Lt(hn::Add(hn::Mul(ad, ad), hn::Mul(bd, bd)), hn::Mul(c, c)));
			bytes = EdgeBytes(d32, d8, edge, corner);
		}
		hn::StoreU(bytes, d8, out + x);
	};
	/* Most of a frame is flat: skip four vectors at a time when none of
	 * their magnitudes passes the threshold. */
	const hn::ScalableTag<std::uint8_t> du8;
	int x = 1;
	for (; x + 4 * N <= w - 1; x += 4 * N) {
		const auto m01 = hn::Max(hn::LoadU(d32, mid + x), hn::LoadU(d32, mid + x + N));
		const auto m23 = hn::Max(hn::LoadU(d32, mid + x + 2 * N), hn::LoadU(d32, mid + x + 3 * N));
		if (hn::AllFalse(d32, hn::Lt(least, hn::Max(m01, m23)))) {
			hn::StoreU(hn::Zero(du8), du8, out + x);
			continue;
		}
		for (int i = 0; i < 4; ++i)
			edgeVector(x + i * N);
	}
	/* The last vector overlaps the previous one instead of a scalar tail. */
	for (; x < w - 1; x += N)
		edgeVector(std::min(x, w - 1 - N));
	return any;
}

#else // HWY_SCALAR: one-lane vectors hold no pairs; the scalar kernels.

void GradientRow(const std::uint8_t *a, const std::uint8_t *b, const std::uint8_t *c, int w,
		 std::int16_t *gx, std::int16_t *gy, std::int32_t *mag, std::int16_t *tmp)
{
	gradientRow(a, b, c, w, gx, gy, mag, tmp);
}

bool EdgeRow(const GradRows &rows, int w, const FrontEndParams &params, std::uint8_t *out)
{
	return edgeRow(rows, w, params, out);
}

#endif

/* This target's kernels, called directly from its own band loop. */
struct TargetKernels {
	static constexpr auto smooth = &SmoothRow;
	static constexpr auto gradient = &GradientRow;
	static constexpr auto edge = &EdgeRow;
	static constexpr auto orRow = &OrRow;
};

void RunBand(const BandJob &job)
{
	runBandRows(TargetKernels{}, job);
}

} // namespace

const char *TargetName()
{
	return hwy::TargetName(HWY_TARGET);
}

} // namespace HWY_NAMESPACE
} // namespace frappe::detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace frappe::detail {

HWY_EXPORT(RunBand);
HWY_EXPORT(TargetName);

/* The same dispatch as the band loop's, so it names the code that runs. */
const char *simdTargetName()
{
	return HWY_DYNAMIC_DISPATCH(TargetName)();
}

namespace {

/* Resolved per band, so a target chosen for a test is honoured. */
void bandDispatch(const BandJob &job)
{
	HWY_DYNAMIC_DISPATCH(RunBand)(job);
}

} // namespace

const BandKernels &bestBandKernels()
{
	/* Each target's band loop calls its own row kernels. */
	static constexpr BandKernels kSimd{ "highway", bandDispatch };
	return kSimd;
}

} // namespace frappe::detail
#endif // HWY_ONCE
