// SPDX-License-Identifier: MIT
// Typed QPU instructions and their 64-bit encoding.
#pragma once

#include <cstdint>
#include <variant>

#include "fields.hpp"

namespace frappe::vc4::isa {

// Destination fields shared by the ALU, load-immediate and semaphore formats (Table 1).
struct Writes {
	bool pm = false;
	Pack pack = Pack::None;
	Cond cond_add = Cond::Never;
	Cond cond_mul = Cond::Never;
	bool sf = false;
	bool ws = false;
	uint8_t waddr_add = waddr::nop;
	uint8_t waddr_mul = waddr::nop;

	bool operator==(const Writes &) const = default;
};

// ALU format, sig 0..13 (Figure 4, Table 1).
struct Alu : Writes {
	Sig sig = Sig::None;
	Unpack unpack = Unpack::None;
	AddOp op_add = AddOp::Nop;
	MulOp op_mul = MulOp::Nop;
	uint8_t raddr_a = raddr::nop;
	uint8_t raddr_b = raddr::nop; // small immediate code when sig == SmallImmediate
	Mux add_a = Mux::R0;
	Mux add_b = Mux::R0;
	Mux mul_a = Mux::R0;
	Mux mul_b = Mux::R0;

	bool operator==(const Alu &) const = default;
};

// Load immediate, sig 14 with a mode other than 4 (section 3 "Load Immediate Instructions").
// Modes 2, 5, 6 and 7 are not documented; they are kept so that decode is total.
struct LoadImm : Writes {
	uint8_t mode = static_cast<uint8_t>(LoadMode::Word);
	uint32_t value = 0;

	bool operator==(const LoadImm &) const = default;
};

// Semaphore, sig 14 with mode 4 (section 3 "Semaphore Instruction").
struct Semaphore : Writes {
	uint8_t number = 0;    // 0..15
	bool down = false;     // sa: 0 = increment, 1 = decrement (blocks at 0)
	uint32_t ignored = 0;  // bits 31:5, written to the destinations with the rest

	bool operator==(const Semaphore &) const = default;
};

// Branch, sig 15 (section 3 "Branches").
struct Branch {
	uint8_t ignored = 0;   // bits 59:56, not used by the hardware
	BranchCond cond = BranchCond::Always;
	bool rel = true;
	bool reg = false;
	uint8_t raddr_a = 0;   // 5 bits; the target adds element 15 of this register (addendum)
	bool ws = false;
	uint8_t waddr_add = waddr::nop; // link registers receive PC + 4 instructions
	uint8_t waddr_mul = waddr::nop;
	int32_t offset = 0;    // bytes

	bool operator==(const Branch &) const = default;
};

using Instr = std::variant<Alu, LoadImm, Semaphore, Branch>;

uint64_t encode(const Instr &instr);
// Total: every 64-bit word decodes, and encode(decode(w)) == w.
Instr decode(uint64_t word);

// The canonical no-op "nop; nop" (0x100009e7009e7000).
inline constexpr uint64_t kNopWord = 0x100009e7009e7000ull;

} // namespace frappe::vc4::isa
