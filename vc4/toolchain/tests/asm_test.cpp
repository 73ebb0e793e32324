// SPDX-License-Identifier: MIT
// Embedded assembler, disassembler and hazard lint. Restrictions from reference guide
// section 3 "Summary of Instruction Restrictions" and the vc4asm addendum constraints.
#include <gtest/gtest.h>

#include "asm/assembler.hpp"
#include "asm/lint.hpp"
#include "isa/disasm.hpp"

using namespace frappe::vc4;
using namespace frappe::vc4::qasm;
using isa::BranchCond;
using isa::Sig;

namespace {
uint64_t word(const AddOp &add, const MulOp &mul = {}, Sig sig = Sig::None)
{
	return isa::encode(assembleAlu(add, mul, sig));
}
std::string dis(const AddOp &add, const MulOp &mul = {}, Sig sig = Sig::None)
{
	return isa::disassemble(word(add, mul, sig));
}
bool has(const std::vector<Diagnostic> &d, Hazard h)
{
	for (const auto &x : d)
		if (x.hazard == h)
			return true;
	return false;
}
std::vector<Diagnostic> lintOf(Assembler &a) { return lint(a.finish(false).code); }
} // namespace

TEST(Assembler, ReadPortAllocation)
{
	const auto alu = assembleAlu(add(r0, ra(1), rb(2)), {}, Sig::None);
	EXPECT_EQ(alu.raddr_a, 1);
	EXPECT_EQ(alu.raddr_b, 2);
	EXPECT_EQ(alu.add_a, isa::Mux::A);
	EXPECT_EQ(alu.add_b, isa::Mux::B);
	EXPECT_EQ(alu.waddr_add, isa::waddr::r0);
	EXPECT_EQ(alu.cond_add, isa::Cond::Always);
	// Canonical encoding as vc4asm produces for "add r0, ra1, rb2".
	EXPECT_EQ(isa::encode(alu), 0x100208270c042dc0ull);
}

TEST(Assembler, SharedPeripheralPicksFreePort)
{
	// unif exists on both files; with file A busy it must go to B.
	const auto alu = assembleAlu(add(r0, ra(3), reg::unif), {}, Sig::None);
	EXPECT_EQ(alu.raddr_a, 3);
	EXPECT_EQ(alu.raddr_b, isa::raddr::uniform);
	// Two reads of unif in one instruction share one port (one pop).
	const auto two = assembleAlu(add(r0, reg::unif, reg::unif), {}, Sig::None);
	EXPECT_EQ(two.add_a, two.add_b);
}

TEST(Assembler, RegfileConflictsAreRejected)
{
	EXPECT_THROW(assembleAlu(add(r0, ra(1), ra(2)), {}, Sig::None), AsmError);
	EXPECT_THROW(assembleAlu(add(r0, rb(1), rb(2)), {}, Sig::None), AsmError);
	EXPECT_THROW(assembleAlu(add(r0, rb(1), imm(2)), {}, Sig::None), AsmError);
	EXPECT_THROW(assembleAlu(add(r0, r1, imm(2)), mul24(r1, r2, imm(3)), Sig::None), AsmError);
	EXPECT_THROW(assembleAlu(add(wa(1), r1, r2), fmul(wa(2), r1, r2), Sig::None), AsmError);
	// A small immediate occupies the signal field.
	EXPECT_THROW(assembleAlu(add(r0, r1, imm(2)), {}, Sig::LoadTmu0), AsmError);
}

TEST(Assembler, WriteSwapFollowsDestinations)
{
	EXPECT_FALSE(assembleAlu(add(wa(1), r1, r2), fmul(wb(2), r1, r2), Sig::None).ws);
	EXPECT_TRUE(assembleAlu(add(wb(1), r1, r2), fmul(wa(2), r1, r2), Sig::None).ws);
	EXPECT_TRUE(assembleAlu({}, fmul(wa(2), r1, r2), Sig::None).ws);
}

TEST(Assembler, BranchOffsetCountsFromAfterDelaySlots)
{
	// Section 3 "Branches": target = PC + 4 instructions + offset.
	Assembler a;
	Label l = a.newLabel();
	a.nop();
	a.branch(l);
	a.nop(); a.nop(); a.nop();
	a.nop(); a.nop();
	a.bind(l);
	a.thrend();
	const auto p = a.finish();
	const auto b = std::get<isa::Branch>(isa::decode(p.code[1]));
	EXPECT_TRUE(b.rel);
	EXPECT_EQ(b.offset, 16); // label at 7, branch at 1: (7 - 5) * 8
	Assembler back;
	Label top = back.newLabel();
	back.bind(top);
	back.nop(); back.nop();
	back.branch(top);
	back.nop(); back.nop(); back.nop();
	back.thrend();
	EXPECT_EQ(std::get<isa::Branch>(isa::decode(back.finish().code[2])).offset, -48);
}

