// SPDX-License-Identifier: MIT
// Whole-instruction behaviour on the emulated QPU: muxes, small immediates, conditions,
// flags, rotation, r5, branches, load immediates, uniforms, SFU, semaphores, mutex,
// host interrupt and program end (reference guide section 3; vc4asm addendum).
#include <gtest/gtest.h>

#include <bit>

#include "harness.hpp"

using namespace frappe::vc4;
using namespace frappe::vc4::qasm;
using frappe::vc4::test::run;
using isa::BranchCond;
using isa::Sig;

namespace {
uint32_t f(float x) { return std::bit_cast<uint32_t>(x); }
} // namespace

TEST(EmuQpu, UniformsFeedBothRegisterFiles)
{
	Assembler a;
	a.emit(mov(wa(0), a.uniform("x")));
	a.emit(mov(wb(0), a.uniform("y")));
	a.nop();
	a.emit(add(r0, ra(0), rb(0)));
	a.thrend();
	auto r = run(a.finish(), {{40, 2}});
	EXPECT_EQ(r->qpu().acc(0)[7], 42u);
	EXPECT_EQ(r->stats.instructions, 7u);
}

TEST(EmuQpu, ElementNumberAndSmallImmediates)
{
	// Table 14: raddr 38 reads the element number on file A; Table 5 small immediates.
	Assembler a;
	a.emit(add(r0, reg::elem_num, imm(-3)));
	a.emit(mov(r1, imm(0.25f)));
	a.emit(mov(r2, reg::qpu_num));
	a.thrend();
	auto r = run(a.finish());
	for (unsigned i = 0; i < 16; ++i)
		EXPECT_EQ(r->qpu().acc(0)[i], i - 3u);
	EXPECT_EQ(r->qpu().acc(1)[5], f(0.25f));
	EXPECT_EQ(r->qpu().acc(2)[5], 0u);
}

TEST(EmuQpu, ConditionCodesSelectLanes)
{
	// "Condition Codes": ifz/ifnz on the Z flag set by and.setf of the element number.
	Assembler a;
	a.emit(band(reg::nop, reg::elem_num, imm(1)).setFlags());
	a.ldi(wa(1), 1);
	a.ldi(wb(2), 2);
	a.nop();
	a.emit(bor(r1, ra(1), ra(1)).ifz(), mmov(r1, rb(2)).ifnz());
	a.emit(sub(reg::nop, reg::elem_num, imm(8)).setFlags());
	a.emit(bor(r2, ra(1), ra(1)).ifn(), mmov(r2, rb(2)).ifnn());
	a.emit(bor(r3, ra(1), ra(1)).ifc(), mmov(r3, rb(2)).ifnc());
	a.thrend();
	auto r = run(a.finish());
	for (unsigned i = 0; i < 16; ++i) {
		EXPECT_EQ(r->qpu().acc(1)[i], i % 2 ? 2u : 1u) << i;
		EXPECT_EQ(r->qpu().acc(2)[i], i < 8 ? 1u : 2u) << i;
		EXPECT_EQ(r->qpu().acc(3)[i], i < 8 ? 1u : 2u) << i; // borrow sets C
	}
}

TEST(EmuQpu, NeverConditionWritesNothing)
{
	Assembler a;
	a.emit(mov(r0, imm(5)));
	a.emit(mov(r0, imm(7)).when(isa::Cond::Never));
	a.thrend();
	EXPECT_EQ(run(a.finish())->qpu().acc(0)[0], 5u);
}

TEST(EmuQpu, FlagsUpdateOnlyWhereConditionTrue)
{
	// Addendum, "Table 1 - set flags": flags change only in lanes whose condition is true.
	Assembler a;
	a.emit(band(reg::nop, reg::elem_num, imm(1)).setFlags());      // Z = even lanes
	a.emit(sub(r0, reg::elem_num, imm(4)).ifz().setFlags());        // only even lanes
	a.thrend();
	auto r = run(a.finish());
	for (unsigned i = 0; i < 16; ++i) {
		if (i % 2 == 0) {
			EXPECT_EQ(r->qpu().flagZ(i), i == 4) << i;
			EXPECT_EQ(r->qpu().flagN(i), i < 4) << i;
		} else {
			EXPECT_FALSE(r->qpu().flagZ(i)) << i; // odd lanes keep Z clear from the and
		}
	}
}

