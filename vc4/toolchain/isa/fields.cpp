// SPDX-License-Identifier: MIT
#include "fields.hpp"

#include <bit>

namespace frappe::vc4::isa {

namespace smallimm {

uint32_t value(uint8_t code)
{
	code &= 63;
	if (code < 16)
		return code;
	if (code < 32)
		return static_cast<uint32_t>(static_cast<int32_t>(code) - 32);
	if (code < 40) // 1.0 .. 128.0: exponent 127 + (code - 32)
		return static_cast<uint32_t>(127 + code - 32) << 23;
	if (code < 48) // 1/256 .. 1/2: exponent 127 - 8 + (code - 40)
		return static_cast<uint32_t>(127 - 8 + code - 40) << 23;
	// Rotation codes read as -16..-1 (vc4asm addendum, "Table 5: Small immediate values").
	return static_cast<uint32_t>(static_cast<int32_t>(code) - 64);
}

int encode(uint32_t v)
{
	for (int code = 0; code < 48; ++code)
		if (value(static_cast<uint8_t>(code)) == v)
			return code;
	return -1;
}

} // namespace smallimm

bool isUnary(AddOp op)
{
	return op == AddOp::Not || op == AddOp::Clz || op == AddOp::FtoI || op == AddOp::ItoF;
}

bool isValid(AddOp op)
{
	const auto v = static_cast<unsigned>(op);
	return v <= 8 || (v >= 12 && v <= 24) || v >= 30;
}

} // namespace frappe::vc4::isa
