// SPDX-License-Identifier: MIT
// Pass 2: non-maximum suppression, the edge threshold, the Shi-Tomasi corner test and the
// empty-tile mask over one half tile, 64x16 pixels (layout: kernels.hpp).
//
// Lane i holds pixels x0 + 4i + j, j = 0..3 (four sub-pixels), so the four result bytes
// pack into the lane's word (regfile-A byte packs) and one 16-word VPM row is a 64-pixel
// image row. The six columns c = 0..5 at x0 + 4i + c - 1 cover the 3x3 neighbourhoods
// of all four sub-pixels. Plane 0 (B = q << 24 | m << 2 | dir) of rows y-1, y, y+1 is a
// window in registers that moves down a row at a time, so a row gathers 24 words a lane for 64
// pixels: plane 0 of row y+1 and the column sums Vxx, Vyy, Vxy of row y, per column.
// Their per-lane addresses are a row base plus a lane pattern (kernels.hpp's interleaved
// layout), and the tensor's horizontal sums are formed as the columns arrive:
//   S_j = V(c = j) + V(j + 1) + V(j + 2).
// The gathers are software-pipelined across the sub-pixels (Builder::interleave, at most
// kTmuDepth in flight): sub-pixel 0 computes while columns 3 and 4 arrive, 1 while column
// 5 does, 2 and 3 while the next row's columns 0 .. 2 land where sub-pixels 0 .. 2 no
// longer look (a column's window moves once its last reader is done).
// The decisions are those of frappe-core's edgeSpan/isCorner, with thresholds that follow
// the light: q = byte 3 of the centre's B (pass 1 put it there; regfile-A unpack .8d),
//   E(q) = ((E' q >> 7) q) >> 7, T(q) = ((T q >> 7) q) >> 7  (mul24: E' q < 2^29, T q < 2^30)
//   edge   : m > E(q), m > m(prev), m >= m(next)
//            (B(prev) < B & ~3 and B(next) < (B & ~3) + 4 on the low 24 bits: those
//            differences lie within +-2^23, so shifted left by 8 (mul24 by 256) the q
//            bytes drop out and the sign is exact; m > E(q) as
//            (E' q >> 7) q < 128 m, i.e. without the last shift, 128 m by mul24 of B & ~3,
//            which reads its low 24 bits only)
//   corner : c = (Sxx + Syy - 2T(q)) >> 9, a = |Sxx - Syy| >> 9, b = |Sxy| >> 8,
//            c > 0 and c*c > a*a + b*b (mul24 of values below 2^16)
// Pixels off the interior are masked at the end of the row (the row's mask comes from
// the uniform stream, the columns' is computed per unit); their gathers land in the
// gradient buffer's margin. Four rows leave by one VDW, double-buffered in the QPU's 8
// VPM rows; after the 16 rows the OR of the edge words, reduced over each 16x16 block,
// goes out as the unit's mask row.
#include "isa/setup_words.hpp"
#include "kernels/builder.hpp"
#include "kernels/kernels.hpp"

