// SPDX-License-Identifier: MIT
// Pass 1: scaled fetch, smoothing, Sobel, magnitude, direction and the vertical sums of the
// structure tensor's products over one 64x32 tile (layout: kernels.hpp).
//
// A work unit is a strip of 16 lanes over a band of rows: lane i holds pixel x + 4i, so a
// 64-pixel group is four strips (x = x0 .. x0+3) and each strip's output row is one
// 16-word run of the gradient buffer (layout: kernels.hpp). The host cuts the frame into
// bands that balance the 12 QPUs (each band pays 6 rows to fill the window). A strip is
// swept top to bottom with a sliding window. For input row R every lane gathers the five
// source pixels at scaled columns x-2 .. x+2 through the TMUs (one request per column,
// 16 per-lane addresses: this is where nearest scaling and edge replication happen, so
// both are free; the source row's address and the row's interior mask come from the
// uniform stream, kernels::gradientRowUniforms()), and the window turns them into:
//   t_k(R-1) = I_k(R-2) + 2 I_k(R-1) + I_k(R)            vertical binomial, k = -2..2
//   p_j(R-1) = (t_{j-1} + 2 t_j + t_{j+1} + 8) >> 4        smoothed, j = -1..1
//   hs = p_-1 + 2 p_0 + p_1,  hd = p_1 - p_-1              horizontal Sobel parts
//   gx(R-2) = hd(R-3) + 2 hd(R-2) + hd(R-1),  gy(R-2) = hs(R-1) - hs(R-3)
// the same integers as frappe-core's smoothRow / gradientRow (linear, so the order of
// the sums does not matter). The running sums keep two generations only (q = I + I',
// G = hd + hd', F = hs - hs'), so the window needs no register rotation. The tensor's
// vertical sums lag one more row: V(g-1) = S' + P(g), S = P' + P, P' = P.
// The thresholds follow the light (front_end_cpu.cpp): the light's q = min(p_0 +
// light_floor, 128) (not the running sums' q above) of the smoothed row rides in B's byte 3
// (a regfile-A pack), one row behind the smoothing as B is (QN -> QP), and pass 2 scales
// both thresholds by it. v8adds saturates at 255, above 128 whatever the floor (the host
// caps it at 128), so v8min(., 128) gives q exactly; both in MUL slots that were free.
// The next row's gathers are issued as soon as this row's are popped, so a whole row of
// work hides the TMU latency: 4 in flight at most (kTmuDepth 4: row R's last column goes
// out after its first is popped), or 5 with the 8-deep build. Each output row (4 planes)
// leaves by one VDW, double-buffered in the QPU's 8 VPM rows.
#include "isa/setup_words.hpp"
#include "kernels/builder.hpp"
#include "kernels/kernels.hpp"

