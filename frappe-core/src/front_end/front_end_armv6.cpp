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
#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <mutex>

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

/* The loops below name r4-r11 (and need 14 registers): no frame pointer,
 * also in a -O0 build. */
__attribute__((optimize("omit-frame-pointer"))) void smoothRowV6(const std::uint8_t *a, const std::uint8_t *b, const std::uint8_t *c, int w,
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
		 * constants): 21 instructions per four pixels. The results are
		 * bits 4..11 of the lanes of sE (even pixels) and sO (odd ones),
		 * stored as they are (see putSmoothed):
		 *   sE = O + 2E + (Oprev >> 16) + (O << 16),
		 *   sO = E + 2O + (E >> 16) + (En << 16),
		 * plain adds, as no lane carries into the next. The previous
		 * word's E, O stay in the registers the next word's are loaded
		 * into, so sE comes first. */
		const std::uint8_t *pa = a, *pb = b, *pc = c;
		std::uint8_t *po = out;
		const std::uint8_t *const oEnd = out + 16 * (words / 2);
		register u32 rE __asm__("r4") = E;
		register u32 rO __asm__("r5") = O;
		register u32 rOprev __asm__("r7") = prevHi << 16;
		register u32 rOne __asm__("r11") = kOne;
		__asm__ volatile(
			"1:\n\t"
#define FRAPPE_SMOOTH_WORD(E, O, EN, ON)                                                          \
			"add     r8, " O ", " E ", lsl #1\n\t"                                  \
			"add     r8, r8, " O ", lsl #16\n\t"                                    \
			"add     r8, r8, " ON ", lsr #16\n\t"        /* sE */                   \
			"ldr     r9, [%[pa], #4]!\n\t"                                          \
			"ldr     r10, [%[pc], #4]!\n\t"                                         \
			"uxtb16  " EN ", r9\n\t"                                                \
			"uxtab16 " EN ", " EN ", r10\n\t"                                       \
			"uxtb16  " ON ", r9, ror #8\n\t"                                        \
			"uxtab16 " ON ", " ON ", r10, ror #8\n\t"                               \
			"ldr     r9, [%[pb], #4]!\n\t"                                          \
			"uxtab16 r10, r11, r9\n\t"                                              \
			"add     " EN ", " EN ", r10, lsl #1\n\t"                               \
			"uxtab16 r10, r11, r9, ror #8\n\t"                                      \
			"add     " ON ", " ON ", r10, lsl #1\n\t"                               \
			"add     r9, " E ", " O ", lsl #1\n\t"                                  \
			"add     r9, r9, " E ", lsr #16\n\t"                                    \
			"add     r9, r9, " EN ", lsl #16\n\t"        /* sO */                   \
			"and     r8, %[mask], r8, lsr #4\n\t"                                   \
			"and     r9, %[mask], r9, lsr #4\n\t"                                   \
			"stmia   %[po]!, {r8, r9}\n\t"
			FRAPPE_SMOOTH_WORD("r4", "r5", "r6", "r7")
			FRAPPE_SMOOTH_WORD("r6", "r7", "r4", "r5")
#undef FRAPPE_SMOOTH_WORD
			"cmp     %[po], %[end]\n\t"
			"bne     1b"
			: [pa] "+r"(pa), [pb] "+r"(pb), [pc] "+r"(pc), [po] "+r"(po), "+r"(rE), "+r"(rO),
			  "+r"(rOprev)
			: "r"(rOne), [mask] "r"(kMask), [end] "r"(oEnd)
			: "r6", "r8", "r9", "r10", "cc", "memory");
		E = rE;
		O = rO;
		prevHi = rOprev >> 16;
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

