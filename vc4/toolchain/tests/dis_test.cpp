// SPDX-License-Identifier: MIT
// The disassembler on hand-built words of real binaries: data words stay data (".int"), both
// link registers of a branch are printed, register reads no ALU input uses are kept
// ("read"), the ADD ALU's v8adds/v8subs are "av8adds"/"av8subs", and forms vc4asm would
// rewrite are kept as data. Every listing reads back to the same words.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "asm/assembler.hpp"
#include "asm/text.hpp"
#include "isa/disasm.hpp"
#include "isa/instr.hpp"

using namespace frappe::vc4;
using isa::Mux;

namespace {

constexpr uint64_t word(uint32_t low, uint32_t high) { return uint64_t{high} << 32 | low; }

// "nop; nop" with the given raddr fields (no input selects them).
uint64_t nopReading(uint8_t raddr_a, uint8_t raddr_b)
{
	isa::Alu alu;
	alu.raddr_a = raddr_a;
	alu.raddr_b = raddr_b;
	return isa::encode(alu);
}

std::string listing(const std::vector<uint64_t> &code) { return isa::disassembleProgram(code, false); }

} // namespace

TEST(DisassemblerData, WordsThatAreNotInstructionsPrintAsData)
{
	// The start of a shader's data: counts and float constants, which decode as
	// instructions whose fields the text cannot carry (an idle ADD ALU writing ra0, a
	// MUL pack vc4asm cannot encode, a branch with its unused bits set).
	const std::vector<uint64_t> code = {
		word(0x00000025, 0x00000000), word(0x3f800000, 0x3f800000),
		word(0xdeadbeef, 0xf1234567), isa::kNopWord,
	};
	EXPECT_EQ(listing(code),
	          "\t.int 0x00000025, 0x00000000\n"
	          "\t.int 0x3f800000, 0x3f800000\n"
	          "\t.int 0xdeadbeef, 0xf1234567\n"
	          "\tnop\n");
	// Data that happens to be an instruction vc4asm re-creates prints as that
	// instruction: the words are the same either way.
	EXPECT_EQ(isa::disassemble(word(0x3f800000, 0x40000000)),
	          "av8subs.never ra0, r0, r0; fmul.never rb0, r0, r0; read ra32; read rb0; sbwait");
	EXPECT_EQ(qasm::assembleText(listing(code)), code);
	// With comments a data word still shows what its bits would mean.
	const std::string commented = isa::disassembleProgram(code, true);
	EXPECT_NE(commented.find("# 0000: 0000000000000025 (nop"), std::string::npos) << commented;
	EXPECT_EQ(qasm::assembleText(commented), code);
}

TEST(DisassemblerData, LabelsAfterDataKeepTheirAddresses)
{
	isa::Branch b;
	b.rel = true;
	b.offset = -32; // to the branch itself: 0x18 + 32 - 32
	const std::vector<uint64_t> code = {
		word(1, 2), word(3, 4), word(5, 6), isa::encode(b), isa::kNopWord, isa::kNopWord, isa::kNopWord,
	};
	EXPECT_EQ(listing(code),
	          "\t.int 0x00000001, 0x00000002\n\t.int 0x00000003, 0x00000004\n"
	          "\t.int 0x00000005, 0x00000006\n:L18\n\tbrr -, r:L18\n\tnop\n\tnop\n\tnop\n");
	EXPECT_EQ(qasm::assembleText(listing(code)), code);
	// vc4asm's other spellings of data: single words, several a line, 64-bit ".long".
	EXPECT_EQ(qasm::assembleText(".int 1\n.int 2\n.int 3, 4, 5, 6\n.long 0x800000070000000a\nnop\n"),
	          (std::vector<uint64_t>{word(1, 2), word(3, 4), word(5, 6), word(10, 0x80000007), isa::kNopWord}));
	EXPECT_THROW(qasm::assembleText(".int 1\nnop\n"), qasm::AsmError);
	EXPECT_THROW(qasm::assembleText("nop\n.int 7\n"), qasm::AsmError);
	EXPECT_THROW(qasm::assembleText(".int 0x100000000, 0\n"), qasm::AsmError);
}

