// SPDX-License-Identifier: MIT
// Suzuki & Abe (1985) border following, list mode: every border of the
// 8-connected edge pixels is followed exactly once. Label values (bit 0 set
// on every non-zero label, so a neighbour test is one AND; the other bits
// are 3 and 4, so that three rows' bit 0 can be gathered with one AND):
//   0 background, 1 (kUnfollowed) edge not yet on a followed border,
//   9 (kFollowed) on a followed border, 25 (kFollowedRightBg) on a followed
//   border whose right neighbour (examined while following) is background:
//   the paper's -NBD, which stops a second hole border from starting at the
//   same place. Sealed marker insides are kFollowedRightBg too: nothing
//   starts there.
// Empty 16x16 tiles hold no edge pixel, so the raster scan jumps over them.
// The data-parallel parts (where borders start, each pixel's neighbour mask,
// a candidate's extreme points, box and side coverage) are trace_kernels.cpp,
// vectorised where Highway is built in; the walk itself is follow().
#include "contour_trace.h"
#include "quad_geometry.h"
#include "rounding.h"
#include "trace_kernels.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <span>
#include <type_traits>

namespace frappe::detail {

namespace {

/* Following a pixel ORs one of the two marks into its label: 1 -> 9 or 25,
 * 9 -> 9 or 25, 25 stays. */
constexpr std::uint8_t kMarkFollowed = 8, kMarkRightBg = 24;
static_assert((kUnfollowed | kMarkFollowed) == kFollowed && (kFollowed | kMarkRightBg) == kFollowedRightBg);

/* Neighbour offsets, counter-clockwise on screen starting at the right. */
constexpr int kDx[8] = { 1, 1, 0, -1, -1, -1, 0, 1 };
constexpr int kDy[8] = { 0, -1, -1, -1, 0, 1, 1, 1 };

/* xy steps per direction back (the move is the opposite direction). */
constexpr std::int32_t kDxyBack[8] = { -kDx[0] - kDy[0] * 65536, -kDx[1] - kDy[1] * 65536,
				       -kDx[2] - kDy[2] * 65536, -kDx[3] - kDy[3] * 65536,
				       -kDx[4] - kDy[4] * 65536, -kDx[5] - kDy[5] * 65536,
				       -kDx[6] - kDy[6] * 65536, -kDx[7] - kDy[7] * 65536 };

/* Step 3.3 of Suzuki's algorithm as a table: for the direction `back` to the
 * previous border pixel and the mask of non-zero neighbours (bit d for
 * direction d), the first non-zero neighbour counter-clockwise after `back`
 * (low 3 bits) and whether the right neighbour (direction 0) was examined
 * and found zero on the way (bit 3). Replaces a data-dependent loop whose
 * branches the CPU cannot predict. */
struct NextStepTable {
	std::uint8_t entry[8][256];
	constexpr NextStepTable() : entry{}
	{
		for (int back = 0; back < 8; ++back)
			for (int mask = 1; mask < 256; ++mask) {
				bool rightExamined = false;
				for (int k = 1; k <= 8; ++k) {
					const int d = (back + k) & 7;
					if (mask & (1 << d)) {
						entry[back][mask] = static_cast<std::uint8_t>(d | (rightExamined ? 8 : 0));
						break;
					}
					if (d == 0)
						rightExamined = true;
				}
			}
	}
};
constexpr NextStepTable kNextStep;

/* The same table indexed by the neighbourhood read a row at a time (see
 * neighbourIndex): bits 0..2 column x+1 (rows above, this, below), 3..5
 * column x (the centre, bit 4, is ignored), 6..8 column x-1. */
struct RowStepTable {
	std::uint8_t entry[8][512];
	constexpr RowStepTable() : entry{}
	{
		/* Index bit of each direction, in kDx/kDy order. */
		constexpr int kBit[8] = { 1, 0, 3, 6, 7, 8, 5, 2 };
		for (int back = 0; back < 8; ++back)
			for (int idx = 0; idx < 512; ++idx) {
				int mask = 0;
				for (int d = 0; d < 8; ++d)
					mask |= ((idx >> kBit[d]) & 1) << d;
				entry[back][idx] = kNextStep.entry[back][mask];
			}
	}
};
constexpr RowStepTable kRowStep;

/* The neighbour mask (bit d for direction d) of a neighbourIndex. */
struct MaskOfIndex {
	std::uint8_t mask[512];
	constexpr MaskOfIndex() : mask{}
	{
		constexpr int kBit[8] = { 1, 0, 3, 6, 7, 8, 5, 2 }; /* as RowStepTable */
		for (int idx = 0; idx < 512; ++idx)
			for (int d = 0; d < 8; ++d)
				mask[idx] = static_cast<std::uint8_t>(mask[idx] | ((idx >> kBit[d]) & 1) << d);
	}
};
[[maybe_unused]] constexpr MaskOfIndex kMaskOfIndex;

inline std::uint32_t load32(const std::uint8_t *p)
{
	std::uint32_t v;
	std::memcpy(&v, p, 4);
	return v;
}

/* The RowStepTable index of the 3x3 neighbourhood around p. The three rows'
 * words (p[3] is read too: the label image has padding) are ORed with
 * shifts of 0, 1, 2, so that bits 0..2 of byte i hold column x-1+i's
 * rows; labels use no bit above 4, so nothing crosses into the next byte.
 * One multiply then moves byte 0's three bits to 29..31, byte 1's to
 * 26..28, byte 2's to 23..25 (the other products land below bit 21 and
 * apart, so nothing carries), and the index is the top nine bits. */
inline unsigned neighbourIndex(const std::uint8_t *p, std::ptrdiff_t w)
{
	if constexpr (std::endian::native == std::endian::little) {
		const std::uint32_t raw = (load32(p - w - 1) | load32(p - 1) << 1 | load32(p + w - 1) << 2) & 0x00070707u;
		return (raw * ((1u << 29) | (1u << 18) | (1u << 7))) >> 23;
	} else {
		unsigned idx = 0;
		for (int dx = -1; dx <= 1; ++dx)
			for (int dy = -1; dy <= 1; ++dy)
				idx |= static_cast<unsigned>(p[dy * w + dx] != 0) << (3 * (1 - dx) + dy + 1);
		return idx;
	}
}

/* Labels of four pixels at p, `here` (their neighbours at p - 1 .. p + 4
 * must be readable): bit 0 of byte i set where pixel i may start a border
 * (see borderStartBits), for 32-bit targets, where 64-bit shifts take
 * several instructions. */
inline std::uint32_t borderStarts4(const std::uint8_t *p, std::uint32_t here)
{
	/* labels are 0, 1, 9, 25: bit 3 marks a followed pixel, bit 4 one
	 * whose right neighbour is background; bit 0 of (left | b3) & (right |
	 * b4) clear: an outer or a hole start */
	return here & ~((load32(p - 1) | here >> 3) & (load32(p + 1) | here >> 4)) & 0x01010101u;
}

/* From x (x + 8 <= x1), the first pixel of the first group of eight with a
 * possible border start (see borderStarts4), or the first pixel left over
 * when fewer than eight remain before x1. Through pointers, and both halves
 * of a group tested without a branch between them: the compiler keeps the
 * loop in registers (7 instructions a group of empty pixels on ARMv6). */
inline int nextStart(const std::uint8_t *row, int x, int x1)
{
	const std::uint8_t *p = row + x;
	const std::uint8_t *const last = row + x1 - 8;
	for (; p <= last; p += 8) {
		const std::uint32_t h0 = load32(p), h1 = load32(p + 4);
		if ((h0 | h1) == 0)
			continue;
		const std::uint32_t s0 = borderStarts4(p, h0), s1 = borderStarts4(p + 4, h1);
		if ((s0 | s1) == 0)
			continue;
		const int at = static_cast<int>(p - row);
		return s0 ? at + (std::countr_zero(s0) >> 3) : at + 4 + (std::countr_zero(s1) >> 3);
	}
	return static_cast<int>(p - row);
}

float cross(Point2f o, Point2f a, Point2f b)
{
	return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

/* More corner clusters than this on one border: clutter, not a marker. */
constexpr std::size_t kMaxClusters = 12;

/* A key that orders directions (x, y) as atan2(y, x) does, over (-pi, pi],
 * without libm: y / (|x| + |y|) is monotonic in the angle on either side
 * of the y axis; the left half is shifted to (1, 2] and [-2, -1). */
float pseudoAngle(float y, float x)
{
	const float s = std::abs(x) + std::abs(y);
	if (s == 0.0f)
		return 0.0f;
	const float p = y / s;
	if (x >= 0.0f)
		return p;
	return std::signbit(y) ? -2.0f - p : 2.0f - p;
}

#ifdef FRAPPE_HAVE_ARMV6_TRACE
/* The 32-bit walk of follow() in ARM assembly: GCC's code for it spilled
 * three values and built the index's mask and multiply from four BICs and
 * three shifted ADDs, 38 instructions a step; this takes 28. It runs steps
 * until the one at p1 or the one that fills the points, which it returns
 * after storing the point and before moving on: p, xy, out, cout and s
 * (then the step's table entry) are written back. */
struct FollowAsm {
	std::uint8_t *p;		  ///< 0: the current pixel's label
	std::uint32_t xy;		  ///< 4: its coordinates, x | y << 16
	std::uint32_t *out, *cout;	  ///< 8, 12: where its point and corner go
	std::uint32_t s;		  ///< 16: in: the table row (back << 9); out: the entry
	const std::int32_t *table;        ///< 20: the step table (kDxyBack[b] at row b, index 0)
	std::int32_t up, down;		  ///< 24, 28: -w - 1, w - 1
	std::int32_t toEdge;		  ///< 32: edge map minus labels (bytes)
	const std::uint8_t *p1;		  ///< 36
	const std::uint32_t *outEnd;	  ///< 40
	std::uint32_t mask;		  ///< 44: 0x00070707
};
static_assert(offsetof(FollowAsm, mask) == 44);
extern "C" void frappe_armv6_follow(FollowAsm *a);
/* The same without the corner list (cout is left as it is): for maps
 * without corner pixels. */
extern "C" void frappe_armv6_follow_bare(FollowAsm *a);

/* r1 p, r2 xy, r3 out, r4 cout, r5 row / entry, r6 table, r7 up, r8 down,
 * r9 toEdge, r10 p1, r11 outEnd, r12 mask; r0, lr temporaries. The index
 * as neighbourIndex: the multiply by 2^7 (1 + 2^11 + 2^22) as two ADDs
 * and a shift. */
__asm__(R"(
	.text
	.arm
	.syntax unified
	.macro FRAPPE_FOLLOW name, corners
	.p2align 2
	.type \name, %function
\name:
	push    {r0, r4-r11, lr}
	ldm     r0, {r1-r12}
	b       .Lfw_body\@
.Lfw_step\@:
	add     r1, r1, r5, asr #12     @ p = next
	and     r5, r5, #0xE00          @ the next row: direction back
	ldr     lr, [r6, r5, lsl #2]    @ kDxyBack[back], at the row's index 0
	add     r2, r2, lr
.Lfw_body\@:
	ldr     lr, [r1, r7]            @ row above, columns x-1 .. x+2
	ldr     r0, [r1, #-1]
	orr     lr, lr, r0, lsl #1
	ldr     r0, [r1, r8]            @ row below
	orr     lr, lr, r0, lsl #2
	and     lr, lr, r12
	add     r0, lr, lr, lsl #11
	add     lr, lr, r0, lsl #11
	lsl     lr, lr, #7
	orr     lr, r5, lr, lsr #23     @ row | neighbourhood index
	ldr     r5, [r6, lr, lsl #2]    @ the step
	ldrb    r0, [r1]
	and     lr, r5, #24
	orr     r0, r0, lr
	strb    r0, [r1]                @ mark the pixel
	str     r2, [r3], #4            @ its point
	.if \corners
	str     r2, [r4]                @ and, kept if it is a corner,
	ldrb    r0, [r1, r9]
	and     r0, r0, #2
	add     r4, r4, r0, lsl #1      @ its corner
	.endif
	cmp     r3, r11
	cmpne   r1, r10
	bne     .Lfw_step\@
	pop     {r0}
	stm     r0, {r1-r5}
	pop     {r4-r11, pc}
	.size \name, .-\name
	.endm
	FRAPPE_FOLLOW frappe_armv6_follow, 1
	FRAPPE_FOLLOW frappe_armv6_follow_bare, 0
	.purgem FRAPPE_FOLLOW
)"
#if defined(__thumb__)
	"\t.thumb\n"
#endif
);
#endif

} // namespace

void ContourTracer::buildStepTables(int w)
{
	/* Moves as pointer offsets: 16 bits hold them up to this width. */
	useMasks_ = sizeof(void *) >= 8 && w <= 32000;
	if (useMasks_) {
		maskTable_.resize(8 * 256);
		for (int back = 0; back < 8; ++back)
			for (int mask = 0; mask < 256; ++mask) {
				const int e = kNextStep.entry[back][mask];
				const int d = e & 7;
				MaskStep &st = maskTable_[static_cast<std::size_t>(back) * 256 + mask];
				st.offset = static_cast<std::int16_t>(kDx[d] + kDy[d] * w);
				st.back = static_cast<std::uint8_t>((d + 4) & 7);
				st.mark = (e & 8) ? kMarkRightBg : kMarkFollowed;
				st.dxy = static_cast<std::uint32_t>(kDx[d]) +
					 static_cast<std::uint32_t>(kDy[d]) * 65536u;
			}
		stepTable_.clear();
		return;
	}
	/* kRowStep as (offset << 12) | back' << 9 | mark: the move's pointer
	 * offset, the direction back from the pixel it reaches (which selects
	 * the next row of the table), and the label mark of the pixel it
	 * leaves. A walked pixel's own label sets bit 4 of its index, so
	 * indices 0 .. 15 are never looked up: index 0 of row b holds
	 * kDxyBack[b] instead, which the ARMv6 walk reads from the row alone. */
	stepTable_.resize(8 * 512);
	for (int back = 0; back < 8; ++back)
		for (int idx = 0; idx < 512; ++idx) {
			const int e = kRowStep.entry[back][idx];
			const int d = e & 7;
			const auto offset = static_cast<std::uint32_t>(kDx[d] + kDy[d] * w);
			stepTable_[static_cast<std::size_t>(back) * 512 + idx] =
				idx == 0 ? kDxyBack[back]
					 : static_cast<std::int32_t>(offset << 12 |
								     static_cast<std::uint32_t>((d + 4) & 7) << 9 |
								     ((e & 8) ? kMarkRightBg : kMarkFollowed));
		}
	maskTable_.clear();
}

void ContourTracer::trace(const TraceMap &edges, const TraceParams &params, std::vector<Quad> &out,
			  MarkerProbe *probe)
{
	out.clear();
	borders_ = 0;
	const int w = edges.width, h = edges.height;
	if (w < 3 || h < 3)
		return;
	if (stride_ != w || (stepTable_.empty() && maskTable_.empty()))
		buildStepTables(w);
	stride_ = w;
	/* A whole squared distance d2 is within the radius when d2 <= r^2,
	 * i.e. d2 <= floor(r^2). */
	const float radius2 = params.cluster_radius * params.cluster_radius;
	radius2Floor_ = radius2 < 4e18f ? static_cast<std::int64_t>(std::floor(radius2)) : INT64_MAX;
	/* Padding: follow reads neighbours a word at a time, and the start
	 * scan reads a vector past the end of a stretch. */
	labels_.resize(static_cast<std::size_t>(w) * h + 128);
	static_assert(EdgeMap::kEdge == kUnfollowed);
	labelsFromEdges(edges.pixels.data(), static_cast<std::size_t>(w) * h, labels_.data());

	/* A border may start at x of row y: follow it and keep it if it makes a
	 * candidate. */
	auto tryStart = [&](std::uint8_t *row, int x, int y) {
		const std::uint8_t f = row[x];
		if (f == 0)
			return;
		int fromDir;
		if (f == kUnfollowed && row[x - 1] == 0)
			fromDir = 4; /* outer border: came from the left */
		else if (params.holes && !(f & (kFollowedRightBg ^ kFollowed)) && row[x + 1] == 0)
			fromDir = 0; /* hole border: the hole is to the right */
		else
			return;

		++borders_;
		follow(x, y, fromDir, edges, params.corners);
		/* A marker outline is at least four sides of min_side pixels,
		 * and spans at least min_side / sqrt(2) each way. */
		if (static_cast<float>(steps_) < 2.8f * params.min_side)
			return;
		clusterCorners();
		/* Both ways of making a quad below need two clusters. */
		if (clusters_.size() < static_cast<std::size_t>(params.min_clusters))
			return;
		if (!spansAtLeast(0.7f * params.min_side, params.max_winding))
			return;
		/* The paper's rule first: the corner clusters; failing that, the
		 * outline's extreme points, for a border with at least two corner
		 * clusters (a marker whose faint corners did not all register
		 * still has two; clutter with none is most of what reaches here). */
		Quad quad;
		std::array<std::size_t, 4> at;
		if ((!tooManyClusters_ && clusters_.size() >= 4 && quadFromClusters(quad) &&
		     acceptQuad(params, w, h, quad)) ||
		    (clusters_.size() >= static_cast<std::size_t>(params.min_clusters) && quadFromOutline(quad, at) &&
		     acceptQuad(params, w, h, quad, &at))) {
			if (probe && probe->isMarker(quad)) {
				quad.probeDecoded = true;
				sealInside(quad, w, h);
			}
			out.push_back(quad);
		}
	};

	/* The runs of occupied tiles in each row of tiles, as column ranges:
	 * borders run only there. */
	constexpr int T = EdgeMap::kTile;
	stretches_.clear();
	stretchRows_.assign(static_cast<std::size_t>(edges.tiles_y) + 1, 0);
	for (int ty = 0; ty < edges.tiles_y; ++ty) {
		const std::uint8_t *tileRow = edges.tiles.data() + static_cast<std::size_t>(ty) * edges.tiles_x;
		for (int tx = 0; tx < edges.tiles_x; ++tx) {
			if (tileRow[tx] == 0)
				continue;
			int tEnd = tx + 1;
			while (tEnd < edges.tiles_x && tileRow[tEnd])
				++tEnd;
			stretches_.push_back({ std::max(1, tx * T), std::min(w - 1, tEnd * T) });
			tx = tEnd;
		}
		stretchRows_[static_cast<std::size_t>(ty) + 1] = static_cast<int>(stretches_.size());
	}
	auto stretchesOf = [&](int y) {
		const std::size_t ty = static_cast<std::size_t>(y / T);
		return std::span<const std::pair<int, int>>(stretches_.data() + stretchRows_[ty],
							    stretches_.data() + stretchRows_[ty + 1]);
	};

	/* Neighbour masks wherever a border can run: from a row's first
	 * stretch to the end of its last, in one call (the masks of empty
	 * tiles between are computed too, and never read). */
	if (useMasks_) {
		/* Padding: the walk reads a word at a time. */
		masks_.resize(static_cast<std::size_t>(w) * h + 4);
		for (int y = 1; y < h - 1; ++y) {
			const auto stretches = stretchesOf(y);
			if (stretches.empty())
				continue;
			neighbourMasks(edges.pixels.data() + static_cast<std::size_t>(y) * w, w, stretches.front().first,
				       stretches.back().second, masks_.data() + static_cast<std::size_t>(y) * w);
		}
	}
	startWords_.resize(static_cast<std::size_t>(w) / 64 + 2);
	for (int y = 1; y < h - 1; ++y) {
		const auto stretches = stretchesOf(y);
		if (stretches.empty())
			continue;
		std::uint8_t *row = labels_.data() + static_cast<std::size_t>(y) * w;
		if constexpr (std::endian::native == std::endian::little && sizeof(void *) >= 8) {
			/* Where borders may start, one bit a pixel, vectorised, from
			 * the first stretch to the end of the last in one call (the
			 * empty tiles between hold no label, so no start); then each
			 * candidate is checked again, since following and sealing
			 * only ever take starts away, never add one. */
			const int x0 = stretches.front().first, x1 = stretches.back().second;
			std::uint64_t *starts = startWords_.data();
			borderStartBits(row, x0, x1, starts);
			const int words = (x1 - x0 + 63) / 64;
			for (int k = 0; k < words; ++k)
				for (std::uint64_t m = starts[k]; m != 0; m &= m - 1)
					tryStart(row, x0 + 64 * k + std::countr_zero(m), y);
			continue;
		}
		for (const auto &[x0, x1] : stretches) {
			for (int x = x0; x < x1; ++x) {
				/* Most pixels are background or lie on a border
				 * already followed: find the next pixel where a border
				 * can start, eight at a time, as two words (64-bit
				 * shifts are library calls here). */
				if constexpr (std::endian::native == std::endian::little) {
					if (x + 8 <= x1) {
						x = nextStart(row, x, x1);
						if (x >= x1)
							break;
					}
				}
				tryStart(row, x, y);
			}
		}
	}
}

/* Labels the marker's inside kFollowedRightBg, where nothing starts (outer
 * borders start at kUnfollowed, hole borders before a 0), so neither the code's
 * cells nor the hole border of the outline are followed. The quad's sides
 * run within a pixel of the outline, inside or outside it: rows (then
 * columns) are filled across the quad and on through the background left
 * between the quad and the outline, as far as the outline, but never more
 * than kReach pixels beyond the quad, so that a side not closed by an
 * outline pixel cannot leak the fill outside. Zero pixels left enclosed
 * would each start a small hole border. */
void ContourTracer::sealInside(const Quad &quad, int w, int h)
{
	constexpr int kReach = 3;
	const auto &q = quad.corners;
	std::uint8_t *L = labels_.data();
	const int stride = stride_;
	float minX = q[0].x, maxX = q[0].x, minY = q[0].y, maxY = q[0].y;
	for (const Point2f &p : q) {
		minX = std::min(minX, p.x);
		maxX = std::max(maxX, p.x);
		minY = std::min(minY, p.y);
		maxY = std::max(maxY, p.y);
	}
	/* Extends a run of filled pixels from `from` in steps of `step` over
	 * background, as far as the outline if it lies within kReach. */
	auto reach = [&](std::ptrdiff_t from, std::ptrdiff_t step, int room) {
		for (int k = 1; k <= std::min(kReach, room); ++k) {
			if (L[from + k * step] != 0) {
				for (int j = 1; j < k; ++j)
					L[from + j * step] = kFollowedRightBg;
				break;
			}
		}
	};
	float lo, hi;
	const QuadSpans rows(q, true), columns(q, false);
	for (int y = std::max(1, ceilInt(minY)); y <= std::min(h - 2, static_cast<int>(maxY)); ++y) {
		if (!rows.span(static_cast<float>(y), lo, hi))
			continue;
		const int x0 = std::max(1, ceilInt(lo));
		const int x1 = std::min(w - 2, floorInt(hi));
		if (x0 > x1)
			continue;
		const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(y) * stride;
		std::memset(L + row + x0, kFollowedRightBg, static_cast<std::size_t>(x1 - x0 + 1));
		reach(row + x0, -1, x0 - 1);
		reach(row + x1, 1, w - 2 - x1);
	}
	for (int x = std::max(1, ceilInt(minX)); x <= std::min(w - 2, static_cast<int>(maxX)); ++x) {
		if (!columns.span(static_cast<float>(x), lo, hi))
			continue;
		const int y0 = std::max(1, ceilInt(lo));
		const int y1 = std::min(h - 2, floorInt(hi));
		if (y0 > y1)
			continue;
		reach(static_cast<std::ptrdiff_t>(y0) * stride + x, -stride, y0 - 1);
		reach(static_cast<std::ptrdiff_t>(y1) * stride + x, stride, h - 2 - y1);
	}
	/* Pixels beside the filled ones now have other neighbours. */
	if (useMasks_) {
		const int y0 = std::max(1, static_cast<int>(minY) - kReach - 1);
		const int y1 = std::min(h - 2, static_cast<int>(maxY) + kReach + 2);
		const int x0 = std::max(1, static_cast<int>(minX) - kReach - 1);
		const int x1 = std::min(w - 1, static_cast<int>(maxX) + kReach + 3);
		for (int y = y0; y <= y1; ++y)
			neighbourMasks(L + static_cast<std::ptrdiff_t>(y) * stride, stride, x0, x1,
				       masks_.data() + static_cast<std::ptrdiff_t>(y) * stride);
	}
}

bool ContourTracer::spansAtLeast(float span, float maxWinding) const
{
	const PointsBox box = pointsBox(points_.data(), static_cast<std::size_t>(steps_));
	const float bw = static_cast<float>(box.maxX - box.minX), bh = static_cast<float>(box.maxY - box.minY);
	/* A convex outline takes at most 2 (bw + bh) steps around its box. */
	return bw >= span && bh >= span && static_cast<float>(steps_) <= maxWinding * 2.0f * (bw + bh + 2.0f);
}

/* Groups the last border's corner pixels, in the order it met them: a
 * pixel within the cluster radius of a cluster's first member joins it.
 * Not suppression.h's rule for repeats: the members are averaged into the
 * corner, not dropped, in integers (the ARMv6 walk's pixels). */
void ContourTracer::clusterCorners()
{
	clusters_.clear();
	tooManyClusters_ = false;
	/* In integers: pixel coordinates, exact sums and squared distances. */
	for (int k = 0; k < cornerCount_; ++k) {
		const std::uint32_t xy = corners_[static_cast<std::size_t>(k)];
		const int x = static_cast<int>(xy & 0xFFFFu), y = static_cast<int>(xy >> 16);
		bool joined = false;
		for (Cluster &c : clusters_) {
			const std::int64_t dx = x - c.fx, dy = y - c.fy;
			if (dx * dx + dy * dy <= radius2Floor_) {
				c.sx += x;
				c.sy += y;
				++c.n;
				joined = true;
				break;
			}
		}
		if (joined)
			continue;
		if (clusters_.size() >= kMaxClusters) {
			tooManyClusters_ = true;
			return;
		}
		clusters_.push_back({ x, y, 1, x, y });
	}
}

/* Follows one border from (x, y); (x, y) + kD[fromDir] is the background
 * pixel the scan came from. Keeps its pixels and, apart, its corner pixels. */
void ContourTracer::follow(int x0, int y0, int fromDir, const TraceMap &edges, bool corners)
{
#ifdef FRAPPE_HAVE_ARMV6_TRACE
	if (!portableWalk_ && !useMasks_) {
		followV6(x0, y0, fromDir, edges, corners);
		return;
	}
#endif
	std::uint8_t *const L = labels_.data();
	const std::ptrdiff_t w = stride_;
	/* The edge map's corner bit of a label pointer (same layout), 0 or 1. */
	const std::uintptr_t toEdge =
		reinterpret_cast<std::uintptr_t>(edges.pixels.data()) - reinterpret_cast<std::uintptr_t>(L);
	auto isCorner = [toEdge](const std::uint8_t *label) {
		return (*reinterpret_cast<const std::uint8_t *>(reinterpret_cast<std::uintptr_t>(label) + toEdge) >>
			1) & 1;
	};
	static_assert(EdgeMap::kCorner == 2);

	/* The points are written through local pointers, and the loop reads
	 * no member: the label stores (bytes, which may alias anything) would
	 * make the compiler reload members on every step. */
	if (points_.size() < 1024) {
		points_.resize(1024);
		corners_.resize(1024);
	}
	/* The last kPointsPadding points stay free: sideCoverage reads a vector
	 * at a time. Every point is written to the corner list too, which
	 * advances only past corners: no branch on them. */
	std::uint32_t *out = points_.data(), *outEnd = out + points_.size() - kPointsPadding;
	std::uint32_t *cornerOut = corners_.data();
	auto grow = [&]() {
		const std::size_t n = points_.size(), nc = static_cast<std::size_t>(cornerOut - corners_.data());
		points_.resize(2 * n);
		corners_.resize(2 * n);
		out = points_.data() + (n - kPointsPadding);
		outEnd = points_.data() + points_.size() - kPointsPadding;
		cornerOut = corners_.data() + nc;
	};
	std::uint32_t xy = static_cast<std::uint32_t>(x0) | static_cast<std::uint32_t>(y0) << 16;

	/* Pointer offsets of the eight neighbours, in kDx/kDy order. */
	const std::ptrdiff_t off[8] = { 1, 1 - w, -w, -1 - w, -1, w - 1, w, w + 1 };
	/* 3.1: clockwise from fromDir, find the first non-zero neighbour. */
	std::uint8_t *const p0 = L + y0 * w + x0;
	unsigned mask0 = 0;
	if (useMasks_) {
		mask0 = masks_[static_cast<std::size_t>(p0 - L)];
	} else {
		for (int d = 0; d < 8; ++d)
			mask0 |= static_cast<unsigned>(p0[off[d]] != 0) << d;
	}
	if (mask0 == 0) {
		*p0 = kFollowedRightBg; /* isolated pixel */
		*out++ = xy;
		*cornerOut = xy;
		cornerOut += corners && isCorner(p0);
		steps_ = 1;
		cornerCount_ = static_cast<int>(cornerOut - corners_.data());
		return;
	}
	/* Turned so that direction fromDir is bit 7, the first non-zero
	 * neighbour clockwise is the highest set bit. */
	const auto turned = static_cast<std::uint8_t>(mask0 << (7 - fromDir) | mask0 >> (fromDir + 1));
	const int d1 = (fromDir - std::countl_zero(turned)) & 7;
	const std::uint8_t *const p1 = p0 + off[d1];
	if (useMasks_) {
		/* Each pixel's neighbourhood is one byte of masks_: a step is
		 * the table entry, then the next pixel's byte (two dependent
		 * loads and some 25 instructions; gathering its eight
		 * neighbours' bytes ahead of the entry took one load but 58). */
		const std::uint8_t *const M = masks_.data();
		const MaskStep *const mt = maskTable_.data();
		const std::ptrdiff_t i0 = p0 - L, i1 = p1 - L;
		/* One loop with the corner test, one without. */
		auto walk = [&](auto withCorners) {
			std::ptrdiff_t i = i0;
			unsigned back = static_cast<unsigned>(d1);
			unsigned mask = M[i0];
			for (;;) {
				const MaskStep st = mt[back << 8 | mask];
				L[i] |= st.mark;
				*out++ = xy;
				if constexpr (decltype(withCorners)::value) {
					*cornerOut = xy;
					cornerOut += isCorner(L + i);
				}
				if (out == outEnd) [[unlikely]] {
					if (points_.size() > 4 * labels_.size())
						break;
					grow();
				}
				const std::ptrdiff_t next = i + st.offset;
				if (i == i1 && next == i0) [[unlikely]]
					break;
				mask = M[next];
				back = st.back;
				xy += st.dxy;
				i = next;
			}
		};
		if (corners)
			walk(std::true_type{});
		else
			walk(std::false_type{});
		steps_ = static_cast<int>(out - points_.data());
		cornerCount_ = static_cast<int>(cornerOut - corners_.data());
		return;
	}
	const std::int32_t *const table = stepTable_.data();
	const std::size_t maxSteps = 4 * labels_.size();
	std::uint8_t *p = p0;
	/* The table row for the direction back to the previous pixel. */
	std::uint32_t row = static_cast<std::uint32_t>(d1) << 9;
	for (;;) {
		/* 3.3: counter-clockwise from the pixel after `back`; the entry
		 * holds the pointer offset of the move, so the next pixel is one
		 * table load away from this one's neighbourhood. */
		const std::int32_t step = table[row | neighbourIndex(p, w)];
		/* 3.4: mark the current pixel. */
		*p |= static_cast<std::uint8_t>(step & kMarkRightBg);
		*out++ = xy;
		*cornerOut = xy;
		cornerOut += corners && isCorner(p);
		if (out == outEnd) [[unlikely]] {
			if (points_.size() > maxSteps) /* only on a corrupt label image */
				break;
			grow();
		}
		std::uint8_t *const next = p + (step >> 12);
		/* 3.5: back at the start, about to repeat the first move. */
		if (p == p1 && next == p0) [[unlikely]]
			break;
		row = static_cast<std::uint32_t>(step) & 0xE00u;
		xy += static_cast<std::uint32_t>(kDxyBack[row >> 9]);
		p = next;
	}
	steps_ = static_cast<int>(out - points_.data());
	cornerCount_ = static_cast<int>(cornerOut - corners_.data());
}

#ifdef FRAPPE_HAVE_ARMV6_TRACE
/* follow() on ARMv6: the same border, walked by frappe_armv6_follow, with
 * the first move found from the neighbourhood index (kMaskOfIndex) rather
 * than eight byte tests, and no more set-up than the walk needs: a border
 * is 34 steps on average, so its set-up counts. */
void ContourTracer::followV6(int x0, int y0, int fromDir, const TraceMap &edges, bool corners)
{
	std::uint8_t *const L = labels_.data();
	const std::ptrdiff_t w = stride_;
	if (points_.size() < 1024) {
		points_.resize(1024);
		corners_.resize(1024);
	}
	std::uint32_t *out = points_.data(), *outEnd = out + points_.size() - kPointsPadding;
	std::uint32_t *cornerOut = corners_.data();
	const std::uint32_t xy = static_cast<std::uint32_t>(x0) | static_cast<std::uint32_t>(y0) << 16;
	std::uint8_t *const p0 = L + y0 * w + x0;
	const std::int32_t toEdge = static_cast<std::int32_t>(reinterpret_cast<std::uintptr_t>(edges.pixels.data()) -
							      reinterpret_cast<std::uintptr_t>(L));
	const unsigned mask0 = kMaskOfIndex.mask[neighbourIndex(p0, w)];
	if (mask0 == 0) {
		*p0 = kFollowedRightBg; /* isolated pixel */
		*out++ = xy;
		*cornerOut = xy;
		cornerOut += corners && (p0[toEdge] >> 1) & 1;
		steps_ = 1;
		cornerCount_ = static_cast<int>(cornerOut - corners_.data());
		return;
	}
	const auto turned = static_cast<std::uint8_t>(mask0 << (7 - fromDir) | mask0 >> (fromDir + 1));
	const int d1 = (fromDir - std::countl_zero(turned)) & 7;
	const std::uint8_t *const p1 = p0 + kDx[d1] + kDy[d1] * w;
	const std::size_t maxSteps = 4 * labels_.size();
	FollowAsm a{ p0,
		     xy,
		     out,
		     cornerOut,
		     static_cast<std::uint32_t>(d1) << 9,
		     stepTable_.data(),
		     static_cast<std::int32_t>(-w - 1),
		     static_cast<std::int32_t>(w - 1),
		     toEdge,
		     p1,
		     outEnd,
		     0x00070707u };
	/* The walk returns at p1 and when the points are full, after storing
	 * the point; the rest of such a step is done here, as follow() does. */
	for (;;) {
		if (corners)
			frappe_armv6_follow(&a);
		else
			frappe_armv6_follow_bare(&a);
		if (a.out == outEnd) [[unlikely]] {
			if (points_.size() > maxSteps)
				break;
			const std::size_t n = points_.size(), nc = static_cast<std::size_t>(a.cout - corners_.data());
			points_.resize(2 * n);
			corners_.resize(2 * n);
			outEnd = points_.data() + points_.size() - kPointsPadding;
			a.out = points_.data() + (n - kPointsPadding);
			a.cout = corners_.data() + nc;
			a.outEnd = outEnd;
		}
		const std::int32_t step = static_cast<std::int32_t>(a.s);
		std::uint8_t *const next = a.p + (step >> 12);
		if (a.p == p1 && next == p0)
			break;
		a.s = static_cast<std::uint32_t>(step) & 0xE00u;
		a.xy += static_cast<std::uint32_t>(kDxyBack[a.s >> 9]);
		a.p = next;
	}
	steps_ = static_cast<int>(a.out - points_.data());
	cornerCount_ = static_cast<int>(a.cout - corners_.data());
}
#endif

/* The paper's rule is "exactly four corner clusters". Noise adds clusters
 * part-way along a side, so with more than four the four spanning the
 * largest quadrilateral are taken: a side's stray cluster adds no area. */
bool ContourTracer::quadFromClusters(Quad &quad) const
{
	const int n = static_cast<int>(clusters_.size());
	std::array<Point2f, kMaxClusters> c{};
	for (int i = 0; i < n; ++i)
		c[i] = { static_cast<float>(clusters_[i].sx) / static_cast<float>(clusters_[i].n),
			 static_cast<float>(clusters_[i].sy) / static_cast<float>(clusters_[i].n) };
	/* Order by angle about the centre: a border that wanders through a gap
	 * can meet the corners out of turn. */
	float mx = 0, my = 0;
	for (int i = 0; i < n; ++i) {
		mx += c[i].x / static_cast<float>(n);
		my += c[i].y / static_cast<float>(n);
	}
	std::array<std::pair<float, Point2f>, kMaxClusters> byAngle{};
	for (int i = 0; i < n; ++i)
		byAngle[i] = { pseudoAngle(c[i].y - my, c[i].x - mx), c[i] };
	std::sort(byAngle.begin(), byAngle.begin() + n,
		  [](const auto &p, const auto &q) { return p.first < q.first; });
	for (int i = 0; i < n; ++i)
		c[i] = byAngle[i].second;
	float bestArea = 0.0f;
	for (int a = 0; a < n; ++a)
		for (int b = a + 1; b < n; ++b)
			for (int cc = b + 1; cc < n; ++cc)
				for (int d = cc + 1; d < n; ++d) {
					/* In angular order a-b-c-d is a simple polygon. */
					const float area = 0.5f * std::abs(cross(c[a], c[b], c[cc]) + cross(c[a], c[cc], c[d]));
					if (area > bestArea) {
						bestArea = area;
						quad.corners = { c[a], c[b], c[cc], c[d] };
					}
				}
	return bestArea > 0.0f;
}

/* When the corner pixels do not give four corners (a faint or blurred
 * corner), the outline itself does: the point farthest from the centroid,
 * the point farthest from that one, and the farthest on either side of the
 * diagonal they span. */
bool ContourTracer::quadFromOutline(Quad &quad, std::array<std::size_t, 4> &at) const
{
	const std::size_t n = static_cast<std::size_t>(steps_);
	if (n < 8)
		return false;
	const OutlineExtremes e = outlineExtremes(points_.data(), n);
	if (e.most <= 0 || e.least >= 0)
		return false;
	auto pt = [this](std::size_t i) {
		return Point2f{ static_cast<float>(points_[i] & 0xFFFFu), static_cast<float>(points_[i] >> 16) };
	};
	quad.corners = { pt(e.i0), pt(e.i1), pt(e.i2), pt(e.i3) };
	at = { e.i0, e.i1, e.i2, e.i3 };
	return true;
}

bool ContourTracer::acceptQuad(const TraceParams &params, int w, int h, Quad &quad,
			       [[maybe_unused]] const std::array<std::size_t, 4> *at)
{
	auto &q = quad.corners;
	/* Convex, and oriented clockwise on screen (positive cross in y-down). */
	float sign = 0.0f;
	for (int i = 0; i < 4; ++i) {
		const float c = cross(q[i], q[(i + 1) & 3], q[(i + 2) & 3]);
		if (c == 0.0f)
			return false;
		if (sign == 0.0f)
			sign = c;
		else if ((c > 0.0f) != (sign > 0.0f))
			return false;
	}
	const bool swapped = sign < 0.0f;
	if (swapped)
		std::swap(q[1], q[3]);

	/* Sides of min_side on average, none under 0.6 of it: a marker tilted
	 * 65 degrees is read across its foreshortened sides. */
	float perimeter = 0.0f, shortest = 1e30f;
	const float minSide2 = 0.36f * params.min_side * params.min_side;
	for (int i = 0; i < 4; ++i) {
		const float s2 = dist2(q[i], q[(i + 1) & 3]);
		if (s2 < minSide2)
			return false;
		shortest = std::min(shortest, s2);
		perimeter += std::sqrt(s2);
		const float m = params.border_margin;
		if (q[i].x < m || q[i].y < m || q[i].x > static_cast<float>(w - 1) - m ||
		    q[i].y > static_cast<float>(h - 1) - m)
			return false;
	}
	if (perimeter < 4.0f * params.min_side)
		return false;
	/* The border must run along all four sides: an open curve, or a corner
	 * cluster that is no corner, leaves a side without border pixels. A
	 * border that also wanders inside (through a gap in a blurred outline)
	 * still covers the four sides, and is kept. */
	/* Per side: unit normal n and offset c (n . p = c on the side), and the
	 * bin of a point along it, t = (u . p - t0) * kBins / len. */
	constexpr int kBins = kSideBins, kCoveredBins = kBins * 7 / 16;
	const float shortSide = std::sqrt(shortest);
	const float tol = std::max(1.5f, 0.06f * shortSide);
	/* A bin is 1/16 of a side: on long sides every point is not needed to
	 * cover one. A border step is at most sqrt(2) px, so every L/24-th point
	 * is at most L/17 apart: still one in every bin the border runs along. */
	const std::size_t stride = std::max(1, static_cast<int>(shortSide / (1.5f * kBins)));
	const std::uint32_t *pts = points_.data();
	std::size_t n = static_cast<std::size_t>(steps_);
	if (stride > 1) {
		sampled_.resize(n / stride + 1 + kPointsPadding);
		std::size_t m = 0;
		for (std::size_t k = 0; k < n; k += stride)
			sampled_[m++] = pts[k];
		pts = sampled_.data();
		n = m;
	}
#ifdef FRAPPE_HAVE_ARMV6_TRACE
	/* Where each side's own stretch of the border begins (in pts): the
	 * scan stops at the bins it needs, which that stretch covers first.
	 * The side from corner a to corner b is the way round from one to
	 * the other that passes no other corner. */
	std::array<std::size_t, 4> first{};
	if (at) {
		std::array<std::size_t, 4> c = *at;
		if (swapped)
			std::swap(c[1], c[3]);
		/* Indices below n: no division (a library call here). */
		const std::size_t all = static_cast<std::size_t>(steps_);
		auto ahead = [all](std::size_t from, std::size_t to) {
			return to >= from ? to - from : to + all - from;
		};
		for (int i = 0; i < 4; ++i) {
			const std::size_t a = c[i], b = c[(i + 1) & 3];
			const std::size_t span = ahead(a, b);
			const std::size_t at0 =
				ahead(a, c[(i + 2) & 3]) < span || ahead(a, c[(i + 3) & 3]) < span ? b : a;
			first[i] = stride == 1 ? at0 : at0 / stride;
		}
	}
#endif
	for (int i = 0; i < 4; ++i) {
		const SideLine side = SideLine::between(q[i], q[(i + 1) & 3]);
#ifdef FRAPPE_HAVE_ARMV6_TRACE
		const std::uint32_t covered = sideCoverageV6(pts, n, side, tol, w + h, kCoveredBins, first[i]);
#else
		const std::uint32_t covered = sideCoverage(pts, n, side, tol);
#endif
		if (std::popcount(covered) < kCoveredBins)
			return false;
	}
	return true;
}

void removeDuplicateQuads(std::vector<Quad> &quads, float tolerance, PointGrid &grid)
{
	const float tol2 = tolerance * tolerance;
	/* A repeat has every corner within the tolerance of one of a kept
	 * quad's, in the same order from some start `shift`: kept corner
	 * `shift` lies within the tolerance of the repeat's first corner, so in
	 * a cell the box of the tolerance around it touches (cells half as wide
	 * again as the tolerance: a rounding of the box or the cell index never
	 * moves a point by a whole cell). Each kept quad is filed under its
	 * four corners; the corner found gives the shift. The same quads are
	 * kept as comparing each with all kept ones did. */
	grid.reset(4 * quads.size(), std::max(1.5f * tolerance, 1e-3f));
	auto repeats = [&](const Quad &q, int keptAt, int shift) {
		const Quad &k = quads[static_cast<std::size_t>(keptAt)];
		for (int c = 0; c < 4; ++c)
			if (!(dist2(q.corners[c], k.corners[(c + shift) & 3]) <= tol2))
				return false;
		return true;
	};
	std::size_t kept = 0;
	for (std::size_t i = 0; i < quads.size(); ++i) {
		const Quad q = quads[i];
		const Point2f p = q.corners[0];
		if (grid.anyIn(p.x - tolerance, p.y - tolerance, p.x + tolerance, p.y + tolerance,
			       [&](int k, int shift) { return repeats(q, k, shift); }))
			continue;
		for (int c = 0; c < 4; ++c)
			grid.add(static_cast<int>(kept), c, q.corners[c]);
		quads[kept++] = q;
	}
	quads.resize(kept);
}

void removeDuplicateQuads(std::vector<Quad> &quads, float tolerance)
{
	PointGrid grid;
	removeDuplicateQuads(quads, tolerance, grid);
}

int capCandidates(std::vector<Quad> &quads, int most)
{
	const std::size_t n = quads.size(), cap = static_cast<std::size_t>(std::max(most, 0));
	if (n <= cap)
		return 0;
	/* The rank a quad earns from the probe: the higher ranks take the cap
	 * first, so a damaged marker among thousands of tiles is read however
	 * large it is. */
	constexpr int kRanks = 4;
	auto rank = [](const Quad &q) { return q.probeDecoded ? 0 : q.probeNearCode ? 1 : q.probeReadable ? 2 : 3; };
	std::array<std::size_t, kRanks> left{};
	for (const Quad &q : quads)
		++left[static_cast<std::size_t>(rank(q))];
	std::size_t room = cap;
	for (std::size_t &l : left) {
		l = std::min(l, room);
		room -= l;
	}
	std::size_t kept = 0;
	for (std::size_t i = 0; i < n; ++i) {
		std::size_t &l = left[static_cast<std::size_t>(rank(quads[i]))];
		if (l == 0)
			continue;
		--l;
		quads[kept++] = quads[i];
	}
	quads.resize(kept);
	return static_cast<int>(n - kept);
}

} // namespace frappe::detail