__attribute__((optimize("omit-frame-pointer"))) void gradientRowV6(const std::uint8_t *a, const std::uint8_t *b, const std::uint8_t *c, int w,
		   std::int16_t *gx, std::int16_t * /* gy: the pairs hold it */, std::int32_t *mag,
		   std::int16_t *tmp)
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
		 * vd = c - a, four columns a step in even and odd lanes (the
		 * smoothed rows are already in lanes), stored per block of four
		 * columns 4k .. 4k+3 as the four words
		 *   sE = vs(4k, 4k+2), sO = vs(4k+1, 4k+3), dE = vd(4k, 4k+2),
		 *   U = dE + dO = (vd(4k) + vd(4k+1), vd(4k+2) + vd(4k+3))
		 * by one STM: 13 instructions per four columns (U saves pass 2
		 * two). The blocks live in tmp (2w + 16 values): w/4 + 1 blocks
		 * of 8 values. */
		std::uint8_t *const blocks = reinterpret_cast<std::uint8_t *>(tmp);
		const int words = w / 4;
		{
			const std::uint8_t *pa = a, *pb = b, *pc = c;
			const std::uint8_t *const aEnd = a + 8 * words;
			std::uint8_t *pt = blocks;
			/* Two blocks a loop; an odd count enters at the second. */
#define FRAPPE_GRAD_COLUMNS                                                                      \
				"ldmia   %[pa]!, {r4, r5}\n\t"     /* ea, oa */            \
				"ldmia   %[pc]!, {r6, r7}\n\t"     /* ec, oc */            \
				"ldmia   %[pb]!, {r8, r9}\n\t"     /* eb, ob */            \
				"ssub16  r10, r6, r4\n\t"          /* dE */                \
				"ssub16  r11, r7, r5\n\t"          /* dO */                \
				"sadd16  r11, r10, r11\n\t"        /* U */                 \
				"add     r4, r4, r6\n\t"                                   \
				"add     r5, r5, r7\n\t"                                   \
				"add     r8, r4, r8, lsl #1\n\t"   /* sE */                \
				"add     r9, r5, r9, lsl #1\n\t"   /* sO */                \
				"stmia   %[pt]!, {r8-r11}\n\t"
			__asm__ volatile(
				"sub     r4, %[end], %[pa]\n\t"
				"tst     r4, #8\n\t"
				"bne     3f\n"
				"1:\n\t"
				FRAPPE_GRAD_COLUMNS
				"3:\n\t"
				FRAPPE_GRAD_COLUMNS
				"cmp     %[pa], %[end]\n\t"
				"bne     1b"
#undef FRAPPE_GRAD_COLUMNS
				: [pa] "+r"(pa), [pb] "+r"(pb), [pc] "+r"(pc), [pt] "+r"(pt)
				: [end] "r"(aEnd)
				: "r4", "r5", "r6", "r7", "r8", "r9", "r10", "r11", "cc", "memory");
		}
		/* The last columns (0 .. 3) in block `words`; an odd column's
		 * U lane adds the even column before it. */
		for (int i = 4 * words; i < w; ++i) {
			auto vd = [&](int j) { return getSmoothed(c, j) - getSmoothed(a, j); };
			const int pa = getSmoothed(a, i), pb = getSmoothed(b, i), pc = getSmoothed(c, i);
			const std::int16_t v[2] = { static_cast<std::int16_t>(pa + 2 * pb + pc),
						    static_cast<std::int16_t>((i & 1) ? vd(i - 1) + vd(i) : vd(i)) };
			for (int q = 0; q < 2; ++q)
				std::memcpy(blocks + 16 * (i >> 2) + 8 * q + 4 * (i & 1) + 2 * ((i >> 1) & 1), &v[q], 2);
		}
		/* Pass 2, pixels 4k+1 .. 4k+4 from block k (C) and the low lanes
		 * of block k+1 (N): with F(X) = (C_X.hi, N_X.lo), the columns
		 * (4k+2, 4k+4) or (4k+3, 4k+5),
		 *   gx(4k+1, 4k+3) = F(sE) - sE,   gx(4k+2, 4k+4) = F(sO) - sO,
		 *   with V = dO + F(dE) = U - dE + F(dE):
		 *   gy(4k+1, 4k+3) = dE + 2 dO + F(dE) = U + V,
		 *   gy(4k+2, 4k+4) = dO + 2 F(dE) + F(dO) = V + F(U);
		 * the (gx, gy) pair of a pixel is one PKHBT/PKHTB, gx^2 + gy^2
		 * one SMUAD; pairs and magnitudes stored by STM. 26 instructions
		 * per four pixels, all loads and stores aligned. */
		const int steps = (w - 2) / 4;
		std::uint8_t *pp = pairs + 4;
		std::uint8_t *m = reinterpret_cast<std::uint8_t *>(mag + 1);
		const std::uint8_t *const ppEnd = pp + 16 * steps;
		const std::uint8_t *pt = blocks;
		/* Block k+1 stays in registers as the next step's block k: two
		 * steps a loop with the register sets swapped (C, N = r4-r7,
		 * r8-r11 and then r8-r11, r4-r7); an odd count of steps enters
		 * at the second. */
