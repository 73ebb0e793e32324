// SPDX-License-Identifier: MIT
// Per-op, pack, unpack and flag semantics of reference guide section 3: Table 2 (ADD op
// codes), Table 3 (MUL op codes), Tables 7/8 (unpack), Tables 9/10 (pack), "Condition
// Codes", and the vc4asm addendum ("no inf, nan, denormal support").
#include <gtest/gtest.h>

#include <bit>

#include "emu/alu.hpp"

using namespace frappe::vc4;
using namespace frappe::vc4::emu;
using isa::AddOp;
using isa::MulOp;

namespace {
uint32_t f(float x) { return std::bit_cast<uint32_t>(x); }
uint32_t add(AddOp op, uint32_t a, uint32_t b) { return addOp(op, a, b).value; }
uint32_t mul(MulOp op, uint32_t a, uint32_t b) { return mulOp(op, a, b).value; }
} // namespace

TEST(EmuAddOps, FloatOps)
{
	EXPECT_EQ(add(AddOp::FAdd, f(1.5f), f(2.25f)), f(3.75f));
	EXPECT_EQ(add(AddOp::FSub, f(1.5f), f(2.25f)), f(-0.75f));
	EXPECT_EQ(add(AddOp::FMin, f(-1.0f), f(2.0f)), f(-1.0f));
	EXPECT_EQ(add(AddOp::FMax, f(-1.0f), f(2.0f)), f(2.0f));
	EXPECT_EQ(add(AddOp::FMinAbs, f(-3.0f), f(2.0f)), f(2.0f));
	EXPECT_EQ(add(AddOp::FMaxAbs, f(-3.0f), f(2.0f)), f(3.0f));
}

TEST(EmuAddOps, Conversions)
{
	// ftoi truncates towards zero; itof converts a signed integer.
	EXPECT_EQ(add(AddOp::FtoI, f(-2.7f), f(-2.7f)), static_cast<uint32_t>(-2));
	EXPECT_EQ(add(AddOp::FtoI, f(3.9f), f(3.9f)), 3u);
	EXPECT_EQ(add(AddOp::ItoF, static_cast<uint32_t>(-5), static_cast<uint32_t>(-5)), f(-5.0f));
}

TEST(EmuAddOps, IntegerArithmetic)
{
	const auto sum = addOp(AddOp::Add, 0xffffffffu, 1);
	EXPECT_EQ(sum.value, 0u);
	EXPECT_TRUE(sum.carry);
	const auto diff = addOp(AddOp::Sub, 3, 5);
	EXPECT_EQ(diff.value, static_cast<uint32_t>(-2));
	EXPECT_TRUE(diff.carry);
	EXPECT_FALSE(addOp(AddOp::Sub, 5, 3).carry);
	EXPECT_EQ(add(AddOp::Min, static_cast<uint32_t>(-1), 1), static_cast<uint32_t>(-1)); // signed
	EXPECT_EQ(add(AddOp::Max, static_cast<uint32_t>(-1), 1), 1u);
}

TEST(EmuAddOps, ShiftsUseLowFiveBitsOfB)
{
	EXPECT_EQ(add(AddOp::Shr, 0x80000000u, 4), 0x08000000u);
	EXPECT_EQ(add(AddOp::Asr, 0x80000000u, 4), 0xf8000000u);
	EXPECT_EQ(add(AddOp::Ror, 1, 1), 0x80000000u);
	EXPECT_EQ(add(AddOp::Shl, 1, 31), 0x80000000u);
	EXPECT_EQ(add(AddOp::Shl, 1, 33), 2u);
	// Addendum example: "shl.setf -, elem_num, 30" sets C from bit 2 of the input.
	EXPECT_TRUE(addOp(AddOp::Shl, 4, 30).carry);
	EXPECT_FALSE(addOp(AddOp::Shl, 3, 30).carry);
}