TEST(EmuQpu, MulSetsFlagsOnlyWhenAddIsNop)
{
	// Addendum: "flags are only updated from the MUL ALU when the ADD ALU executes a nop".
	Assembler a;
	a.emit(mov(r0, imm(0)));
	a.emit(add(r1, r0, imm(1)).setFlags(), mul24(r2, r0, r0));     // flags from ADD: nonzero
	a.emit(mov(r3, imm(1)).ifz());
	a.emit(mul24(r2, r0, r0).setFlags());                           // flags from MUL: zero
	a.emit(mov(r3, imm(2)).ifz());
	a.thrend();
	auto r = run(a.finish());
	EXPECT_EQ(r->qpu().acc(3)[0], 2u);
	EXPECT_TRUE(r->qpu().flagZ(0));
}

TEST(EmuQpu, FullVectorRotation)
{
	// Section 3 "Vector rotation": MUL result rotated by n when both inputs are r0..r3.
	Assembler a;
	a.emit(mov(r0, reg::elem_num));
	a.nop();
	a.emit(mmov(r1, r0).rot(3));
	a.thrend();
	auto r = run(a.finish());
	for (unsigned i = 0; i < 16; ++i)
		EXPECT_EQ(r->qpu().acc(1)[i], (i - 3) & 15) << i;
}

TEST(EmuQpu, RotationByR5AndWithinQuadFromRegfile)
{
	Assembler a;
	a.emit(mov(r0, reg::elem_num), mmov(reg::r5rep, imm(6)));
	a.emit(mov(wa(1), reg::elem_num));
	a.emit(mmov(r1, r0).rotR5());
	a.emit(mmov(r2, ra(1)).rot(1));
	a.thrend();
	auto r = run(a.finish());
	for (unsigned i = 0; i < 16; ++i) {
		EXPECT_EQ(r->qpu().acc(1)[i], (i - 6) & 15) << i;
		// Addendum: an input outside r0..r3 rotates only within each quad.
		EXPECT_EQ(r->qpu().acc(2)[i], (i & ~3u) | ((i - 1) & 3)) << i;
	}
}

TEST(EmuQpu, R5QuadAndReplicate)
{
	// Addendum "Writing to r5": via file A per quad (elements 0,4,8,12), via B element 0.
	Assembler a;
	a.emit(add(reg::r5quad, reg::elem_num, imm(10)));
	a.emit(mov(r0, r5));
	a.emit(mmov(reg::r5rep, reg::elem_num[Unpack::None]).when(isa::Cond::Always));
	a.emit(add(r1, r5, imm(0)));
	a.thrend();
	auto r = run(a.finish());
	for (unsigned i = 0; i < 16; ++i) {
		EXPECT_EQ(r->qpu().acc(0)[i], (i & ~3u) + 10) << i;
		EXPECT_EQ(r->qpu().acc(1)[i], 0u) << i;
	}
}

TEST(EmuQpu, LoadImmediateModes)
{
	// Section 3 "Load Immediate Instructions": 32-bit broadcast and per-element 2-bit.
	Assembler a;
	a.ldi(r0, 0xdeadbeef);
	std::array<int, 16> s{};
	std::array<int, 16> u{};
	for (int i = 0; i < 16; ++i) {
		s[i] = (i % 4) - 2;
		u[i] = i % 4;
	}
	a.ldiPerElement(r1, s, true);
	a.ldiPerElement(r2, u, false);
	a.ldi(wa(3), wb(4), 77);
	a.nop();
	a.emit(add(r3, ra(3), rb(4)));
	a.thrend();
	auto r = run(a.finish());
	for (unsigned i = 0; i < 16; ++i) {
		EXPECT_EQ(r->qpu().acc(0)[i], 0xdeadbeefu);
		EXPECT_EQ(static_cast<int32_t>(r->qpu().acc(1)[i]), static_cast<int>(i % 4) - 2) << i;
		EXPECT_EQ(r->qpu().acc(2)[i], i % 4) << i;
		EXPECT_EQ(r->qpu().acc(3)[i], 154u);
	}
}

