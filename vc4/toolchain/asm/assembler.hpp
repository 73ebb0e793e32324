// SPDX-License-Identifier: MIT
// Embedded C++ assembler for QPU programs.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "asm/operands.hpp"
#include "asm/program.hpp"
#include "isa/instr.hpp"

namespace frappe::vc4::qasm {

class AsmError : public std::runtime_error {
public:
	using std::runtime_error::runtime_error;
};

// One ADD-pipe operation.
struct AddOp {
	isa::AddOp op = isa::AddOp::Nop;
	Dst dst = reg::nop;
	Src a = r0;
	Src b = r0;
	isa::Cond cond = isa::Cond::Always;
	bool setf = false;

	AddOp when(isa::Cond c) const { AddOp o = *this; o.cond = c; return o; }
	AddOp ifz() const { return when(isa::Cond::ZSet); }
	AddOp ifnz() const { return when(isa::Cond::ZClear); }
	AddOp ifn() const { return when(isa::Cond::NSet); }
	AddOp ifnn() const { return when(isa::Cond::NClear); }
	AddOp ifc() const { return when(isa::Cond::CSet); }
	AddOp ifnc() const { return when(isa::Cond::CClear); }
	AddOp setFlags() const { AddOp o = *this; o.setf = true; return o; }
};

// One MUL-pipe operation, optionally with a vector rotation of its result.
struct MulOp {
	isa::MulOp op = isa::MulOp::Nop;
	Dst dst = reg::nop;
	Src a = r0;
	Src b = r0;
	isa::Cond cond = isa::Cond::Always;
	bool setf = false;
	uint8_t rotate = 0; // 0 none, 1..15 by elements, kRotateByR5

	static constexpr uint8_t kRotateByR5 = 16;
	MulOp when(isa::Cond c) const { MulOp o = *this; o.cond = c; return o; }
	MulOp ifz() const { return when(isa::Cond::ZSet); }
	MulOp ifnz() const { return when(isa::Cond::ZClear); }
	MulOp ifn() const { return when(isa::Cond::NSet); }
	MulOp ifnn() const { return when(isa::Cond::NClear); }
	MulOp ifc() const { return when(isa::Cond::CSet); }
	MulOp ifnc() const { return when(isa::Cond::CClear); }
	MulOp setFlags() const { MulOp o = *this; o.setf = true; return o; }
	MulOp rot(uint8_t n) const { MulOp o = *this; o.rotate = n; return o; }
	MulOp rotR5() const { return rot(kRotateByR5); }
};

#define FRAPPE_VC4_ADD(name, code) \
	inline AddOp name(Dst d, Src a, Src b) { return {isa::AddOp::code, d, a, b}; }
FRAPPE_VC4_ADD(fadd, FAdd) FRAPPE_VC4_ADD(fsub, FSub) FRAPPE_VC4_ADD(fmin, FMin)
FRAPPE_VC4_ADD(fmax, FMax) FRAPPE_VC4_ADD(fminabs, FMinAbs) FRAPPE_VC4_ADD(fmaxabs, FMaxAbs)
FRAPPE_VC4_ADD(add, Add) FRAPPE_VC4_ADD(sub, Sub) FRAPPE_VC4_ADD(shr, Shr)
FRAPPE_VC4_ADD(asr, Asr) FRAPPE_VC4_ADD(ror, Ror) FRAPPE_VC4_ADD(shl, Shl)
FRAPPE_VC4_ADD(min, Min) FRAPPE_VC4_ADD(max, Max) FRAPPE_VC4_ADD(band, And)
FRAPPE_VC4_ADD(bor, Or) FRAPPE_VC4_ADD(bxor, Xor) FRAPPE_VC4_ADD(v8adds, V8Adds)
FRAPPE_VC4_ADD(v8subs, V8Subs)
#undef FRAPPE_VC4_ADD
// Unary ops feed the operand to both inputs (as vc4asm does).
inline AddOp ftoi(Dst d, Src a) { return {isa::AddOp::FtoI, d, a, a}; }
inline AddOp itof(Dst d, Src a) { return {isa::AddOp::ItoF, d, a, a}; }
inline AddOp bnot(Dst d, Src a) { return {isa::AddOp::Not, d, a, a}; }
inline AddOp clz(Dst d, Src a) { return {isa::AddOp::Clz, d, a, a}; }
inline AddOp mov(Dst d, Src a) { return {isa::AddOp::Or, d, a, a}; }
inline AddOp addOp(isa::AddOp op, Dst d, Src a, Src b) { return {op, d, a, b}; }

#define FRAPPE_VC4_MUL(name, code) \
	inline MulOp name(Dst d, Src a, Src b) { return {isa::MulOp::code, d, a, b}; }
FRAPPE_VC4_MUL(fmul, FMul) FRAPPE_VC4_MUL(mul24, Mul24) FRAPPE_VC4_MUL(v8muld, V8Muld)
FRAPPE_VC4_MUL(v8min, V8Min) FRAPPE_VC4_MUL(v8max, V8Max) FRAPPE_VC4_MUL(mv8adds, V8Adds)
FRAPPE_VC4_MUL(mv8subs, V8Subs)
#undef FRAPPE_VC4_MUL
inline MulOp mmov(Dst d, Src a) { return {isa::MulOp::V8Min, d, a, a}; }
inline MulOp mulOp(isa::MulOp op, Dst d, Src a, Src b) { return {op, d, a, b}; }

class Label {
public:
	explicit Label(int id = -1) : id_(id) {}
	int id() const { return id_; }

private:
	int id_;
};

// Builds a program instruction by instruction. Each emit call is one 64-bit word; read
// ports, small immediates and write swap are allocated here and conflicts throw AsmError.
class Assembler {
public:
	explicit Assembler(std::string name = "program");

