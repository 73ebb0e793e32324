// SPDX-License-Identifier: MIT
// A thin layer over qasm::Assembler for the front-end kernels: named registers usable as
// both source and destination, and an automatic nop where an instruction would read a
// register-file location written by the instruction before it (reference guide section 3,
// "Summary of Instruction Restrictions"), so the kernel code can be written in data-flow
// order and the listing stays hazard free. nops() counts the slots that could not be
// filled, to show where reordering would pay.
#pragma once

#include <cstdint>
#include <string>

#include "asm/assembler.hpp"

namespace frappe::vc4::kernels {

using namespace qasm;

/// One register of file A or B, as a source and as a destination.
struct Reg {
	bool file_b = false;
	uint8_t n = 0;
	operator Src() const { return file_b ? rb(n) : ra(n); }
	operator Dst() const { return file_b ? wb(n) : wa(n); }
	Src operator[](Unpack u) const { return Src(*this)[u]; }
};
inline constexpr Reg A(uint8_t n) { return {false, n}; }
inline constexpr Reg B(uint8_t n) { return {true, n}; }

class Builder {
public:
	explicit Builder(std::string name) : a_(std::move(name)) {}

	Assembler &assembler() { return a_; }

	void op(const AddOp &add, const MulOp &mul = {}, isa::Sig sig = isa::Sig::None)
	{
		if (readsWritten(add, mul)) {
			a_.nop();
			++nops_;
			written_a_ = written_b_ = 0;
		}
		a_.emit(add, mul, sig);
		record(add.op != isa::AddOp::Nop ? add.dst : reg::nop,
		       mul.op != isa::MulOp::Nop ? mul.dst : reg::nop);
	}
	void op(const MulOp &mul) { op(AddOp{}, mul); }
	/// Pops one TMU result into r4 at the end of this instruction.
	void ldtmu(unsigned tmu, const AddOp &add = {}, const MulOp &mul = {})
	{
		op(add, mul, tmu ? isa::Sig::LoadTmu1 : isa::Sig::LoadTmu0);
	}
	void ldi(Dst d, uint32_t value)
	{
		a_.ldi(d, value);
		record(d, reg::nop);
	}
	void nop()
	{
		a_.nop();
		written_a_ = written_b_ = 0;
	}
	/// A loop back-edge: decrement `counter`, branch while it is not zero. The three
	/// delay slots run nops (the loop bodies are long, so this costs under 2%).
	void loopEnd(Label top, Reg counter)
	{
		op(sub(counter, counter, imm(1)).setFlags());
		a_.branch(top, isa::BranchCond::AnyZClear);
		nop();
		nop();
		nop();
	}
	/// The end of a tile's body: another tile follows when the uniform `more` is
	/// non-zero (the host closes each tile's uniform block with it); then wait for the
	/// last VDW store.
	void nextTileOrEnd(Label tile)
	{
		op(mov(r0, uniform("more")).setFlags());
		a_.branch(tile, isa::BranchCond::AnyZClear);
		nop();
		nop();
		nop();
		op(mov(reg::nop, reg::vw_wait));
	}
	Label label()
	{
		// The other way in is a loop's last delay slot, a nop: the fall-through
		// predecessor's writes are the ones to respect.
		Label l = a_.newLabel();
		a_.bind(l);
		return l;
	}
	Src uniform(const char *name, UniformKind kind = UniformKind::Value) { return a_.uniform(name, kind); }
	/// Raises the host interrupt (the firmware's execute_qpu waits for one per program)
	/// and ends the program.
	Program finish()
	{
		a_.emit(mov(reg::host_int, imm(1)));
		a_.thrend();
		return a_.finish();
	}
	unsigned nops() const { return nops_; }

private:
	static bool reads(const Src &s, uint32_t a, uint32_t b)
	{
		if (s.kind == Src::Kind::FileA && s.value < 32)
			return (a >> s.value) & 1;
		if (s.kind == Src::Kind::FileB && s.value < 32)
			return (b >> s.value) & 1;
		return false;
	}
	bool readsWritten(const AddOp &add, const MulOp &mul) const
	{
		const uint32_t a = written_a_, b = written_b_;
		if (add.op != isa::AddOp::Nop && (reads(add.a, a, b) || reads(add.b, a, b)))
			return true;
		return mul.op != isa::MulOp::Nop && (reads(mul.a, a, b) || reads(mul.b, a, b));
	}
	void record(const Dst &add, const Dst &mul)
	{
		written_a_ = written_b_ = 0;
		for (const Dst &d : {add, mul}) {
			if (d.waddr >= 32)
				continue;
			if (d.kind == Dst::Kind::FileA)
				written_a_ |= 1u << d.waddr;
			else if (d.kind == Dst::Kind::FileB)
				written_b_ |= 1u << d.waddr;
		}
	}

	Assembler a_;
	uint32_t written_a_ = 0, written_b_ = 0;
	unsigned nops_ = 0;
};

} // namespace frappe::vc4::kernels