TEST(EmuQpu, RegfilePackAndUnpack)
{
	Assembler a;
	a.ldi(wa(0), 0x11223344);
	a.nop();
	a.emit(mov(r0, ra(0)[Unpack::B8C]));
	a.emit(mov(wa(1)[Pack::H16B], imm(-1)));
	a.nop();
	a.emit(mov(r1, ra(1)[Unpack::H16B]));
	a.thrend();
	auto r = run(a.finish());
	EXPECT_EQ(r->qpu().acc(0)[0], 0x22u);
	EXPECT_EQ(r->qpu().regA(1)[0], 0xffff0000u);
	EXPECT_EQ(r->qpu().acc(1)[0], 0xffffffffu);
}

TEST(EmuQpu, MulPackFloatToColourByte)
{
	Assembler a;
	a.emit(mov(r0, imm(0)));
	a.emit(fmul(r0[Pack::B8C], imm(1.0f), imm(1.0f)));
	a.emit(fmul(r0[Pack::B8A], imm(0.5f), imm(0.5f)));
	a.thrend();
	EXPECT_EQ(run(a.finish())->qpu().acc(0)[3], 0x00ff0040u); // 0.25 * 255 rounds to 64
}

TEST(EmuQpu, RelativeBranchRunsThreeDelaySlots)
{
	// Section 3 "Branches": three instructions after a branch always execute.
	Assembler a;
	Label skip = a.newLabel();
	a.emit(mov(r0, imm(0)));
	a.branch(skip, BranchCond::Always, wa(2));
	a.emit(add(r0, r0, imm(1)));
	a.emit(add(r0, r0, imm(1)));
	a.emit(add(r0, r0, imm(1)));
	a.emit(add(r0, r0, imm(8))); // skipped
	a.bind(skip);
	a.nop();
	a.thrend();
	auto r = run(a.finish());
	EXPECT_EQ(r->qpu().acc(0)[0], 3u);
	// The link register holds PC + 4 instructions of the branch (index 1 -> byte 40).
	EXPECT_EQ(r->qpu().regA(2)[0] & 0xfff, 40u);
}

TEST(EmuQpu, LoopWithAnyAndAllConditions)
{
	Assembler a;
	Label loop = a.newLabel();
	a.emit(mov(r0, imm(0)));
	a.emit(mov(r1, imm(5)));
	a.bind(loop);
	a.emit(sub(r1, r1, imm(1)).setFlags(), mmov(r2, r1));
	a.emit(add(r0, r0, imm(2)));
	a.branch(loop, BranchCond::AnyZClear);
	a.nop();
	a.nop();
	a.nop();
	a.thrend();
	auto r = run(a.finish());
	EXPECT_EQ(r->qpu().acc(0)[0], 10u);
	EXPECT_EQ(r->qpu().acc(1)[0], 0u);
}

TEST(EmuQpu, BranchConditionsAllVersusAny)
{
	// "Branches": all/any over the 16 lanes. Z is set only in lane 0 here.
	Assembler a;
	Label any = a.newLabel(), end = a.newLabel();
	a.emit(mov(r0, imm(0)));
	a.emit(mov(reg::nop, reg::elem_num).setFlags());
	a.branch(end, BranchCond::AllZSet); // not taken
	a.nop(); a.nop(); a.nop();
	a.emit(mov(r0, imm(1)));
	a.branch(any, BranchCond::AnyZSet); // taken
	a.nop(); a.nop(); a.nop();
	a.emit(mov(r0, imm(9)));
	a.bind(any);
	a.emit(add(r0, r0, imm(2)));
	a.bind(end);
	a.thrend();
	EXPECT_EQ(run(a.finish())->qpu().acc(0)[0], 3u);
}

TEST(EmuQpu, RegisterBranchUsesElement15)
{
	// Addendum "Branch Instruction - register source": element 15, not 0.
	Assembler a;
	a.emit(shl(wa(4), reg::elem_num, imm(3)));   // lane i: 8 * i bytes
	a.nop();
	a.branchRegister(4, 0, BranchCond::Always, reg::nop, true); // relative to PC + 4
	a.nop(); a.nop(); a.nop();
	for (int i = 0; i < 16; ++i)
		a.emit(add(r0, r0, imm(1)));
	a.thrend();
	// Lane 15 holds 120 bytes = 15 instructions skipped of the 16 adds.
	EXPECT_EQ(run(a.finish())->qpu().acc(0)[0], 1u);
}