	void emit(const AddOp &add, const MulOp &mul = {}, isa::Sig sig = isa::Sig::None);
	void emit(const MulOp &mul, isa::Sig sig = isa::Sig::None);
	void nop(isa::Sig sig = isa::Sig::None);
	void thrend(); // program end plus its two delay slots
	void ldtmu(unsigned tmu, const AddOp &add = {}, const MulOp &mul = {});

	// Load immediate (section 3 "Load Immediate Instructions"); both destinations get it.
	void ldi(Dst dst, uint32_t value, isa::Cond cond = isa::Cond::Always, bool setf = false);
	void ldi(Dst dst_add, Dst dst_mul, uint32_t value);
	void ldiFloat(Dst dst, float value);
	// Per-element 2-bit values, element i gets values[i].
	void ldiPerElement(Dst dst, const std::array<int, 16> &values, bool is_signed);
	// Loads any 32-bit value: a small immediate mov when one fits, ldi otherwise.
	void loadConstant(Dst dst, uint32_t value);

	void semaphoreAcquire(uint8_t n);
	void semaphoreRelease(uint8_t n);

	Label newLabel();
	void bind(Label l);
	// Relative branch to a label; three delay-slot instructions always follow and run.
	void branch(Label target, isa::BranchCond cond = isa::BranchCond::Always,
	            Dst link = reg::nop);
	// Absolute branch to regfile-A register (element 15) plus offset.
	void branchRegister(uint8_t raddr_a, int32_t offset = 0,
	                    isa::BranchCond cond = isa::BranchCond::Always, Dst link = reg::nop,
	                    bool relative = false);

	// Declares the next uniform the program reads and returns the read operand.
	Src uniform(std::string name, UniformKind kind = UniformKind::Value);

	size_t size() const { return words_.size(); }
	// Resolves labels, runs the hazard lint (throwing on errors unless told not to).
	Program finish(bool lint_errors_throw = true);

private:
	struct Fixup {
		size_t index;
		int label;
	};

	void push(const isa::Instr &instr);

	std::string name_;
	std::vector<uint64_t> words_;
	std::vector<std::optional<size_t>> labels_;
	std::vector<Fixup> fixups_;
	std::vector<UniformSlot> uniforms_;
};

// Converts one ALU description to an instruction (exposed for tests and tools).
isa::Alu assembleAlu(const AddOp &add, const MulOp &mul, isa::Sig sig);

} // namespace frappe::vc4::qasm