TEST(DisassemblerBranch, BothLinkRegistersArePrinted)
{
	isa::Branch b;
	b.rel = true;
	b.waddr_add = 8;  // ra8
	b.waddr_mul = 9;  // rb9 (ws = 0: the MUL writes file B)
	b.offset = 0x1b0;
	EXPECT_EQ(isa::disassemble(isa::encode(b)), "brr ra8, rb9, -, +432");
	b.reg = true;
	b.raddr_a = 6;
	b.rel = false;
	b.offset = 0x40;
	EXPECT_EQ(isa::disassemble(isa::encode(b)), "bra ra8, rb9, ra6, 0x40");
	b.offset = 0;
	EXPECT_EQ(isa::disassemble(isa::encode(b)), "bra ra8, rb9, ra6, 0x0");
	// Only the MUL link register: the ADD's destination is "-".
	b.waddr_add = isa::waddr::nop;
	b.reg = false;
	b.raddr_a = 0;
	b.rel = true;
	b.offset = -8;
	EXPECT_EQ(isa::disassemble(isa::encode(b)), "brr -, rb9, -, -8");
	// ws = 1: the ADD link register is in file B, the MUL's in file A.
	b.ws = true;
	b.waddr_add = 3;
	EXPECT_EQ(isa::disassemble(isa::encode(b)), "brr rb3, ra9, -, -8");
	// One link register and a register target keep the short forms.
	isa::Branch r;
	r.rel = false;
	r.reg = true;
	r.raddr_a = 8;
	EXPECT_EQ(isa::disassemble(isa::encode(r)), "bra -, ra8");

	std::vector<uint64_t> code;
	b = {};
	b.waddr_add = 12;
	b.waddr_mul = 13;
	b.offset = -32; // to itself
	code.push_back(isa::encode(b));
	code.insert(code.end(), 3, isa::kNopWord);
	EXPECT_EQ(listing(code), ":L0\n\tbrr ra12, rb13, -, r:L0\n\tnop\n\tnop\n\tnop\n");
	EXPECT_EQ(qasm::assembleText(listing(code)), code);
	for (uint64_t w : {isa::encode(r), word(0x40, 0xf0f822a4)})
		EXPECT_EQ(qasm::assembleText(isa::disassemble(w)), std::vector<uint64_t>{w}) << isa::disassemble(w);
}

TEST(DisassemblerReads, PeripheralReadsNoInputUsesAreKept)
{
	using namespace isa::raddr;
	// "mov -, vw_wait" written as a bare read (GPU_FFT's VDW wait), the VDR wait, a mutex
	// acquire, a uniform and a varying pop, a VPM read, a small immediate read.
	EXPECT_EQ(isa::disassemble(nopReading(nop, vdr_wait)), "nop; read vw_wait");
	EXPECT_EQ(isa::disassemble(nopReading(vdr_wait, nop)), "nop; read vr_wait");
	EXPECT_EQ(isa::disassemble(nopReading(mutex_acquire, nop)), "nop; read ra51");
	EXPECT_EQ(isa::disassemble(nopReading(nop, uniform)), "nop; read rb32");
	EXPECT_EQ(isa::disassemble(nopReading(varying, vpm_read)), "nop; read ra35; read rb48");
	isa::Alu smi;
	smi.sig = isa::Sig::SmallImmediate;
	smi.raddr_b = 5;
	EXPECT_EQ(isa::disassemble(isa::encode(smi)), "nop; read 5");
	// Next to ALU ops and a signal, in vc4asm's order: ops, reads, signal.
	isa::Alu add;
	add.op_add = isa::AddOp::Add;
	add.cond_add = isa::Cond::Always;
	add.waddr_add = isa::waddr::r0;
	add.add_a = Mux::R1;
	add.add_b = Mux::A;
	add.raddr_a = 3;
	add.raddr_b = vdr_wait;
	add.sig = isa::Sig::ProgramEnd;
	EXPECT_EQ(isa::disassemble(isa::encode(add)), "add r0, r1, ra3; read vw_wait; thrend");
	for (uint64_t w : {nopReading(nop, vdr_wait), nopReading(vdr_wait, nop), nopReading(mutex_acquire, nop),
	                   nopReading(varying, vpm_read), isa::encode(smi), isa::encode(add)})
		EXPECT_EQ(qasm::assembleText(isa::disassemble(w)), std::vector<uint64_t>{w}) << isa::disassemble(w);
}

