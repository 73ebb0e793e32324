// SPDX-License-Identifier: MIT
//
// PERSPECTIVE_WARP kernel (issue 6; the paper's QPU3 stage).
//
// One program invocation takes a list of candidates (candidate k of a launch runs on
// program k % 12) and, for each, computes the 16 x 16 samples of warpReference() exactly:
//
//  * Lanes and vectors. A candidate is 16 vectors of 16 lanes. Vector (c, b), c, b = 0..3,
//    lane w computes sample i = 4 (w % 4) + b, j = 4 c + w / 4, so that after the four
//    vectors of a chunk are packed into bytes (byte b of word w), VPM row c holds sample
//    rows 4c .. 4c+3 in raster order: one 4-row VDW writes the 256 bytes row-major.
//  * Homography. The host quantises it per candidate into three linear forms over the
//    sample grid (warpParams()); the kernel only adds: per-lane start values from the
//    element-number bits, +di per vector, +4 dj - 4 di per chunk.
//  * Division. x = ox + N_x / D, y = oy + N_y / D by 21-step restoring division (11 integer
//    and 10 fraction bits) on the ADD/MUL pipes, x and y interleaved so that the two
//    pipes share 6 instructions per step: sub.setf / conditional v8min-move / doubling for
//    the remainder, conditional +1 and mul24-by-2 for the quotient. No SFU (its reciprocal
//    has undocumented precision) and no float arithmetic (rounding on the QPU is not
//    documented to be IEEE round-to-nearest), so the result is defined by integers alone.
//  * Bilinear. Four general-memory TMU lookups per vector (p00, p01, p10, p11 at
//    word-aligned addresses; the byte is shifted out with shr by 8 * (address & 3)), then
//    exact integer weights of 10 bits: ((p00 (1024-fx) + p01 fx)(1024-fy) + (...) fy + 2^19) >> 20.
//    The TMU's own bilinear filter would save those ALU instructions but needs the frame
//    in T/LT tiling and has unspecified weight precision (vc4-research.md 5.2): that is an
//    approximate variant for later, not this bit-exact path.
//  * Output. Each program owns VPM rows 4 qpu .. 4 qpu + 3; the VDW to memory runs under
//    the hardware mutex (one VDW queue per V3D). The program ends with a host interrupt,
//    which the firmware's execute_qpu counts to see the launch complete.
//
// Why binarise and decode stay on the ARM (the paper ran them as its second VPU stage):
// per candidate they are branchy, serial work on tiny data - a min/max over the 144
// payload samples, 36 cell means against a threshold, then a nearest-codeword search over
// 4 rotations of a 36-bit code against up to 2320 dictionary words with popcounts and an
// early exit on ambiguity. That maps badly onto 16-lane SIMD with no popcount instruction
// and no per-lane branching, moves only 256 bytes per candidate, and costs tens of
// microseconds on the ARM1176; the warp, by contrast, is 256 independent samples with a
// division each, which is exactly what 12 x 16 lanes are for.
#include "kernels/warp.hpp"

#include <algorithm>
#include <stdexcept>

#include "asm/assembler.hpp"
#include "isa/setup_words.hpp"

