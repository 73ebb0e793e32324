// SPDX-License-Identifier: MIT
// The region map on the QPUs: frappe-core's EdgeMap::regions (the rule at the top of
// front_end_cpu.cpp), byte for byte, in two launches over blocks of 64 x 16 region-map
// pixels (layout and uniforms: kernels.hpp).
//
// Lane i of a block holds tile column i (region-map pixels x0 + 4i .. x0 + 4i + 3), so a
// lane's four pixels are one word and a 16-word VPM row is a 64-pixel map row.
//  means (regionMeansPass): each pixel's four frame pixels are per-lane TMU gathers through
//    scaleNearest's mapping (source rows from the uniform stream, columns computed here, as
//    pass 1 does), r = (sum + 2) >> 2 packed into the lane's word by regfile-A byte packs;
//    each tile's least and greatest r by per-byte v8min/v8max over its four rows. Out: per
//    tile row the four rows of r and a row of tile words lo | (255 - hi) << 8, one VDW.
//  dark (regionDarkPass): the nine tile words around a tile (clamped to the tiles that
//    exist) reduced by v8min, which gives the least lo and, in byte 1, 255 - the greatest
//    hi; mid = (lo + hi + 1) >> 1 when hi - lo >= C, else 0, where the contrast follows the
//    light, C = (contrast * min(lo + hi + 2 floor, 256) + 255) >> 8; a pixel is dark when
//    v8subs(mid x 4, r) is non-zero in its byte (r < mid), v8min with the lane's interior
//    column bytes makes that kEdge, a row mask from the uniform stream clears the outer
//    rows. Four rows a VDW, double-buffered; the OR of the block's words is its mask row.
// Gathers are pipelined four deep (both TMUs together): the hardware's reliable limit.
#include <initializer_list>

#include "isa/setup_words.hpp"
#include "kernels/builder.hpp"
#include "kernels/kernels.hpp"

