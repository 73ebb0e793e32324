// SPDX-License-Identifier: MIT
// The contour tracer's kernels for ARMv6 with the SIMD32 instructions (the
// Pi Zero's ARM1176), beside their scalar references in trace_kernels.cpp;
// tests/armv6 checks them against each other.
//
// A border point is (x | y << 16) with x, y < 2^15: two 16-bit lanes, so a
// point minus a point is one SSUB16 (exact: the differences fit an int16),
// dx^2 + dy^2 one SMUAD and a cross product one SMUSDX; the least and
// greatest of both coordinates are USUB16 + SEL.
#include "trace_kernels.h"

#ifdef FRAPPE_HAVE_ARMV6_TRACE

#include <arm_acle.h>

#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace frappe::detail {

/* Functions whose inline asm names r4-r7 (LDM lists must ascend) keep no
 * frame pointer, which is r7 in Thumb code and r11 in ARM code, also at
 * -O0 (the attribute on each). */

namespace {

using u32 = std::uint32_t;

inline u32 ssub16(u32 a, u32 b)
{
	return static_cast<u32>(__ssub16(static_cast<int16x2_t>(a), static_cast<int16x2_t>(b)));
}

/* Lane-wise least and greatest of unsigned 16-bit lanes. */
inline u32 min16(u32 a, u32 b)
{
	u32 t, r;
	__asm__("usub16 %[t], %[a], %[b]\n\tsel %[r], %[b], %[a]" : [t] "=&r"(t), [r] "=&r"(r) : [a] "r"(a), [b] "r"(b) : "cc");
	return r;
}

inline u32 max16(u32 a, u32 b)
{
	u32 t, r;
	__asm__("usub16 %[t], %[a], %[b]\n\tsel %[r], %[a], %[b]" : [t] "=&r"(t), [r] "=&r"(r) : [a] "r"(a), [b] "r"(b) : "cc");
	return r;
}

} // namespace

/* Eight words a step by LDM / STM (both buffers are vectors' data, word
 * aligned): 19 instructions per 32 bytes where the compiler's word loop
 * takes 40. r4-r11 are named: no frame pointer, also at -O0. */
__attribute__((optimize("omit-frame-pointer"))) void labelsFromEdgesV6(const std::uint8_t *edges, std::size_t n,
								       std::uint8_t *labels)
{
	std::size_t i = 0;
	if (((reinterpret_cast<std::uintptr_t>(edges) | reinterpret_cast<std::uintptr_t>(labels)) & 3) == 0 && n >= 32) {
		const std::uint8_t *src = edges;
		std::uint8_t *dst = labels;
		const std::uint8_t *const end = edges + (n & ~std::size_t{ 31 });
		const u32 mask = 0x01010101u * kUnfollowed;
		__asm__ volatile("1:\n\t"
				 "ldmia   %[src]!, {r4, r5, r6, r7, r8, r9, r10, r11}\n\t"
				 "and     r4, r4, %[m]\n\t"
				 "and     r5, r5, %[m]\n\t"
				 "and     r6, r6, %[m]\n\t"
				 "and     r7, r7, %[m]\n\t"
				 "and     r8, r8, %[m]\n\t"
				 "and     r9, r9, %[m]\n\t"
				 "and     r10, r10, %[m]\n\t"
				 "and     r11, r11, %[m]\n\t"
				 "stmia   %[dst]!, {r4, r5, r6, r7, r8, r9, r10, r11}\n\t"
				 "cmp     %[src], %[end]\n\t"
				 "bne     1b"
				 : [src] "+r"(src), [dst] "+r"(dst)
				 : [end] "r"(end), [m] "r"(mask)
				 : "r4", "r5", "r6", "r7", "r8", "r9", "r10", "r11", "cc", "memory");
		i = n & ~std::size_t{ 31 };
	}
	for (; i < n; ++i)
		labels[i] = edges[i] & kUnfollowed;
}

