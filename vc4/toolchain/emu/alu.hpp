// SPDX-License-Identifier: MIT
// Per-lane semantics of the two ALU pipes, pack/unpack and flags (reference guide
// section 3: "ALU Instructions", Tables 2-3, "Pack and Unpack", Tables 7-10,
// "Condition Codes"), with the vc4asm addendum corrections.
#pragma once

#include <cstdint>

#include "isa/fields.hpp"

namespace frappe::vc4::emu {

struct LaneResult {
	uint32_t value = 0;
	bool carry = false;
	int64_t wide = 0; // exact integer result of add/sub, for the saturating packs
};

// Whether an op reads its inputs as floats (drives unpack conversions)...
bool isFloatOp(isa::AddOp op);
bool isFloatOp(isa::MulOp op);
// ...and whether its result is a float (drives flags and float16 packing): ftoi reads a
// float and returns an integer, itof the reverse.
bool hasFloatResult(isa::AddOp op);

LaneResult addOp(isa::AddOp op, uint32_t a, uint32_t b);
LaneResult mulOp(isa::MulOp op, uint32_t a, uint32_t b);

// Regfile-A unpack (pm = 0) as seen by a consumer that is a float op or not.
uint32_t unpackRegfileA(isa::Unpack mode, uint32_t v, bool float_consumer);
// r4 unpack (pm = 1): conversions to float.
uint32_t unpackR4(isa::Unpack mode, uint32_t v);
// Regfile-A pack (pm = 0); `old` is the register's previous content for partial writes.
uint32_t packRegfileA(isa::Pack mode, const LaneResult &r, bool float_op, uint32_t old);
// MUL pack (pm = 1): float in [0, 1] to an 8-bit colour.
uint32_t packMul(isa::Pack mode, uint32_t value, uint32_t old);

// Z/N of a result (the C flag comes from LaneResult::carry).
bool zeroFlag(uint32_t value, bool float_op);
bool negativeFlag(uint32_t value, bool float_op);

// Float helpers: flush denormals to signed zero (addendum: "no denormal support").
float toFloat(uint32_t bits);
uint32_t fromFloat(float f);
float halfToFloat(uint16_t h);
uint16_t floatToHalf(float f);

} // namespace frappe::vc4::emu
