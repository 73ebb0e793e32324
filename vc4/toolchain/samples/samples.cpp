// SPDX-License-Identifier: MIT
#include "samples/samples.hpp"

#include "asm/assembler.hpp"
#include "isa/setup_words.hpp"

namespace frappe::vc4::samples {

using namespace qasm;
using isa::BranchCond;
using isa::Sig;

namespace {

// Stores r-value `src` (a 16-lane vector in an accumulator) to `address` (regfile A) via
// VPM row `row` (rb) and a one-row VDW, serialised with the hardware mutex.
void storeRow(Assembler &a, Src value, Src row_setup, Src vdw_setup, uint8_t address_ra)
{
	a.emit(mov(reg::nop, reg::mutex_acq));
	a.emit(mov(reg::vw_setup, row_setup));
	a.emit(mov(reg::vpm_write, value));
	a.emit(mov(reg::vw_setup, vdw_setup));
	a.emit(mov(reg::vw_addr, ra(address_ra)));
	a.emit(mov(reg::nop, reg::vw_wait));
	a.emit(mov(reg::mutex_rel, imm(1)));
}

// rb10 = VPM write setup of row qpu_num, rb11 = VDW setup for that row (1 x 16 words).
void rowSetups(Assembler &a)
{
	a.ldi(r0, isa::VpmWriteSetup{.stride = 1, .horizontal = true, .laned = false,
	                             .size = isa::VpmSize::Bits32, .addr = 0}.word());
	a.ldi(r1, isa::VdwSetup{.units = 1, .depth = 16, .horizontal = true, .vpm_base = 0, .modew = 0}.word());
	a.emit(add(wb(10), r0, reg::qpu_num));
	a.emit(mov(r2, reg::qpu_num));
	a.emit(shl(r2, r2, imm(7))); // VPMBASE Y sits at bit 7 of the VDW word
	a.emit(add(wb(11), r1, r2));
}

} // namespace

Program vectorSum()
{
	Assembler a("vector_sum");
	a.emit(mov(wa(0), a.uniform("a", UniformKind::Address)));
	a.emit(mov(wa(1), a.uniform("b", UniformKind::Address)));
	a.emit(mov(wa(2), a.uniform("out", UniformKind::Address)));
	a.emit(mov(wa(3), a.uniform("vectors")));
	rowSetups(a);
	a.emit(shl(wb(12), reg::elem_num, imm(2)));
	a.ldi(wb(13), 64);
	Label loop = a.newLabel();
	a.bind(loop);
	a.emit(add(reg::tmu0_s, ra(0), rb(12)));
	a.emit(add(reg::tmu0_s, ra(1), rb(12)));
	a.ldtmu(0);
	a.emit(mov(r2, r4));
	a.ldtmu(0);
	a.emit(add(r3, r2, r4));
	storeRow(a, r3, rb(10), rb(11), 2);
	a.emit(add(wa(0), ra(0), rb(13)));
	a.emit(add(wa(1), ra(1), rb(13)));
	a.emit(add(wa(2), ra(2), rb(13)));
	a.emit(sub(wa(3), ra(3), imm(1)).setFlags());
	a.branch(loop, BranchCond::AnyZClear);
	a.nop();
	a.nop();
	a.nop();
	a.thrend();
	return a.finish();
}

Program laneReduction()
{
	Assembler a("lane_reduction");
	a.emit(shl(r1, reg::elem_num, imm(2)));
	a.emit(add(reg::tmu0_s, a.uniform("in", UniformKind::Address), r1));
	a.emit(mov(wa(2), a.uniform("out", UniformKind::Address)));
	rowSetups(a);
	a.ldtmu(0);
	a.emit(mov(r0, r4));
	for (uint8_t n : {8, 4, 2, 1}) {
		a.nop(); // a rotated accumulator must not be written by the previous instruction
		a.emit(mmov(r1, r0).rot(n));
		a.emit(add(r0, r0, r1));
	}
	storeRow(a, r0, rb(10), rb(11), 2);
	a.thrend();
	return a.finish();
}

Program tileCopy()
{
	Assembler a("tile_copy");
	a.emit(mov(wa(0), a.uniform("src", UniformKind::Address)));
	a.emit(mov(wa(1), a.uniform("dst", UniformKind::Address)));
	a.emit(mov(wa(2), a.uniform("src_pitch")));
	a.emit(mov(wa(3), a.uniform("dst_pitch")));
	// The VPM rows 0..15 are shared by all QPUs: hold the mutex while using them.
	a.emit(mov(reg::nop, reg::mutex_acq));
	a.ldi(r0, isa::VdrStride{0}.word());
	a.emit(bor(reg::vr_setup, r0, ra(2)));
	a.ldi(reg::vr_setup, isa::VdrSetup{.modew = 0, .mpitch = 0, .rowlen = 0, .nrows = 0,
	                                   .vpitch = 1, .vertical = false, .addrxy = 0}.word());
	a.emit(mov(reg::vr_addr, ra(0)));
	a.emit(mov(reg::nop, reg::vr_wait));
	// Brighten every byte on its way through the QPU (generic block read + write).
	a.ldi(reg::vr_setup, isa::VpmReadSetup{.num = 0, .stride = 1, .horizontal = true, .laned = false,
	                                       .size = isa::VpmSize::Bits32, .addr = 0}.word());
	a.ldi(reg::vw_setup, isa::VpmWriteSetup{.stride = 1, .horizontal = true, .laned = false,
	                                        .size = isa::VpmSize::Bits32, .addr = 0}.word());
	a.ldi(r2, 0x01010101);
	for (int row = 0; row < 16; ++row)
		a.emit(v8adds(reg::vpm_write, reg::vpm, r2));
	a.ldi(r0, isa::VdwStride{0}.word());
	a.ldi(r1, 64);
	a.emit(sub(r3, ra(3), r1));
	a.emit(bor(reg::vw_setup, r0, r3));
	a.ldi(reg::vw_setup, isa::VdwSetup{.units = 16, .depth = 16, .horizontal = true,
	                                   .vpm_base = 0, .modew = 0}.word());
	a.emit(mov(reg::vw_addr, ra(1)));
	a.emit(mov(reg::nop, reg::vw_wait));
	a.emit(mov(reg::mutex_rel, imm(1)));
	a.thrend();
	return a.finish();
}

Program textureFetch()
{
	Assembler a("texture_fetch");
	a.emit(shl(r1, reg::elem_num, imm(2)));
	a.emit(add(reg::tmu0_s, a.uniform("s", UniformKind::Address), r1));
	a.emit(add(reg::tmu0_s, a.uniform("t", UniformKind::Address), r1));
	a.ldtmu(0);
	a.emit(mov(wa(0), r4));
	a.ldtmu(0);
	a.emit(mov(reg::tmu0_t, r4));
	a.emit(mov(reg::tmu0_s, ra(0)));
	a.uniform("p0", UniformKind::TextureConfig);
	a.uniform("p1", UniformKind::TextureConfig);
	a.emit(mov(wa(2), a.uniform("out", UniformKind::Address)));
	rowSetups(a);
	a.ldtmu(0);
	a.emit(mov(r0, r4));
	storeRow(a, r0, rb(10), rb(11), 2);
	a.thrend();
	return a.finish();
}

Program semaphoreGather()
{
	Assembler a("semaphore_gather");
	Label leader = a.newLabel(), end = a.newLabel();
	a.emit(mov(wa(2), a.uniform("out", UniformKind::Address)));
	a.emit(mov(wa(3), a.uniform("qpus")));
	rowSetups(a);
	a.emit(mov(reg::nop, reg::qpu_num).setFlags());
	a.branch(leader, BranchCond::AllZSet);
	a.nop();
	a.nop();
	a.nop();
	// Workers: store qpu_num + 100 at out + 64 * qpu_num, then signal.
	a.emit(mov(r0, reg::qpu_num));
	a.emit(shl(r0, r0, imm(6)));
	a.emit(add(wa(2), ra(2), r0));
	a.ldi(r1, 100);
	a.emit(add(r3, r1, reg::qpu_num));
	storeRow(a, r3, rb(10), rb(11), 2);
	a.semaphoreRelease(0);
	a.branch(end);
	a.nop();
	a.nop();
	a.nop();
	// Leader: one acquire per worker, then add up the first word of each worker row.
	a.bind(leader);
	a.emit(sub(wa(3), ra(3), imm(1)));
	a.emit(mov(r0, imm(0)));
	Label wait = a.newLabel();
	a.bind(wait);
	a.semaphoreAcquire(0);
	a.emit(sub(wa(3), ra(3), imm(1)).setFlags());
	a.branch(wait, BranchCond::AnyZClear);
	a.nop();
	a.nop();
	a.nop();
	a.ldi(r1, 64);
	a.emit(mov(r2, r1));
	a.ldi(wa(5), 11);
	Label sum = a.newLabel();
	a.bind(sum);
	a.emit(add(reg::tmu0_s, ra(2), r2));
	a.emit(add(r2, r2, r1));
	a.ldtmu(0);
	a.emit(add(r0, r0, r4));
	a.emit(sub(wa(5), ra(5), imm(1)).setFlags());
	a.branch(sum, BranchCond::AnyZClear);
	a.nop();
	a.nop();
	a.nop();
	storeRow(a, r0, rb(10), rb(11), 2);
	a.bind(end);
	a.thrend();
	return a.finish();
}

} // namespace frappe::vc4::samples
