// SPDX-License-Identifier: MIT
// The disassembler's output carries every field the assembler sets: listings read back by
// assembleText give the same words (the property the external vc4asm cross-check needs).
#include <gtest/gtest.h>

#include <random>

#include "asm/assembler.hpp"
#include "asm/text.hpp"
#include "isa/disasm.hpp"
#include "samples/samples.hpp"

using namespace frappe::vc4;
using namespace frappe::vc4::qasm;

TEST(TextRoundTrip, SamplesSurviveDisassembly)
{
	for (const auto &p : {samples::vectorSum(), samples::laneReduction(), samples::tileCopy(),
	                      samples::textureFetch(), samples::semaphoreGather()}) {
		EXPECT_EQ(assembleText(isa::disassembleProgram(p.code, true)), p.code) << p.name;
		EXPECT_EQ(assembleText(isa::disassembleProgram(p.code, false)), p.code) << p.name;
	}
}

TEST(TextRoundTrip, RandomAssemblerInstructions)
{
	std::mt19937 rng(11);
	auto pick = [&](int n) { return static_cast<int>(rng() % static_cast<unsigned>(n)); };
	const isa::AddOp add_ops[] = {isa::AddOp::FAdd, isa::AddOp::FSub, isa::AddOp::FMin, isa::AddOp::FMax,
	                              isa::AddOp::FMinAbs, isa::AddOp::FMaxAbs, isa::AddOp::FtoI, isa::AddOp::ItoF,
	                              isa::AddOp::Add, isa::AddOp::Sub, isa::AddOp::Shr, isa::AddOp::Asr,
	                              isa::AddOp::Ror, isa::AddOp::Shl, isa::AddOp::Min, isa::AddOp::Max,
	                              isa::AddOp::And, isa::AddOp::Or, isa::AddOp::Xor, isa::AddOp::Not,
	                              isa::AddOp::Clz, isa::AddOp::V8Adds, isa::AddOp::V8Subs};
	auto src = [&]() -> Src {
		switch (pick(6)) {
		case 0: return acc(static_cast<uint8_t>(pick(6)));
		case 1: return ra(static_cast<uint8_t>(pick(32)));
		case 2: return rb(static_cast<uint8_t>(pick(32)));
		case 3: return imm(pick(32) - 16);
		case 4: return pick(2) ? reg::elem_num : reg::qpu_num;
		default: return pick(2) ? ra(static_cast<uint8_t>(pick(4)))[static_cast<Unpack>(pick(8))] : reg::unif;
		}
	};
	auto dst = [&]() -> Dst {
		switch (pick(5)) {
		case 0: return Dst{Dst::Kind::Either, static_cast<uint8_t>(32 + pick(4)), Pack::None};
		case 1: return wa(static_cast<uint8_t>(pick(32)));
		case 2: return wb(static_cast<uint8_t>(pick(32)));
		case 3: return pick(2) ? reg::vw_setup : reg::tmu0_s;
		default: return wa(static_cast<uint8_t>(pick(32)))[static_cast<Pack>(1 + pick(15))];
		}
	};
	int checked = 0;
	for (int n = 0; n < 20000; ++n) {
		AddOp add;
		MulOp mul;
		if (pick(4)) {
			const auto op = add_ops[pick(23)];
			add = isa::isUnary(op) ? AddOp{op, dst(), src(), {}} : AddOp{op, dst(), src(), src()};
			if (isa::isUnary(op))
				add.b = add.a;
			add.cond = static_cast<isa::Cond>(1 + pick(7));
			add.setf = pick(4) == 0;
		}
		if (pick(2)) {
			mul = MulOp{static_cast<isa::MulOp>(1 + pick(7)), dst(), src(), src()};
			mul.cond = static_cast<isa::Cond>(1 + pick(7));
			if (pick(5) == 0)
				mul.rotate = static_cast<uint8_t>(1 + pick(16));
		}
		const auto sig = pick(3) == 0 ? static_cast<isa::Sig>(pick(13)) : isa::Sig::None;
		uint64_t word;
		try {
			word = isa::encode(assembleAlu(add, mul, sig));
		} catch (const AsmError &) {
			continue; // conflicting operands: not an instruction
		}
		const std::string text = isa::disassemble(word);
		ASSERT_EQ(assembleText(text), std::vector<uint64_t>{word}) << text;
		++checked;
	}
	EXPECT_GT(checked, 5000);
}

TEST(TextRoundTrip, LoadsSemaphoresAndBranches)
{
	Assembler a;
	Label top = a.newLabel();
	a.bind(top);
	a.ldi(r0, 0x80000000u);
	a.ldi(wa(3), wb(7), static_cast<uint32_t>(-5));
	a.ldi(reg::vw_setup, 0x1a00);
	a.ldiPerElement(r1, {0, 1, 2, 3, 3, 2, 1, 0, 0, 0, 0, 0, 1, 1, 1, 1}, false);
	a.ldiPerElement(wb(2), {-2, -1, 0, 1, -2, -1, 0, 1, -2, -1, 0, 1, -2, -1, 0, 1}, true);
	a.semaphoreAcquire(15);
	a.semaphoreRelease(0);
	a.branch(top, isa::BranchCond::AllCClear, wb(4));
	a.nop(); a.nop(); a.nop();
	a.branchRegister(6, 64, isa::BranchCond::AnyNSet, wa(1));
	a.nop(); a.nop(); a.nop();
	a.thrend();
	const auto code = a.finish(false).code;
	EXPECT_EQ(assembleText(isa::disassembleProgram(code, false)), code);
}

TEST(TextRoundTrip, RejectsUnknownSyntax)
{
	EXPECT_THROW(assembleText("frob r0, r1, r2\n"), AsmError);
	EXPECT_THROW(assembleText("add r0, ra1, ra2\n"), AsmError);
	EXPECT_THROW(assembleText("brr -, r:nowhere\n"), AsmError);
}
