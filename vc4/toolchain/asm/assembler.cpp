// SPDX-License-Identifier: MIT
#include "asm/assembler.hpp"

#include <bit>
#include <cstring>

#include "asm/lint.hpp"
#include "isa/disasm.hpp"

namespace frappe::vc4::qasm {

using isa::Mux;

std::string Src::name() const
{
	switch (kind) {
	case Kind::Acc: return std::string(1, 'r').append(std::to_string(value));
	case Kind::FileA: return isa::readRegisterName(value, false);
	case Kind::FileB: return isa::readRegisterName(value, true);
	case Kind::Either: return isa::readRegisterName(value, false);
	case Kind::SmallImm: return std::string("smallimm").append(std::to_string(value));
	}
	return "?";
}

Src imm(int32_t value)
{
	const int code = isa::smallimm::encode(static_cast<uint32_t>(value));
	if (code < 0)
		throw AsmError("no small immediate for " + std::to_string(value));
	return {Src::Kind::SmallImm, static_cast<uint8_t>(code), Unpack::None};
}

Src imm(float value)
{
	const int code = isa::smallimm::encode(std::bit_cast<uint32_t>(value));
	if (code < 0)
		throw AsmError("no small immediate for float " + std::to_string(value));
	return {Src::Kind::SmallImm, static_cast<uint8_t>(code), Unpack::None};
}

size_t Program::uniformIndex(const std::string &n) const
{
	for (size_t i = 0; i < uniforms.size(); ++i)
		if (uniforms[i].name == n)
			return i;
	throw std::out_of_range("no uniform " + n);
}

namespace {

// Read-port allocation for one instruction.
class Ports {
public:
	explicit Ports(isa::Alu &alu) : alu_(alu) {}

	Mux use(const Src &s)
	{
		switch (s.kind) {
		case Src::Kind::Acc:
			if (s.value > 5)
				throw AsmError("no accumulator r" + std::to_string(s.value));
			unpack(s, s.value == 4);
			return static_cast<Mux>(s.value);
		case Src::Kind::FileA:
			takeA(s);
			return Mux::A;
		case Src::Kind::FileB:
			takeB(s);
			return Mux::B;
		case Src::Kind::Either:
			// Reuse a port already reading it (a second read would pop a FIFO twice).
			if (a_used_ && alu_.raddr_a == s.value) {
				takeA(s);
				return Mux::A;
			}
			if (b_used_ && !smi_ && alu_.raddr_b == s.value && s.unpack == Unpack::None) {
				takeB(s);
				return Mux::B;
			}
			if (!a_used_) {
				takeA(s);
				return Mux::A;
			}
			takeB(s);
			return Mux::B;
		case Src::Kind::SmallImm:
			if (b_used_ && (!smi_ || alu_.raddr_b != s.value))
				throw AsmError("read port B already used; cannot add small immediate " + s.name());
			b_used_ = smi_ = true;
			alu_.raddr_b = s.value;
			return Mux::B;
		}
		return Mux::R0;
	}

	void rotation(uint8_t code)
	{
		if (b_used_ && (!smi_ || alu_.raddr_b != code))
			throw AsmError("vector rotation needs the small immediate field, already used");
		b_used_ = smi_ = true;
		alu_.raddr_b = code;
	}

	bool smallImmediate() const { return smi_; }

private:
	void takeA(const Src &s)
	{
		if (a_used_ && alu_.raddr_a != s.value)
			throw AsmError("regfile A conflict: " + isa::readRegisterName(alu_.raddr_a, false) +
			               " and " + isa::readRegisterName(s.value, false) + " in one instruction");
		a_used_ = true;
		alu_.raddr_a = s.value;
		unpack(s, false);
	}
	void takeB(const Src &s)
	{
		if (b_used_ && (smi_ || alu_.raddr_b != s.value))
			throw AsmError("regfile B conflict: " + (smi_ ? std::string("small immediate") : isa::readRegisterName(alu_.raddr_b, true)) +
			               " and " + isa::readRegisterName(s.value, true) + " in one instruction");
		if (s.unpack != Unpack::None)
			throw AsmError("unpack applies only to regfile A or r4 reads");
		b_used_ = true;
		alu_.raddr_b = s.value;
	}
	void unpack(const Src &s, bool r4)
	{
		if (s.unpack == Unpack::None)
			return;
		if (s.kind == Src::Kind::Acc && !r4)
			throw AsmError("unpack applies only to regfile A or r4 reads");
		if ((unpack_set_ && (alu_.unpack != s.unpack || r4_unpack_ != r4)))
			throw AsmError("two different unpack modes in one instruction");
		unpack_set_ = true;
		r4_unpack_ = r4;
		alu_.unpack = s.unpack;
	}