__attribute__((optimize("omit-frame-pointer"))) OutlineExtremes outlineExtremesV6(const std::uint32_t *pts, std::size_t n)
{
	/* Below 2^15 points the sums fit an int32: the same sums, so the same
	 * centroid, as the scalar form's int64 ones. */
	if (n >= (std::size_t{ 1 } << 15))
		return outlineExtremesScalar(pts, n);
	/* Four points a step by LDM (the points are a u32 array): UXTAH adds
	 * the low lane, an ADD with LSR the high one. */
	std::int32_t sx = 0, sy = 0;
	const std::uint32_t *const end4 = pts + (n & ~std::size_t{ 3 });
	register u32 q0 __asm__("r4"), q1 __asm__("r5"), q2 __asm__("r6"), q3 __asm__("r7");
	if (end4 != pts) {
		const std::uint32_t *p = pts;
		__asm__("1:\n\t"
			"ldmia   %[p]!, {%[q0], %[q1], %[q2], %[q3]}\n\t"
			"uxtah   %[sx], %[sx], %[q0]\n\t"
			"add     %[sy], %[sy], %[q0], lsr #16\n\t"
			"uxtah   %[sx], %[sx], %[q1]\n\t"
			"add     %[sy], %[sy], %[q1], lsr #16\n\t"
			"uxtah   %[sx], %[sx], %[q2]\n\t"
			"add     %[sy], %[sy], %[q2], lsr #16\n\t"
			"uxtah   %[sx], %[sx], %[q3]\n\t"
			"add     %[sy], %[sy], %[q3], lsr #16\n\t"
			"cmp     %[p], %[end]\n\t"
			"bne     1b"
			: [p] "+r"(p), [sx] "+r"(sx), [sy] "+r"(sy), [q0] "=&r"(q0), [q1] "=&r"(q1), [q2] "=&r"(q2),
			  [q3] "=&r"(q3)
			: [end] "r"(end4)
			: "cc", "memory");
	}
	for (const std::uint32_t *p = end4; p != pts + n; ++p) {
		sx += static_cast<std::int32_t>(*p & 0xFFFFu);
		sy += static_cast<std::int32_t>(*p >> 16);
	}
	/* The farthest point from the centroid: the scalar form's double
	 * arithmetic, as it is (its result depends on the rounding). */
	const double mx = static_cast<double>(sx) / static_cast<double>(n);
	const double my = static_cast<double>(sy) / static_cast<double>(n);
	OutlineExtremes e;
	double bd = -1;
	for (std::size_t i = 0; i < n; ++i) {
		const double dx = static_cast<std::int32_t>(pts[i] & 0xFFFFu) - mx;
		const double dy = static_cast<std::int32_t>(pts[i] >> 16) - my;
		if (dx * dx + dy * dy > bd) {
			bd = dx * dx + dy * dy;
			e.i0 = i;
		}
	}
	/* The rest on both lanes at once: d = p - p0, |d|^2 = SMUAD(d, d),
	 * cross(p0, p2, p) = ex dy - ey dx = SMUSDX(e, d). */
	const u32 p0 = pts[e.i0];
	std::int32_t bd2 = -1;
	/* The farthest from p0, four points a step by LDM; the best is kept
	 * as the address of its point (the LDM base minus its offset). */
	const std::uint32_t *best = pts;
	if (end4 != pts) {
		const std::uint32_t *p = pts;
		u32 t;
		__asm__(".syntax unified\n\t"
			"1:\n\t"
			"ldmia   %[p]!, {%[q0], %[q1], %[q2], %[q3]}\n\t"
#define FRAPPE_FARTHEST(Q, OFF)                                              \
			"ssub16  %[t], %[" Q "], %[p0]\n\t"                    \
			"smuad   %[t], %[t], %[t]\n\t"                           \
			"cmp     %[t], %[bd]\n\t"                                \
			"itt     gt\n\t"                                         \
			"movgt   %[bd], %[t]\n\t"                                \
			"subgt   %[best], %[p], #" OFF "\n\t"
			FRAPPE_FARTHEST("q0", "16") FRAPPE_FARTHEST("q1", "12")
			FRAPPE_FARTHEST("q2", "8") FRAPPE_FARTHEST("q3", "4")
#undef FRAPPE_FARTHEST
			"cmp     %[p], %[end]\n\t"
			"bne     1b"
			: [p] "+r"(p), [bd] "+r"(bd2), [best] "+r"(best), [t] "=&r"(t), [q0] "=&r"(q0), [q1] "=&r"(q1),
			  [q2] "=&r"(q2), [q3] "=&r"(q3)
			: [end] "r"(end4), [p0] "r"(p0)
			: "cc", "memory");
	}
	for (const std::uint32_t *p = end4; p != pts + n; ++p) {
		const u32 d = ssub16(*p, p0);
		const std::int32_t d2 = __smuad(static_cast<int16x2_t>(d), static_cast<int16x2_t>(d));
		if (d2 > bd2) {
			bd2 = d2;
			best = p;
		}
	}
	const std::size_t i2 = static_cast<std::size_t>(best - pts);
	e.i2 = i2;
	const u32 ed = ssub16(pts[i2], p0);
	/* The farthest on either side of the diagonal, four points a step
	 * by LDM; as for i2, each is kept as the address of its point. A
	 * cross product above most (>= 0) is never below least (<= 0): two
	 * independent tests are the scalar form's if / else. */
	std::int32_t most = 0, least = 0;
	const std::uint32_t *b1 = pts, *b3 = pts;
	if (end4 != pts) {
		const std::uint32_t *p = pts;
		u32 t;
		__asm__(".syntax unified\n\t"
			"1:\n\t"
			"ldmia   %[p]!, {%[q0], %[q1], %[q2], %[q3]}\n\t"
#define FRAPPE_ACROSS(Q, OFF)                                                                                          \
	"ssub16  %[t], %[" Q                                                                                           \
	"], %[p0]\n\t"                                                                                                 \
	"smusdx  %[t], %[ed], %[t]\n\t"                                                                                \
	"cmp     %[t], %[most]\n\t"                                                                                    \
	"itt     gt\n\t"                                                                                               \
	"movgt   %[most], %[t]\n\t"                                                                                    \
	"subgt   %[b1], %[p], #" OFF                                                                                   \
	"\n\t"                                                                                                         \
	"cmp     %[t], %[least]\n\t"                                                                                   \
	"itt     lt\n\t"                                                                                               \
	"movlt   %[least], %[t]\n\t"                                                                                   \
	"sublt   %[b3], %[p], #" OFF "\n\t"
			FRAPPE_ACROSS("q0", "16") FRAPPE_ACROSS("q1", "12") FRAPPE_ACROSS("q2", "8")
				FRAPPE_ACROSS("q3", "4")
#undef FRAPPE_ACROSS
					"cmp     %[p], %[end]\n\t"
					"bne     1b"
			: [p] "+r"(p), [most] "+r"(most), [least] "+r"(least), [b1] "+r"(b1), [b3] "+r"(b3),
			  [t] "=&r"(t), [q0] "=&r"(q0), [q1] "=&r"(q1), [q2] "=&r"(q2), [q3] "=&r"(q3)
			: [end] "r"(end4), [p0] "r"(p0), [ed] "r"(ed)
			: "cc", "memory");
	}
	for (const std::uint32_t *p = end4; p != pts + n; ++p) {
		const std::int32_t c = __smusdx(static_cast<int16x2_t>(ed), static_cast<int16x2_t>(ssub16(*p, p0)));
		if (c > most) {
			most = c;
			b1 = p;
		} else if (c < least) {
			least = c;
			b3 = p;
		}
	}
	e.i1 = static_cast<std::size_t>(b1 - pts);
	e.i3 = static_cast<std::size_t>(b3 - pts);
	e.most = most;
	e.least = least;
	return e;
}