TEST(Assembler, UniformLayoutInReadOrder)
{
	Assembler a("layout");
	a.emit(mov(r0, a.uniform("src", UniformKind::Address)));
	a.emit(mov(r1, a.uniform("count")));
	a.thrend();
	const Program p = a.finish();
	ASSERT_EQ(p.uniforms.size(), 2u);
	EXPECT_EQ(p.uniforms[0].name, "src");
	EXPECT_EQ(p.uniforms[0].kind, UniformKind::Address);
	EXPECT_EQ(p.uniformIndex("count"), 1u);
}

TEST(Assembler, LoadConstantPrefersSmallImmediate)
{
	Assembler a;
	a.loadConstant(r0, 15);
	a.loadConstant(r0, 0x12345678);
	a.thrend();
	const auto p = a.finish();
	EXPECT_EQ(isa::field::sig.get(p.code[0]), 13u);
	EXPECT_EQ(isa::field::sig.get(p.code[1]), 14u);
}

TEST(Disassembler, AluSyntaxMatchesVc4asm)
{
	EXPECT_EQ(isa::disassemble(isa::kNopWord), "nop");
	EXPECT_EQ(dis(add(r0, ra(1), rb(2))), "add r0, ra1, rb2");
	EXPECT_EQ(dis(add(wb(3), r1, r2)), "add rb3, r1, r2");
	EXPECT_EQ(dis({}, fmul(wb(1), r0, r1).ifz()), "nop; fmul.ifz rb1, r0, r1");
	EXPECT_EQ(dis(sub(reg::nop, r1, imm(3)).setFlags()), "sub.setf -, r1, 3");
	EXPECT_EQ(dis(fadd(r0, r1, imm(1.0f))), "fadd r0, r1, 1.0");
	EXPECT_EQ(dis(add(r0, r1, imm(-16))), "add r0, r1, -16");
	EXPECT_EQ(dis({}, mmov(r1, r0).rot(3)), "nop; v8min.rot 3, r1, r0, r0");
	// Rotation by r5 is spelt differently by vc4asm's versions: kept as data.
	EXPECT_EQ(dis({}, mmov(r1, r0).rotR5()), ".int 0x809f0000, 0xd00049e1");
	EXPECT_EQ(dis({}, {}, Sig::LoadTmu0), "nop; ldtmu0");
	EXPECT_EQ(dis({}, {}, Sig::ProgramEnd), "nop; thrend");
	// vc4asm leaves a unary op's second input at r0; ours repeats the first (add_b = r1).
	EXPECT_EQ(dis(bnot(r0, r1)), ".int 0x179e7240, 0x10020827");
	EXPECT_EQ(isa::disassemble(0x10020827179e7200ull), "not r0, r1");
	EXPECT_EQ(dis(add(r0, ra(1)[Unpack::B8A], r2)), "add r0, ra1.8a, r2");
	EXPECT_EQ(dis(mov(wa(1)[Pack::H16B], imm(-1))), "or ra1.16b, -1, -1");
	EXPECT_EQ(dis(mov(reg::vw_setup, ra(0))), "or vw_setup, ra0, ra0");
	EXPECT_EQ(dis(mov(reg::tmu0_s, reg::elem_num)), "or t0s, elem_num, elem_num");
	EXPECT_EQ(dis({}, fmul(r0[Pack::B8C], r4[Unpack::B8A], r1)), "nop; fmul r0.8c, r4.8a, r1");
}

TEST(Disassembler, AmbiguousNamesPinTheRegisterFile)
{
	// "unif" exists on both files; vc4asm would pick either, so raddr_a is pinned as ra32.
	EXPECT_EQ(dis(mov(r0, reg::unif)), "or r0, ra32, ra32");
	EXPECT_EQ(dis(add(r0, ra(1), reg::unif)), "add r0, ra1, rb32");
	// ws = 1 with accumulator-only destinations is pinned with an rb name.
	isa::Alu alu = assembleAlu(add(r0, r1, r2), {}, Sig::None);
	alu.ws = true;
	EXPECT_EQ(isa::disassemble(isa::encode(alu)), "add rb32, r1, r2");
}

TEST(Disassembler, LoadImmediateSemaphoreBranch)
{
	Assembler a;
	a.ldi(r0, 0xdeadbeef);
	a.ldiPerElement(r1, {0, 1, -1, -2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1}, true);
	a.semaphoreAcquire(7);
	a.semaphoreRelease(3);
	a.ldi(wa(2), wb(5), 100);
	const auto p = a.finish(false);
	EXPECT_EQ(isa::disassemble(p.code[0]), "ldi r0, 0xdeadbeef");
	EXPECT_EQ(isa::disassemble(p.code[1]), "ldipes r1, [0,1,-1,-2,0,0,0,0,0,0,0,0,0,0,0,1]");
	EXPECT_EQ(isa::disassemble(p.code[2]), "sacq -, 7");
	EXPECT_EQ(isa::disassemble(p.code[3]), "srel -, 3");
	EXPECT_EQ(isa::disassemble(p.code[4]), "ldi ra2, rb5, 100");
}

