// SPDX-License-Identifier: MIT
// The region map's row kernels for ARMv6 with the SIMD32 instructions and
// no NEON (the Pi Zero's ARM1176), beside the scalar references in
// region_map.cpp that tests/armv6 checks them against byte for byte.
//
// Four bytes a word: the 2 x 2 means in two 16-bit lanes (UXTAB16 adds two
// bytes to two lanes at once; the sums stay below 1024, so no lane carries),
// byte minima and maxima by USUB8, which sets a GE flag per byte, and SEL,
// which picks each byte by its flag.
#include "region_map.h"

#ifdef FRAPPE_HAVE_ARMV6_REGION

#include <arm_acle.h>

#include <algorithm>
#include <cstdint>
#include <cstring>

namespace frappe::detail {

/* Functions whose inline asm names r4-r7 (LDM lists must ascend) keep no
 * frame pointer, which is r7 in Thumb code and r11 in ARM code, also at
 * -O0 (the attribute on each). */

namespace {

using u32 = std::uint32_t;

inline u32 load32(const void *p)
{
	u32 v;
	std::memcpy(&v, p, 4); /* LDR: ARMv6 allows unaligned word accesses */
	return v;
}

inline void store32(void *p, u32 v)
{
	std::memcpy(p, &v, 4);
}

/* acc + the odd bytes of v (1 and 3) in two 16-bit lanes. */
inline u32 uxtab16ror8(u32 acc, u32 v)
{
	u32 r;
	__asm__("uxtab16 %0, %1, %2, ror #8" : "=r"(r) : "r"(acc), "r"(v));
	return r;
}

/* (lo.lo, hi.lo) and (lo.hi, hi.hi) of two words of 16-bit lanes. */
inline u32 pkhbt16(u32 lo, u32 hi)
{
	u32 r;
	__asm__("pkhbt %0, %1, %2, lsl #16" : "=r"(r) : "r"(lo), "r"(hi));
	return r;
}

inline u32 pkhtb16(u32 hi, u32 lo)
{
	u32 r;
	__asm__("pkhtb %0, %1, %2, asr #16" : "=r"(r) : "r"(hi), "r"(lo));
	return r;
}

/* Byte-wise least and greatest of a and b: one USUB8 for both SELs (the
 * GE flags live only inside the asm). */
inline void minMax8(u32 a, u32 b, u32 &mn, u32 &mx)
{
	u32 t;
	__asm__("usub8 %[t], %[a], %[b]\n\t"
		"sel %[mx], %[a], %[b]\n\t"
		"sel %[mn], %[b], %[a]"
		: [t] "=&r"(t), [mn] "=&r"(mn), [mx] "=&r"(mx)
		: [a] "r"(a), [b] "r"(b)
		: "cc");
}

inline u32 min8(u32 a, u32 b)
{
	u32 t, r;
	__asm__("usub8 %[t], %[a], %[b]\n\tsel %[r], %[b], %[a]" : [t] "=&r"(t), [r] "=&r"(r) : [a] "r"(a), [b] "r"(b) : "cc");
	return r;
}

inline u32 max8(u32 a, u32 b)
{
	u32 t, r;
	__asm__("usub8 %[t], %[a], %[b]\n\tsel %[r], %[a], %[b]" : [t] "=&r"(t), [r] "=&r"(r) : [a] "r"(a), [b] "r"(b) : "cc");
	return r;
}

/* kEdge in each byte where d < m, else 0. */
inline u32 darkWord(u32 d, u32 m, u32 ones)
{
	u32 t, r;
	__asm__("usub8 %[t], %[d], %[m]\n\tsel %[r], %[z], %[o]"
		: [t] "=&r"(t), [r] "=&r"(r)
		: [d] "r"(d), [m] "r"(m), [z] "r"(0u), [o] "r"(ones)
		: "cc");
	return r;
}

} // namespace

__attribute__((optimize("omit-frame-pointer"))) void decimateRowV6(const std::uint8_t *r0, const std::uint8_t *r1, int w, std::uint8_t *out)
{
	/* The +2 of the rounding rides in the first UXTAB16's accumulator. */
	const u32 kTwo = 0x00020002u, kMask = 0x00FF00FFu;
	int x = 0;
	if (w >= 4 && ((reinterpret_cast<std::uintptr_t>(r0) | reinterpret_cast<std::uintptr_t>(r1) |
			reinterpret_cast<std::uintptr_t>(out)) & 3) == 0) {
		/* Word-aligned rows (frames whose stride is a multiple of four):
		 * each row's two words by one LDM, 18 instructions per four
		 * outputs (the loop below: 21). The same arithmetic. */
		const std::uint8_t *p0 = r0, *p1 = r1;
		std::uint8_t *po = out;
		const std::uint8_t *const end = r0 + 2 * (w & ~3);
		register u32 a0 __asm__("r4"), a1 __asm__("r5"), b0 __asm__("r6"), b1 __asm__("r7");
		u32 t, u;
		__asm__ volatile("1:\n\t"
				 "ldmia   %[p0]!, {%[a0], %[a1]}\n\t"
				 "ldmia   %[p1]!, {%[b0], %[b1]}\n\t"
				 "uxtab16 %[t], %[k], %[a0]\n\t"
				 "uxtab16 %[t], %[t], %[a0], ror #8\n\t"
				 "uxtab16 %[t], %[t], %[b0]\n\t"
				 "uxtab16 %[t], %[t], %[b0], ror #8\n\t"
				 "uxtab16 %[u], %[k], %[a1]\n\t"
				 "uxtab16 %[u], %[u], %[a1], ror #8\n\t"
				 "uxtab16 %[u], %[u], %[b1]\n\t"
				 "uxtab16 %[u], %[u], %[b1], ror #8\n\t"
				 "pkhbt   %[a0], %[t], %[u], lsl #16\n\t"
				 "pkhtb   %[a1], %[u], %[t], asr #16\n\t"
				 "and     %[a0], %[m], %[a0], lsr #2\n\t"
				 "and     %[a1], %[m], %[a1], lsr #2\n\t"
				 "orr     %[a0], %[a0], %[a1], lsl #8\n\t"
				 "str     %[a0], [%[po]], #4\n\t"
				 "cmp     %[p0], %[end]\n\t"
				 "bne     1b"
				 : [p0] "+r"(p0), [p1] "+r"(p1), [po] "+r"(po), [a0] "=&r"(a0), [a1] "=&r"(a1),
				   [b0] "=&r"(b0), [b1] "=&r"(b1), [t] "=&r"(t), [u] "=&r"(u)
				 : [end] "r"(end), [k] "r"(kTwo), [m] "r"(kMask)
				 : "cc", "memory");
		x = w & ~3;
	}
	for (; x + 4 <= w; x += 4) {
		const u32 a0 = load32(r0 + 2 * x), a1 = load32(r0 + 2 * x + 4);
		const u32 b0 = load32(r1 + 2 * x), b1 = load32(r1 + 2 * x + 4);
		/* (o0, o1) * 4 + 2 and (o2, o3) * 4 + 2, one output a lane */
		const u32 s0 = uxtab16ror8(__uxtab16(uxtab16ror8(__uxtab16(kTwo, a0), a0), b0), b0);
		const u32 s1 = uxtab16ror8(__uxtab16(uxtab16ror8(__uxtab16(kTwo, a1), a1), b1), b1);
		/* (o0, o2) and (o1, o3), shifted and interleaved into bytes */
		const u32 even = pkhbt16(s0, s1), odd = pkhtb16(s1, s0);
		store32(out + x, (kMask & (even >> 2)) | (kMask & (odd >> 2)) << 8);
	}
	if (x < w)
		decimateRowScalar(r0 + 2 * x, r1 + 2 * x, w - x, out + x);
}

void tileExtremesV6(const std::uint8_t *rows, std::ptrdiff_t stride, int n, int w, std::uint8_t *tmin,
		    std::uint8_t *tmax)
{
	/* Rows past the n-th repeat the last: the extremes do not change. */
	const std::uint8_t *r0 = rows, *r1 = rows + static_cast<std::ptrdiff_t>(std::min(1, n - 1)) * stride;
	const std::uint8_t *r2 = rows + static_cast<std::ptrdiff_t>(std::min(2, n - 1)) * stride;
	const std::uint8_t *r3 = rows + static_cast<std::ptrdiff_t>(std::min(3, n - 1)) * stride;
	const int full = w / kRegionTile;
	static_assert(kRegionTile == 4, "a tile's row is one word");
	int i = 0;
	if (full >= 2) {
		/* Two tiles a step: down each, then across both at once, their
		 * halves paired by PKHBT / PKHTB: (A0 A1 B0 B1) against (A2 A3
		 * B2 B3), then each byte against the next. Pointers, so that
		 * GCC keeps everything in registers. */
		const std::uint8_t *p0 = r0, *p1 = r1, *p2 = r2, *p3 = r3;
		std::uint8_t *pmin = tmin, *pmax = tmax;
		const std::uint8_t *const end = r0 + 4 * (full & ~1);
		for (; p0 != end; p0 += 8, p1 += 8, p2 += 8, p3 += 8, pmin += 2, pmax += 2) {
			u32 mnA, mxA, mnB, mxB, mn23, mx23;
			minMax8(load32(p0), load32(p1), mnA, mxA);
			minMax8(load32(p2), load32(p3), mn23, mx23);
			mnA = min8(mnA, mn23);
			mxA = max8(mxA, mx23);
			minMax8(load32(p0 + 4), load32(p1 + 4), mnB, mxB);
			minMax8(load32(p2 + 4), load32(p3 + 4), mn23, mx23);
			mnB = min8(mnB, mn23);
			mxB = max8(mxB, mx23);
			u32 mn = min8(pkhbt16(mnA, mnB), pkhtb16(mnB, mnA));
			u32 mx = max8(pkhbt16(mxA, mxB), pkhtb16(mxB, mxA));
			mn = min8(mn, mn >> 8);
			mx = max8(mx, mx >> 8);
			pmin[0] = static_cast<std::uint8_t>(mn);
			pmin[1] = static_cast<std::uint8_t>(mn >> 16);
			pmax[0] = static_cast<std::uint8_t>(mx);
			pmax[1] = static_cast<std::uint8_t>(mx >> 16);
		}
		i = full & ~1;
	}
	for (; i < full; ++i) {
		const int x = 4 * i;
		u32 mn01, mx01, mn23, mx23;
		minMax8(load32(r0 + x), load32(r1 + x), mn01, mx01);
		minMax8(load32(r2 + x), load32(r3 + x), mn23, mx23);
		/* down the tile, then across: halves, then bytes */
		u32 mn = min8(mn01, mn23), mx = max8(mx01, mx23);
		mn = min8(mn, mn >> 16);
		mx = max8(mx, mx >> 16);
		tmin[i] = static_cast<std::uint8_t>(min8(mn, mn >> 8));
		tmax[i] = static_cast<std::uint8_t>(max8(mx, mx >> 8));
	}
	if (full * kRegionTile < w)
		tileExtremesScalar(rows + full * kRegionTile, stride, n, w - full * kRegionTile, tmin + full, tmax + full);
}

void spreadTilesV6(std::uint8_t *tileMin, std::uint8_t *tileMax, int tx, int ty, std::uint8_t *work)
{
	/* Four tiles a word: across, from three unaligned loads of the padded
	 * copy (the tiles left of, at and right of each); down, from the row
	 * above as it was, the row and the row below. */
	auto across = [](const std::uint8_t *a, const std::uint8_t *b, std::uint8_t *tmin, std::uint8_t *tmax,
			 int n) {
		int i = 0;
		for (; i + 4 <= n; i += 4) {
			store32(tmin + i, min8(min8(load32(a + i), load32(a + i + 1)), load32(a + i + 2)));
			store32(tmax + i, max8(max8(load32(b + i), load32(b + i + 1)), load32(b + i + 2)));
		}
		return i;
	};
	auto down = [](std::uint8_t *upMin, std::uint8_t *upMax, const std::uint8_t *dnMin, const std::uint8_t *dnMax,
		       std::uint8_t *tmin, std::uint8_t *tmax, int n) {
		int i = 0;
		for (; i + 4 <= n; i += 4) {
			const u32 m = load32(tmin + i), x = load32(tmax + i);
			store32(tmin + i, min8(min8(load32(upMin + i), m), load32(dnMin + i)));
			store32(tmax + i, max8(max8(load32(upMax + i), x), load32(dnMax + i)));
			store32(upMin + i, m);
			store32(upMax + i, x);
		}
		return i;
	};
	spreadTilesWith(tileMin, tileMax, tx, ty, work, across, down);
}

__attribute__((optimize("omit-frame-pointer"))) void darkRowV6(const std::uint8_t *d, const std::uint8_t *mid, int w, std::uint8_t *out, std::uint8_t *tiles)
{
	constexpr int ET = TraceMap::kTile;
	static_assert(ET == 16 && TraceMap::kEdge == 1);
	const u32 ones = 0x01010101u;
	/* Pointers, not indices: GCC keeps them in registers. */
	const std::uint8_t *pd = d, *pm = mid;
	std::uint8_t *po = out, *pt = tiles;
	const std::uint8_t *const end = d + (w & ~(ET - 1));
	if (pd != end && ((reinterpret_cast<std::uintptr_t>(d) | reinterpret_cast<std::uintptr_t>(mid) |
			   reinterpret_cast<std::uintptr_t>(out)) & 3) == 0) {
		/* Word-aligned rows: two words a step by LDM / STM, and the dark
		 * bit as the sign of UHSUB8 (d - mid halved keeps the borrow in
		 * bit 7), moved to bit 0: 21 instructions a tile of 16 (the
		 * loop below: 37). */
		register u32 d0 __asm__("r4"), d1 __asm__("r5"), m0 __asm__("r6"), m1 __asm__("r7");
		u32 acc;
		__asm__ volatile(".syntax unified\n\t"
				 "1:\n\t"
				 "ldmia   %[pd]!, {%[d0], %[d1]}\n\t"
				 "ldmia   %[pm]!, {%[m0], %[m1]}\n\t"
				 "uhsub8  %[m0], %[d0], %[m0]\n\t"
				 "uhsub8  %[m1], %[d1], %[m1]\n\t"
				 "and     %[m0], %[ones], %[m0], lsr #7\n\t"
				 "and     %[m1], %[ones], %[m1], lsr #7\n\t"
				 "stmia   %[po]!, {%[m0], %[m1]}\n\t"
				 "orr     %[acc], %[m0], %[m1]\n\t"
				 "ldmia   %[pd]!, {%[d0], %[d1]}\n\t"
				 "ldmia   %[pm]!, {%[m0], %[m1]}\n\t"
				 "uhsub8  %[m0], %[d0], %[m0]\n\t"
				 "uhsub8  %[m1], %[d1], %[m1]\n\t"
				 "and     %[m0], %[ones], %[m0], lsr #7\n\t"
				 "and     %[m1], %[ones], %[m1], lsr #7\n\t"
				 "stmia   %[po]!, {%[m0], %[m1]}\n\t"
				 "orr     %[acc], %[acc], %[m0]\n\t"
				 "orrs    %[acc], %[acc], %[m1]\n\t"
				 "it      ne\n\t"
				 "strbne  %[ones], [%[pt]]\n\t" /* its low byte is kEdge */
				 "add     %[pt], %[pt], #1\n\t"
				 "cmp     %[pd], %[end]\n\t"
				 "bne     1b"
				 : [pd] "+r"(pd), [pm] "+r"(pm), [po] "+r"(po), [pt] "+r"(pt), [d0] "=&r"(d0),
				   [d1] "=&r"(d1), [m0] "=&r"(m0), [m1] "=&r"(m1), [acc] "=&r"(acc)
				 : [end] "r"(end), [ones] "r"(ones)
				 : "cc", "memory");
	}
	for (; pd != end; pd += ET, pm += ET, po += ET, ++pt) {
		const u32 o0 = darkWord(load32(pd), load32(pm), ones);
		const u32 o1 = darkWord(load32(pd + 4), load32(pm + 4), ones);
		const u32 o2 = darkWord(load32(pd + 8), load32(pm + 8), ones);
		const u32 o3 = darkWord(load32(pd + 12), load32(pm + 12), ones);
		store32(po, o0);
		store32(po + 4, o1);
		store32(po + 8, o2);
		store32(po + 12, o3);
		const u32 t = o0 | o1 | o2 | o3;
		if (t != 0)
			*pt = TraceMap::kEdge;
	}
	const int x = static_cast<int>(pd - d);
	if (x < w)
		darkRowTilesScalar(pd, pm, w - x, po, pt);
}

} // namespace frappe::detail

#endif
