// SPDX-License-Identifier: MIT
// The CPU front end's row kernels for ARMv6 with the SIMD32 ("media")
// instructions and no NEON: the Raspberry Pi Zero's ARM1176. They compute
// exactly what the scalar kernels in front_end_rows.cpp compute (the
// arithmetic is defined at the top of front_end_cpu.cpp); the EdgeMap is the
// same byte for byte (tests/armv6 checks it under qemu-arm -cpu arm1176).
//
// Two 16-bit lanes per 32-bit register: four pixels of a row are split into
// the even pixels (bytes 0 and 2 of the little-endian word, UXTB16) and the
// odd ones (bytes 1 and 3, UXTB16 with ROR #8). A pixel's left and right
// neighbours are then the other parity's lanes, and the neighbour across a
// word boundary is one shift and one ORR away.
//
// One difference in the rows between the kernels (they are a set, never
// mixed with others): the gradient row stores (gx, gy) as one int16 pair per
// pixel in the `gx` buffer (2w int16 values, see RowScratch), so that
// gx^2 + gy^2 is one SMUAD and the corner test's sums are SMLAD / SMLSD /
// SMLATB on the same words; the `gy` buffer is not used.
#include "front_end_rows.h"

#if defined(__ARM_FEATURE_SIMD32) && defined(__ARM_FEATURE_DSP) && defined(__ARMEL__)

#include <arm_acle.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>