TEST(Disassembler, ProgramListingUsesLabels)
{
	Assembler a;
	Label l = a.newLabel();
	a.bind(l);
	a.emit(add(r0, r0, imm(1)));
	a.nop();
	a.branch(l, BranchCond::AnyZClear, wa(3));
	a.nop(); a.nop(); a.nop();
	a.thrend();
	const std::string text = isa::disassembleProgram(a.finish().code, false);
	EXPECT_EQ(text,
	          ":L0\n\tadd r0, r0, 1\n\tnop\n\tbrr.anynz ra3, r:L0\n\tnop\n\tnop\n\tnop\n"
	          "\tnop; thrend\n\tnop\n\tnop\n");
}

TEST(Disassembler, FieldDump)
{
	EXPECT_EQ(isa::fieldDump(isa::kNopWord),
	          "sig=1 unpack=0 pm=0 pack=0 cond_add=0 cond_mul=0 sf=0 ws=0 waddr_add=39 "
	          "waddr_mul=39 op_mul=0 op_add=0 raddr_a=39 raddr_b=39 add_a=0 add_b=0 mul_a=0 mul_b=0");
	EXPECT_EQ(isa::fieldDump(0xe80009e700000017ull),
	          "sig=14 mode=4 pm=0 pack=0 cond_add=0 cond_mul=0 sf=0 ws=0 waddr_add=39 "
	          "waddr_mul=39 sa=1 semaphore=7 ignored=0x0");
}

TEST(Lint, RegfileReadAfterWrite)
{
	Assembler a;
	a.emit(mov(wa(1), r0));
	a.emit(mov(r1, ra(1)));
	a.thrend();
	EXPECT_TRUE(has(lintOf(a), Hazard::RegfileReadAfterWrite));
	Assembler ok;
	ok.emit(mov(wa(1), r0));
	ok.nop();
	ok.emit(mov(r1, ra(1)));
	ok.thrend();
	EXPECT_TRUE(lintOf(ok).empty());
}

TEST(Lint, RotationHazards)
{
	Assembler a;
	a.emit(mov(r0, reg::elem_num));
	a.emit(mmov(r1, r0).rot(2));
	a.thrend();
	EXPECT_TRUE(has(lintOf(a), Hazard::RotateAfterWrite));
	Assembler b;
	b.emit(mmov(reg::r5rep, reg::elem_num));
	b.emit(mmov(r1, r0).rotR5());
	b.thrend();
	EXPECT_TRUE(has(lintOf(b), Hazard::RotateR5AfterWrite));
}

TEST(Lint, UniformAfterAddressWrite)
{
	Assembler a;
	a.emit(mov(reg::unif_addr, r0));
	a.nop();
	a.emit(mov(r1, reg::unif));
	a.thrend();
	EXPECT_TRUE(has(lintOf(a), Hazard::UniformAfterAddressWrite));
}

TEST(Lint, TmuAfterNoSwap)
{
	Assembler a;
	a.emit(mov(reg::tmu_noswap, imm(1)));
	a.nop();
	a.emit(mov(reg::tmu0_s, r0));
	a.thrend();
	EXPECT_TRUE(has(lintOf(a), Hazard::TmuAfterNoSwap));
}

TEST(Lint, SfuResultTiming)
{
	Assembler a;
	a.emit(mov(reg::sfu_recip, r0));
	a.nop();
	a.emit(mov(r1, r4));
	a.thrend();
	EXPECT_TRUE(has(lintOf(a), Hazard::SfuResultTooEarly));
	Assembler b;
	b.emit(mov(reg::tmu0_s, r1));
	b.emit(mov(reg::sfu_recip, r0));
	b.nop(Sig::LoadTmu0);
	b.thrend();
	EXPECT_TRUE(has(lintOf(b), Hazard::SfuResultTooEarly));
	Assembler c;
	c.emit(mov(reg::tmu0_s, r0));
	c.emit(mov(reg::tmu1_s, r0));
	c.nop(Sig::LoadTmu0);
	c.emit(mov(r0, r4), {}, Sig::LoadTmu1);
	c.thrend();
	EXPECT_TRUE(has(lintOf(c), Hazard::R4ReadWithLdtmu));
}

