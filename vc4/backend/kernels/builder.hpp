// SPDX-License-Identifier: MIT
// A thin layer over qasm::Assembler for the front-end kernels: named registers usable as
// both source and destination, and an automatic nop where an instruction would read a
// register-file location written by the instruction before it (reference guide section 3,
// "Summary of Instruction Restrictions"), so the kernel code can be written in data-flow
// order and the listing stays hazard free. nops() counts the slots that could not be
// filled, to show where reordering would pay. interleave() schedules TMU gathers into a
// stream of compute instructions, never more than kTmuDepth in flight.
#pragma once

#include <cstdint>
#include <deque>
#include <stdexcept>
#include <string>
#include <vector>

#include "asm/assembler.hpp"
#include "tmu_depth.hpp"

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

/// One instruction's worth of work: an ADD op, a MUL op, or both.
struct Ins {
	AddOp add;
	MulOp mul;
};
inline Ins ins(const AddOp &a, const MulOp &m = {}) { return {a, m}; }
inline Ins ins(const MulOp &m) { return {AddOp{}, m}; }

/// A TMU gather for Builder::interleave(): the request (an ADD op writing tmu0_s or
/// tmu1_s) and the instructions that consume its result from r4, in order.
struct Gather {
	AddOp issue;
	unsigned tmu = 0;
	std::vector<Ins> consume;
};

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
	/// delay slots run `slots` (which run on both paths, so they must be wanted after the
	/// loop too, and must not read what the slot before them writes), then nops.
	void loopEnd(Label top, Reg counter, std::initializer_list<AddOp> slots = {})
	{
		if (slots.size() > 3)
			throw std::logic_error("a branch has three delay slots");
		op(sub(counter, counter, imm(1)).setFlags());
		a_.branch(top, isa::BranchCond::AnyZClear);
		written_a_ = written_b_ = 0;
		for (const AddOp &s : slots) {
			if (readsWritten(s, {}))
				throw std::logic_error("a delay slot reads what the slot before it writes");
			a_.emit(s);
			record(s.dst, reg::nop);
		}
		for (size_t n = slots.size(); n < 3; ++n)
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

	/// Emits `compute` in order with `gathers` issued, popped and consumed in between:
	/// at most kTmuDepth requests in flight, a pop once a request is `latency`
	/// instructions old (or when room is needed), consumers riding in a free pipe of
	/// other instructions where the encoding allows. Gathers issued here or earlier may
	/// stay pending (in flight or unconsumed) at the end, `keep` at most, oldest first out.
	/// The caller guarantees that the consumers do not write what `compute` reads
	/// (nor the reverse) and that the gathers' results may land anywhere in the stream.
	/// No request pops before the first `hold` compute instructions ran (they may move
	/// registers the results land in).
	void interleave(std::vector<Ins> compute, std::vector<Gather> gathers, size_t keep = 0, size_t hold = 0,
	                unsigned latency = 10)
	{
		size_t c = 0, g = 0;
		auto fits = [](const AddOp &a, const MulOp &m, isa::Sig sig) {
			try {
				(void)assembleAlu(a, m, sig);
				return true;
			} catch (const AsmError &) {
				return false;
			}
		};
		auto busy = [](const AddOp &a) { return a.op != isa::AddOp::Nop; };
		auto mbusy = [](const MulOp &m) { return m.op != isa::MulOp::Nop; };
		while (c < compute.size() || g < gathers.size() || pending() > keep) {
			const size_t at = a_.size();
			const bool room = flight_.size() < kTmuDepth;
			const bool can_issue = g < gathers.size() && room;
			// 1. r4 holds a result: consume it before anything pops again.
			if (!consume_.empty()) {
				Ins k = consume_.front();
				consume_.pop_front();
				if (!busy(k.add) && can_issue && fits(gathers[g].issue, k.mul, isa::Sig::None)) {
					k.add = gathers[g].issue;
					issued(gathers[g++], at);
				} else if (c < compute.size() && !busy(k.add) && !mbusy(compute[c].mul) &&
				           fits(compute[c].add, k.mul, isa::Sig::None)) {
					k.add = compute[c++].add;
				} else if (c < compute.size() && !mbusy(k.mul) && !busy(compute[c].add) &&
				           fits(k.add, compute[c].mul, isa::Sig::None)) {
					k.mul = compute[c++].mul;
				}
				op(k.add, k.mul);
				continue;
			}
			// 2. Pop the oldest request once it is ripe: on a compute instruction that can
			// carry the signal if one comes within a few, alone when nothing else is left.
			// Never on a TMU request: the guide does not say that a request and a pop may
			// share an instruction (it would save 2% of pass 2; try it on hardware first).
			if (!flight_.empty() && c >= hold) {
				const Flight &f = flight_.front();
				const size_t age = at - f.issued_at;
				const isa::Sig sig = f.tmu ? isa::Sig::LoadTmu1 : isa::Sig::LoadTmu0;
				const bool idle = c >= compute.size() && !can_issue;
				const bool rides = c < compute.size() && fits(compute[c].add, compute[c].mul, sig);
				if (idle || age >= latency) {
					enum { Alone, WithCompute, Wait } how = Wait;
					if (rides)
						how = WithCompute;
					else if (idle || age >= latency + 3 || c >= compute.size())
						how = Alone;
					if (how != Wait) {
						for (const Ins &k : f.consume)
							consume_.push_back(k);
						flight_.pop_front();
						if (how == WithCompute) {
							op(compute[c].add, compute[c].mul, sig);
							++c;
						} else {
							op(AddOp{}, MulOp{}, sig);
						}
						continue;
					}
				}
			}
			// 3. Issue the next request, beside a MUL-only compute instruction if one is next.
			if (can_issue) {
				MulOp m;
				if (c < compute.size() && !busy(compute[c].add) && fits(gathers[g].issue, compute[c].mul, isa::Sig::None))
					m = compute[c++].mul;
				const Gather &q = gathers[g++];
				op(q.issue, m);
				issued(q, at);
				continue;
			}
			// 4. Compute.
			if (c < compute.size()) {
				op(compute[c].add, compute[c].mul);
				++c;
				continue;
			}
			// Only waiting is left: a request not yet ripe that must go.
			if (flight_.empty())
				throw std::logic_error("interleave: nothing to pop");
			const Flight &f = flight_.front();
			for (const Ins &k : f.consume)
				consume_.push_back(k);
			op(AddOp{}, MulOp{}, f.tmu ? isa::Sig::LoadTmu1 : isa::Sig::LoadTmu0);
			flight_.pop_front();
		}
	}

	/// Puts `movs` (MUL-pipe ops, kept in order) beside ADD-only instructions of
	/// `compute` from the start, inserting them alone where none fits; returns the index
	/// after the last one.
	static size_t mergeMul(std::vector<Ins> &compute, const std::vector<MulOp> &movs)
	{
		size_t at = 0;
		for (const MulOp &m : movs) {
			while (at < compute.size() && (compute[at].mul.op != isa::MulOp::Nop || !fitsNoSig(compute[at].add, m)))
				++at;
			if (at < compute.size())
				compute[at].mul = m;
			else
				compute.insert(compute.begin() + static_cast<long>(at), ins(m));
			++at;
		}
		return at;
	}

private:
	static bool fitsNoSig(const AddOp &a, const MulOp &m)
	{
		try {
			(void)assembleAlu(a, m, isa::Sig::None);
			return true;
		} catch (const AsmError &) {
			return false;
		}
	}
	struct Flight {
		unsigned tmu;
		size_t issued_at;
		std::vector<Ins> consume;
	};
	void issued(const Gather &q, size_t at) { flight_.push_back({q.tmu, at, q.consume}); }
	/// Gathers in flight or with their consumers still to run.
	size_t pending() const { return flight_.size() + (consume_.empty() ? 0 : 1); }

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
	std::deque<Flight> flight_;
	std::deque<Ins> consume_;
};

} // namespace frappe::vc4::kernels