TEST(DisassemblerOps, AddAndMulOpsWithTheSameNameAreDistinguished)
{
	// "op r0, r1, r2" on the ADD ALU, "op r3, r1, r2" on the MUL ALU.
	auto with = [](isa::Alu alu, bool mul, unsigned op) {
		if (mul)
			alu.op_mul = static_cast<isa::MulOp>(op);
		else
			alu.op_add = static_cast<isa::AddOp>(op);
		(mul ? alu.cond_mul : alu.cond_add) = isa::Cond::Always;
		(mul ? alu.waddr_mul : alu.waddr_add) = mul ? isa::waddr::r3 : isa::waddr::r0;
		(mul ? alu.mul_a : alu.add_a) = Mux::R1;
		(mul ? alu.mul_b : alu.add_b) = Mux::R2;
		return alu;
	};
	auto withAdd = [&](isa::Alu alu, isa::AddOp op) { return with(alu, false, static_cast<unsigned>(op)); };
	auto withMul = [&](isa::Alu alu, isa::MulOp op) { return with(alu, true, static_cast<unsigned>(op)); };
	EXPECT_EQ(isa::disassemble(isa::encode(withAdd({}, isa::AddOp::V8Adds))), "av8adds r0, r1, r2");
	EXPECT_EQ(isa::disassemble(isa::encode(withAdd({}, isa::AddOp::V8Subs))), "av8subs r0, r1, r2");
	EXPECT_EQ(isa::disassemble(isa::encode(withMul({}, isa::MulOp::V8Adds))), "nop; v8adds r3, r1, r2");
	EXPECT_EQ(isa::disassemble(isa::encode(withMul({}, isa::MulOp::V8Subs))), "nop; v8subs r3, r1, r2");
	// Both at once: ADD first, MUL second.
	const isa::Alu both = withMul(withAdd({}, isa::AddOp::V8Subs), isa::MulOp::V8Subs);
	EXPECT_EQ(isa::disassemble(isa::encode(both)), "av8subs r0, r1, r2; v8subs r3, r1, r2");
	for (const auto &alu : {both, withMul({}, isa::MulOp::V8Adds), withAdd({}, isa::AddOp::V8Adds)}) {
		const uint64_t w = isa::encode(alu);
		EXPECT_EQ(qasm::assembleText(isa::disassemble(w)), std::vector<uint64_t>{w});
	}
	// A plain v8adds alone is the MUL's, as vc4asm reads it.
	EXPECT_EQ(qasm::assembleText("v8adds r3, r1, r2\n"), qasm::assembleText("nop; v8adds r3, r1, r2\n"));
}

TEST(DisassemblerCanonical, FormsVc4asmRewritesStayData)
{
	// "sub r0, r1, r1" alone: vc4asm stores "ldi r0, 0".
	EXPECT_EQ(isa::disassemble(word(0x0d9e7240, 0x10020827)), ".int 0x0d9e7240, 0x10020827");
	// The same reading a register (vc4asm keeps it): printed.
	EXPECT_EQ(isa::disassemble(word(0x0d0e7d80, 0x10020827)), "sub r0, ra3, ra3");
	// A destination "-" with cond always and no setf: vc4asm writes cond never.
	EXPECT_EQ(isa::disassemble(word(0x159e7000, 0x100209e7)), ".int 0x159e7000, 0x100209e7");
	EXPECT_EQ(isa::disassemble(word(0x159e7000, 0x100009e7)), "or.never -, r0, r0");
	// A unary op's unused second input other than r0.
	EXPECT_EQ(isa::disassemble(word(0x179e7240, 0x10020827)), ".int 0x179e7240, 0x10020827");
	EXPECT_EQ(isa::disassemble(word(0x179e7200, 0x10020827)), "not r0, r1");
	// An idle MUL ALU with inputs, a reserved ADD op, a MUL pack vc4asm cannot encode.
	EXPECT_EQ(isa::disassemble(word(0x009e7001, 0x100009e7)), ".int 0x009e7001, 0x100009e7");
	EXPECT_EQ(isa::disassemble(word(0x099e7240, 0x10020827)), ".int 0x099e7240, 0x10020827");
	EXPECT_EQ(isa::disassemble(word(0x209e7009, 0x118049e0)), ".int 0x209e7009, 0x118049e0");
	EXPECT_EQ(isa::disassemble(word(0x209e7009, 0x117049e0)), "nop; fmul r0.8d, r1, r1");
}