std::uint32_t sideCoverageV6(const std::uint32_t *pts, std::size_t n, const SideLine &side, float tol, int bound,
			     int need, std::size_t first)
{
	/* A point far from the line is told in integers first, with SMLAD on
	 * its two lanes: a = NX x + NY y - NC, the side's normal and offset
	 * in Q14, truncated (NX = (int) (2^14 nx) ...: conversions, no libm).
	 * Each is off by less than 1, so a is off by less than x + y + 1 <=
	 * bound + 1 from 2^14 (nx x + ny y - nc); the float sum is off by at
	 * most 4 * 2^-24 (|nx| x + |ny| y + |nc|) <= 2^-21 * 3 bound (with
	 * |nx|, |ny| <= 1.5 and |nc| <= bound + 1) from the exact one, below
	 * bound / 64 in Q14. So |a| > T = (int) (2^14 tol) + bound + bound / 64
	 * + 4 means the float test rejects the point too. Only the others
	 * take the scalar form's float arithmetic, which decides. */
	const bool ok = bound >= 0 && bound <= (1 << 15) && std::abs(side.nx) <= 1.5f && std::abs(side.ny) <= 1.5f &&
			std::abs(side.nc) <= static_cast<float>(bound + 1) && tol >= 0.0f && tol < 16384.0f;
	if (!ok)
		return sideCoverageScalar(pts, n, side, tol);
	const std::int32_t nx = static_cast<std::int32_t>(side.nx * 16384.0f);
	const std::int32_t ny = static_cast<std::int32_t>(side.ny * 16384.0f);
	const std::int32_t nc = static_cast<std::int32_t>(side.nc * 16384.0f);
	const u32 normal = static_cast<u32>(nx & 0xFFFF) | static_cast<u32>(ny) << 16;
	const std::int32_t T = static_cast<std::int32_t>(tol * 16384.0f) + bound + bound / 64 + 4;
	const u32 span = 2 * static_cast<u32>(T);
	std::uint32_t covered = 0;
	/* Bins still to cover before the caller's answer is known: the
	 * scan stops there (a side that is covered is usually so half-way
	 * through its own stretch of the border). */
	int left = need > 0 ? need : INT_MAX;
	/* Points [from, to); false once the answer is known. */
	auto scan = [&](const std::uint32_t *from, const std::uint32_t *to) {
		for (const std::uint32_t *p = from; p != to; ++p) {
			u32 v = *p;
			const std::int32_t a = __smlad(static_cast<int16x2_t>(v), static_cast<int16x2_t>(normal), -nc);
			if (static_cast<u32>(a + T) > span) /* a > T or a < -T */
				continue;
			__asm__("" : "+r"(v)); /* unpack only here, not before the test */
			const float px = static_cast<float>(v & 0xFFFFu), py = static_cast<float>(v >> 16);
			if (std::abs(side.nx * px + side.ny * py - side.nc) > tol)
				continue;
			const float t = side.ux * px + side.uy * py - side.t0;
			if (t >= 0.0f && t < static_cast<float>(kSideBins)) {
				const std::uint32_t bit = 1u << static_cast<int>(t);
				if ((covered & bit) == 0) {
					covered |= bit;
					if (--left == 0)
						return false;
				}
			}
		}
		return true;
	};
	const std::uint32_t *const start = pts + (first < n ? first : 0);
	if (scan(start, pts + n))
		scan(pts, start);
	return covered;
}