#define FRAPPE_GRAD_STEP(C0, C1, C2, C3, N0, N1, N2, N3, N)                                                      \
			"ldmia   %[pt]!, {" N "}\n\t"                                      \
			"lsr     r12, " C0 ", #16\n\t"                                     \
			"orr     r12, r12, " N0 ", lsl #16\n\t"  /* F(sE) */              \
			"ssub16  " C0 ", r12, " C0 "\n\t"        /* gx odd */             \
			"lsr     r12, " C1 ", #16\n\t"                                     \
			"orr     r12, r12, " N1 ", lsl #16\n\t"  /* F(sO) */              \
			"ssub16  " C1 ", r12, " C1 "\n\t"        /* gx even */            \
			"lsr     r12, " C2 ", #16\n\t"                                     \
			"orr     r12, r12, " N2 ", lsl #16\n\t"  /* F(dE) */              \
			"lsr     lr, " C3 ", #16\n\t"                                      \
			"orr     lr, lr, " N3 ", lsl #16\n\t"    /* F(U) */               \
			"ssub16  " C2 ", " C3 ", " C2 "\n\t"     /* dO */                 \
			"sadd16  " C2 ", " C2 ", r12\n\t"        /* V */                  \
			"sadd16  " C3 ", " C3 ", " C2 "\n\t"     /* gy odd */             \
			"sadd16  " C2 ", " C2 ", lr\n\t"         /* gy even */            \
			"pkhtb   r12, " C3 ", " C0 ", asr #16\n\t" /* pixel 4k+3 */       \
			"pkhtb   lr, " C2 ", " C1 ", asr #16\n\t"  /* pixel 4k+4 */       \
			"pkhbt   " C0 ", " C0 ", " C3 ", lsl #16\n\t" /* pixel 4k+1 */    \
			"pkhbt   " C1 ", " C1 ", " C2 ", lsl #16\n\t" /* pixel 4k+2 */    \
			"stmia   %[pp]!, {" C0 ", " C1 ", r12, lr}\n\t"                    \
			"smuad   " C0 ", " C0 ", " C0 "\n\t"                               \
			"smuad   " C1 ", " C1 ", " C1 "\n\t"                               \
			"smuad   r12, r12, r12\n\t"                                        \
			"smuad   lr, lr, lr\n\t"                                           \
			"stmia   %[m]!, {" C0 ", " C1 ", r12, lr}\n\t"
		__asm__ volatile(
			"sub     r12, %[end], %[pp]\n\t"
			"tst     r12, #16\n\t"
			"it      ne\n\t"
			"ldmne   %[pt]!, {r8-r11}\n\t"
			"bne     3f\n\t"
			"ldmia   %[pt]!, {r4-r7}\n"
			"1:\n\t"
			FRAPPE_GRAD_STEP("r4", "r5", "r6", "r7", "r8", "r9", "r10", "r11", "r8-r11")
			"3:\n\t"
			FRAPPE_GRAD_STEP("r8", "r9", "r10", "r11", "r4", "r5", "r6", "r7", "r4-r7")
			"cmp     %[pp], %[end]\n\t"
			"bne     1b"
#undef FRAPPE_GRAD_STEP
			: [pt] "+r"(pt), [pp] "+r"(pp), [m] "+r"(m)
			: [end] "r"(ppEnd)
			: "r4", "r5", "r6", "r7", "r8", "r9", "r10", "r11", "r12", "lr", "cc", "memory");
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

/* The thresholds of each smoothed value p (FrontEndParams::relativeThreshold):
 * t[p][0] the edge threshold (never below leastEdgeThreshold(), as the
 * scalar rule tests both), t[p][1] minus twice the corner threshold (the
 * corner sum's first addend). Both grow with p when light_floor >= 0. */
struct LightTable {
	std::int32_t edgeT, cornerT, floor;
	std::int32_t t[256][2];
};