TEST(Lint, DoubleAccessAndConditionalPeripheral)
{
	Assembler a;
	a.emit(mov(reg::sfu_recip, r0), mmov(reg::tmu0_s, r1));
	a.thrend();
	EXPECT_TRUE(has(lintOf(a), Hazard::DoubleAccess));
	Assembler b;
	b.emit(mov(reg::vpm_write, r0).ifz());
	b.thrend();
	EXPECT_TRUE(has(lintOf(b), Hazard::ConditionalPeripheral));
	Assembler c;
	c.emit(mov(r1, r0), mmov(r1, r2));
	c.thrend();
	EXPECT_TRUE(has(lintOf(c), Hazard::SameDestinationBothPipes));
	Assembler d;
	d.emit(mov(r1, r0).ifz(), mmov(r1, r2).ifnz());
	d.thrend();
	EXPECT_TRUE(lintOf(d).empty());
}

TEST(Lint, BranchesTooClose)
{
	Assembler a;
	Label l = a.newLabel();
	a.branch(l);
	a.nop();
	a.branch(l);
	a.nop(); a.nop(); a.nop();
	a.bind(l);
	a.thrend();
	EXPECT_TRUE(has(lintOf(a), Hazard::BranchTooClose));
}

TEST(Lint, ProgramEndRules)
{
	Assembler a;
	a.emit(mov(wa(0), r0), {}, Sig::ProgramEnd);
	a.nop();
	a.nop();
	EXPECT_TRUE(has(lintOf(a), Hazard::ProgramEndWritesRegfile));
	Assembler b;
	b.nop(Sig::ProgramEnd);
	b.emit(mov(r0, reg::unif));
	b.nop();
	EXPECT_TRUE(has(lintOf(b), Hazard::ProgramEndAccess));
	Assembler c;
	c.nop(Sig::ProgramEnd);
	c.nop();
	EXPECT_TRUE(has(lintOf(c), Hazard::ProgramEndTooShort));
}

TEST(Lint, VpmSetupOrdering)
{
	Assembler a;
	a.emit(mov(r0, reg::vpm));
	a.thrend();
	EXPECT_TRUE(has(lintOf(a), Hazard::VpmReadWithoutSetup));
	Assembler b;
	b.emit(mov(reg::vw_addr, r0));
	b.thrend();
	EXPECT_TRUE(has(lintOf(b), Hazard::DmaWithoutSetup));
	Assembler c;
	c.emit(mov(reg::vw_setup, r0), mmov(reg::vpm_write, r1));
	c.thrend();
	EXPECT_TRUE(has(lintOf(c), Hazard::VpmConcurrentAccess));
	Assembler ok;
	ok.emit(mov(reg::vr_setup, r0));
	ok.emit(mov(reg::vw_setup, r1));
	ok.emit(v8adds(reg::vpm_write, reg::vpm, r2));
	ok.emit(mov(reg::vw_addr, r3));
	ok.thrend();
	EXPECT_TRUE(lintOf(ok).empty());
}

TEST(Lint, TmuRequestCounting)
{
	Assembler a;
	a.nop(Sig::LoadTmu0);
	a.thrend();
	EXPECT_TRUE(has(lintOf(a), Hazard::LdtmuWithoutRequest));
	// n requests alternating over the TMUs, then their pops.
	auto inFlight = [](int n) {
		Assembler b;
		for (int i = 0; i < n; ++i)
			b.emit(mov(i % 2 ? reg::tmu1_s : reg::tmu0_s, r0));
		for (int i = 0; i < n; ++i)
			b.nop(i % 2 ? Sig::LoadTmu1 : Sig::LoadTmu0);
		b.thrend();
		return b.finish(false).code;
	};
	// Five in flight, split over both TMUs: the depth counts per QPU, so this fails at
	// depth 4 (the default build) and passes at 8.
	const auto code = inFlight(5);
	const auto at4 = lint(code, 4);
	ASSERT_EQ(at4.size(), 1u);
	EXPECT_EQ(at4[0].hazard, Hazard::TmuTooManyOutstanding);
	EXPECT_EQ(at4[0].index, 4u); // the fifth request
	EXPECT_TRUE(lint(code, 8).empty());
	EXPECT_EQ(lint(code).empty(), kTmuDepth >= 5);
	// Four in flight pass at either depth; a pop makes room for the next request.
	Assembler ok;
	for (int i = 0; i < 4; ++i)
		ok.emit(mov(i % 2 ? reg::tmu1_s : reg::tmu0_s, r0));
	ok.nop(Sig::LoadTmu0);
	ok.emit(mov(reg::tmu0_s, r0));
	for (int i = 0; i < 4; ++i)
		ok.nop(i % 2 ? Sig::LoadTmu0 : Sig::LoadTmu1);
	ok.thrend();
	EXPECT_TRUE(lint(ok.finish(false).code, 4).empty());
	// Nine in flight fail even at depth 8.
	EXPECT_TRUE(has(lint(inFlight(9), 8), Hazard::TmuTooManyOutstanding));
}