namespace frappe::vc4::kernels {

namespace {

// Registers. Port rule: one read of file A and one of file B per instruction (a small
// immediate takes B's), and ADD and MUL results of one instruction go to different files.
constexpr Reg SWMAX = A(1), STEPX = A(2), WMAX = A(3), ROWADDR = A(5), DSTS = A(6),
	      VPMW = A(7), C106 = A(8), HS = A(22), FP = A(23), COLMASK = A(25), PXX = A(26),
	      SYY = A(27), PXY = A(28), CNT = A(29), ELEM4 = A(30), VDWTOG = A(31), FLOOR = A(0),
	      QT = A(4), BPREV = A(24);
constexpr Reg DPITCH = B(4), ROWS = B(7), HD = B(20), GP = B(21), SXX = B(22),
	      PYY = B(23), SXY = B(24), VDWSTRIDE = B(26), VDWS = B(27),
	      TMPB = B(29), XS = B(30), K128 = B(3), QN = B(5), QP = B(6);
constexpr Reg COLOFF[5] = {B(8), B(9), B(10), B(11), B(12)};
constexpr Reg COLSH[5] = {A(9), A(10), A(11), A(12), A(13)};
constexpr Reg T[5] = {A(14), B(13), A(15), B(14), A(16)};
constexpr Reg Q[5] = {B(15), A(17), B(16), A(18), B(17)};
constexpr Reg I[5] = {A(19), B(18), A(20), B(19), A(21)};

// With 4 requests in flight a row's fifth column goes out only after its first is popped.
constexpr bool kDeep = kTmuDepth >= 5;

Dst tmuS(int k) { return (k & 1) ? reg::tmu1_s : reg::tmu0_s; }

// Rows come from the uniform stream: the host maps each row like scaleNearest (clamped to
// the frame), so the scaled fetch costs one uniform read a row.
// One input row: pop the five gathers of row R, issue row R+1's, and compute the
// vertical sums t_k into T[k]; then smoothing and the horizontal Sobel parts, leaving
// gx in r2 and gy in r3 (garbage until the window is full).
void rowBody(Builder &b)
{
	for (int k = 0; k < 5; ++k) {
		// The next row's address; r1 keeps this row's for its last column (4 deep).
		if (k == 0)
			b.ldtmu(0, mov(ROWADDR, rb(isa::raddr::uniform)), mmov(r1, ROWADDR));
		b.op(shr(r2, r4, COLSH[k]));
		// Issue column k of row R+1 (deep), or row R's column 4 then row R+1's k-1.
		const int col = kDeep ? k : k == 0 ? 4 : k - 1;
		const Src base = !kDeep && k == 0 ? Src(r1) : Src(ROWADDR);
		b.op(add(tmuS(col), base, COLOFF[col]), v8min(r2, r2, r5)); // r5 = 0xff: byte mask
		b.op(add(r3, I[k], r2), mmov(I[k], r2));                  // q = I(R-1) + I(R)
		if (k < 4)
			b.ldtmu((k + 1) & 1, add(T[k], Q[k], r3), mmov(Q[k], r3)); // t = q' + q
		else
			b.op(add(T[k], Q[k], r3), mmov(Q[k], r3));
	}
	// Horizontal binomial with rounding: e_k = t_k + t_k+1, p_j = (e_j-1 + e_j + 8) >> 4.
	b.op(add(r0, T[0], T[1]));
	b.op(add(r1, T[1], T[2]));
	b.op(add(r2, T[2], T[3]));
	b.op(add(r3, T[3], T[4]));
	b.op(add(r1, r1, imm(8)));
	b.op(add(r3, r3, imm(8)));
	b.op(add(r0, r0, r1));
	b.op(add(r1, r1, r2));
	b.op(add(r2, r2, r3));
	b.op(shr(r0, r0, imm(4)));
	b.op(shr(r1, r1, imm(4)));
	b.op(shr(r2, r2, imm(4)), mv8adds(QT, r1, FLOOR)); // p0 + floor, saturated
	// hs = p-1 + 2 p0 + p1 (r3), hd = p1 - p-1 (r2); q of the row before to QP, this one's
	// to QN.
	b.op(add(r3, r0, r2), mul24(r1, r1, imm(2)));
	b.op(sub(r2, r2, r0), mmov(QP, QN));
	b.op(add(r3, r3, r1), v8min(QN, QT, K128));
	// Two-generation window: F = hs - hs', G = hd + hd'; gy = F' + F, gx = G' + G.
	b.op(sub(r0, r3, HS), mmov(HS, r3));
	b.op(add(r1, r2, HD), mmov(HD, r2));
	b.op(add(r3, r0, FP), mmov(FP, r0));
	b.op(add(r2, r1, GP), mmov(GP, r1));
}

// gx in r2, gy in r3 of gradient row g: zero them off the interior; B(g) and the tensor
// products P(g); write row g-1 (B, Vxx, Vyy, Vxy) to the VPM.
void rowOutput(Builder &b)
{
	// Interior: the row's mask (uniform stream: -1 for rows 1 .. h-2, else 0) and the
	// column's.
	// Row G-1's B goes to the VPM first, so that B(G) can be made in BPREV itself.
	b.op(band(r0, COLMASK, reg::unif));
	b.op(band(r2, r2, r0), mmov(reg::vw_setup, VPMW));
	b.op(band(r3, r3, r0), mmov(reg::vpm_write, BPREV));
	b.op(sub(r0, imm(0), r2));
	b.op(max(r0, r2, r0));                          // |gx|
	b.op(sub(r1, imm(0), r3));
	b.op(max(r1, r3, r1), mul24(T[0], r0, r0));     // |gy|, gx^2
	b.op(bxor(r2, r2, r3), mul24(T[1], r1, r1));    // gy^2
	b.op(asr(r2, r2, imm(-1)), mul24(r3, r0, r1));  // sign of gx*gy (-1 / 0); |gx gy|
	b.op(bxor(r3, r3, r2));
	b.op(sub(T[2], r3, r2));                        // gx*gy
	b.op(shr(r2, r2, imm(-1)), mul24(r3, r0, C106)); // 1 when gx*gy < 0; 106|gx|
	b.op(add(r2, r2, imm(2)), mul24(TMPB, r1, C106)); // diagonal code 2 or 3; 106|gy|
	b.op(shl(r0, r0, imm(8)));
	b.op(shl(r1, r1, imm(8)));
	b.op(sub(reg::nop, TMPB, r0).setFlags());       // 256|gx| <= 106|gy|: vertical
	b.op(mov(r2, imm(1)).ifnn());
	b.op(sub(reg::nop, r3, r1).setFlags());         // 256|gy| <= 106|gx|: horizontal wins
	b.op(mov(r2, imm(0)).ifnn());
	b.op(add(r0, T[0], T[1]));
	b.op(shl(r0, r0, imm(2)));
	b.op(bor(BPREV, r0, r2));                       // B(G) = m << 2 | dir
	b.op(mov(r0, T[0]), mmov(r1, T[1]));
	b.op(mov(Dst(BPREV)[Pack::B8D], QP), mmov(r3, T[2])); // q(G) in byte 3
	// The rest of row G-1 to the VPM: V = S' + P, S = P' + P, P' = P per product.
	b.op(add(reg::vpm_write, SXX, r0));
	b.op(add(SXX, PXX, r0), mmov(PXX, r0));
	b.op(add(reg::vpm_write, SYY, r1));
	b.op(add(SYY, PYY, r1), mmov(PYY, r1));
	b.op(add(reg::vpm_write, SXY, r3));
	b.op(add(SXY, PXY, r3), mmov(PXY, r3));
}

// Store the finished row: wait for the previous row's VDW (it had a whole row of compute
// to finish), then start this one and flip to the other VPM half.
// (The next row's address and VPM halves are set in the loop's delay slots.)
void storeRow(Builder &b)
{
	b.op(mov(reg::nop, reg::vw_wait));
	b.op(mov(reg::nop, reg::mutex_acq));
	b.op(mov(reg::vw_setup, VDWSTRIDE));
	b.op(mov(reg::vw_setup, VDWS));
	b.op(mov(reg::vw_addr, DSTS));
	b.op(mov(reg::mutex_rel, imm(1)));
}

Built build()
{
	Builder b("frappe_gradient_pass");
	b.ldi(reg::r5rep, 0xff); // the byte mask of the gathers, in r5 for a free read port
	b.ldi(C106, 106);
	b.ldi(VDWTOG, 4u << 7); // VDW VPM base Y sits at bit 7: flip between the two halves
	// VPM rows 8q .. 8q+7 of QPU q: generic write setup (stride 1) and VDW of 4 rows.
	b.op(mov(r0, reg::qpu_num));
	b.op(shl(r1, r0, imm(3)));
	b.ldi(r2, isa::VpmWriteSetup{.stride = 1, .horizontal = true, .laned = false,
	                             .size = isa::VpmSize::Bits32, .addr = 0}.word());
	b.op(add(VPMW, r2, r1));
	b.ldi(r2, isa::VdwSetup{.units = 4, .depth = 16, .horizontal = true, .vpm_base = 0, .modew = 0}.word());
	b.op(shl(r1, r0, imm(10))); // Y = 8q at bit 7
	b.op(add(VDWS, r2, r1));
	b.op(mov(r0, reg::elem_num));
	b.op(shl(ELEM4, r0, imm(2)));
	b.op(mov(SWMAX, b.uniform("src_wmax")));
	b.op(mov(STEPX, b.uniform("step_x")));
	b.op(mov(WMAX, b.uniform("wmax")));
	b.op(mov(DPITCH, b.uniform("dst_pitch")));
	b.op(mov(VDWSTRIDE, b.uniform("vdw_stride")));
	b.op(mov(FLOOR, b.uniform("light_floor")));
	b.ldi(K128, 128);

	Label unit = b.label();
	{
		b.op(mov(XS, b.uniform("x")));
		b.op(mov(DSTS, b.uniform("dst", UniformKind::Address)));
		b.op(mov(ROWS, b.uniform("rows")));
		// Per-lane source columns of x-2 .. x+2 (clamped to the scaled frame, then
		// mapped like scaleNearest) and the interior-column term (x-1) | (w-2-x).
		b.op(add(r0, XS, ELEM4));
		for (int k = 0; k < 5; ++k) {
			b.op(add(r1, r0, imm(k - 2)));
			b.op(max(r1, r1, imm(0)));
			b.op(min(r1, r1, WMAX));
			b.op(shl(r1, r1, imm(1)));
			b.op(add(r1, r1, imm(1)));
			b.op(mul24(r1, r1, STEPX));
			b.op(shr(r1, r1, imm(-15)));
			b.op(min(r1, r1, SWMAX));
			b.op(band(COLOFF[k], r1, imm(-4)));
			b.op(band(r2, r1, imm(3)));
			b.op(shl(COLSH[k], r2, imm(3)));
		}
		b.op(sub(r1, r0, imm(1)));
		b.op(sub(r2, WMAX, r0));
		b.op(sub(r2, r2, imm(1)));
		b.op(bor(r1, r1, r2));
		b.op(asr(r1, r1, imm(-1)));   // -1 off the interior columns
		b.op(bnot(COLMASK, r1));
		// Prefetch the first input row (its fifth column waits for room when 4 deep).
		b.op(mov(ROWADDR, reg::unif));
		for (int k = 0; k < (kDeep ? 5 : 4); ++k)
			b.op(add(tmuS(k), ROWADDR, COLOFF[k]));
		// Prologue: rows y0-3 .. y0+2 fill the window (gradient rows y0-1 and y0 are the
		// first needed: by row y0's tensor sum).
		b.ldi(CNT, 6);
		Label pro = b.label();
		rowBody(b);
		rowOutput(b);
		b.loopEnd(pro, CNT);
		// Main loop: one output row and one VDW per trip.
		b.op(mov(CNT, ROWS));
		Label main = b.label();
		rowBody(b);
		rowOutput(b);
		storeRow(b);
		b.loopEnd(main, CNT, {add(DSTS, DSTS, DPITCH), bxor(VDWS, VDWS, VDWTOG), bxor(VPMW, VPMW, imm(4))});
		// The last trip gathered one row beyond the window: drain it.
		for (int k = 0; k < (kDeep ? 5 : 4); ++k)
			b.ldtmu(k & 1);
	}
	b.nextTileOrEnd(unit);
	Built out;
	out.nops = b.nops();
	out.program = b.finish();
	return out;
}

} // namespace

Built gradientPass() { return build(); }

} // namespace frappe::vc4::kernels