TEST(EmuAddOps, Logic)
{
	EXPECT_EQ(add(AddOp::And, 0xf0f0u, 0xff00u), 0xf000u);
	EXPECT_EQ(add(AddOp::Or, 0xf0f0u, 0xff00u), 0xfff0u);
	EXPECT_EQ(add(AddOp::Xor, 0xf0f0u, 0xff00u), 0x0ff0u);
	EXPECT_EQ(add(AddOp::Not, 0x0000ffffu, 0x0000ffffu), 0xffff0000u);
	EXPECT_EQ(add(AddOp::Clz, 1, 1), 31u);
	EXPECT_EQ(add(AddOp::Clz, 0, 0), 32u);
	EXPECT_EQ(add(AddOp::Clz, 0x80000000u, 0x80000000u), 0u);
}

TEST(EmuAddOps, PerByteSaturating)
{
	EXPECT_EQ(add(AddOp::V8Adds, 0x01ff8010u, 0x01018020u), 0x02ffff30u);
	EXPECT_EQ(add(AddOp::V8Subs, 0x00108010u, 0x01208001u), 0x0000000fu);
}

TEST(EmuMulOps, AllOps)
{
	EXPECT_EQ(mul(MulOp::FMul, f(1.5f), f(-2.0f)), f(-3.0f));
	// mul24 multiplies the low 24 bits of each input.
	EXPECT_EQ(mul(MulOp::Mul24, 0x01000003u, 2), 6u);
	EXPECT_EQ(mul(MulOp::Mul24, 0xffffffu, 0xffffffu), 0xfe000001u);
	// v8muld: per-byte colour multiply, 255 * x / 255 == x.
	EXPECT_EQ(mul(MulOp::V8Muld, 0xff80ff00u, 0x80ff40ffu), 0x80804000u);
	EXPECT_EQ(mul(MulOp::V8Min, 0x10203040u, 0x40302010u), 0x10202010u);
	EXPECT_EQ(mul(MulOp::V8Max, 0x10203040u, 0x40302010u), 0x40303040u);
	EXPECT_EQ(mul(MulOp::V8Adds, 0xf0000001u, 0x20000001u), 0xff000002u);
	EXPECT_EQ(mul(MulOp::V8Subs, 0x10000005u, 0x20000001u), 0x00000004u);
}

TEST(EmuFloat, DenormalsFlushToZero)
{
	const uint32_t denormal = 0x00000001u;
	EXPECT_EQ(add(AddOp::FAdd, denormal, 0), 0u);
	EXPECT_EQ(mul(MulOp::FMul, f(1e-20f), f(1e-20f)), 0u);
}

TEST(EmuUnpack, RegfileAUnpackTable7)
{
	using U = isa::Unpack;
	EXPECT_EQ(unpackRegfileA(U::H16A, 0x1234ffffu, false), 0xffffffffu); // sign-extended
	EXPECT_EQ(unpackRegfileA(U::H16B, 0x80001234u, false), 0xffff8000u);
	EXPECT_EQ(unpackRegfileA(U::H16A, 0x00003c00u, true), f(1.0f));     // float16 -> float32
	EXPECT_EQ(unpackRegfileA(U::H16B, 0xc0000000u, true), f(-2.0f));
	EXPECT_EQ(unpackRegfileA(U::B8DRep, 0xab000000u, false), 0xababababu);
	EXPECT_EQ(unpackRegfileA(U::B8A, 0x11223344u, false), 0x44u);
	EXPECT_EQ(unpackRegfileA(U::B8B, 0x11223344u, false), 0x33u);
	EXPECT_EQ(unpackRegfileA(U::B8C, 0x11223344u, false), 0x22u);
	EXPECT_EQ(unpackRegfileA(U::B8D, 0x11223344u, false), 0x11u);
	EXPECT_EQ(unpackRegfileA(U::B8A, 0x000000ffu, true), f(1.0f));      // colour -> [0, 1]
}

TEST(EmuUnpack, R4UnpackTable8)
{
	using U = isa::Unpack;
	EXPECT_EQ(unpackR4(U::H16A, 0x00003800u), f(0.5f));
	EXPECT_EQ(unpackR4(U::B8D, 0xff000000u), f(1.0f));
	EXPECT_EQ(unpackR4(U::B8A, 0x00000000u), f(0.0f));
	EXPECT_EQ(unpackR4(U::B8DRep, 0x7f000000u), 0x7f7f7f7fu);
}