void fillLightTable(LightTable &tab, const FrontEndParams &params)
{
	const std::int32_t e = edgeThreshold(params), c = cornerThreshold(params);
	const std::int32_t least = leastEdgeThreshold(params);
	for (int p = 0; p < 256; ++p) {
		tab.t[p][0] = std::max(least, params.relativeThreshold(e, p));
		tab.t[p][1] = -2 * params.relativeThreshold(c, p);
	}
	tab.edgeT = e;
	tab.cornerT = c;
	tab.floor = params.light_floor;
}

/* A table is made once for each params a process uses (a detector's
 * floor takes the values from half its light_floor to it), then read without a lock: a per-row table would cost more than
 * the row's edge pass saves, thread_local a __tls_get_addr call a row in
 * a shared library. Beyond kLightTables a row makes its own in `own`. */
constexpr int kLightTables = 16; /* a detector's floors follow its frames' noise: up to 9 */
LightTable gLightTables[kLightTables];
std::atomic<int> gLightTablesMade{ 0 };
std::mutex gLightTablesLock;

const LightTable &lightTable(const FrontEndParams &params, LightTable &own)
{
	const std::int32_t e = edgeThreshold(params), c = cornerThreshold(params), f = params.light_floor;
	auto find = [&](int n) -> const LightTable * {
		for (int i = 0; i < n; ++i) {
			const LightTable &t = gLightTables[i];
			if (t.edgeT == e && t.cornerT == c && t.floor == f)
				return &t;
		}
		return nullptr;
	};
	if (const LightTable *t = find(gLightTablesMade.load(std::memory_order_acquire)))
		return *t;
	std::lock_guard<std::mutex> lock(gLightTablesLock);
	const int n = gLightTablesMade.load(std::memory_order_relaxed);
	if (const LightTable *t = find(n))
		return *t;
	LightTable &tab = n < kLightTables ? gLightTables[n] : own;
	fillLightTable(tab, params);
	if (n < kLightTables)
		gLightTablesMade.store(n + 1, std::memory_order_release);
	return tab;
}

struct EdgeRowCtx {
	const std::int32_t *up, *mid, *down;
	const std::int16_t *pairs[3];
};

/* One pixel above its edge threshold: non-maximum suppression along the
 * gradient direction, then the corner test against twoT. */
__attribute__((noinline)) u32 edgePixel(const EdgeRowCtx &e, int x, std::int32_t m, std::int32_t twoT)
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
	return isCornerV6(e.pairs, x, twoT) ? EdgeMap::kEdge | EdgeMap::kCorner : EdgeMap::kEdge;
}

/* The edge pass over the groups of eight pixels of a row, in one assembly
 * function (GCC's code for the group work spilled): frappe_armv6_edge_row8.
 *
 * Scan: one LDM of eight magnitudes, their OR against the least threshold
 * of any pixel, two word stores of zeros: 15 instructions per eight pixels.
 * A group whose OR is above it: the least smoothed value of its pixels
 * (one LDM of pixels 8g .. 8g+10, USUB16 + SEL) gives a threshold no
 * pixel's is below, and the group is empty if the OR is not above that
 * ("hit" otherwise). Then, for each half whose OR is above it, non-maximum
 * suppression of its pixels above the group's threshold; a local maximum
 * is then tested against its own (a table lookup), unless every pixel's
 * is the group's (the threshold of full light); |gx|, |gy| by SSUB16 + SEL on the
 * pair and the direction tests by SMUSD / SMUSDX with (53, 128). Then the
 * corner test of each edge pixel as isCornerV6 (its three rows of three
 * pairs by LDM) against its own threshold, and the eight result bytes from
 * a 16-entry table. */
struct EdgeRowAsm {
	std::int32_t du, dd, dp1, k;	  ///< 0: up, down, pairs[1] minus mid (bytes); k = (53, 128)
	std::int32_t dq0, dq1, dq2, unused; ///< 16: pairs[r] minus mid plus 88 (bytes)
	const std::int32_t *pm;		  ///< 32: mid (groups from pixel 0)
	std::uint8_t *po;		  ///< 36: out
	const std::int32_t *end;	  ///< 40: pm + 8 * groups (groups >= 1)
	std::int32_t least;		  ///< 44: no pixel's edge threshold is below it
	u32 any;			  ///< 48: out: the OR of the edge bits found
	u32 sdelta;			  ///< 52: smoothed row - (mid + 32) / 2, as addresses
	const std::int32_t *table;	  ///< 56: LightTable::t
};
static_assert(offsetof(EdgeRowAsm, pm) == 32 && offsetof(EdgeRowAsm, any) == 48 &&
	      offsetof(EdgeRowAsm, table) == 56);

