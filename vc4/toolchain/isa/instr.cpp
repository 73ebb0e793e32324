// SPDX-License-Identifier: MIT
#include "instr.hpp"

namespace frappe::vc4::isa {

namespace {

uint64_t encodeWrites(const Writes &w)
{
	return field::pm.put(w.pm) | field::pack.put(static_cast<uint64_t>(w.pack)) |
	       field::cond_add.put(static_cast<uint64_t>(w.cond_add)) |
	       field::cond_mul.put(static_cast<uint64_t>(w.cond_mul)) | field::sf.put(w.sf) |
	       field::ws.put(w.ws) | field::waddr_add.put(w.waddr_add) |
	       field::waddr_mul.put(w.waddr_mul);
}

void decodeWrites(uint64_t word, Writes &w)
{
	w.pm = field::pm.get(word);
	w.pack = static_cast<Pack>(field::pack.get(word));
	w.cond_add = static_cast<Cond>(field::cond_add.get(word));
	w.cond_mul = static_cast<Cond>(field::cond_mul.get(word));
	w.sf = field::sf.get(word);
	w.ws = field::ws.get(word);
	w.waddr_add = static_cast<uint8_t>(field::waddr_add.get(word));
	w.waddr_mul = static_cast<uint8_t>(field::waddr_mul.get(word));
}

uint64_t sigBits(Sig sig) { return field::sig.put(static_cast<uint64_t>(sig)); }

struct Encoder {
	uint64_t operator()(const Alu &i) const
	{
		return sigBits(i.sig) | field::unpack.put(static_cast<uint64_t>(i.unpack)) |
		       encodeWrites(i) | field::op_mul.put(static_cast<uint64_t>(i.op_mul)) |
		       field::op_add.put(static_cast<uint64_t>(i.op_add)) |
		       field::raddr_a.put(i.raddr_a) | field::raddr_b.put(i.raddr_b) |
		       field::add_a.put(static_cast<uint64_t>(i.add_a)) |
		       field::add_b.put(static_cast<uint64_t>(i.add_b)) |
		       field::mul_a.put(static_cast<uint64_t>(i.mul_a)) |
		       field::mul_b.put(static_cast<uint64_t>(i.mul_b));
	}
	uint64_t operator()(const LoadImm &i) const
	{
		return sigBits(Sig::LoadImmediate) | field::ldi_mode.put(i.mode) | encodeWrites(i) |
		       field::immediate.put(i.value);
	}
	uint64_t operator()(const Semaphore &i) const
	{
		return sigBits(Sig::LoadImmediate) |
		       field::ldi_mode.put(static_cast<uint64_t>(LoadMode::Semaphore)) |
		       encodeWrites(i) | field::sema_number.put(i.number) |
		       field::sema_down.put(i.down) | field::sema_rest.put(i.ignored);
	}
	uint64_t operator()(const Branch &i) const
	{
		return sigBits(Sig::Branch) | field::br_unused.put(i.ignored) |
		       field::cond_br.put(static_cast<uint64_t>(i.cond)) | field::br_rel.put(i.rel) |
		       field::br_reg.put(i.reg) | field::br_raddr_a.put(i.raddr_a) |
		       field::ws.put(i.ws) | field::waddr_add.put(i.waddr_add) |
		       field::waddr_mul.put(i.waddr_mul) |
		       field::immediate.put(static_cast<uint32_t>(i.offset));
	}
};

} // namespace

uint64_t encode(const Instr &instr) { return std::visit(Encoder{}, instr); }

Instr decode(uint64_t word)
{
	const auto sig = static_cast<Sig>(field::sig.get(word));
	if (sig == Sig::Branch) {
		Branch b;
		b.ignored = static_cast<uint8_t>(field::br_unused.get(word));
		b.cond = static_cast<BranchCond>(field::cond_br.get(word));
		b.rel = field::br_rel.get(word);
		b.reg = field::br_reg.get(word);
		b.raddr_a = static_cast<uint8_t>(field::br_raddr_a.get(word));
		b.ws = field::ws.get(word);
		b.waddr_add = static_cast<uint8_t>(field::waddr_add.get(word));
		b.waddr_mul = static_cast<uint8_t>(field::waddr_mul.get(word));
		b.offset = static_cast<int32_t>(static_cast<uint32_t>(field::immediate.get(word)));
		return b;
	}
	if (sig == Sig::LoadImmediate) {
		const auto mode = static_cast<uint8_t>(field::ldi_mode.get(word));
		if (mode == static_cast<uint8_t>(LoadMode::Semaphore)) {
			Semaphore s;
			decodeWrites(word, s);
			s.number = static_cast<uint8_t>(field::sema_number.get(word));
			s.down = field::sema_down.get(word);
			s.ignored = static_cast<uint32_t>(field::sema_rest.get(word));
			return s;
		}
		LoadImm l;
		decodeWrites(word, l);
		l.mode = mode;
		l.value = static_cast<uint32_t>(field::immediate.get(word));
		return l;
	}
	Alu a;
	a.sig = sig;
	decodeWrites(word, a);
	a.unpack = static_cast<Unpack>(field::unpack.get(word));
	a.op_mul = static_cast<MulOp>(field::op_mul.get(word));
	a.op_add = static_cast<AddOp>(field::op_add.get(word));
	a.raddr_a = static_cast<uint8_t>(field::raddr_a.get(word));
	a.raddr_b = static_cast<uint8_t>(field::raddr_b.get(word));
	a.add_a = static_cast<Mux>(field::add_a.get(word));
	a.add_b = static_cast<Mux>(field::add_b.get(word));
	a.mul_a = static_cast<Mux>(field::mul_a.get(word));
	a.mul_b = static_cast<Mux>(field::mul_b.get(word));
	return a;
}

} // namespace frappe::vc4::isa