	isa::Alu &alu_;
	bool a_used_ = false;
	bool b_used_ = false;
	bool smi_ = false;
	bool unpack_set_ = false;

public:
	bool r4_unpack_ = false;
	bool unpackUsed() const { return unpack_set_; }
};

// Which file a destination forces for its pipe: 0 = A, 1 = B, -1 = either.
int fileOf(const Dst &d)
{
	return d.kind == Dst::Kind::FileA ? 0 : d.kind == Dst::Kind::FileB ? 1 : -1;
}

} // namespace

isa::Alu assembleAlu(const AddOp &add, const MulOp &mul, isa::Sig sig)
{
	isa::Alu alu;
	alu.sig = sig;
	Ports ports(alu);
	const bool has_add = add.op != isa::AddOp::Nop;
	const bool has_mul = mul.op != isa::MulOp::Nop;
	if (has_add) {
		alu.op_add = add.op;
		alu.add_a = ports.use(add.a);
		alu.add_b = ports.use(add.b);
		alu.cond_add = add.cond;
		alu.waddr_add = add.dst.waddr;
	}
	if (has_mul) {
		alu.op_mul = mul.op;
		alu.mul_a = ports.use(mul.a);
		alu.mul_b = ports.use(mul.b);
		alu.cond_mul = mul.cond;
		alu.waddr_mul = mul.dst.waddr;
		if (mul.rotate) {
			if (mul.rotate > MulOp::kRotateByR5)
				throw AsmError("rotation must be 1..15 or r5");
			ports.rotation(static_cast<uint8_t>(mul.rotate == MulOp::kRotateByR5 ? 48 : 48 + mul.rotate));
		}
	}
	if (ports.smallImmediate()) {
		if (sig != isa::Sig::None)
			throw AsmError("a signal cannot share an instruction with a small immediate");
		alu.sig = isa::Sig::SmallImmediate;
	}
	if (add.setf && mul.setf && has_add)
		throw AsmError("only one pipe can set flags");
	if (add.setf && has_add)
		alu.sf = true;
	if (mul.setf) {
		if (has_add)
			throw AsmError("flags come from the ADD pipe when it is busy (addendum)");
		alu.sf = true;
	}
	// Write swap: ws = 0 puts ADD on file A and MUL on file B.
	const int add_file = has_add ? fileOf(add.dst) : -1;
	const int mul_file = has_mul ? fileOf(mul.dst) : -1;
	int ws = -1;
	if (add_file >= 0)
		ws = add_file;
	if (mul_file >= 0) {
		const int want = 1 - mul_file;
		if (ws >= 0 && ws != want)
			throw AsmError("ADD and MUL both write register file " + std::string(mul_file ? "B" : "A"));
		ws = want;
	}
	// Packs: a regfile-A pack (pm = 0) follows the pipe writing file A, a MUL pack sets pm.
	const bool add_pack = has_add && add.dst.pack != Pack::None;
	const bool mul_pack = has_mul && mul.dst.pack != Pack::None;
	if (add_pack && mul_pack)
		throw AsmError("only one pack per instruction");
	if (add_pack) {
		if (ws == 1)
			throw AsmError("ADD pack needs an ADD write to regfile A");
		ws = 0;
		alu.pack = add.dst.pack;
		if (ports.r4_unpack_ && ports.unpackUsed())
			throw AsmError("regfile-A pack and r4 unpack exclude each other");
	}
	if (mul_pack) {
		const auto p = static_cast<unsigned>(mul.dst.pack);
		if (mul.dst.kind == Dst::Kind::FileA) {
			alu.pack = mul.dst.pack; // regfile-A pack applied to the MUL result (ws = 1)
		} else {
			if (p < 3 || p > 7)
				throw AsmError("MUL pack (pm = 1) supports only 8888 and 8a..8d");
			if (ports.unpackUsed() && !ports.r4_unpack_)
				throw AsmError("MUL pack and regfile-A unpack exclude each other");
			alu.pm = true;
			alu.pack = mul.dst.pack;
		}
	}
	if (ports.unpackUsed() && ports.r4_unpack_)
		alu.pm = true;
	alu.ws = ws == 1;
	return alu;
}

Assembler::Assembler(std::string name) : name_(std::move(name)) {}

void Assembler::push(const isa::Instr &instr) { words_.push_back(isa::encode(instr)); }

void Assembler::emit(const AddOp &add, const MulOp &mul, isa::Sig sig)
{
	push(assembleAlu(add, mul, sig));
}

void Assembler::emit(const MulOp &mul, isa::Sig sig) { emit(AddOp{}, mul, sig); }

void Assembler::nop(isa::Sig sig) { emit(AddOp{}, MulOp{}, sig); }

void Assembler::thrend()
{
	nop(isa::Sig::ProgramEnd);
	nop();
	nop();
}

void Assembler::ldtmu(unsigned tmu, const AddOp &add, const MulOp &mul)
{
	emit(add, mul, tmu ? isa::Sig::LoadTmu1 : isa::Sig::LoadTmu0);
}

namespace {
isa::LoadImm loadImm(Dst dst, uint32_t value, isa::Cond cond, bool setf)
{
	isa::LoadImm l;
	l.value = value;
	l.sf = setf;
	if (dst.kind == Dst::Kind::FileB) {
		l.ws = true;
	}
	l.waddr_add = dst.waddr;
	l.cond_add = cond;
	if (dst.pack != Pack::None) {
		if (dst.kind == Dst::Kind::FileB)
			throw AsmError("regfile-A pack on a regfile-B destination");
		l.pack = dst.pack;
	}
	return l;
}
} // namespace

void Assembler::ldi(Dst dst, uint32_t value, isa::Cond cond, bool setf)
{
	push(loadImm(dst, value, cond, setf));
}

void Assembler::ldi(Dst dst_add, Dst dst_mul, uint32_t value)
{
	isa::LoadImm l = loadImm(dst_add, value, isa::Cond::Always, false);
	if (fileOf(dst_mul) == (l.ws ? 1 : 0))
		throw AsmError("both ldi destinations in the same register file");
	if (fileOf(dst_add) < 0 && fileOf(dst_mul) == 0)
		l.ws = true;
	l.waddr_mul = dst_mul.waddr;
	l.cond_mul = isa::Cond::Always;
	push(l);
}

void Assembler::ldiFloat(Dst dst, float value) { ldi(dst, std::bit_cast<uint32_t>(value)); }

void Assembler::ldiPerElement(Dst dst, const std::array<int, 16> &values, bool is_signed)
{
	uint32_t word = 0;
	for (unsigned e = 0; e < 16; ++e) {
		const int v = values[e];
		if (is_signed ? (v < -2 || v > 1) : (v < 0 || v > 3))
			throw AsmError("per-element value out of range");
		const auto bits = static_cast<uint32_t>(v) & 3;
		word |= (bits & 1) << e | (bits >> 1) << (16 + e);
	}
	isa::LoadImm l = loadImm(dst, word, isa::Cond::Always, false);
	l.mode = static_cast<uint8_t>(is_signed ? isa::LoadMode::PerElementSigned
	                                        : isa::LoadMode::PerElementUnsigned);
	push(l);
}

void Assembler::loadConstant(Dst dst, uint32_t value)
{
	if (isa::smallimm::encode(value) >= 0)
		emit(mov(dst, imm(static_cast<int32_t>(value))));
	else
		ldi(dst, value);
}

void Assembler::semaphoreAcquire(uint8_t n)
{
	isa::Semaphore s;
	s.number = n & 15;
	s.down = true;
	push(s);
}

void Assembler::semaphoreRelease(uint8_t n)
{
	isa::Semaphore s;
	s.number = n & 15;
	push(s);
}

Label Assembler::newLabel()
{
	labels_.emplace_back();
	return Label(static_cast<int>(labels_.size() - 1));
}

void Assembler::bind(Label l)
{
	if (l.id() < 0 || static_cast<size_t>(l.id()) >= labels_.size())
		throw AsmError("unknown label");
	if (labels_[l.id()])
		throw AsmError("label bound twice");
	labels_[l.id()] = words_.size();
}

namespace {
void setLink(isa::Branch &b, Dst link)
{
	if (link.kind == Dst::Kind::FileB)
		b.ws = true;
	b.waddr_add = link.waddr;
}
} // namespace

void Assembler::branch(Label target, isa::BranchCond cond, Dst link)
{
	isa::Branch b;
	b.cond = cond;
	b.rel = true;
	setLink(b, link);
	fixups_.push_back({words_.size(), target.id()});
	push(b);
}

void Assembler::branchRegister(uint8_t raddr_a, int32_t offset, isa::BranchCond cond, Dst link,
                               bool relative)
{
	isa::Branch b;
	b.cond = cond;
	b.rel = relative;
	b.reg = true;
	b.raddr_a = raddr_a & 31;
	b.offset = offset;
	setLink(b, link);
	push(b);
}

Src Assembler::uniform(std::string name, UniformKind kind)
{
	uniforms_.push_back({std::move(name), kind});
	return reg::unif;
}

Program Assembler::finish(bool lint_errors_throw)
{
	for (const auto &f : fixups_) {
		if (f.label < 0 || static_cast<size_t>(f.label) >= labels_.size() || !labels_[f.label])
			throw AsmError("branch to an unbound label");
		auto b = std::get<isa::Branch>(isa::decode(words_[f.index]));
		// Relative offsets count from the instruction after the three delay slots.
		b.offset = static_cast<int32_t>((static_cast<int64_t>(*labels_[f.label]) -
		                                 static_cast<int64_t>(f.index + 4)) * 8);
		words_[f.index] = isa::encode(b);
	}
	Program p{name_, words_, uniforms_};
	if (lint_errors_throw) {
		const auto diags = lint(p.code);
		if (!diags.empty())
			throw AsmError(name_ + ": " + diags.front().text());
	}
	return p;
}

} // namespace frappe::vc4::qasm