namespace frappe::vc4::kernels {

namespace {

constexpr unsigned kDepth = 4; // TMU requests in flight per QPU

Dst tmuAt(unsigned k) { return (k & 1) ? reg::tmu1_s : reg::tmu0_s; }
Pack byteLane(unsigned j) { return static_cast<Pack>(static_cast<unsigned>(Pack::B8A) + j); }

// This QPU's VPM rows 8q .. 8q+7: the write setup of row 8q and a VDW of `units` rows from it.
void vpmRows(Builder &b, Reg vpmw, Reg vdws, uint8_t units)
{
	b.op(mov(r0, reg::qpu_num));
	b.op(shl(r1, r0, imm(3)));
	b.ldi(r2, isa::VpmWriteSetup{.stride = 1, .horizontal = true, .laned = false,
	                             .size = isa::VpmSize::Bits32, .addr = 0}.word());
	b.op(add(vpmw, r2, r1));
	b.ldi(r2, isa::VdwSetup{.units = units, .depth = 16, .horizontal = true, .vpm_base = 0, .modew = 0}.word());
	b.op(shl(r1, r0, imm(10))); // Y = 8q at bit 7
	b.op(add(vdws, r2, r1));
}

// A block's uniforms, in stream order, each into its register.
struct UniformTo {
	Reg reg;
	const char *name;
	UniformKind kind = UniformKind::Value;
};
void readUniforms(Builder &b, std::initializer_list<UniformTo> list)
{
	for (const UniformTo &u : list)
		b.op(mov(u.reg, b.uniform(u.name, u.kind)));
}

// The end of a block: the next one, or the end of the program.
Built lastBlock(Builder &b, Label block)
{
	b.nextTileOrEnd(block);
	Built out;
	out.nops = b.nops();
	out.program = b.finish();
	return out;
}

// Starts the VDW of `setup` to `addr` (setup registers under the mutex, as the other passes).
void startVdw(Builder &b, Reg stride, Src setup, Reg addr)
{
	b.op(mov(reg::nop, reg::mutex_acq));
	b.op(mov(reg::vw_setup, stride));
	b.op(mov(reg::vw_setup, setup));
	b.op(mov(reg::vw_addr, addr));
	b.op(mov(reg::mutex_rel, imm(1)));
}

namespace means {

// RW: the four rows of a tile row (byte j = pixel 4i + j), written by byte packs.
constexpr Reg RW[4] = {A(0), A(1), A(2), A(3)};
constexpr Reg COLSH[8] = {A(4), A(5), A(6), A(7), A(8), A(9), A(10), A(11)};
constexpr Reg STAT = A(12), SWMAX = A(13), STEPX = A(14), RWMAX = A(15), TRCNT = A(16), VPMW = A(17),
	      DSTSTEP = A(18);
constexpr Reg COLOFF[8] = {B(0), B(1), B(2), B(3), B(4), B(5), B(6), B(7)};
constexpr Reg LO4 = B(8), HI4 = B(9), DST = B(10), VDWSTRIDE = B(11), VDWS = B(13), XS = B(14), TWO = B(15);

// Request q of a tile row (16 per map row: pixel j = k / 4, then source row a, a, b, b and
// column 2x, 2x+1); r0 and r1 hold the source rows' addresses of the row being issued.
AddOp issue(unsigned q)
{
	const unsigned k = q % 16, s = k % 4;
	return add(tmuAt(q), s < 2 ? Src(r0) : Src(r1), COLOFF[2 * (k / 4) + (s & 1)]);
}

// Adds request q's masked value (r2) into the pixel's sum (r3, which starts at 2).
AddOp accumulate(unsigned q)
{
	return q % 4 == 0 ? add(r3, r2, TWO) : add(r3, r3, r2);
}

// One tile row: pops the 64 requests of its four rows while issuing four ahead (the last
// four are the next tile row's first: the host's uniform stream has one more row).
void tileRow(Builder &b)
{
	for (unsigned q = 0; q < 64; ++q) {
		const unsigned n = q / 16, k = q % 16;
		MulOp m1;
		if (k == 12)
			m1 = mmov(r0, reg::unif); // the next row's source rows: its requests start at q + 4
		else if (n > 0 && k == 2)
			m1 = n == 1 ? mmov(LO4, RW[0]) : v8min(LO4, LO4, RW[n - 1]);
		else if (n > 0 && k == 3)
			m1 = n == 1 ? mmov(HI4, RW[0]) : v8max(HI4, HI4, RW[n - 1]);
		b.ldtmu(q & 1, q ? accumulate(q - 1) : AddOp{}, m1);
		if (q > 0 && q % 4 == 0) // pixel q - 1 is summed: r = (sum + 2) >> 2 into its byte
			b.op(shr(Dst(RW[(q - 1) / 16])[byteLane(((q - 1) % 16) / 4)], r3, imm(2)));
		b.op(shr(r2, r4, COLSH[2 * (k / 4) + (k & 1)]), k == 12 ? mmov(r1, reg::unif) : MulOp{});
		b.op(issue(q + kDepth), v8min(r2, r2, r5)); // r5 = 0xff: the byte
	}
	b.op(accumulate(63));
	b.op(shr(Dst(RW[3])[Pack::B8D], r3, imm(2)));
	b.op(v8min(LO4, LO4, RW[3]));
	b.op(v8max(HI4, HI4, RW[3]));
	// The tile's extremes: each lane's four bytes reduced by two shifts (in r2 and r3: r0 and
	// r1 hold the next tile row's source rows).
	b.op(mov(r2, LO4));
	b.op(shr(r3, r2, imm(-16)));
	b.op(v8min(r2, r2, r3));
	b.op(shr(r3, r2, imm(8)));
	b.op(v8min(r2, r2, r3));
	b.op(mov(Dst(STAT)[Pack::B8A], r2));
	b.op(mov(r2, HI4));
	b.op(shr(r3, r2, imm(-16)));
	b.op(v8max(r2, r2, r3));
	b.op(shr(r3, r2, imm(8)));
	b.op(v8max(r2, r2, r3));
	b.op(bxor(Dst(STAT)[Pack::B8B], r2, r5));
	// Out: rows of r and the tile words, once the last VDW has read the VPM.
	b.op(mov(reg::nop, reg::vw_wait));
	b.op(mov(reg::vw_setup, VPMW));
	for (const Reg &row : RW)
		b.op(mov(reg::vpm_write, row));
	b.op(mov(reg::vpm_write, STAT));
	startVdw(b, VDWSTRIDE, VDWS, DST);
	b.op(add(DST, DST, DSTSTEP));
}

Built build()
{
	Builder b("frappe_region_means");
	b.ldi(reg::r5rep, 0xff);
	b.ldi(TWO, 2);
	vpmRows(b, VPMW, VDWS, 5);

	Label block = b.label();
	readUniforms(b, {{SWMAX, "src_wmax"}, {STEPX, "step_x"}, {RWMAX, "rwmax"}, {XS, "x0"},
	                 {DST, "dst", UniformKind::Address}, {VDWSTRIDE, "vdw_stride"}, {DSTSTEP, "dst_step"}});
	// Per lane and pixel j: x = min(x0 + 4 lane + j, w - 1), frame columns 2x and 2x + 1,
	// mapped like scaleNearest: min(W - 1, ((2X + 1) step_x) >> 17) in the source.
	b.op(shl(r0, reg::elem_num, imm(2)));
	b.op(add(r0, r0, XS));
	for (int j = 0; j < 4; ++j) {
		b.op(add(r1, r0, imm(j)));
		b.op(min(r1, r1, RWMAX));
		b.op(shl(r1, r1, imm(2)));
		for (int c = 0; c < 2; ++c) {
			b.op(add(r2, r1, imm(2 * c + 1)));
			b.op(mul24(r2, r2, STEPX));
			b.op(shr(r2, r2, imm(-15))); // >> 17 (shift counts use 5 bits)
			b.op(min(r2, r2, SWMAX));
			b.op(band(COLOFF[2 * j + c], r2, imm(-4)));
			b.op(band(r3, r2, imm(3)));
			b.op(shl(COLSH[2 * j + c], r3, imm(3)));
		}
	}
	// Row 0's requests, then four tile rows.
	b.op(mov(r0, reg::unif));
	b.op(mov(r1, reg::unif));
	for (unsigned q = 0; q < kDepth; ++q)
		b.op(issue(q));
	b.ldi(TRCNT, 4);
	Label trow = b.label();
	tileRow(b);
	b.loopEnd(trow, TRCNT);
	// The requests of the row after the block.
	for (unsigned q = 0; q < kDepth; ++q)
		b.ldtmu(q & 1);
	return lastBlock(b, block);
}

} // namespace means

namespace dark {

constexpr Reg COLW = A(0), M4 = A(1), MASKACC = A(2), VPMROW = A(3), EDST = A(4), MDST = A(5),
	      VDWTOG = A(6), UNITDIFF = A(7), TRCNT = A(8), TXM1 = A(9), RWM2 = A(10), CONTRAST = A(11);
constexpr Reg COLOFF[3] = {B(0), B(1), B(2)};
constexpr Reg FLOOR2 = B(9), C256 = B(10);
constexpr Reg LANE4 = B(3), VDWSTRIDE = B(5), EPITCH4 = B(6), VDWS = B(7), XS = B(8);

// Requests 0 .. 8: the tile words of rows up, this, down (r0, r1, r2) at the clamped columns
// left, this, right; 9 .. 12: the four rows of r (addresses from the uniform stream).
AddOp issue(unsigned k)
{
	if (k < 9)
		return add(tmuAt(k), k / 3 == 0 ? Src(r0) : k / 3 == 1 ? Src(r1) : Src(r2), COLOFF[k % 3]);
	return add(tmuAt(k), reg::unif, LANE4);
}

void tileRow(Builder &b)
{
	b.op(mov(r0, reg::unif));
	b.op(mov(r1, reg::unif));
	b.op(mov(r2, reg::unif));
	for (unsigned k = 0; k < kDepth; ++k)
		b.op(issue(k));
	for (unsigned k = 0; k < 9; ++k) {
		b.ldtmu(k & 1);
		const MulOp fold = k ? v8min(r3, r3, r4) : mmov(r3, r4);
		if (k + kDepth < 13)
			b.op(issue(k + kDepth), fold);
		else
			b.op(fold);
	}
	// r3: byte 0 the least lo, byte 1 255 - the greatest hi, of the nine tiles.
	b.op(band(r0, r3, r5));
	b.op(shr(r1, r3, imm(8)));
	b.op(band(r1, r1, r5));
	b.op(bxor(r1, r1, r5));                       // hi
	b.op(sub(r2, r1, r0));                        // hi - lo
	b.op(add(r1, r1, r0));                        // lo + hi
	// The contrast at this light: (contrast * min(lo + hi + 2 floor, 256) + 255) >> 8
	// (contrast <= 2^16: the product fits mul24).
	b.op(add(r3, r1, FLOOR2));
	b.op(min(r3, r3, C256));
	b.op(add(r1, r1, imm(1)), mul24(r3, r3, CONTRAST));
	b.op(shr(r1, r1, imm(1)));                    // mid
	b.op(add(r3, r3, r5));                        // + 255
	b.op(shr(r3, r3, imm(8)));
	b.op(sub(reg::nop, r2, r3).setFlags());
	b.op(mov(r1, imm(0)).ifn());                  // too little contrast: nothing is dark
	b.op(mov(Dst(M4)[Pack::B8888], r1));          // mid in every byte
	b.op(mov(reg::vw_setup, VPMROW));
	for (unsigned k = 9; k < 13; ++k) {
		b.ldtmu(k & 1);
		b.op(mv8subs(r0, M4, r4));            // byte > 0 where r < mid
		b.op(v8min(r0, r0, COLW));            // kEdge, on interior columns
		b.op(band(r0, r0, reg::unif));        // the row's mask: -1 on rows 1 .. h-2
		b.op(bor(MASKACC, MASKACC, r0), mmov(reg::vpm_write, r0));
	}
	// Four rows out; flip to the other VPM half (its VDW is done by the wait).
	b.op(bxor(VPMROW, VPMROW, imm(4)));
	b.op(mov(reg::nop, reg::vw_wait));
	startVdw(b, VDWSTRIDE, VDWS, EDST);
	b.op(add(EDST, EDST, EPITCH4));
	b.op(bxor(VDWS, VDWS, VDWTOG));
}

Built build()
{
	Builder b("frappe_region_dark");
	b.ldi(reg::r5rep, 0xff);
	b.ldi(VDWTOG, 4u << 7);     // VDW VPM base Y sits at bit 7: flip between the two halves
	b.ldi(UNITDIFF, 3u << 23);  // VDW units 4 -> 1
	b.ldi(C256, 256);
	vpmRows(b, VPMROW, VDWS, 4);

	Label block = b.label();
	readUniforms(b, {{CONTRAST, "contrast"}, {FLOOR2, "floor2"}, {XS, "x0"}, {TXM1, "txm1"}, {RWM2, "rwm2"},
	                 {EDST, "out_dst", UniformKind::Address}, {VDWSTRIDE, "vdw_stride"},
	                 {EPITCH4, "out_pitch4"}, {MDST, "mask_dst", UniformKind::Address}});
	// Byte j of COLW: 1 when pixel x = x0 + 4 lane + j is in 1 .. w-2 (the outermost
	// columns are never dark).
	b.op(shl(r0, reg::elem_num, imm(2)));
	b.op(add(r0, r0, XS));
	b.op(mov(LANE4, r0));                         // the lane's word in a row of r
	for (int j = 0; j < 4; ++j) {
		b.op(sub(r1, r0, imm(1 - j)));        // x - 1
		b.op(sub(r2, RWM2, r0));
		b.op(sub(r2, r2, imm(j)));            // w - 2 - x
		b.op(bor(r1, r1, r2));
		b.op(bnot(r1, r1));
		b.op(shr(Dst(COLW)[byteLane(j)], r1, imm(-1)));
	}
	// The lane's tile column c and its neighbours, clamped to 0 .. tiles_x - 1.
	b.op(shr(r0, r0, imm(2)));
	for (int d = -1; d <= 1; ++d) {
		b.op(add(r1, r0, imm(d)));
		b.op(max(r1, r1, imm(0)));
		b.op(min(r1, r1, TXM1));
		b.op(shl(COLOFF[d + 1], r1, imm(2)));
	}
	b.op(mov(MASKACC, imm(0)));
	b.ldi(TRCNT, 4);
	Label trow = b.label();
	tileRow(b);
	b.loopEnd(trow, TRCNT);
	// The block's mask row (the OR of each lane's words; lanes 4t .. 4t+3 cover the 16 x 16
	// block t) through the idle VPM half.
	b.op(mov(reg::vw_setup, VPMROW));
	b.op(mov(reg::vpm_write, MASKACC));
	b.op(sub(r2, VDWS, UNITDIFF));
	b.op(mov(reg::nop, reg::vw_wait));
	startVdw(b, VDWSTRIDE, r2, MDST);
	b.op(mov(reg::nop, reg::vw_wait));
	return lastBlock(b, block);
}

} // namespace dark

} // namespace

Built regionMeansPass() { return means::build(); }
Built regionDarkPass() { return dark::build(); }

uint32_t *regionSourceRows(uint32_t *out, uint32_t src, uint32_t stride, int src_h, uint32_t step_y, int h, int y0)
{
	// Scaled frame row Y: scaleNearest's source row; map row y: frame rows 2y and 2y + 1.
	auto row = [&](int y) {
		const uint64_t sy = ((2 * static_cast<uint64_t>(y) + 1) * step_y) >> 17;
		return src + stride * static_cast<uint32_t>(sy < static_cast<uint64_t>(src_h - 1) ? sy : src_h - 1);
	};
	for (int i = 0; i <= kRegionBlockH; ++i) {
		const int y = y0 + i < h - 1 ? y0 + i : h - 1;
		*out++ = row(2 * y);
		*out++ = row(2 * y + 1);
	}
	return out;
}

uint32_t *regionTileRows(uint32_t *out, uint32_t buffer, uint32_t pitch, int h, int y0)
{
	const int tiles_y = (h + 3) / 4;
	for (int g = 0; g < kRegionBlockH / 4; ++g) {
		const int t = y0 / 4 + g;
		for (int d = -1; d <= 1; ++d) {
			const int u = t + d < 0 ? 0 : t + d > tiles_y - 1 ? tiles_y - 1 : t + d;
			*out++ = buffer + (5 * static_cast<uint32_t>(u) + 4) * pitch;
		}
		for (int k = 0; k < 4; ++k)
			*out++ = buffer + (5 * static_cast<uint32_t>(t) + static_cast<uint32_t>(k)) * pitch;
		for (int k = 0; k < 4; ++k) {
			const int y = 4 * t + k;
			*out++ = y >= 1 && y <= h - 2 ? 0xffffffffu : 0u;
		}
	}
	return out;
}

} // namespace frappe::vc4::kernels