extern "C" void frappe_armv6_edge_row8(EdgeRowAsm *a);

/* Registers. Scan: r4 pm (after the group once loaded), r5 po, r6 end,
 * r7 least, r8 zero, lr any; r0-r3, r9-r12 the magnitudes. Hit: r4-r9 and
 * lr saved (r9, the upper half's OR, read back from the stack); r9 the
 * group's smoothed values (pixel 8g at 0: sdelta + pm / 2), lr the table, r7 the group's threshold, r1 up, r2 down, r3
 * pairs (all at pm), r10 k, r11 mask, r0 m, r12 the pair, r5 |pair| /
 * previous / the pixel's threshold, r6 next. Corners: the smoothed base,
 * the edge bits and the table + 4 pushed; r1-r3 the pairs rows (see dq),
 * r7 the pixel's -2T, r8 corner bits, r11 the edge bits left, r0 the
 * lowest, r12 its CLZ, r4 Sxx + Syy - 2T, r5 Sxx - Syy, r6 Sxy, r9 r10 lr one
 * row's three pairs. */
__asm__(R"(
	.text
	.arm
	.syntax unified
	.p2align 2
	.type frappe_armv6_edge_row8, %function
frappe_armv6_edge_row8:
	push    {r0, r4-r11, lr}
	add     r1, r0, #32
	ldm     r1, {r4, r5, r6, r7}
	mov     r8, #0
	mov     lr, #0
.Lfe8_scan:
	ldmia   r4!, {r0, r1, r2, r3, r9, r10, r11, r12}
	orr     r0, r0, r1
	orr     r2, r2, r3
	orr     r9, r9, r10
	orr     r11, r11, r12
	orr     r0, r0, r2
	orr     r9, r9, r11
	orr     r1, r0, r9
	cmp     r1, r7
	bgt     .Lfe8_hit
	str     r8, [r5], #4
	str     r8, [r5], #4
	cmp     r4, r6
	bne     .Lfe8_scan
.Lfe8_done:
	ldr     r0, [sp]
	str     lr, [r0, #48]
	pop     {r0, r4-r11, pc}

	@ Pixel at \off bytes from pm, bit \bit of the mask; \own: r7 is
	@ only the group's least threshold, and a local maximum is held to its
	@ own (its smoothed value at \soff from r9): after the NMS, as most
	@ pixels above r7 are above their own too.
	.macro  FE8_NMS off, bit, own=0, soff=0
	ldr     r0, [r4, #\off]
	cmp     r0, r7
	ble     .Lfe8_n\@
	ldr     r12, [r3, #\off]
	ssub16  r5, r8, r12
	sel     r5, r5, r12                 @ (|gx|, |gy|)
	smusd   r6, r5, r10                 @ 53|gx| - 128|gy|
	cmp     r6, #0
	bge     .Lfe8_h\@
	smusdx  r6, r5, r10                 @ 128|gx| - 53|gy|
	cmp     r6, #0
	ble     .Lfe8_v\@
	teq     r12, r12, lsl #16           @ N: the signs of gx and gy differ
	ldrpl   r5, [r1, #\off - 4]
	ldrpl   r6, [r2, #\off + 4]
	ldrmi   r5, [r1, #\off + 4]
	ldrmi   r6, [r2, #\off - 4]
	b       .Lfe8_c\@
.Lfe8_h\@:
	ldr     r5, [r4, #\off - 4]
	ldr     r6, [r4, #\off + 4]
	b       .Lfe8_c\@
.Lfe8_v\@:
	ldr     r5, [r1, #\off]
	ldr     r6, [r2, #\off]
.Lfe8_c\@:
	cmp     r0, r5
	ble     .Lfe8_n\@
	cmp     r0, r6
	.if \own
	blt     .Lfe8_n\@
	ldrh    r5, [r9, #\soff]
	ldr     r5, [lr, r5, lsl #3]
	cmp     r0, r5
	orrgt   r11, r11, #\bit
	.else
	orrge   r11, r11, #\bit
	.endif
.Lfe8_n\@:
	.endm

	.macro  FE8_ROW rp, first
	sub     lr, \rp, r12, lsl #2
	ldm     lr, {r9, r10, lr}
	.if \first
	smlad   r4, r9, r9, r7              @ from -2T
	smusd   r5, r9, r9
	smultb  r6, r9, r9
	.else
	smlad   r4, r9, r9, r4
	smlsd   r5, r9, r9, r5
	smlatb  r6, r9, r9, r6
	.endif
	smlad   r4, r10, r10, r4
	smlsd   r5, r10, r10, r5
	smlatb  r6, r10, r10, r6
	smlad   r4, lr, lr, r4
	smlsd   r5, lr, lr, r5
	smlatb  r6, lr, lr, r6
	.endm

	@ The corner test of each edge pixel (r11), as isCornerV6; \same: every
	@ pixel's -2T is full light's, else each looks its own up.
	.macro  FE8_CORNERS same
	.if \same
	ldr     r7, [lr, #2044]
	push    {r11}                       @ a at [sp, #32]
	ldr     r12, [sp, #32]
	.else
	add     lr, lr, #4
	push    {r9, r11, lr}               @ smoothed base, edge bits, table + 4; a at [sp, #40]
	ldr     r12, [sp, #40]
	.endif
	add     r12, r12, #16
	ldm     r12, {r1, r2, r3}
	add     r1, r1, r4
	add     r2, r2, r4
	add     r3, r3, r4
	mov     r8, #0
.Lfe8_cl\@:                                 @ V is clear here (CMP with 0 or of two values below 2^31)
	rsb     r12, r11, #0
	and     r0, r11, r12                @ the lowest edge bit, pixel i
	clz     r12, r0                     @ 31 - i
	.if !\same
	adr     r9, .Lfe8_soff
	ldrb    r9, [r9, r12]
	ldr     r7, [sp]
	ldrh    r9, [r7, r9]
	ldr     r7, [sp, #8]
	ldr     r7, [r7, r9, lsl #3]        @ -2T of the pixel
	.endif
	FE8_ROW r1, 1
	FE8_ROW r2, 0
	FE8_ROW r3, 0
	movs    r4, r4, asr #9              @ c
	ble     .Lfe8_cn\@
	cmp     r5, #0
	rsblt   r5, r5, #0
	asr     r5, r5, #9                  @ a
	cmp     r6, #0
	rsblt   r6, r6, #0
	asr     r6, r6, #8                  @ b
	mul     r9, r5, r5
	mla     r9, r6, r6, r9
	mul     r10, r4, r4
	cmp     r10, r9
	orrgt   r8, r8, r0
.Lfe8_cn\@:
	bics    r11, r11, r0
	bne     .Lfe8_cl\@
	.if \same
	pop     {r11}
	b       .Lfe8_bytes
	.else
	pop     {r9, r11, lr}
	.endif
	.endm

.Lfe8_hit:                                  @ r0: OR of the lower half, r9: upper, r1: both
	push    {r4-r9, lr}                 @ a at [sp, #28], r9 at [sp, #20]
	ldr     r12, [sp, #28]
	add     r12, r12, #52
	ldm     r12, {r2, r3}               @ sdelta, table
	add     r9, r2, r4, lsr #1
	ldm     r9, {r2, r5, r6, r7}        @ pixels 8g .. 8g+7
	usub16  r10, r2, r5
	sel     r2, r5, r2
	usub16  r10, r6, r7
	sel     r6, r7, r6
	usub16  r10, r2, r6
	sel     r2, r6, r2
	uxth    r5, r2
	cmp     r5, r2, lsr #16
	movhi   r5, r2, lsr #16             @ the least smoothed value
	ldr     r7, [r3, r5, lsl #3]        @ no pixel's threshold is below its
	cmp     r1, r7
	ble     .Lfe8_none
	mov     lr, r3
	ldr     r12, [sp, #28]
	ldm     r12, {r1, r2, r3, r10}
	add     r1, r1, r4
	add     r2, r2, r4
	add     r3, r3, r4
	mov     r8, #0
	mov     r11, #0
	ldr     r12, [lr, #2040]            @ the threshold in full light, the greatest
	cmp     r7, r12
	beq     .Lfe8_same
	cmp     r0, r7
	ble     .Lfe8_hi
	FE8_NMS -32, 1, 1, 0
	FE8_NMS -28, 2, 1, 4
	FE8_NMS -24, 4, 1, 2
	FE8_NMS -20, 8, 1, 6
.Lfe8_hi:
	ldr     r0, [sp, #20]
	cmp     r0, r7
	ble     .Lfe8_nmsdone
	FE8_NMS -16, 16, 1, 8
	FE8_NMS -12, 32, 1, 12
	FE8_NMS -8, 64, 1, 10
	FE8_NMS -4, 128, 1, 14
	b       .Lfe8_nmsdone
.Lfe8_same:                                 @ every pixel's threshold is r7
	cmp     r0, r7
	ble     .Lfe8_samehi
	FE8_NMS -32, 1
	FE8_NMS -28, 2
	FE8_NMS -24, 4
	FE8_NMS -20, 8
.Lfe8_samehi:
	ldr     r0, [sp, #20]
	cmp     r0, r7
	ble     .Lfe8_samedone
	FE8_NMS -16, 16
	FE8_NMS -12, 32
	FE8_NMS -8, 64
	FE8_NMS -4, 128
	b       .Lfe8_samedone
.Lfe8_nmsdone:
	cmp     r11, #0                     @ also clears V for the corner loop
	bne     .Lfe8_corners
.Lfe8_none:
	pop     {r4-r9, lr}
	str     r8, [r5], #4
	str     r8, [r5], #4
	cmp     r4, r6
	bne     .Lfe8_scan
	b       .Lfe8_done
.Lfe8_samedone:
	cmp     r11, #0
	beq     .Lfe8_none
	FE8_CORNERS 1
.Lfe8_corners:
	FE8_CORNERS 0
.Lfe8_bytes:
	adr     r12, .Lfe8_spread
	and     r0, r11, #15
	ldr     r0, [r12, r0, lsl #2]
	lsr     r1, r11, #4
	ldr     r1, [r12, r1, lsl #2]
	cmp     r8, #0
	beq     .Lfe8_out
	and     r2, r8, #15
	ldr     r2, [r12, r2, lsl #2]
	add     r0, r0, r2, lsl #1
	lsr     r2, r8, #4
	ldr     r2, [r12, r2, lsl #2]
	add     r1, r1, r2, lsl #1
.Lfe8_out:
	pop     {r4-r9, lr}
	str     r0, [r5], #4
	str     r1, [r5], #4
	orr     lr, lr, r11
	cmp     r4, r6
	bne     .Lfe8_scan
	b       .Lfe8_done
	.p2align 2
.Lfe8_spread:                               @ bit j of the index -> byte j = 1
	.word   0x00000000, 0x00000001, 0x00000100, 0x00000101
	.word   0x00010000, 0x00010001, 0x00010100, 0x00010101
	.word   0x01000000, 0x01000001, 0x01000100, 0x01000101
	.word   0x01010000, 0x01010001, 0x01010100, 0x01010101
	.set    .Lfe8_soff, . - 24          @ indexed by 31 - i: pixel i's smoothed offset
	.byte   14, 10, 12, 8, 6, 2, 4, 0
	.size frappe_armv6_edge_row8, .-frappe_armv6_edge_row8
	.purgem FE8_NMS
	.purgem FE8_ROW
	.purgem FE8_CORNERS
)"
#if defined(__thumb__)
	"\t.thumb\n"
#endif
);

bool edgeRowV6(const GradRows &rows, int w, const FrontEndParams &params, std::uint8_t *out)
{
	out[0] = 0;
	out[w - 1] = 0;
	LightTable own;
	const LightTable &lt = lightTable(params, own);
	const EdgeRowCtx e{ rows.mag[0], rows.mag[1], rows.mag[2], { rows.gx[0], rows.gx[1], rows.gx[2] } };
	const std::int32_t *mid = rows.mag[1];
	const int x1 = w - 1;
	int x = 1;
	u32 any = 0;
	/* Groups of eight from pixel 0, as the smoothed row's blocks: pixels 0
	 * and w-1 (magnitude 0) are never edges while no threshold is
	 * negative. A group's least smoothed value has the least threshold of
	 * its pixels: thresholds rise with the light (light_floor >= 0). */
	if (const int groups = w / 8; groups > 0 && params.light_floor >= 0 && lt.t[0][0] >= 0) {
		auto bytesFromMid = [&](const void *p) {
			return static_cast<std::int32_t>(reinterpret_cast<std::intptr_t>(p) -
							 reinterpret_cast<std::intptr_t>(mid));
		};
		auto address = [](const void *p) { return static_cast<u32>(reinterpret_cast<std::uintptr_t>(p)); };
		EdgeRowAsm a{ bytesFromMid(e.up),
			      bytesFromMid(e.down),
			      bytesFromMid(e.pairs[1]),
			      53 | 128 << 16,
			      bytesFromMid(e.pairs[0]) + 88,
			      bytesFromMid(e.pairs[1]) + 88,
			      bytesFromMid(e.pairs[2]) + 88,
			      0,
			      mid,
			      out,
			      mid + 8 * groups,
			      lt.t[0][0],
			      0,
			      address(rows.smooth) - (address(mid) + 32) / 2,
			      &lt.t[0][0] };
		frappe_armv6_edge_row8(&a);
		x = 8 * groups;
		any = a.any;
	}
	for (; x < x1; ++x) {
		const std::int32_t m = mid[x];
		const std::int32_t *t = lt.t[getSmoothed(rows.smooth, x)];
		const u32 v = m > t[0] ? edgePixel(e, x, m, -t[1]) : 0;
		out[x] = static_cast<std::uint8_t>(v);
		any |= v;
	}
	return any != 0;
}
} // namespace

/* Two tiles' 32 bytes by one LDM (edge rows are word aligned when the
 * width is a multiple of four): 12 instructions per two tiles, the loop of
 * one tile a step 16, GCC's 28. The occupancy bytes are 0 or 1, so storing
 * 1 is ORing. */
__attribute__((optimize("omit-frame-pointer"))) void markTilesV6(const std::uint8_t *edgeRow, int w, std::uint8_t *tileRow)
{
	const int tiles = w / EdgeMap::kTile;
	if (tiles == 0 || (reinterpret_cast<std::uintptr_t>(edgeRow) & 3) != 0) {
		markTilesScalar(edgeRow, w, tileRow);
		return;
	}
	static_assert(EdgeMap::kTile == 16);
	const std::uint8_t *p = edgeRow;
	std::uint8_t *t = tileRow;
	if (tiles >= 2) {
		const std::uint8_t *const end = edgeRow + 2 * EdgeMap::kTile * (tiles / 2);
		/* Unified syntax for the conditional stores (GCC's inline asm
		 * is divided in ARM state; it switches back after the block);
		 * the ITs are for Thumb-2 and assemble to nothing in ARM state. */
		__asm__ volatile(".syntax unified\n\t"
				 "1:\n\t"
				 "ldmia   %[p]!, {r4-r11}\n\t"
				 "orr     r4, r4, r5\n\t"
				 "orr     r6, r6, r7\n\t"
				 "orr     r8, r8, r9\n\t"
				 "orr     r10, r10, r11\n\t"
				 "orrs    r4, r4, r6\n\t"
				 "it      ne\n\t"
				 "strbne  %[one], [%[t]]\n\t"
				 "orrs    r8, r8, r10\n\t"
				 "it      ne\n\t"
				 "strbne  %[one], [%[t], #1]\n\t"
				 "add     %[t], %[t], #2\n\t"
				 "cmp     %[p], %[end]\n\t"
				 "bne     1b"
				 : [p] "+r"(p), [t] "+r"(t)
				 : [end] "r"(end), [one] "r"(1u)
				 : "r4", "r5", "r6", "r7", "r8", "r9", "r10", "r11", "cc", "memory");
	}
	if (tiles & 1) {
		std::uint32_t v[4];
		std::memcpy(v, p, 16);
		if (v[0] | v[1] | v[2] | v[3])
			*t = 1;
		p += EdgeMap::kTile;
		++t;
	}
	if (EdgeMap::kTile * tiles < w)
		markTilesScalar(p, w - EdgeMap::kTile * tiles, t);
}

const RowKernels &armv6RowKernels()
{
	static constexpr RowKernels kArmv6{ "armv6-simd32", smoothRowV6, gradientRowV6, edgeRowV6 };
	return kArmv6;
}

const BandKernels &armv6BandKernels()
{
	static constexpr BandKernels kArmv6{ "armv6-simd32", [](const BandJob &job) {
		runBandRows(armv6RowKernels(), job);
	} };
	return kArmv6;
}

} // namespace frappe::detail

#endif