TEST(DisassemblerRoundTrip, EveryWordReadsBack)
{
	// Any 64-bit word, printed as an instruction or as data, reads back unchanged;
	// random words mostly hit data, field-wise random ALU words mostly instructions.
	std::mt19937_64 rng(14);
	std::vector<uint64_t> code;
	for (int n = 0; n < 20000; ++n)
		code.push_back(rng());
	int printed = 0;
	for (int n = 0; n < 20000; ++n) {
		isa::Alu alu;
		alu.sig = static_cast<isa::Sig>(rng() % 14);
		alu.op_add = static_cast<isa::AddOp>(rng() % 32);
		alu.op_mul = static_cast<isa::MulOp>(rng() % 8);
		alu.cond_add = static_cast<isa::Cond>(rng() % 8);
		alu.cond_mul = static_cast<isa::Cond>(rng() % 8);
		alu.waddr_add = static_cast<uint8_t>(rng() % 64);
		alu.waddr_mul = static_cast<uint8_t>(rng() % 64);
		alu.ws = rng() % 2;
		alu.sf = rng() % 4 == 0;
		alu.raddr_a = static_cast<uint8_t>(rng() % 64);
		alu.raddr_b = static_cast<uint8_t>(rng() % 64);
		alu.add_a = static_cast<Mux>(rng() % 8);
		alu.add_b = static_cast<Mux>(rng() % 8);
		alu.mul_a = static_cast<Mux>(rng() % 8);
		alu.mul_b = static_cast<Mux>(rng() % 8);
		if (rng() % 4 == 0) {
			alu.pm = rng() % 2;
			alu.pack = static_cast<isa::Pack>(rng() % 16);
			alu.unpack = static_cast<isa::Unpack>(rng() % 8);
		}
		if (alu.op_add == isa::AddOp::Nop) {
			alu.waddr_add = isa::waddr::nop;
			alu.add_a = alu.add_b = Mux::R0;
			alu.cond_add = isa::Cond::Never;
		}
		if (alu.op_mul == isa::MulOp::Nop) {
			alu.waddr_mul = isa::waddr::nop;
			alu.mul_a = alu.mul_b = Mux::R0;
			alu.cond_mul = isa::Cond::Never;
		}
		code.push_back(isa::encode(alu));
		printed += isa::printsAsInstruction(code.back());
	}
	EXPECT_GT(printed, 4000);
	EXPECT_EQ(qasm::assembleText(isa::disassembleProgram(code, false)), code);
}

TEST(DisassemblerGpuFft, WordsOfTheGpuFftShaders)
{
	// Words of GPU_FFT's shader_256/512 (hello_fft/hex): the VDW wait written as a
	// never-taken "mov", a rotation, a relative branch with a link register, and
	// "mov r0, 64" encoded as ftoi of the small immediate 64.0 on both inputs, which
	// "ftoi r0, 64.0" (second input r0) cannot re-create.
	const std::vector<uint64_t> code = {
		word(0x159f2fc0, 0x100009e7), word(0x959f8492, 0xd002c3e2),
		word(0x000001b0, 0xf0f80227), word(0x87726ff6, 0xd0024831),
	};
	EXPECT_EQ(listing(code),
	          "\tor.never -, vw_wait, vw_wait\n"
	          "\tor ra15, r2, r2; v8min.ifnz.rot 8, r2, r2, r2\n"
	          "\tbrr ra8, +432\n"
	          "\t.int 0x87726ff6, 0xd0024831\n");
	EXPECT_EQ(qasm::assembleText(listing(code)), code);
}

TEST(DisassemblerGpuFft, WordsOfShader256New)
{
	// Words of vc4asm's test/shader_256_new.hex. Its data table (37 words before the
	// code) holds two that decode as ALU words with the breakpoint signal: data, as
	// vc4asm's spelling of that signal changed ("bpkt", "bkpt"). Its code branches
	// through a register plus an offset (with one or both link registers), links into
	// r5 by regfile B (r5rep) and writes r2 as "ra34" from the MUL ALU (ws = 1).
	const std::vector<uint64_t> code = {
		word(0x88024020, 0x00000100), word(0x88024820, 0x00000500), word(0x00000000, 0xf0fc8000),
		word(0x00000230, 0xf0f80025), word(0xffffff88, 0xf0fc8027), word(0xffffff18, 0xf0fc89e7),
		word(0x809ff000, 0xd00159e2),
	};
	EXPECT_EQ(listing(code),
		  "\t.int 0x88024020, 0x00000100\n"
		  "\t.int 0x88024820, 0x00000500\n"
		  "\tbrr ra0, rb0, ra4, +0\n"
		  "\tbrr ra0, r5rep, -, +560\n"
		  "\tbrr ra0, ra4, -120\n"
		  "\tbrr -, ra4, -232\n"
		  "\tnop; v8min.ifnn.rot 15, ra34, r0, r0\n");
	EXPECT_EQ(qasm::assembleText(listing(code)), code);
	// Any breakpoint word is data, whatever its other fields.
	isa::Alu alu;
	alu.sig = isa::Sig::Breakpoint;
	EXPECT_FALSE(isa::printsAsInstruction(isa::encode(alu)));
	alu.sig = isa::Sig::None;
	EXPECT_TRUE(isa::printsAsInstruction(isa::encode(alu)));
}