TEST(EmuQpu, UniformsAddressRestartsStream)
{
	// Table 14 waddr 40: writing the uniforms address restarts the stream there.
	Assembler a;
	a.emit(mov(reg::unif_addr, a.uniform("restart")));
	a.nop();
	a.nop();
	a.emit(mov(r1, reg::unif));
	a.thrend();
	test::Run r;
	const uint32_t stream = r.memory.load(std::vector<uint32_t>{4321});
	const uint32_t code = r.memory.load(a.finish().code);
	const uint32_t unif = r.memory.load(std::vector<uint32_t>{stream});
	const emu::Job job{unif, code};
	r.v3d.launch(std::span(&job, 1));
	EXPECT_EQ(r.qpu().acc(1)[0], 4321u);
}

TEST(EmuQpu, SfuResultArrivesInR4AfterTwoInstructions)
{
	// Section 3 "SFU": r4 is written two instructions after the SFU register write.
	Assembler a;
	a.emit(mov(reg::sfu_recip, imm(4.0f)));
	a.nop();
	a.nop();
	a.emit(mov(r0, r4));
	a.emit(mov(reg::sfu_exp2, imm(2.0f)));
	a.nop();
	a.nop();
	a.emit(mov(r1, r4));
	a.emit(mov(reg::sfu_log2, imm(8.0f)));
	a.nop();
	a.nop();
	a.emit(mov(r2, r4));
	a.emit(mov(reg::sfu_recipsqrt, imm(16.0f)));
	a.nop();
	a.nop();
	a.emit(mov(r3, r4));
	a.thrend();
	auto r = run(a.finish());
	EXPECT_EQ(r->qpu().acc(0)[0], f(0.25f));
	EXPECT_EQ(r->qpu().acc(1)[0], f(4.0f));
	EXPECT_EQ(r->qpu().acc(2)[0], f(3.0f));
	EXPECT_EQ(r->qpu().acc(3)[0], f(0.25f));
}

TEST(EmuQpu, HostInterruptNeedsNonZeroValue)
{
	Assembler a;
	a.emit(mov(reg::host_int, imm(0)));
	a.emit(mov(reg::host_int, imm(1)));
	a.thrend();
	EXPECT_EQ(run(a.finish())->stats.host_interrupts, 1u);
}

TEST(EmuQpu, ProgramEndRunsTwoDelaySlots)
{
	Assembler a;
	a.emit(mov(r0, imm(1)));
	a.nop(Sig::ProgramEnd);
	a.emit(add(r0, r0, imm(1)));
	a.emit(add(r0, r0, imm(1)));
	a.emit(add(r0, r0, imm(8))); // never runs
	auto r = run(a.finish(false));
	EXPECT_EQ(r->qpu().acc(0)[0], 3u);
	EXPECT_EQ(r->stats.instructions, 4u);
}

TEST(EmuQpuStrict, RegfileReadAfterWriteFaults)
{
	Assembler a;
	a.emit(mov(wa(0), imm(1)));
	a.emit(mov(r0, ra(0)));
	a.thrend();
	EXPECT_THROW(run(a.finish(false)), emu::Fault);
}

TEST(EmuQpuStrict, UniformReadTooSoonAfterAddressWriteFaults)
{
	Assembler a;
	a.emit(mov(reg::unif_addr, a.uniform("u")));
	a.nop();
	a.emit(mov(r0, reg::unif));
	a.thrend();
	EXPECT_THROW(run(a.finish(false), {{0x10000000u}}), emu::Fault);
}

TEST(EmuQpuStrict, R4ReadBeforeSfuResultFaults)
{
	Assembler a;
	a.emit(mov(reg::sfu_recip, imm(2.0f)));
	a.nop();
	a.emit(mov(r0, r4));
	a.thrend();
	EXPECT_THROW(run(a.finish(false)), emu::Fault);
}