TEST(EmuPack, RegfileAPackTable9)
{
	using P = isa::Pack;
	const LaneResult r{0x12345678u, false, 0x12345678};
	EXPECT_EQ(packRegfileA(P::H16A, r, false, 0xaaaaaaaau), 0xaaaa5678u);
	EXPECT_EQ(packRegfileA(P::H16B, r, false, 0xaaaaaaaau), 0x5678aaaau);
	EXPECT_EQ(packRegfileA(P::B8888, r, false, 0), 0x78787878u);
	EXPECT_EQ(packRegfileA(P::B8A, r, false, 0xaaaaaaaau), 0xaaaaaa78u);
	EXPECT_EQ(packRegfileA(P::B8B, r, false, 0xaaaaaaaau), 0xaaaa78aau);
	EXPECT_EQ(packRegfileA(P::B8C, r, false, 0xaaaaaaaau), 0xaa78aaaau);
	EXPECT_EQ(packRegfileA(P::B8D, r, false, 0xaaaaaaaau), 0x78aaaaaau);
	EXPECT_EQ(packRegfileA(P::H16A, {f(1.0f), false, 0}, true, 0), 0x3c00u); // float -> float16
}

TEST(EmuPack, SaturatingPacks)
{
	using P = isa::Pack;
	const auto overflow = addOp(AddOp::Add, 0x7fffffffu, 1);
	EXPECT_EQ(packRegfileA(P::Sat32, overflow, false, 0), 0x7fffffffu);
	const auto underflow = addOp(AddOp::Sub, 0x80000000u, 1);
	EXPECT_EQ(packRegfileA(P::Sat32, underflow, false, 0), 0x80000000u);
	EXPECT_EQ(packRegfileA(P::H16ASat, addOp(AddOp::Add, 40000, 0), false, 0), 0x7fffu);
	EXPECT_EQ(packRegfileA(P::H16BSat, addOp(AddOp::Sub, 0, 40000), false, 0), 0x80000000u);
	EXPECT_EQ(packRegfileA(P::B8ASat, addOp(AddOp::Add, 300, 0), false, 0), 0xffu);
	EXPECT_EQ(packRegfileA(P::B8ASat, addOp(AddOp::Sub, 0, 5), false, 0x1200u), 0x1200u);
	EXPECT_EQ(packRegfileA(P::B8888Sat, addOp(AddOp::Add, 256, 0), false, 0), 0xffffffffu);
}

TEST(EmuPack, MulPackTable10)
{
	using P = isa::Pack;
	EXPECT_EQ(packMul(P::B8888, f(1.0f), 0), 0xffffffffu);
	EXPECT_EQ(packMul(P::B8A, f(0.5f), 0xaaaaaaaau), 0xaaaaaa80u);
	EXPECT_EQ(packMul(P::B8D, f(2.0f), 0), 0xff000000u);  // clamped to 1.0
	EXPECT_EQ(packMul(P::B8B, f(-1.0f), 0xffffffffu), 0xffff00ffu);
}

TEST(EmuFlags, ZeroAndNegative)
{
	EXPECT_TRUE(zeroFlag(0, false));
	EXPECT_FALSE(zeroFlag(0x80000000u, false));
	EXPECT_TRUE(zeroFlag(0x80000000u, true)); // -0.0
	EXPECT_TRUE(negativeFlag(0x80000001u, false));
	EXPECT_FALSE(negativeFlag(0x80000000u, true));
	EXPECT_TRUE(negativeFlag(f(-1.0f), true));
}

TEST(EmuFloat, ConversionResultKinds)
{
	// ftoi returns an integer (flags as integer), itof a float.
	EXPECT_TRUE(isFloatOp(AddOp::FtoI));
	EXPECT_FALSE(hasFloatResult(AddOp::FtoI));
	EXPECT_FALSE(isFloatOp(AddOp::ItoF));
	EXPECT_TRUE(hasFloatResult(AddOp::ItoF));
	EXPECT_TRUE(hasFloatResult(AddOp::FMaxAbs));
	EXPECT_FALSE(hasFloatResult(AddOp::Add));
}