namespace frappe::vc4::kernels {

namespace {

// Plane 0 of rows y-1 (U), y (C), y+1 (D) at columns 0..5. Files are chosen so that the
// pairs the direction selects (left/right, up/down, and the diagonals) can move in one
// instruction, and the centre (C row, columns 1..4) is in file A beside a small immediate.
constexpr Reg BV[3][6] = {
	{A(0), B(0), A(1), B(1), A(2), B(2)},
	{B(3), A(3), A(4), A(5), A(6), B(4)},
	{B(5), A(7), B(6), A(8), B(7), A(9)},
};
// Tensor sums of the four sub-pixels.
constexpr Reg SX[4] = {A(10), A(11), A(12), A(13)};
constexpr Reg SY[4] = {B(8), B(9), B(10), B(11)};
constexpr Reg SZ[4] = {A(14), A(15), A(16), A(17)};
// Row bases: plane 0 of rows y-1, y, y+1 and planes 1..3 of row y, at the group of x0.
constexpr Reg BASE[6] = {A(18), A(19), A(20), A(21), A(22), A(23)};
// Lane patterns of the columns (byte offsets from a row base), and of the next row's.
constexpr Reg LANEOFF[6] = {B(12), B(13), B(14), B(15), B(16), B(17)};
constexpr Reg LANEOFFN[3] = {B(18), B(19), B(20)};
constexpr Reg OUTW = A(24), VPMROW = A(25), VDWTOG = A(26), EDST = A(27), ROWCNT = A(28),
	      GRPCNT = A(29);
// T (a uniform; E' is in r5), the edge test's (E' q >> 7) q, T(q) on its way, 32 and 256.
constexpr Reg CT = B(21), XE = B(22), TA = A(30), TB = B(31), K32 = B(30), K256 = A(31);
constexpr Reg COLMASK = B(23), MASKACC = B(24), VDWS = B(25),
	      VDWSTRIDE = B(26), EPITCH4 = B(27), PITCH = B(28), MDST = B(29);

Dst tmuS(unsigned k) { return (k & 1) ? reg::tmu1_s : reg::tmu0_s; }

// The gathers of column c: plane 0 of rows `from` .. `from + n - 1` (bases BASE[from]..)
// into the window rows `to` .., and the tensor planes of the row whose bases are in BASE
// (or none), for the row of BASE (`next`: the row after it, through the lane patterns
// that include a pitch), with their consumers.
std::vector<Gather> column(int c, bool next, int from, int to, int n, bool tensor)
{
	std::vector<Gather> out;
	const Reg off = next ? LANEOFFN[c] : LANEOFF[c];
	for (int r = 0; r < n; ++r)
		out.push_back({add(tmuS(out.size()), BASE[from + r], off), static_cast<unsigned>(out.size() & 1),
		               {ins(mmov(BV[to + r][c], r4))}});
	const Reg *sums[3] = {SX, SY, SZ};
	for (int p = 0; tensor && p < 3; ++p) {
		Gather g{add(tmuS(out.size()), BASE[3 + p], off), static_cast<unsigned>(out.size() & 1), {}};
		if (c <= 3)
			g.consume.push_back(ins(mmov(sums[p][c], r4)));
		for (int j = std::max(0, c - 2); j < std::min(c, 4); ++j)
			g.consume.push_back(ins(add(sums[p][j], sums[p][j], r4)));
		out.push_back(g);
	}
	return out;
}

// In the row loop only the window's new row (D) of plane 0 is gathered.
std::vector<Gather> columns(std::initializer_list<int> cs, bool next)
{
	std::vector<Gather> out;
	for (int c : cs)
		for (const Gather &g : column(c, next, 2, 2, 1, true))
			out.push_back(g);
	return out;
}

// The window moves down a row in columns `cs` (their last reader is done): U = C, C = D.
std::vector<MulOp> shift(std::initializer_list<int> cs)
{
	std::vector<MulOp> out;
	for (int c : cs) {
		out.push_back(mmov(BV[0][c], BV[1][c]));
		out.push_back(mmov(BV[1][c], BV[2][c]));
	}
	return out;
}

// One phase of the row: the decisions of a sub-pixel with the window's shift of `cs` at
// its start (before any result lands) and the gathers `g`.
void phase(Builder &b, std::vector<Ins> compute, std::initializer_list<int> cs, std::vector<Gather> g, size_t keep)
{
	const size_t hold = Builder::mergeMul(compute, shift(cs));
	b.interleave(std::move(compute), std::move(g), keep, hold);
}

// Sub-pixel j: the edge and corner decisions, the byte packed into OUTW's byte j.
std::vector<Ins> decide(int j)
{
	const Reg bc = BV[1][j + 1];
	const Reg l = BV[1][j], r = BV[1][j + 2], u = BV[0][j + 1], d = BV[2][j + 1];
	const Reg ul = BV[0][j], dr = BV[2][j + 2], ur = BV[0][j + 2], dl = BV[2][j];
	std::vector<Ins> v;
	// The thresholds at the centre's light q (byte 3 of its B, unpacked where read) ride in
	// the MUL slots of the decisions: XE = (E' q >> 7) q in the direction tests (E' in r5),
	// T(q) = ((T q >> 7) q) >> 7 in TA beside the edge test and the corner's a and b; only
	// the three shifts and a second subtraction of T(q) take instructions of their own.
	const Src q = bc[Unpack::B8D];
	// Neighbours along the direction: prev in r1, next in r2.
	v.push_back(ins(band(r3, bc, imm(3))));
	if (l.file_b != r.file_b) {
		v.push_back(ins(mov(r1, l), mmov(r2, r)));          // 0: left, right
	} else {
		v.push_back(ins(mov(r1, l)));
		v.push_back(ins(mov(r2, r)));
	}
	v.push_back(ins(sub(reg::nop, r3, imm(1)).setFlags(), mul24(r0, q, r5)));
	v.push_back(ins(shr(r0, r0, imm(7))));
	v.push_back(ins(mov(r1, u).ifz(), mmov(r2, d).ifz()));    // 1: up, down
	v.push_back(ins(sub(reg::nop, r3, imm(2)).setFlags(), mul24(XE, r0, q)));
	v.push_back(ins(mov(r1, ul).ifz(), mmov(r2, dr).ifz()));  // 2: up-left, down-right
	v.push_back(ins(sub(reg::nop, r3, imm(3)).setFlags()));
	v.push_back(ins(mov(r1, ur).ifz(), mmov(r2, dl).ifz()));  // 3: up-right, down-left
	// Edge: the sign bits of (prev - (B & ~3)) << 8, (next - (B & ~3) - 4) << 8 (the low
	// 24 bits' differences: q's bytes shifted out, by mul24) and XE - 128 m.
	v.push_back(ins(band(r0, bc, imm(-4))));
	v.push_back(ins(sub(r1, r1, r0), mul24(r3, r0, K32))); // 128 m
	v.push_back(ins(add(r0, r0, imm(4))));
	v.push_back(ins(sub(r2, r2, r0), mul24(TA, q, CT)));
	v.push_back(ins(band(r1, r1, r2)));
	v.push_back(ins(shr(TB, TA, imm(7))));
	v.push_back(ins(sub(r2, XE, r3), mul24(r1, r1, K256)));
	v.push_back(ins(band(r1, r1, r2), mul24(TA, TB, q)));    // edge: sign
	// Corner: a in r2, b in r3, c in r0; the sign of (a^2 + b^2 - c^2) & -c.
	v.push_back(ins(sub(r2, SX[j], SY[j])));
	v.push_back(ins(sub(r3, imm(0), r2)));
	v.push_back(ins(max(r2, r2, r3)));
	v.push_back(ins(shr(r2, r2, imm(9))));
	v.push_back(ins(sub(r3, imm(0), SZ[j])));
	v.push_back(ins(max(r3, r3, SZ[j])));
	v.push_back(ins(shr(r3, r3, imm(8)), mul24(r2, r2, r2)));
	v.push_back(ins(shr(TA, TA, imm(7)), mul24(r3, r3, r3))); // T(q)
	v.push_back(ins(add(r0, SX[j], SY[j])));
	v.push_back(ins(sub(r0, r0, TA)));
	v.push_back(ins(sub(r0, r0, TA)));
	v.push_back(ins(asr(r0, r0, imm(9))));
	v.push_back(ins(add(r2, r2, r3), mul24(r3, r0, r0)));
	v.push_back(ins(sub(r2, r2, r3)));                       // a^2 + b^2 - c^2
	v.push_back(ins(sub(r3, imm(0), r0)));                   // -c
	v.push_back(ins(band(r2, r2, r3)));                      // corner: sign
	// Byte j = edge | (edge & corner) << 1.
	v.push_back(ins(band(r2, r2, r1)));
	v.push_back(ins(shr(r1, r1, imm(-1))));
	v.push_back(ins(shr(r2, r2, imm(-1))));
	v.push_back(ins(add(r1, r1, r2)));
	const Pack pack[4] = {Pack::B8A, Pack::B8B, Pack::B8C, Pack::B8D};
	v.push_back(ins(add(Dst(OUTW)[pack[j]], r1, r2)));
	return v;
}

Built build()
{
	Builder b("frappe_edge_pass");
	b.ldi(VDWTOG, 4u << 7);
	b.op(mov(r0, reg::qpu_num));
	b.op(shl(r1, r0, imm(3)));
	b.ldi(r2, isa::VpmWriteSetup{.stride = 1, .horizontal = true, .laned = false,
	                             .size = isa::VpmSize::Bits32, .addr = 0}.word());
	b.op(add(VPMROW, r2, r1));
	b.ldi(r2, isa::VdwSetup{.units = 4, .depth = 16, .horizontal = true, .vpm_base = 0, .modew = 0}.word());
	b.op(shl(r1, r0, imm(10))); // Y = 8q at bit 7
	b.op(add(VDWS, r2, r1));
	b.op(mov(PITCH, b.uniform("grad_pitch")));
	b.op(mov(reg::r5rep, b.uniform("edge_thr")));
	b.op(mov(CT, b.uniform("corner_t")));
	b.ldi(K32, 32);
	b.ldi(K256, 256);
	b.op(mov(VDWSTRIDE, b.uniform("vdw_stride")));
	b.op(mov(EPITCH4, b.uniform("edge_pitch4")));
	// Lane patterns (kernels.hpp): column c >= 1 is the run of sub-pixel c-1, 4 lane + 64
	// (c-1) bytes; column 0 is pixel x0 + 4i - 1, the word before lane i's run of
	// sub-pixel 3 (lane 0: the previous group's last word); column 5 is pixel x0 + 4i + 4,
	// sub-pixel 0 of lane i+1 (lane 15: the next group's first word).
	b.op(mov(r0, reg::elem_num));
	b.op(shl(r0, r0, imm(2)));
	b.op(mov(LANEOFF[1], r0));
	for (int c = 2; c <= 4; ++c) {
		b.ldi(r1, 64u * (c - 1));
		b.op(add(LANEOFF[c], r0, r1));
	}
	b.ldi(r1, 4u * 47);
	b.op(add(LANEOFF[0], r0, r1));
	b.op(add(LANEOFF[5], r0, imm(4)));
	b.op(mov(reg::nop, reg::elem_num).setFlags());
	b.op(mov(LANEOFF[0], imm(-4)).ifz());
	b.op(sub(reg::nop, reg::elem_num, imm(15)).setFlags());
	b.ldi(r1, 256);
	b.op(mov(LANEOFF[5], r1).ifz());
	b.op(mov(r1, PITCH));
	for (int c = 0; c < 3; ++c)
		b.op(add(LANEOFFN[c], LANEOFF[c], r1));

	Label unit = b.label();
	{
		// Interior columns: byte j of lane i is 0xff when x0 + 4i + j lies in 1 .. w-2.
		b.op(mov(r0, b.uniform("x0")));
		b.op(mov(r3, b.uniform("wm2")));
		b.op(mov(r1, reg::elem_num));
		b.op(shl(r1, r1, imm(2)));
		b.op(add(r0, r0, r1));
		const Pack pack[4] = {Pack::B8A, Pack::B8B, Pack::B8C, Pack::B8D};
		for (int j = 0; j < 4; ++j) {
			b.op(sub(r1, r0, imm(1 - j)));  // x - 1
			b.op(sub(r2, r3, r0));
			b.op(sub(r2, r2, imm(j)));      // w - 2 - x
			b.op(bor(r1, r1, r2));
			b.op(asr(r1, r1, imm(-1)));     // -1 off the interior
			b.op(bnot(Dst(OUTW)[pack[j]], r1));
		}
		b.op(mov(COLMASK, OUTW));
		// Row bases from plane 0 at (x0, y0 - 1).
		b.op(mov(r0, b.uniform("grad", UniformKind::Address)));
		b.op(mov(r2, b.uniform("plane")));
		b.op(add(r1, r0, PITCH), mmov(BASE[0], r0));
		b.op(add(r3, r1, PITCH), mmov(BASE[1], r1));
		b.op(add(r1, r1, r2), mmov(BASE[2], r3));
		b.op(add(r3, r1, r2), mmov(BASE[3], r1));
		b.op(add(r1, r3, r2), mmov(BASE[4], r3));
		b.op(mov(BASE[5], r1));
		b.op(mov(EDST, b.uniform("edge_dst", UniformKind::Address)));
		b.op(mov(MDST, b.uniform("mask_dst", UniformKind::Address)));
		b.op(mov(MASKACC, imm(0)));
		// The first row's window: rows y0-1 .. y0+1 of columns 0 .. 2 with their tensor
		// sums, rows y0-1 and y0 of columns 3 .. 5 (in C and D: phase A moves them up).
		std::vector<Gather> first;
		for (int c = 0; c < 6; ++c)
			for (const Gather &g : c < 3 ? column(c, false, 0, 0, 3, true) : column(c, false, 0, 1, 2, false))
				first.push_back(g);
		b.interleave({}, std::move(first));
		b.ldi(GRPCNT, 4);
		Label group = b.label();
		{
			// The VPM write setup advances a row a write: set once for four rows.
			b.op(mov(reg::vw_setup, VPMROW));
			b.ldi(ROWCNT, 4);
			Label row = b.label();
			{
				phase(b, decide(0), {3, 4, 5}, columns({3, 4}, false), 4);
				phase(b, decide(1), {}, columns({5}, false), 4);
				phase(b, decide(2), {0, 1}, columns({0, 1}, true), 8);
				std::vector<Ins> tail = decide(3);
				// The row's word: interior only; into the VPM and the tile mask.
				tail.push_back(ins(band(r0, COLMASK, reg::unif)));
				tail.push_back(ins(band(r0, OUTW, r0)));
				tail.push_back(ins(mov(reg::vpm_write, r0)));
				tail.push_back(ins(bor(MASKACC, MASKACC, r0)));
				phase(b, std::move(tail), {2}, columns({2}, true), 0);
				// The next row's bases.
				for (int k = 0; k < 3; ++k)
					b.op(add(BASE[k], BASE[k], PITCH));
			}
			b.loopEnd(row, ROWCNT, {add(BASE[3], BASE[3], PITCH), add(BASE[4], BASE[4], PITCH),
			                        add(BASE[5], BASE[5], PITCH)});
			// Four rows out; flip to the other VPM half.
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
		b.ldi(r3, 3u << 23); // VDW units 4 -> 1
		b.op(sub(r2, VDWS, r3));
		b.op(mmov(r1, r0).rot(2));
		b.op(bor(reg::vpm_write, r0, r1));
		b.op(mov(reg::nop, reg::mutex_acq));
		b.op(mov(reg::vw_setup, VDWSTRIDE));
		b.op(mov(reg::vw_setup, r2));
		b.op(mov(reg::vw_addr, MDST));
		b.op(mov(reg::mutex_rel, imm(1)));
		b.op(mov(reg::nop, reg::vw_wait));
	}
	b.nextTileOrEnd(unit);
	Built out;
	out.nops = b.nops();
	out.program = b.finish();
	return out;
}

} // namespace

Built edgePass() { return build(); }

} // namespace frappe::vc4::kernels
