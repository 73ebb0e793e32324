// SPDX-License-Identifier: MIT
#include "emu/alu.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

namespace frappe::vc4::emu {

using isa::AddOp;
using isa::MulOp;

float toFloat(uint32_t bits)
{
	if ((bits & 0x7f800000u) == 0)
		bits &= 0x80000000u;
	return std::bit_cast<float>(bits);
}

uint32_t fromFloat(float f)
{
	uint32_t bits = std::bit_cast<uint32_t>(f);
	if ((bits & 0x7f800000u) == 0)
		bits &= 0x80000000u;
	return bits;
}

float halfToFloat(uint16_t h)
{
	const uint32_t sign = (h >> 15) & 1;
	const int exp = (h >> 10) & 31;
	const uint32_t mant = h & 1023;
	float v;
	if (exp == 0)
		v = std::ldexp(static_cast<float>(mant), -24);
	else if (exp == 31)
		v = mant ? std::numeric_limits<float>::quiet_NaN() : std::numeric_limits<float>::infinity();
	else
		v = std::ldexp(static_cast<float>(mant | 1024), exp - 25);
	return sign ? -v : v;
}

uint16_t floatToHalf(float f)
{
	const uint32_t bits = std::bit_cast<uint32_t>(f);
	const uint16_t sign = static_cast<uint16_t>((bits >> 16) & 0x8000);
	const float a = std::fabs(f);
	if (std::isnan(f))
		return static_cast<uint16_t>(sign | 0x7e00);
	if (a >= 65520.0f)
		return static_cast<uint16_t>(sign | 0x7c00);
	if (a < std::ldexp(1.0f, -14)) // subnormal half, rounded to nearest even
		return static_cast<uint16_t>(sign | static_cast<uint16_t>(std::nearbyint(std::ldexp(a, 24))));
	int e;
	const float m = std::frexp(a, &e); // a = m * 2^e, m in [0.5, 1)
	auto mant = static_cast<uint32_t>(std::nearbyint(std::ldexp(m, 11))); // 11 significant bits
	if (mant == 2048) {
		mant = 1024;
		++e;
	}
	const int he = e - 1 + 15;
	if (he >= 31)
		return static_cast<uint16_t>(sign | 0x7c00);
	return static_cast<uint16_t>(sign | (he << 10) | (mant & 1023));
}

bool isFloatOp(AddOp op)
{
	switch (op) {
	case AddOp::FAdd: case AddOp::FSub: case AddOp::FMin: case AddOp::FMax:
	case AddOp::FMinAbs: case AddOp::FMaxAbs: case AddOp::FtoI:
		return true;
	default:
		return false;
	}
}

bool isFloatOp(MulOp op) { return op == MulOp::FMul; }

bool hasFloatResult(AddOp op) { return op == AddOp::ItoF || (isFloatOp(op) && op != AddOp::FtoI); }

namespace {

LaneResult floatResult(float f) { return {fromFloat(f), false, 0}; }
LaneResult intResult(uint32_t v, bool carry = false)
{
	return {v, carry, static_cast<int32_t>(v)};
}

uint32_t perByte(uint32_t a, uint32_t b, int (*f)(int, int))
{
	uint32_t out = 0;
	for (unsigned i = 0; i < 32; i += 8) {
		const int x = f(static_cast<int>((a >> i) & 255), static_cast<int>((b >> i) & 255));
		out |= static_cast<uint32_t>(std::clamp(x, 0, 255)) << i;
	}
	return out;
}

// Last bit shifted out: the addendum shows "shl.setf -, x, 30" puts bit 2 of x into C.
bool shiftCarry(uint32_t a, unsigned n, bool left)
{
	if (n == 0)
		return false;
	return left ? ((a >> (32 - n)) & 1) : ((a >> (n - 1)) & 1);
}

} // namespace

LaneResult addOp(AddOp op, uint32_t a, uint32_t b)
{
	const float fa = toFloat(a), fb = toFloat(b);
	const auto sa = static_cast<int32_t>(a), sb = static_cast<int32_t>(b);
	const unsigned n = b & 31;
	switch (op) {
	case AddOp::Nop: return {};
	case AddOp::FAdd: return floatResult(fa + fb);
	case AddOp::FSub: return floatResult(fa - fb);
	case AddOp::FMin: return floatResult(std::fmin(fa, fb));
	case AddOp::FMax: return floatResult(std::fmax(fa, fb));
	case AddOp::FMinAbs: return floatResult(std::fmin(std::fabs(fa), std::fabs(fb)));
	case AddOp::FMaxAbs: return floatResult(std::fmax(std::fabs(fa), std::fabs(fb)));
	case AddOp::FtoI: {
		// Unary ops take input a (see README: operand choice).
		if (std::isnan(fa))
			return intResult(0);
		const float t = std::trunc(fa);
		if (t >= 2147483648.0f || t < -2147483648.0f)
			return intResult(0);
		return intResult(static_cast<uint32_t>(static_cast<int32_t>(t)));
	}
	case AddOp::ItoF: return floatResult(static_cast<float>(sa));
	case AddOp::Add: {
		const uint64_t u = uint64_t{a} + b;
		LaneResult r = intResult(static_cast<uint32_t>(u), (u >> 32) != 0);
		r.wide = int64_t{sa} + sb;
		return r;
	}
	case AddOp::Sub: {
		LaneResult r = intResult(a - b, a < b);
		r.wide = int64_t{sa} - sb;
		return r;
	}
	case AddOp::Shr: return intResult(a >> n, shiftCarry(a, n, false));
	case AddOp::Asr: return intResult(static_cast<uint32_t>(sa >> n), shiftCarry(a, n, false));
	case AddOp::Ror: return intResult(std::rotr(a, static_cast<int>(n)), shiftCarry(a, n, false));
	case AddOp::Shl: return intResult(a << n, shiftCarry(a, n, true));
	case AddOp::Min: return intResult(static_cast<uint32_t>(std::min(sa, sb)), sa > sb);
	case AddOp::Max: return intResult(static_cast<uint32_t>(std::max(sa, sb)), sa > sb);
	case AddOp::And: return intResult(a & b);
	case AddOp::Or: return intResult(a | b);
	case AddOp::Xor: return intResult(a ^ b);
	case AddOp::Not: return intResult(~a);
	case AddOp::Clz: return intResult(static_cast<uint32_t>(std::countl_zero(a)));
	case AddOp::V8Adds: return intResult(perByte(a, b, [](int x, int y) { return x + y; }));
	case AddOp::V8Subs: return intResult(perByte(a, b, [](int x, int y) { return x - y; }));
	default: return {}; // undocumented op codes 9-11, 25-29
	}
}

LaneResult mulOp(MulOp op, uint32_t a, uint32_t b)
{
	switch (op) {
	case MulOp::Nop: return {};
	case MulOp::FMul: return floatResult(toFloat(a) * toFloat(b));
	case MulOp::Mul24: return intResult((a & 0xffffff) * (b & 0xffffff));
	case MulOp::V8Muld:
		return intResult(perByte(a, b, [](int x, int y) { return (x * y + 127) / 255; }));
	case MulOp::V8Min: return intResult(perByte(a, b, [](int x, int y) { return std::min(x, y); }));
	case MulOp::V8Max: return intResult(perByte(a, b, [](int x, int y) { return std::max(x, y); }));
	case MulOp::V8Adds: return intResult(perByte(a, b, [](int x, int y) { return x + y; }));
	case MulOp::V8Subs: return intResult(perByte(a, b, [](int x, int y) { return x - y; }));
	}
	return {};
}

uint32_t unpackRegfileA(isa::Unpack mode, uint32_t v, bool float_consumer)
{
	using U = isa::Unpack;
	switch (mode) {
	case U::None: return v;
	case U::H16A:
	case U::H16B: {
		const auto h = static_cast<uint16_t>(mode == U::H16A ? v : v >> 16);
		if (float_consumer)
			return fromFloat(halfToFloat(h));
		return static_cast<uint32_t>(static_cast<int32_t>(static_cast<int16_t>(h)));
	}
	case U::B8DRep: return ((v >> 24) & 255) * 0x01010101u;
	default: {
		const uint32_t byte = (v >> (8 * (static_cast<unsigned>(mode) - 4))) & 255;
		return float_consumer ? fromFloat(static_cast<float>(byte) / 255.0f) : byte;
	}
	}
}

uint32_t unpackR4(isa::Unpack mode, uint32_t v)
{
	using U = isa::Unpack;
	switch (mode) {
	case U::None: return v;
	case U::H16A: return fromFloat(halfToFloat(static_cast<uint16_t>(v)));
	case U::H16B: return fromFloat(halfToFloat(static_cast<uint16_t>(v >> 16)));
	case U::B8DRep: return ((v >> 24) & 255) * 0x01010101u;
	default: {
		const uint32_t byte = (v >> (8 * (static_cast<unsigned>(mode) - 4))) & 255;
		return fromFloat(static_cast<float>(byte) / 255.0f);
	}
	}
}

namespace {
uint32_t insertByte(uint32_t old, unsigned lane, uint32_t byte)
{
	const unsigned s = 8 * lane;
	return (old & ~(255u << s)) | ((byte & 255) << s);
}
uint32_t insertHalf(uint32_t old, bool high, uint32_t half)
{
	return high ? (old & 0xffffu) | (half << 16) : (old & 0xffff0000u) | (half & 0xffff);
}
} // namespace

uint32_t packRegfileA(isa::Pack mode, const LaneResult &r, bool float_op, uint32_t old)
{
	using P = isa::Pack;
	const auto m = static_cast<unsigned>(mode);
	const bool saturate = m >= 8;
	switch (mode) {
	case P::None: return r.value;
	case P::Sat32:
		return static_cast<uint32_t>(static_cast<int32_t>(
			std::clamp<int64_t>(r.wide, std::numeric_limits<int32_t>::min(), std::numeric_limits<int32_t>::max())));
	case P::H16A: case P::H16B: case P::H16ASat: case P::H16BSat: {
		uint32_t half;
		if (float_op)
			half = floatToHalf(toFloat(r.value));
		else if (saturate)
			half = static_cast<uint16_t>(std::clamp<int64_t>(r.wide, -32768, 32767));
		else
			half = r.value & 0xffff;
		return insertHalf(old, mode == P::H16B || mode == P::H16BSat, half);
	}
	default: {
		const uint32_t byte = saturate ? static_cast<uint32_t>(std::clamp<int64_t>(r.wide, 0, 255)) : (r.value & 255);
		const unsigned kind = m & 7; // 3 = 8888, 4..7 = 8a..8d
		if (kind == 3)
			return byte * 0x01010101u;
		return insertByte(old, kind - 4, byte);
	}
	}
}

uint32_t packMul(isa::Pack mode, uint32_t value, uint32_t old)
{
	const auto m = static_cast<unsigned>(mode);
	if (m == 0)
		return value;
	const float f = std::clamp(toFloat(value), 0.0f, 1.0f);
	const auto byte = static_cast<uint32_t>(std::nearbyint(f * 255.0f));
	if (m == 3)
		return byte * 0x01010101u;
	if (m >= 4 && m <= 7)
		return insertByte(old, m - 4, byte);
	return value; // pm = 1 with another pack code is not documented
}

bool zeroFlag(uint32_t value, bool float_op)
{
	return float_op ? (value & 0x7fffffffu) == 0 : value == 0;
}

bool negativeFlag(uint32_t value, bool float_op)
{
	return float_op ? (value >> 31) && (value & 0x7fffffffu) != 0 : (value >> 31) != 0;
}

} // namespace frappe::vc4::emu