namespace frappe::detail {

namespace {

using u32 = std::uint32_t;

inline u32 load32(const void *p)
{
	u32 v;
	std::memcpy(&v, p, 4); /* LDR: ARMv6 allows unaligned word loads */
	return v;
}

inline void store32(void *p, u32 v)
{
	std::memcpy(p, &v, 4);
}

/* Bytes 0 and 2 into two 16-bit lanes; bytes 1 and 3. */
inline u32 evenBytes(u32 v)
{
	return __uxtb16(v);
}

inline u32 oddBytes(u32 v)
{
	u32 r;
	__asm__("uxtb16 %0, %1, ror #8" : "=r"(r) : "r"(v));
	return r;
}

/* UXTAB16 with ROR #8: the odd bytes of v added to the lanes of acc. */
inline u32 uxtab16ror8(u32 acc, u32 v)
{
	u32 r;
	__asm__("uxtab16 %0, %1, %2, ror #8" : "=r"(r) : "r"(acc), "r"(v));
	return r;
}

/* (lo.lo, hi.lo): low lane of `lo`, low lane of `hi` in the high lane. */
inline u32 pkhbt16(u32 lo, u32 hi)
{
	u32 r;
	__asm__("pkhbt %0, %1, %2, lsl #16" : "=r"(r) : "r"(lo), "r"(hi));
	return r;
}

/* (lo.hi, hi.hi): high lane of `lo` in the low lane, high lane of `hi`. */
inline u32 pkhtb16(u32 hi, u32 lo)
{
	u32 r;
	__asm__("pkhtb %0, %1, %2, asr #16" : "=r"(r) : "r"(hi), "r"(lo));
	return r;
}

inline u32 sadd16(u32 a, u32 b)
{
	return static_cast<u32>(__sadd16(static_cast<int16x2_t>(a), static_cast<int16x2_t>(b)));
}

inline u32 ssub16(u32 a, u32 b)
{
	return static_cast<u32>(__ssub16(static_cast<int16x2_t>(a), static_cast<int16x2_t>(b)));
}

inline std::int32_t smuad(u32 a)
{
	return __smuad(static_cast<int16x2_t>(a), static_cast<int16x2_t>(a));
}

/* The smoothed rows of these kernels are stored lane-split, as the SIMD32
 * code makes them: per four pixels 4k .. 4k+3 two words, (p0, p2) and
 * (p1, p3), each value in a 16-bit lane (2w + 8 bytes a row, see
 * RowScratch). The gradient pass loads them without unpacking. */
inline void putSmoothed(std::uint8_t *row, int x, std::uint8_t v)
{
	const std::uint16_t v16 = v;
	std::memcpy(row + armv6SmoothedOffset(x), &v16, 2);
}

inline int getSmoothed(const std::uint8_t *row, int x)
{
	std::uint16_t v16;
	std::memcpy(&v16, row + armv6SmoothedOffset(x), 2);
	return v16;
}

/* The (gx, gy) pair of pixel x of the middle of smoothed rows a, b, c, for
 * the first and last few pixels (x in 1 .. w-2). */
inline u32 gradientPair(const std::uint8_t *a, const std::uint8_t *b, const std::uint8_t *c, int x,
			std::int32_t &mag)
{
	auto vs = [&](int i) { return getSmoothed(a, i) + 2 * getSmoothed(b, i) + getSmoothed(c, i); };
	auto vd = [&](int i) { return getSmoothed(c, i) - getSmoothed(a, i); };
	const std::int32_t sx = vs(x + 1) - vs(x - 1);
	const std::int32_t sy = vd(x - 1) + 2 * vd(x) + vd(x + 1);
	mag = sx * sx + sy * sy;
	return static_cast<std::uint16_t>(sx) | static_cast<u32>(static_cast<std::uint16_t>(sy)) << 16;
}

void smoothRowV6(const std::uint8_t *a, const std::uint8_t *b, const std::uint8_t *c, int w,
		 std::uint8_t *out, std::uint16_t *tmp)
{
	if (w < 16) {
		std::uint8_t bytes[16];
		smoothRow(a, b, c, w, bytes, tmp);
		for (int x = 0; x < w; ++x)
			putSmoothed(out, x, bytes[x]);
		return;
	}
	auto t = [&](int x) {
		x = std::clamp(x, 0, w - 1);
		return a[x] + 2 * b[x] + c[x];
	};
	/* Vertical sums of four pixels plus 2 (the rounding: the horizontal
	 * weights add up to 4): E = (t0, t2) + 2, O = (t1, t3) + 2, each below
	 * 1024, so plain 32-bit adds cannot carry from one lane into the other.
	 * UXTAB16 extends two bytes and adds them to two lanes in one go. */
	const u32 kMask = 0x00FF00FF, kOne = 0x00010001;
	auto even = [&](u32 wa, u32 wb, u32 wc) {
		return __uxtab16(__uxtb16(wa), wc) + (__uxtab16(kOne, wb) << 1);
	};
	auto odd = [&](u32 wa, u32 wb, u32 wc) {
		return uxtab16ror8(oddBytes(wa), wc) + (uxtab16ror8(kOne, wb) << 1);
	};
	u32 E = even(load32(a), load32(b), load32(c));
	u32 O = odd(load32(a), load32(b), load32(c));
	u32 prevHi = static_cast<u32>(t(0)) + 2; /* t[-1] = t[0] */
	/* Word k needs word k+1's first pixel: whole words up to w-1. */
	const int words = (w - 4) / 4;
	int k = 0;
	if (words >= 2) {
		/* Two words a step, written out (GCC spills and reloads its
		 * constants): 24 instructions per four pixels. The results are
		 * bits 4..11 of the lanes of sE (even pixels) and sO (odd ones),
		 * stored as they are (see putSmoothed). */
		const std::uint8_t *pa = a, *pb = b, *pc = c;
		std::uint8_t *po = out;
		const std::uint8_t *const oEnd = out + 16 * (words / 2);
		u32 En, On, t0, t1;
		__asm__ volatile(
			"1:\n\t"
#define FRAPPE_SMOOTH_WORD(E, O, EN, ON)                                                          \
			"ldr     %[t0], [%[pa], #4]!\n\t"                                         \
			"ldr     %[t1], [%[pc], #4]!\n\t"                                         \
			"uxtb16  %[" EN "], %[t0]\n\t"                                            \
			"uxtab16 %[" EN "], %[" EN "], %[t1]\n\t"                                 \
			"uxtb16  %[" ON "], %[t0], ror #8\n\t"                                    \
			"uxtab16 %[" ON "], %[" ON "], %[t1], ror #8\n\t"                         \
			"ldr     %[t0], [%[pb], #4]!\n\t"                                         \
			"uxtab16 %[t1], %[one], %[t0]\n\t"                                        \
			"add     %[" EN "], %[" EN "], %[t1], lsl #1\n\t"                         \
			"uxtab16 %[t1], %[one], %[t0], ror #8\n\t"                                \
			"add     %[" ON "], %[" ON "], %[t1], lsl #1\n\t"                         \
			"orr     %[t0], %[P], %[" O "], lsl #16\n\t"                              \
			"add     %[t0], %[t0], %[" O "]\n\t"                                      \
			"add     %[t0], %[t0], %[" E "], lsl #1\n\t"    /* sE */                  \
			"mov     %[t1], %[" E "], lsr #16\n\t"                                    \
			"orr     %[t1], %[t1], %[" EN "], lsl #16\n\t"                            \
			"add     %[t1], %[t1], %[" E "]\n\t"                                      \
			"add     %[t1], %[t1], %[" O "], lsl #1\n\t"    /* sO */                  \
			"and     %[t0], %[mask], %[t0], lsr #4\n\t"                              \
			"and     %[t1], %[mask], %[t1], lsr #4\n\t"                              \
			"str     %[t0], [%[po]], #8\n\t"                                          \
			"str     %[t1], [%[po], #-4]\n\t"                                         \
			"mov     %[P], %[" O "], lsr #16\n\t"
			FRAPPE_SMOOTH_WORD("E", "O", "En", "On")
			FRAPPE_SMOOTH_WORD("En", "On", "E", "O")
#undef FRAPPE_SMOOTH_WORD
			"cmp     %[po], %[end]\n\t"
			"bne     1b"
			: [pa] "+r"(pa), [pb] "+r"(pb), [pc] "+r"(pc), [po] "+r"(po), [E] "+r"(E), [O] "+r"(O),
			  [P] "+r"(prevHi), [En] "=&r"(En), [On] "=&r"(On), [t0] "=&r"(t0), [t1] "=&r"(t1)
			: [one] "r"(kOne), [mask] "r"(kMask), [end] "r"(oEnd)
			: "cc", "memory");
		k = 2 * (words / 2);
	}
	for (; k < words; ++k) {
		const int xn = 4 * k + 4;
		const u32 wa = load32(a + xn), wb = load32(b + xn), wc = load32(c + xn);
		const u32 En = even(wa, wb, wc), On = odd(wa, wb, wc);
		/* Even pixels: left (t[-1], t1), right (t1, t3) = O. Odd pixels:
		 * left E, right (t2, t4). The sums stay below 4096. */
		const u32 sE = (prevHi | (O << 16)) + O + (E << 1);
		const u32 sO = ((E >> 16) | (En << 16)) + E + (O << 1);
		store32(out + 8 * k, (sE >> 4) & kMask);
		store32(out + 8 * k + 4, (sO >> 4) & kMask);
		prevHi = O >> 16;
		E = En;
		O = On;
	}
	for (int x = 4 * words; x < w; ++x)
		putSmoothed(out, x, static_cast<std::uint8_t>((t(x - 1) + 2 * t(x) + t(x + 1) + 8) >> 4));
}

void gradientRowV6(const std::uint8_t *a, const std::uint8_t *b, const std::uint8_t *c, int w,
		   std::int16_t *gx, std::int16_t * /* gy: the pairs hold it */, std::int32_t *mag,
		   std::int16_t *tmp, TensorRow /* the corner test sums on demand */)
{
	std::uint8_t *pairs = reinterpret_cast<std::uint8_t *>(gx);
	auto storePair = [&](int x, u32 p) { store32(pairs + 4 * x, p); };
	storePair(0, 0);
	mag[0] = 0;
	storePair(w - 1, 0);
	mag[w - 1] = 0;
	int x = 1;
	if (w >= 16) {
		/* Pass 1: the column sums vs = a + 2b + c and differences
		 * vd = c - a, four columns a step in even and odd lanes (UXTB16),
		 * stored as they come: the even columns' vs in one int16 array,
		 * the odd columns' in another, and so for vd. */
		const int half = ((w + 1) / 2 + 3) & ~1; /* values per array, word-aligned */
		std::int16_t *const sE = tmp, *const sO = tmp + half, *const dE = tmp + 2 * half,
				   *const dO = tmp + 3 * half; /* RowScratch: 2w + 16 values */
		const int words = w / 4;
		{
			/* 18 instructions per four columns: the smoothed rows are
			 * already in lanes. */
			const std::uint8_t *pa = a, *pb = b, *pc = c;
			const std::uint8_t *const aEnd = a + 8 * words;
			std::int16_t *pse = sE, *pso = sO, *pde = dE, *pdo = dO;
			u32 t0, t1, t2, t3, t4;
			__asm__ volatile(
				"1:\n\t"
				"ldr     %[t1], [%[pa], #4]\n\t"         /* oa */
				"ldr     %[t0], [%[pa]], #8\n\t"         /* ea */
				"ldr     %[t3], [%[pc], #4]\n\t"         /* oc */
				"ldr     %[t2], [%[pc]], #8\n\t"         /* ec */
				"ssub16  %[t4], %[t2], %[t0]\n\t"
				"str     %[t4], [%[pde]], #4\n\t"        /* vd even */
				"ssub16  %[t4], %[t3], %[t1]\n\t"
				"str     %[t4], [%[pdo]], #4\n\t"        /* vd odd */
				"add     %[t0], %[t0], %[t2]\n\t"
				"add     %[t1], %[t1], %[t3]\n\t"
				"ldr     %[t3], [%[pb], #4]\n\t"         /* ob */
				"ldr     %[t2], [%[pb]], #8\n\t"         /* eb */
				"add     %[t0], %[t0], %[t2], lsl #1\n\t"
				"add     %[t1], %[t1], %[t3], lsl #1\n\t"
				"str     %[t0], [%[pse]], #4\n\t"        /* vs even */
				"str     %[t1], [%[pso]], #4\n\t"        /* vs odd */
				"cmp     %[pa], %[end]\n\t"
				"bne     1b"
				: [pa] "+r"(pa), [pb] "+r"(pb), [pc] "+r"(pc), [pse] "+r"(pse), [pso] "+r"(pso),
				  [pde] "+r"(pde), [pdo] "+r"(pdo), [t0] "=&r"(t0), [t1] "=&r"(t1), [t2] "=&r"(t2),
				  [t3] "=&r"(t3), [t4] "=&r"(t4)
				: [end] "r"(aEnd)
				: "cc", "memory");
		}
		for (int i = 4 * words; i < w; ++i) {
			std::int16_t *vs = (i & 1) ? sO : sE, *vd = (i & 1) ? dO : dE;
			const int pa = getSmoothed(a, i), pb = getSmoothed(b, i), pc = getSmoothed(c, i);
			vs[i / 2] = static_cast<std::int16_t>(pa + 2 * pb + pc);
			vd[i / 2] = static_cast<std::int16_t>(pc - pa);
		}
		/* Pass 2, pixels 2j+1 .. 2j+4: a word loaded at index j of an
		 * array holds columns (2j, 2j+2) or (2j+1, 2j+3), so
		 *   gx(2j+1, 2j+3) = sE[j+1..] - sE[j..]        (one SSUB16)
		 *   gy(2j+1, 2j+3) = dE[j..] + dE[j+1..] + 2 dO[j..]
		 * and the even pixels 2j+2, 2j+4 likewise with E and O swapped;
		 * the loads at j+1 are unaligned (allowed on ARMv6). */
		/* Written out: GCC keeps a counter and spills; this is 34
		 * instructions per four pixels. */
		const int steps = (w - 2) / 4;
		std::uint8_t *pp = pairs + 4;
		std::uint8_t *m = reinterpret_cast<std::uint8_t *>(mag + 1);
		const std::uint8_t *const ppEnd = pp + 16 * steps;
		const std::int16_t *pse = sE, *pso = sO, *pde = dE, *pdo = dO;
		u32 t0, t1, t2, t3, t4, t5;
		__asm__ volatile(
			"1:\n\t"
			"ldr    %[t4], [%[pdo], #2]\n\t"        /* do1 */
			"ldr    %[t3], [%[pdo]], #4\n\t"        /* do0 */
			"ldr    %[t2], [%[pde], #2]\n\t"        /* de1 */
			"ldr    %[t1], [%[pde]], #4\n\t"        /* de0 */
			"sadd16 %[t1], %[t1], %[t2]\n\t"
			"sadd16 %[t5], %[t3], %[t3]\n\t"
			"sadd16 %[t1], %[t1], %[t5]\n\t"        /* gy odd */
			"sadd16 %[t3], %[t3], %[t4]\n\t"
			"sadd16 %[t2], %[t2], %[t2]\n\t"
			"sadd16 %[t3], %[t3], %[t2]\n\t"        /* gy even */
			"ldr    %[t0], [%[pse], #2]\n\t"
			"ldr    %[t2], [%[pse]], #4\n\t"
			"ssub16 %[t0], %[t0], %[t2]\n\t"        /* gx odd */
			"ldr    %[t4], [%[pso], #2]\n\t"
			"ldr    %[t2], [%[pso]], #4\n\t"
			"ssub16 %[t4], %[t4], %[t2]\n\t"        /* gx even */
			"pkhbt  %[t2], %[t0], %[t1], lsl #16\n\t" /* pixel 2j+1 */
			"pkhtb  %[t1], %[t1], %[t0], asr #16\n\t" /* pixel 2j+3 */
			"pkhbt  %[t0], %[t4], %[t3], lsl #16\n\t" /* pixel 2j+2 */
			"pkhtb  %[t3], %[t3], %[t4], asr #16\n\t" /* pixel 2j+4 */
			"str    %[t2], [%[pp]], #16\n\t"
			"str    %[t0], [%[pp], #-12]\n\t"
			"str    %[t1], [%[pp], #-8]\n\t"
			"str    %[t3], [%[pp], #-4]\n\t"
			"smuad  %[t2], %[t2], %[t2]\n\t"
			"smuad  %[t0], %[t0], %[t0]\n\t"
			"smuad  %[t1], %[t1], %[t1]\n\t"
			"smuad  %[t3], %[t3], %[t3]\n\t"
			"str    %[t2], [%[m]], #16\n\t"
			"str    %[t0], [%[m], #-12]\n\t"
			"str    %[t1], [%[m], #-8]\n\t"
			"str    %[t3], [%[m], #-4]\n\t"
			"cmp    %[pp], %[end]\n\t"
			"bne    1b"
			: [pse] "+r"(pse), [pso] "+r"(pso), [pde] "+r"(pde), [pdo] "+r"(pdo), [pp] "+r"(pp),
			  [m] "+r"(m), [t0] "=&r"(t0), [t1] "=&r"(t1), [t2] "=&r"(t2), [t3] "=&r"(t3),
			  [t4] "=&r"(t4), [t5] "=&r"(t5)
			: [end] "r"(ppEnd)
			: "cc", "memory");
		x = 1 + 4 * steps;
	}
	for (; x < w - 1; ++x)
		storePair(x, gradientPair(a, b, c, x, mag[x]));
}

inline u32 pairAt(const std::int16_t *row, int x)
{
	return load32(reinterpret_cast<const std::uint8_t *>(row) + 4 * x);
}

/* isCorner on the pair rows: Sxx + Syy by SMLAD, Sxx - Syy by SMLSD, Sxy
 * by SMLATB; then the scalar kernel's int32 test. */
inline bool isCornerV6(const std::int16_t *const pairRows[3], int x, std::int32_t twoT)
{
	std::int32_t s = 0, d = 0, xy = 0;
	for (int r = 0; r < 3; ++r) {
		const std::uint8_t *p = reinterpret_cast<const std::uint8_t *>(pairRows[r]) + 4 * (x - 1);
		for (int i = 0; i < 3; ++i) {
			const auto v = static_cast<int16x2_t>(load32(p + 4 * i));
			s = __smlad(v, v, s);
			d = __smlsd(v, v, d);
			xy = __smlatb(static_cast<std::int32_t>(v), static_cast<std::int32_t>(v), xy);
		}
	}
	const std::int32_t c = (s - twoT) >> 9;
	if (c <= 0)
		return false;
	const std::int32_t a = std::abs(d) >> 9;
	const std::int32_t b = std::abs(xy) >> 8;
	return c * c > a * a + b * b;
}

struct EdgeRowCtx {
	const std::int32_t *up, *mid, *down;
	const std::int16_t *pairs[3];
	std::int32_t twoT;
};

/* One pixel whose magnitude m is above the threshold: non-maximum
 * suppression along the gradient direction, then the corner test. Out of
 * line, so that the scan over the (mostly empty) row keeps its registers. */
__attribute__((noinline)) u32 edgePixel(const EdgeRowCtx &e, int x, std::int32_t m)
{
	const u32 p = pairAt(e.pairs[1], x);
	const int gx = static_cast<std::int16_t>(p), gy = static_cast<std::int32_t>(p) >> 16;
	const int ax = std::abs(gx), ay = std::abs(gy);
	std::int32_t prev, next;
	if (256 * ay <= 106 * ax) {
		prev = e.mid[x - 1];
		next = e.mid[x + 1];
	} else if (256 * ax <= 106 * ay) {
		prev = e.up[x];
		next = e.down[x];
	} else if ((gx > 0) == (gy > 0)) {
		prev = e.up[x - 1];
		next = e.down[x + 1];
	} else {
		prev = e.up[x + 1];
		next = e.down[x - 1];
	}
	if (!(m > prev && m >= next))
		return 0;
	return isCornerV6(e.pairs, x, e.twoT) ? EdgeMap::kEdge | EdgeMap::kCorner : EdgeMap::kEdge;
}

/* The threshold test, direction and non-maximum suppression of the four
 * pixels x .. x+3, written out (~3 instructions a pixel below the
 * threshold, ~20 above): bit i set when pixel x+i is an edge. The direction
 * tests 256|gy| <= 106|gx| and 256|gx| <= 106|gy| as 128|gy| <= 53|gx| and
 * 128|gx| <= 53|gy|; in the diagonal case both are non-zero, so
 * (gx > 0) == (gy > 0) is gx ^ gy >= 0. */
inline u32 nmsGroup(const EdgeRowCtx &e, int x, std::int32_t thr)
{
	const std::int32_t *pm = e.mid + x, *pu = e.up + x, *pd = e.down + x;
	const std::uint8_t *pp = reinterpret_cast<const std::uint8_t *>(e.pairs[1]) + 4 * x;
	const u32 c53 = 53;
	u32 mask, m, gx, gy, sg, t;
#define FRAPPE_NMS_PIXEL(OFF, BIT, NEXT)                                                   \
	"ldr     %[m], [%[pm], #" OFF "]\n\t"                                              \
	"cmp     %[m], %[thr]\n\t"                                                         \
	"ble     " NEXT "f\n\t"                                                            \
	"ldr     %[gx], [%[pp], #" OFF "]\n\t"                                             \
	"asr     %[gy], %[gx], #16\n\t"                                                    \
	"sxth    %[gx], %[gx]\n\t"                                                         \
	"eor     %[sg], %[gx], %[gy]\n\t"                                                  \
	"eor     %[t], %[gx], %[gx], asr #31\n\t"                                          \
	"sub     %[gx], %[t], %[gx], asr #31\n\t"      /* |gx| */                          \
	"eor     %[t], %[gy], %[gy], asr #31\n\t"                                          \
	"sub     %[gy], %[t], %[gy], asr #31\n\t"      /* |gy| */                          \
	"mul     %[t], %[gx], %[c53]\n\t"                                                  \
	"cmp     %[t], %[gy], lsl #7\n\t"                                                  \
	"bge     5" NEXT "f\n\t"                       /* horizontal */                    \
	"mul     %[t], %[gy], %[c53]\n\t"                                                  \
	"cmp     %[t], %[gx], lsl #7\n\t"                                                  \
	"bge     6" NEXT "f\n\t"                       /* vertical */                      \
	"cmp     %[sg], #0\n\t"                                                            \
	"itt     ge\n\t"                                                                   \
	"ldrge   %[gx], [%[pu], #" OFF " - 4]\n\t"     /* diagonal (gx > 0) == (gy > 0) */ \
	"ldrge   %[gy], [%[pd], #" OFF " + 4]\n\t"                                         \
	"itt     lt\n\t"                                                                   \
	"ldrlt   %[gx], [%[pu], #" OFF " + 4]\n\t"     /* the other diagonal */            \
	"ldrlt   %[gy], [%[pd], #" OFF " - 4]\n\t"                                         \
	"b       7" NEXT "f\n"                                                              \
	"5" NEXT ":\n\t"                                                                   \
	"ldr     %[gx], [%[pm], #" OFF " - 4]\n\t"                                         \
	"ldr     %[gy], [%[pm], #" OFF " + 4]\n\t"                                         \
	"b       7" NEXT "f\n"                                                              \
	"6" NEXT ":\n\t"                                                                   \
	"ldr     %[gx], [%[pu], #" OFF "]\n\t"                                             \
	"ldr     %[gy], [%[pd], #" OFF "]\n"                                                \
	"7" NEXT ":\n\t"                                                                   \
	"cmp     %[m], %[gx]\n\t"                      /* m > prev */                      \
	"ble     " NEXT "f\n\t"                                                            \
	"cmp     %[m], %[gy]\n\t"                      /* m >= next */                     \
	"it      ge\n\t"                                                                   \
	"orrge   %[mask], %[mask], #" BIT "\n"                                              \
	NEXT ":\n\t"
	__asm__ volatile(
		"mov     %[mask], #0\n\t"
		FRAPPE_NMS_PIXEL("0", "1", "1")
		FRAPPE_NMS_PIXEL("4", "2", "2")
		FRAPPE_NMS_PIXEL("8", "4", "3")
		FRAPPE_NMS_PIXEL("12", "8", "4")
		: [mask] "=&r"(mask), [m] "=&r"(m), [gx] "=&r"(gx), [gy] "=&r"(gy), [sg] "=&r"(sg), [t] "=&r"(t)
		: [pm] "r"(pm), [pu] "r"(pu), [pd] "r"(pd), [pp] "r"(pp), [thr] "r"(thr), [c53] "r"(c53)
		: "cc", "memory");
#undef FRAPPE_NMS_PIXEL
	return mask;
}

/* The four result bytes of the pixels x .. x+3; out of line, so that the
 * scan over the (mostly empty) row keeps its registers. */
__attribute__((noinline)) u32 edgeGroup(const EdgeRowCtx &e, int x, std::int32_t thr)
{
	u32 v = 0;
	for (u32 edges = nmsGroup(e, x, thr); edges; edges &= edges - 1) {
		const int i = __builtin_ctz(edges);
		v |= (isCornerV6(e.pairs, x + i, e.twoT) ? EdgeMap::kEdge | EdgeMap::kCorner : EdgeMap::kEdge)
		     << (8 * i);
	}
	return v;
}

bool edgeRowV6(const GradRows &rows, int w, const FrontEndParams &params, std::uint8_t *out)
{
	out[0] = 0;
	out[w - 1] = 0;
	const EdgeRowCtx e{ rows.mag[0], rows.mag[1], rows.mag[2], { rows.gx[0], rows.gx[1], rows.gx[2] },
			    2 * static_cast<std::int32_t>(params.corner_threshold) };
	const std::int32_t *mid = rows.mag[1];
	/* m >= 0 and m < 2^31: clamping the threshold keeps m > thr. */
	const std::int32_t thr = static_cast<std::int32_t>(
		std::clamp<std::int64_t>(params.edge_threshold_sq, -1, INT32_MAX));
	u32 any = 0;
	const int x1 = w - 1;
	int x = 1;
	for (; x + 4 <= x1; x += 4) {
		/* Most pixels are far below the threshold: the OR of four
		 * non-negative magnitudes bounds their maximum. */
		const std::int32_t m0 = mid[x], m1 = mid[x + 1], m2 = mid[x + 2], m3 = mid[x + 3];
		u32 v = 0;
		if ((m0 | m1 | m2 | m3) > thr) {
			v = edgeGroup(e, x, thr);
			any |= v;
		}
		store32(out + x, v);
	}
	for (; x < x1; ++x) {
		const std::int32_t m = mid[x];
		const u32 v = m > thr ? edgePixel(e, x, m) : 0;
		out[x] = static_cast<std::uint8_t>(v);
		any |= v;
	}
	return any != 0;
}

} // namespace

const RowKernels &armv6RowKernels()
{
	static constexpr RowKernels kArmv6{ "armv6-simd32", smoothRowV6, gradientRowV6, edgeRowV6 };
	return kArmv6;
}

} // namespace frappe::detail

#endif
