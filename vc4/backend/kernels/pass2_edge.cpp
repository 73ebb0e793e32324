// SPDX-License-Identifier: MIT
// Pass 2: non-maximum suppression, the edge threshold, the Shi-Tomasi corner test and the
// empty-tile mask over one 64x32 tile (layout: kernels.hpp).
//
// Lane i of sub-pass j (0..3) handles pixel x0 + 4i + j of the current row, so the four
// result bytes pack into the lane's word and one 16-word VPM row is a 64-pixel image row.
// Each pixel gathers 18 words through the TMUs: plane 0 (B = m << 2 | dir) of its 3x3
// neighbourhood and the three column sums Vxx, Vyy, Vxy of columns x-1 .. x+1, at most 4
// requests per TMU in flight. The four sub-passes are unrolled so that their addresses are
// small-immediate offsets from six row bases. Pixels off the interior are forced to zero
// (their reads land in the gradient buffer's margin). The decisions are those of
// frappe-core's edgeSpan/isCorner:
//   edge   : B > thr << 2 | 3, m > m(prev), m >= m(next)
//   corner : c = (Sxx + Syy - 2T) >> 9, a = |Sxx - Syy| >> 9, b = |Sxy| >> 8,
//            c > 0 and c*c > a*a + b*b (mul24 of values below 2^16)
// Four rows leave by one VDW, double-buffered in the QPU's 8 VPM rows; after 16 rows the
// OR of the edge words, reduced over each 16x16 block, goes out as the tile's mask row.
#include "isa/setup_words.hpp"
#include "kernels/builder.hpp"
#include "kernels/kernels.hpp"