__attribute__((optimize("omit-frame-pointer"))) PointsBox pointsBoxV6(const std::uint32_t *pts, std::size_t n)
{
	u32 lo = pts[0], hi = lo;
	std::size_t i = 0;
	if (n >= 4) {
		/* Four points a step by LDM. */
		const std::uint32_t *p = pts;
		const std::uint32_t *const end = pts + (n & ~std::size_t{ 3 });
		register u32 q0 __asm__("r4"), q1 __asm__("r5"), q2 __asm__("r6"), q3 __asm__("r7");
		u32 t;
		__asm__("1:\n\t"
			"ldmia   %[p]!, {%[q0], %[q1], %[q2], %[q3]}\n\t"
#define FRAPPE_BOX(Q)                                                        \
			"usub16  %[t], %[" Q "], %[lo]\n\t"                    \
			"sel     %[lo], %[lo], %[" Q "]\n\t"                   \
			"usub16  %[t], %[" Q "], %[hi]\n\t"                    \
			"sel     %[hi], %[" Q "], %[hi]\n\t"
			FRAPPE_BOX("q0") FRAPPE_BOX("q1") FRAPPE_BOX("q2") FRAPPE_BOX("q3")
#undef FRAPPE_BOX
			"cmp     %[p], %[end]\n\t"
			"bne     1b"
			: [p] "+r"(p), [lo] "+r"(lo), [hi] "+r"(hi), [t] "=&r"(t), [q0] "=&r"(q0), [q1] "=&r"(q1),
			  [q2] "=&r"(q2), [q3] "=&r"(q3)
			: [end] "r"(end)
			: "cc", "memory");
		i = n & ~std::size_t{ 3 };
	}
	for (; i + 2 <= n; i += 2) {
		const u32 a = pts[i], b = pts[i + 1];
		lo = min16(min16(lo, a), b);
		hi = max16(max16(hi, a), b);
	}
	if (i < n) {
		lo = min16(lo, pts[i]);
		hi = max16(hi, pts[i]);
	}
	return { lo & 0xFFFFu, hi & 0xFFFFu, lo >> 16, hi >> 16 };
}

} // namespace frappe::detail

#endif