namespace frappe::vc4::kernels {

using namespace qasm;
using isa::BranchCond;

namespace {

// Register file A.
constexpr uint8_t QX = 0, QY = 1, NX = 2, NY = 3, DD = 4, T1 = 5, T3 = 6, FX = 7, FY = 8, BASE = 9,
                  STRIDE = 10, MASK = 11, PACK = 12, SH8 = 13, C255 = 14, CNT = 15, CC = 16, BC = 17,
                  OUT = 18, WX0 = 19;
// Register file B.
constexpr uint8_t OXF = 0, OYF = 1, XMAX = 2, YMAX = 3, WM2 = 4, HM2 = 5, YS = 6, S00 = 7, S01 = 8,
                  S10 = 9, S11 = 10, C1024 = 11, RND = 12, DXI = 13, DYI = 14, DDI = 15, CXS = 16,
                  CYS = 17, CDS = 18, VPMW = 19, VDWS = 20, WY0 = 21;

// Reads one linear form (at00, di, dj) from the uniforms and leaves in `state` (file A)
// its per-lane value for vector (0, 0), in `di_reg` (file B) di and in `chunk_reg` (B)
// 4 dj - 4 di.
void laneStart(Assembler &a, const std::string &n, uint8_t state, uint8_t di_reg, uint8_t chunk_reg)
{
	a.emit(mov(r0, a.uniform(n + ".at00")));
	a.emit(mov(r1, a.uniform(n + ".di")));
	a.emit(mov(r2, a.uniform(n + ".dj")));
	a.emit(shl(r3, r1, imm(2)));                              // 4 di: lanes with w & 1
	a.emit(band(reg::nop, reg::elem_num, imm(1)).setFlags(), mmov(wb(di_reg), r1));
	a.emit(add(r0, r0, r3).ifnz());
	a.emit(shl(r3, r1, imm(3)));                              // 8 di: w & 2
	a.emit(band(reg::nop, reg::elem_num, imm(2)).setFlags());
	a.emit(add(r0, r0, r3).ifnz());
	a.emit(band(reg::nop, reg::elem_num, imm(4)).setFlags()); // dj: w & 4
	a.emit(add(r0, r0, r2).ifnz());
	a.emit(shl(r3, r2, imm(1)));                              // 2 dj: w & 8
	a.emit(band(reg::nop, reg::elem_num, imm(8)).setFlags());
	a.emit(add(r0, r0, r3).ifnz());
	a.emit(sub(r3, r2, r1), mmov(wa(state), r0));
	a.emit(shl(wb(chunk_reg), r3, imm(2)));
}

// One vector of 16 samples: ORs (sample << SH8) into PACK.
void sampleVector(Assembler &a)
{
	// Division set-up: r3 = Dk = D << 10; remainders clamped to [0, 2 Dk - 1].
	a.emit(shl(r3, ra(DD), imm(10)));
	a.emit(add(r0, r3, r3));
	a.emit(sub(r0, r0, imm(1)));
	a.emit(max(r1, ra(NX), imm(0)), mmov(wa(QX), imm(0)));
	a.emit(min(r1, r1, r0));
	a.emit(max(r2, ra(NY), imm(0)), mmov(wa(QY), imm(0)));
	a.emit(min(r2, r2, r0));
	// 21 restoring-division steps, x (r1 -> QX) and y (r2 -> QY) interleaved; r0 is the
	// trial remainder. A quotient is doubled before each of its bits is added.
	for (int k = 0; k < kWarpDivisionSteps; ++k) {
		const bool last = k == kWarpDivisionSteps - 1;
		a.emit(sub(r0, r1, r3).setFlags(), mul24(wa(QY), ra(QY), imm(2)));
		a.emit(add(wa(QX), ra(QX), imm(1)).ifnn(), mmov(r1, r0).ifnn());
		if (!last)
			a.emit(add(r1, r1, r1));
		a.emit(sub(r0, r2, r3).setFlags());
		a.emit(add(wa(QY), ra(QY), imm(1)).ifnn(), mmov(r2, r0).ifnn());
		if (!last)
			a.emit(add(r2, r2, r2), mul24(wa(QX), ra(QX), imm(2)));
	}
	// Positions with 10 fraction bits clamped to the image (r0 = X, r1 = Y), cells
	// (r2 = x0, r3 = y0) and weights (FX, FY).
	a.emit(add(r0, ra(QX), rb(OXF)));
	a.emit(add(r1, ra(QY), rb(OYF)));
	a.emit(max(r0, r0, imm(0)));
	a.emit(max(r1, r1, imm(0)));
	a.emit(min(r0, r0, rb(XMAX)));
	a.emit(min(r1, r1, rb(YMAX)));
	a.emit(shr(r2, r0, imm(10)));
	a.emit(shr(r3, r1, imm(10)));
	a.emit(min(r2, r2, rb(WM2)));
	a.emit(min(r3, r3, rb(HM2)));
	a.emit(shl(wa(T1), r2, imm(10)), mul24(wb(YS), r3, ra(STRIDE)));
	a.emit(shl(wa(T3), r3, imm(10)));
	a.emit(sub(wa(FX), r0, ra(T1)));
	a.emit(sub(wa(FY), r1, ra(T3)));
	// Addresses of p00, p01, p10, p11 in r0..r3; TMU reads of their aligned words, byte
	// shifts 8 * (address & 3) by mul24 (shr uses the low 5 bits only).
	a.emit(add(r0, r2, rb(YS)));
	a.emit(add(r0, r0, ra(BASE)));
	a.emit(band(reg::tmu0_s, r0, ra(MASK)), mul24(wb(S00), r0, imm(8)));
	a.emit(add(r1, r0, imm(1)));
	a.emit(band(reg::tmu0_s, r1, ra(MASK)), mul24(wb(S01), r1, imm(8)));
	a.emit(add(r2, r0, ra(STRIDE)));
	a.emit(band(reg::tmu0_s, r2, ra(MASK)), mul24(wb(S10), r2, imm(8)));
	a.emit(add(r3, r2, imm(1)));
	a.emit(band(reg::tmu0_s, r3, ra(MASK)), mul24(wb(S11), r3, imm(8)));
	a.emit(sub(wa(WX0), rb(C1024), ra(FX)));
	a.emit(sub(wb(WY0), rb(C1024), ra(FY)));
	// Bilinear in integers: top = p00 wx0 + p01 fx, bot = p10 wx0 + p11 fx,
	// v = top wy0 + bot fy, sample = (v + 2^19) >> 20.
	a.ldtmu(0);
	a.emit(shr(r0, r4, rb(S00)));
	a.ldtmu(0, band(r0, r0, ra(C255)));
	a.emit(shr(r1, r4, rb(S01)), mul24(r2, r0, ra(WX0)));
	a.ldtmu(0, band(r1, r1, ra(C255)));
	a.emit(shr(r0, r4, rb(S10)), mul24(r1, r1, ra(FX)));
	a.emit(add(r2, r2, r1));
	a.ldtmu(0, band(r0, r0, ra(C255)));
	a.emit(shr(r1, r4, rb(S11)), mul24(r0, r0, ra(WX0)));
	a.emit(band(r1, r1, ra(C255)), mul24(r2, r2, rb(WY0)));
	a.emit(mul24(r1, r1, ra(FX)));
	a.emit(add(r0, r0, r1));
	a.emit(mul24(r0, r0, ra(FY)));
	a.emit(add(r0, r0, r2));
	a.emit(add(r0, r0, rb(RND)));
	a.emit(shr(r0, r0, imm(-12))); // shifts use the low 5 bits: -12 & 31 = 20
	a.emit(shl(r0, r0, ra(SH8)));
	a.emit(bor(wa(PACK), ra(PACK), r0));
}

} // namespace

qasm::Program warpKernel()
{
	Assembler a("warp");
	Label candidate = a.newLabel(), chunk = a.newLabel(), vector = a.newLabel(), end = a.newLabel();
	a.emit(mov(wa(BASE), a.uniform("image", UniformKind::Address)));
	a.emit(mov(wa(STRIDE), a.uniform("stride")));
	a.emit(mov(wb(XMAX), a.uniform("xmax")));
	a.emit(mov(wb(YMAX), a.uniform("ymax")));
	a.emit(mov(wb(WM2), a.uniform("width_minus_2")));
	a.emit(mov(wb(HM2), a.uniform("height_minus_2")));
	a.emit(mov(wa(CNT), a.uniform("candidates")).setFlags());
	a.branch(end, BranchCond::AllZSet);
	a.ldi(wa(C255), 255);
	a.ldi(wb(C1024), 1u << kWarpFracBits);
	a.ldi(wb(RND), 1u << (2 * kWarpFracBits - 1));
	a.emit(mov(wa(MASK), imm(-4)));
	// This program's VPM rows 4 q .. 4 q + 3: write setup and the matching 4-row VDW.
	a.emit(mov(r0, reg::qpu_num));
	a.emit(shl(r0, r0, imm(2)));
	a.ldi(r1, isa::VpmWriteSetup{.stride = 1, .horizontal = true, .laned = false, .size = isa::VpmSize::Bits32,
	                             .addr = 0}.word());
	a.emit(add(wb(VPMW), r1, r0));
	a.emit(shl(r2, r0, imm(7))); // VPM Y sits at bit 7 of the VDW word
	a.ldi(r1, isa::VdwSetup{.units = 4, .depth = 16, .horizontal = true, .vpm_base = 0, .modew = 0}.word());
	a.emit(add(wb(VDWS), r1, r2));

	a.bind(candidate);
	a.emit(mov(wa(OUT), a.uniform("out", UniformKind::Address)));
	a.emit(mov(wb(OXF), a.uniform("ox_fixed")));
	a.emit(mov(wb(OYF), a.uniform("oy_fixed")));
	laneStart(a, "x", NX, DXI, CXS);
	laneStart(a, "y", NY, DYI, CYS);
	laneStart(a, "d", DD, DDI, CDS);
	a.emit(mov(reg::vw_setup, rb(VPMW)));
	a.ldi(wa(CC), 4);

	a.bind(chunk);
	a.emit(mov(wa(PACK), imm(0)));
	a.emit(mov(wa(SH8), imm(0)));
	a.ldi(wa(BC), 4);
	a.bind(vector);
	sampleVector(a);
	a.emit(add(wa(SH8), ra(SH8), imm(8)));
	a.emit(sub(wa(BC), ra(BC), imm(1)).setFlags());
	a.branch(vector, BranchCond::AnyZClear);
	a.emit(add(wa(DD), ra(DD), rb(DDI))); // delay slots: the per-vector steps, in the
	a.emit(add(wa(NX), ra(NX), rb(DXI))); // order the loop head reads them
	a.emit(add(wa(NY), ra(NY), rb(DYI)));
	a.emit(mov(reg::vpm_write, ra(PACK)));
	a.emit(add(wa(NX), ra(NX), rb(CXS)));
	a.emit(add(wa(NY), ra(NY), rb(CYS)));
	a.emit(add(wa(DD), ra(DD), rb(CDS)));
	a.emit(sub(wa(CC), ra(CC), imm(1)).setFlags());
	a.branch(chunk, BranchCond::AnyZClear);
	a.nop();
	a.nop();
	a.nop();

	// 4 VPM rows -> 256 contiguous bytes at OUT, one VDW at a time across the QPUs.
	a.emit(mov(reg::nop, reg::mutex_acq));
	a.ldi(reg::vw_setup, isa::VdwStride{0}.word());
	a.emit(mov(reg::vw_setup, rb(VDWS)));
	a.emit(mov(reg::vw_addr, ra(OUT)));
	a.emit(mov(reg::nop, reg::vw_wait));
	a.emit(mov(reg::mutex_rel, imm(1)));
	a.emit(sub(wa(CNT), ra(CNT), imm(1)).setFlags());
	a.branch(candidate, BranchCond::AnyZClear);
	a.nop();
	a.nop();
	a.nop();

	a.bind(end);
	a.emit(mov(reg::host_int, imm(1)));
	a.thrend();
	return a.finish();
}

unsigned writeWarpUniforms(const WarpImage &image, std::span<const WarpParams> candidates, uint32_t out_bus,
                           unsigned programs, std::span<uint32_t *const> streams)
{
	if (candidates.size() > static_cast<size_t>(kWarpMaxCandidates))
		throw std::invalid_argument("warpUniforms: at most 32 candidates a launch");
	if (image.width < 2 || image.height < 2 || programs == 0 || programs > 12)
		throw std::invalid_argument("warpUniforms: image of at least 2 x 2, 1 to 12 programs");
	const size_t n = std::min<size_t>(programs, candidates.size());
	if (streams.size() < n)
		throw std::invalid_argument("warpUniforms: fewer streams than programs");
	for (size_t p = 0; p < n; ++p) {
		const auto count = static_cast<uint32_t>((candidates.size() - p + n - 1) / n);
		const uint32_t head[kWarpProgramUniforms] = {image.bus,
		                                             image.stride,
		                                             static_cast<uint32_t>(image.width - 1) << kWarpFracBits,
		                                             static_cast<uint32_t>(image.height - 1) << kWarpFracBits,
		                                             static_cast<uint32_t>(image.width - 2),
		                                             static_cast<uint32_t>(image.height - 2),
		                                             count};
		std::copy(std::begin(head), std::end(head), streams[p]);
	}
	for (size_t k = 0; k < candidates.size(); ++k) {
		const WarpParams &c = candidates[k];
		uint32_t *s = streams[k % n] + kWarpProgramUniforms + kWarpCandidateUniforms * (k / n);
		const auto u = [](int32_t v) { return static_cast<uint32_t>(v); };
		const uint32_t words[kWarpCandidateUniforms] = {
			out_bus + static_cast<uint32_t>(kWarpOutputBytes * k), u(c.ox) << kWarpFracBits,
			u(c.oy) << kWarpFracBits, u(c.x.at00), u(c.x.di), u(c.x.dj), u(c.y.at00), u(c.y.di),
			u(c.y.dj), u(c.d.at00), u(c.d.di), u(c.d.dj)};
		std::copy(std::begin(words), std::end(words), s);
	}
	return static_cast<unsigned>(n);
}

std::vector<std::vector<uint32_t>> warpUniforms(const WarpImage &image, std::span<const WarpParams> candidates,
                                                uint32_t out_bus, unsigned programs)
{
	const size_t n = std::min<size_t>(std::clamp(programs, 1u, 12u), candidates.size());
	std::vector<std::vector<uint32_t>> streams(n);
	uint32_t *heads[12] = {};
	for (size_t p = 0; p < n; ++p) {
		const size_t count = (candidates.size() - p + n - 1) / n;
		streams[p].resize(kWarpProgramUniforms + kWarpCandidateUniforms * count);
		heads[p] = streams[p].data();
	}
	writeWarpUniforms(image, candidates, out_bus, programs, std::span<uint32_t *const>(heads, n));
	return streams;
}

} // namespace frappe::vc4::kernels