namespace frappe::vc4::kernels {

namespace {

constexpr Reg GRAD = A(0), LANEADDR = A(1), EDST = A(2), MDST = A(3), VPMROW = A(4), BC = A(5),
	      O = A(6), HALFCNT = A(7), GRPCNT = A(8), ROWCNT = A(9), PITCHA = A(10), ROWTERM = A(11),
	      VDWTOG = A(13), RU = A(14), RC = A(15), RD = A(16), RXX = A(17), RYY = A(18),
	      RXY = A(19), SXX = A(20), SXY = A(21), UNITDIFF = A(22), MASKACC = A(25);
constexpr Reg PITCH = B(0), PLANE = B(1), WM2 = B(2), HM2 = B(3), THR = B(4), CC = B(5),
	      VDWSTRIDE = B(6), EPITCH4 = B(7), VDWS = B(8), ROWOFF = B(9), OUTW = B(11), SYY = B(22);
// (x - 1) | (w - 2 - x) of sub-pass j's pixel: sign set off the interior columns.
constexpr Reg COLTERM[4] = {B(18), B(19), B(20), B(21)};
// Neighbours: up-left, up, up-right, left | right, down-left, down, down-right. Each
// direction's pair (prev, next) sits in different files so one instruction moves both.
constexpr Reg NB[8] = {A(26), A(27), A(28), A(29), B(14), B(15), B(16), B(17)};

Dst tmuS(int k) { return (k & 1) ? reg::tmu1_s : reg::tmu0_s; }

struct Request {
	Reg base;
	int offset;
};

// The row bases: RC = plane 0 at (x0 + 4 lane + 1, O) (the pixel of sub-pass 1), RU/RD the
// rows above and below, RXX/RYY/RXY planes 1..3; and the row's interior term.
void rowSetup(Builder &b)
{
	b.op(add(RC, LANEADDR, ROWOFF));
	b.op(sub(RU, RC, PITCH));
	b.op(add(RD, RC, PITCH));
	b.op(add(RXX, RC, PLANE));
	b.op(add(RYY, RXX, PLANE));
	b.op(add(RXY, RYY, PLANE));
	b.op(add(ROWOFF, ROWOFF, PITCHA));
	b.op(sub(r0, O, imm(1)));
	b.op(sub(r1, HM2, O));
	b.op(bor(ROWTERM, r0, r1));
}

// Sub-pass j: one pixel per lane at (x0 + 4 lane + j, O): gathers, decisions, and the
// byte ORed into OUTW at bit 8j. The gradient buffer has a margin of one row and more on
// each side, so the unclamped addresses of border pixels stay inside it; those pixels are
// forced to zero.
void pixel(Builder &b, int j)
{
	const int d = 4 * (j - 1);
	const Request req[18] = {
		{RC, d},       {RU, d - 4},   {RU, d},      {RU, d + 4},   {RC, d - 4},  {RC, d + 4},
		{RD, d - 4},   {RD, d},       {RD, d + 4},  {RXX, d - 4},  {RXX, d},     {RXX, d + 4},
		{RYY, d - 4},  {RYY, d},      {RYY, d + 4}, {RXY, d - 4},  {RXY, d},     {RXY, d + 4},
	};
	auto dest = [&](int i) { return i == 0 ? BC : NB[i - 1]; };
	auto issue = [&](int k, bool consume) {
		// A plane-0 pop's move rides along in the MUL pipe.
		if (consume)
			b.op(add(tmuS(k), req[k].base, imm(req[k].offset)), mmov(dest(k - 8), r4));
		else
			b.op(add(tmuS(k), req[k].base, imm(req[k].offset)));
	};
	auto pop = [&](int i, bool consumed_later) {
		b.ldtmu(i & 1);
		if (consumed_later)
			return;
		if (i <= 8) {
			b.op(mov(dest(i), r4));
			return;
		}
		const Reg sum = i < 12 ? SXX : i < 15 ? SYY : SXY;
		if ((i - 9) % 3 == 0)
			b.op(mov(sum, r4));
		else
			b.op(add(sum, sum, r4));
	};
	for (int k = 0; k < 18; ++k) {
		const bool merge = k >= 8 && k - 8 <= 8;
		if (k >= 8)
			pop(k - 8, merge);
		issue(k, merge);
	}
	for (int i = 10; i < 18; ++i)
		pop(i, false);

	// Neighbours along the direction: prev in r1, next in r2.
	b.op(band(r3, BC, imm(3)));
	b.op(mov(r1, NB[3]), mmov(r2, NB[4]));                  // 0: left, right
	b.op(sub(reg::nop, r3, imm(1)).setFlags());
	b.op(mov(r1, NB[1]).ifz(), mmov(r2, NB[6]).ifz());      // 1: up, down
	b.op(sub(reg::nop, r3, imm(2)).setFlags());
	b.op(mov(r1, NB[0]).ifz(), mmov(r2, NB[7]).ifz());      // 2: up-left, down-right
	b.op(sub(reg::nop, r3, imm(3)).setFlags());
	b.op(mov(r1, NB[2]).ifz(), mmov(r2, NB[5]).ifz());      // 3: up-right, down-left
	// Edge: sign bits of thr - B, m(prev) - m, m(next) - m - 1, and the interior.
	b.op(shr(r0, BC, imm(2)));
	b.op(shr(r1, r1, imm(2)));
	b.op(shr(r2, r2, imm(2)));
	b.op(sub(r1, r1, r0));
	b.op(sub(r2, r2, r0));
	b.op(sub(r2, r2, imm(1)));
	b.op(band(r1, r1, r2));
	b.op(sub(r2, THR, BC));
	b.op(band(r1, r1, r2));
	b.op(bor(r2, ROWTERM, COLTERM[j]));
	b.op(bnot(r2, r2));
	b.op(band(r1, r1, r2));
	b.op(shr(r1, r1, imm(-1)));                              // edge: 0 / 1
	// Corner: c in r0, a in r2, b in r3.
	b.op(add(r0, SXX, SYY));
	b.op(sub(r0, r0, CC));
	b.op(asr(r0, r0, imm(9)));
	b.op(sub(r2, SXX, SYY));
	b.op(sub(r3, imm(0), r2));
	b.op(max(r2, r2, r3));
	b.op(shr(r2, r2, imm(9)));
	b.op(sub(r3, imm(0), SXY));
	b.op(max(r3, r3, SXY));
	b.op(shr(r3, r3, imm(8)), mul24(r2, r2, r2));
	b.op(mul24(r3, r3, r3));
	b.op(add(r2, r2, r3), mul24(r3, r0, r0));
	b.op(sub(r2, r2, r3));                                   // a^2 + b^2 - c^2
	b.op(sub(r3, imm(0), r0));                               // -c
	b.op(band(r2, r2, r3));
	b.op(shr(r2, r2, imm(-1)));                              // corner: 0 / 1
	b.op(band(r2, r2, r1));
	b.op(shl(r2, r2, imm(1)));
	b.op(bor(r1, r1, r2));
	if (j == 0) {
		b.op(mov(OUTW, r1));
	} else {
		b.op(shl(r1, r1, imm(j == 2 ? -16 : j == 3 ? -8 : 8))); // 8j: shift counts use 5 bits
		b.op(bor(OUTW, OUTW, r1));
	}
}

Built build()
{
	Builder b("frappe_edge_pass");
	b.ldi(VDWTOG, 4u << 7);
	b.ldi(UNITDIFF, 3u << 23); // VDW units 4 -> 1
	b.op(mov(r0, reg::qpu_num));
	b.op(shl(r1, r0, imm(3)));
	b.ldi(r2, isa::VpmWriteSetup{.stride = 1, .horizontal = true, .laned = false,
	                             .size = isa::VpmSize::Bits32, .addr = 0}.word());
	b.op(add(VPMROW, r2, r1));
	b.ldi(r2, isa::VdwSetup{.units = 4, .depth = 16, .horizontal = true, .vpm_base = 0, .modew = 0}.word());
	b.op(shl(r1, r0, imm(10))); // Y = 8q at bit 7
	b.op(add(VDWS, r2, r1));

	Label tile = b.label();
	b.op(mov(GRAD, b.uniform("grad", UniformKind::Address)));
	b.op(mov(r0, b.uniform("grad_pitch")));
	b.op(mov(PITCH, r0), mmov(PITCHA, r0));
	b.op(mov(PLANE, b.uniform("plane")));
	b.op(mov(WM2, b.uniform("wm2")));
	b.op(mov(HM2, b.uniform("hm2")));
	// x of sub-pass j: x0 + 4 lane + j; LANEADDR = grad + 4 (x0 + 4 lane + 1).
	b.op(mov(r0, b.uniform("x0")));
	b.op(mov(r1, reg::elem_num));
	b.op(shl(r1, r1, imm(2)));
	b.op(add(r0, r0, r1));
	for (int j = 0; j < 4; ++j) {
		b.op(sub(r1, r0, imm(1 - j)));                   // x - 1
		b.op(sub(r2, WM2, r0));
		b.op(sub(r2, r2, imm(j)));                       // w - 2 - x
		b.op(bor(COLTERM[j], r1, r2));
	}
	b.op(shl(r0, r0, imm(2)));
	b.op(add(r0, r0, GRAD));
	b.op(add(LANEADDR, r0, imm(4)));
	b.op(mov(r0, b.uniform("y0")));
	b.op(mov(O, r0), mul24(r1, r0, PITCH));
	b.op(mov(ROWOFF, r1));
	b.op(mov(THR, b.uniform("edge_thr")));
	b.op(mov(CC, b.uniform("corner_c")));
	b.op(mov(EDST, b.uniform("edge_dst", UniformKind::Address)));
	b.op(mov(VDWSTRIDE, b.uniform("vdw_stride")));
	b.op(mov(EPITCH4, b.uniform("edge_pitch4")));
	b.op(mov(MDST, b.uniform("mask_dst", UniformKind::Address)));
	b.ldi(HALFCNT, 2);
	Label half = b.label();
	{
		b.op(mov(MASKACC, imm(0)));
		b.ldi(GRPCNT, 4);
		Label group = b.label();
		{
			b.ldi(ROWCNT, 4);
			Label row = b.label();
			{
				rowSetup(b);
				for (int j = 0; j < 4; ++j)
					pixel(b, j);
				b.op(mov(reg::vw_setup, VPMROW));
				b.op(add(VPMROW, VPMROW, imm(1)));
				b.op(mov(reg::vpm_write, OUTW));
				b.op(bor(MASKACC, MASKACC, OUTW));
				b.op(add(O, O, imm(1)));
			}
			b.loopEnd(row, ROWCNT);
			// Four rows out; flip to the other VPM half.
			b.op(sub(VPMROW, VPMROW, imm(4)));
			b.op(bxor(VPMROW, VPMROW, imm(4)));
			b.op(mov(reg::nop, reg::vw_wait));
			b.op(mov(reg::nop, reg::mutex_acq));
			b.op(mov(reg::vw_setup, VDWSTRIDE));
			b.op(mov(reg::vw_setup, VDWS));
			b.op(mov(reg::vw_addr, EDST));
			b.op(mov(reg::mutex_rel, imm(1)));
			b.op(add(EDST, EDST, EPITCH4));
			b.op(bxor(VDWS, VDWS, VDWTOG));
		}
		b.loopEnd(group, GRPCNT);
		// The mask row of these 16 rows, through the current (idle) VPM half: lane 4t+3
		// gets the OR of lanes 4t .. 4t+3 (two vector rotations), i.e. of block t.
		b.op(mov(r0, MASKACC));
		b.op(mov(reg::vw_setup, VPMROW)); // (a rotation must not read r0 just written)
		b.op(mmov(r1, r0).rot(1));
		b.op(bor(r0, r0, r1));
		b.op(sub(r2, VDWS, UNITDIFF));
		b.op(mmov(r1, r0).rot(2));
		b.op(bor(reg::vpm_write, r0, r1));
		b.op(mov(reg::nop, reg::mutex_acq));
		b.op(mov(reg::vw_setup, VDWSTRIDE));
		b.op(mov(reg::vw_setup, r2));
		b.op(mov(reg::vw_addr, MDST));
		b.op(mov(reg::mutex_rel, imm(1)));
		b.ldi(r0, 64);
		b.op(add(MDST, MDST, r0));
		b.op(mov(reg::nop, reg::vw_wait));
	}
	b.loopEnd(half, HALFCNT);
	b.nextTileOrEnd(tile);
	Built out;
	out.nops = b.nops();
	out.program = b.finish();
	return out;
}

} // namespace

Built edgePass() { return build(); }

} // namespace frappe::vc4::kernels
