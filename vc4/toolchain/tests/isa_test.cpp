// SPDX-License-Identifier: MIT
// Encoding tests: every field position of reference guide section 3, Figure 4 / Table 1
// (ALU), "Load Immediate Instructions", "Semaphore Instruction" and "Branches".
#include <gtest/gtest.h>

#include <random>

#include "isa/disasm.hpp"
#include "isa/instr.hpp"
#include "isa/setup_words.hpp"

using namespace frappe::vc4::isa;

namespace {

// Sets one field of an otherwise zero instruction and checks the single bit range it lands in.
template<typename T, typename Setter>
uint64_t encodeWith(Setter set)
{
	T instr{};
	set(instr);
	return encode(Instr{instr});
}

} // namespace

TEST(IsaEncode, CanonicalNopMatchesGuideNopEncoding)
{
	// Section 3: sig = 1 (no signal), waddr_add = waddr_mul = 39 (nop), raddr_a = raddr_b = 39.
	EXPECT_EQ(encode(Alu{}), 0x100009e7009e7000ull);
	EXPECT_EQ(kNopWord, 0x100009e7009e7000ull);
}

TEST(IsaEncode, AluFieldsLandAtTable1Positions)
{
	const uint64_t base = encode(Alu{});
	auto diff = [&](auto set) { return encode(Instr{[&] { Alu a; set(a); return a; }()}) ^ base; };
	EXPECT_EQ(diff([](Alu &a) { a.sig = Sig::ProgramEnd; }), uint64_t{0x2} << 60);
	EXPECT_EQ(diff([](Alu &a) { a.unpack = Unpack::B8D; }), uint64_t{7} << 57);
	EXPECT_EQ(diff([](Alu &a) { a.pm = true; }), uint64_t{1} << 56);
	EXPECT_EQ(diff([](Alu &a) { a.pack = Pack::B8DSat; }), uint64_t{15} << 52);
	EXPECT_EQ(diff([](Alu &a) { a.cond_add = Cond::CClear; }), uint64_t{7} << 49);
	EXPECT_EQ(diff([](Alu &a) { a.cond_mul = Cond::CClear; }), uint64_t{7} << 46);
	EXPECT_EQ(diff([](Alu &a) { a.sf = true; }), uint64_t{1} << 45);
	EXPECT_EQ(diff([](Alu &a) { a.ws = true; }), uint64_t{1} << 44);
	EXPECT_EQ(diff([](Alu &a) { a.waddr_add = 39 ^ 63; }), uint64_t{63} << 38);
	EXPECT_EQ(diff([](Alu &a) { a.waddr_mul = 39 ^ 63; }), uint64_t{63} << 32);
	EXPECT_EQ(diff([](Alu &a) { a.op_mul = MulOp::V8Subs; }), uint64_t{7} << 29);
	EXPECT_EQ(diff([](Alu &a) { a.op_add = AddOp::V8Subs; }), uint64_t{31} << 24);
	EXPECT_EQ(diff([](Alu &a) { a.raddr_a = 39 ^ 63; }), uint64_t{63} << 18);
	EXPECT_EQ(diff([](Alu &a) { a.raddr_b = 39 ^ 63; }), uint64_t{63} << 12);
	EXPECT_EQ(diff([](Alu &a) { a.add_a = Mux::B; }), uint64_t{7} << 9);
	EXPECT_EQ(diff([](Alu &a) { a.add_b = Mux::B; }), uint64_t{7} << 6);
	EXPECT_EQ(diff([](Alu &a) { a.mul_a = Mux::B; }), uint64_t{7} << 3);
	EXPECT_EQ(diff([](Alu &a) { a.mul_b = Mux::B; }), uint64_t{7} << 0);
}

TEST(IsaEncode, OpCodeValuesFollowTables2And3)
{
	const std::pair<AddOp, unsigned> add[] = {
		{AddOp::FAdd, 1}, {AddOp::FSub, 2}, {AddOp::FMin, 3}, {AddOp::FMax, 4},
		{AddOp::FMinAbs, 5}, {AddOp::FMaxAbs, 6}, {AddOp::FtoI, 7}, {AddOp::ItoF, 8},
		{AddOp::Add, 12}, {AddOp::Sub, 13}, {AddOp::Shr, 14}, {AddOp::Asr, 15},
		{AddOp::Ror, 16}, {AddOp::Shl, 17}, {AddOp::Min, 18}, {AddOp::Max, 19},
		{AddOp::And, 20}, {AddOp::Or, 21}, {AddOp::Xor, 22}, {AddOp::Not, 23},
		{AddOp::Clz, 24}, {AddOp::V8Adds, 30}, {AddOp::V8Subs, 31}};
	for (auto [op, code] : add) {
		Alu a;
		a.op_add = op;
		EXPECT_EQ((encode(a) >> 24) & 31, code);
	}
	const std::pair<MulOp, unsigned> mul[] = {
		{MulOp::FMul, 1}, {MulOp::Mul24, 2}, {MulOp::V8Muld, 3}, {MulOp::V8Min, 4},
		{MulOp::V8Max, 5}, {MulOp::V8Adds, 6}, {MulOp::V8Subs, 7}};
	for (auto [op, code] : mul) {
		Alu a;
		a.op_mul = op;
		EXPECT_EQ((encode(a) >> 29) & 7, code);
	}
}

TEST(IsaEncode, LoadImmediateFormat)
{
	// Section 3 "Load Immediate Instructions": sig = 14 (0xe), mode in 59:57, value in 31:0.
	LoadImm l;
	l.cond_add = Cond::Always;
	l.waddr_add = waddr::r0;
	l.value = 0xdeadbeef;
	EXPECT_EQ(encode(l), 0xe0020827deadbeefull);
	l.mode = static_cast<uint8_t>(LoadMode::PerElementUnsigned);
	EXPECT_EQ(encode(l) >> 57, (0xeull << 3) | 3);
}

TEST(IsaEncode, SemaphoreFormat)
{
	// Section 3 "Semaphore Instruction": mode 4 (bits 59:57 = 100), sa in bit 4, number in 3:0.
	Semaphore s;
	s.number = 7;
	s.down = true;
	EXPECT_EQ(encode(s), 0xe80009e700000017ull);
	s.down = false;
	EXPECT_EQ(encode(s) & 0xffffffff, 7u);
}

TEST(IsaEncode, BranchFormat)
{
	// Section 3 "Branches": sig = 15, cond_br 55:52, rel 51, reg 50, raddr_a 49:45.
	Branch b;
	b.cond = BranchCond::AnyZClear;
	b.rel = true;
	b.offset = -64;
	EXPECT_EQ(encode(b), 0xf03809e7ffffffc0ull);
	b.reg = true;
	b.raddr_a = 5;
	b.rel = false;
	EXPECT_EQ(encode(b) >> 45 & 0x7f, (1u << 5) | 5u);
}

TEST(IsaDecode, RoundTripIsTotalOverRandomWords)
{
	std::mt19937_64 rng(5);
	for (int n = 0; n < 200000; ++n) {
		const uint64_t w = rng();
		ASSERT_EQ(encode(decode(w)), w) << std::hex << w;
	}
}

TEST(IsaDecode, RoundTripEveryBitOfEveryFormat)
{
	for (uint64_t sig = 0; sig < 16; ++sig)
		for (unsigned bit = 0; bit < 60; ++bit) {
			const uint64_t w = (sig << 60) | (uint64_t{1} << bit);
			ASSERT_EQ(encode(decode(w)), w) << std::hex << w;
			const uint64_t v = (sig << 60) | (~(uint64_t{0xf} << 60) ^ (uint64_t{1} << bit));
			ASSERT_EQ(encode(decode(v)), v) << std::hex << v;
		}
}

TEST(IsaDecode, FormatSelectedBySig)
{
	EXPECT_TRUE(std::holds_alternative<Alu>(decode(0xd000000000000000ull)));
	EXPECT_TRUE(std::holds_alternative<LoadImm>(decode(0xe000000000000000ull)));
	EXPECT_TRUE(std::holds_alternative<Semaphore>(decode(0xe800000000000000ull)));
	EXPECT_TRUE(std::holds_alternative<Branch>(decode(0xf000000000000000ull)));
}

TEST(IsaSmallImmediate, Table5Values)
{
	// Table 5: 0..15 -> 0..15, 16..31 -> -16..-1, 32..39 -> 1.0..128.0, 40..47 -> 1/256..1/2.
	EXPECT_EQ(smallimm::value(0), 0u);
	EXPECT_EQ(smallimm::value(15), 15u);
	EXPECT_EQ(smallimm::value(16), 0xfffffff0u);
	EXPECT_EQ(smallimm::value(31), 0xffffffffu);
	EXPECT_EQ(smallimm::value(32), 0x3f800000u); // 1.0f
	EXPECT_EQ(smallimm::value(39), 0x43000000u); // 128.0f
	EXPECT_EQ(smallimm::value(40), 0x3b800000u); // 1/256
	EXPECT_EQ(smallimm::value(47), 0x3f000000u); // 0.5f
	EXPECT_EQ(smallimm::encode(0x3f800000u), 32);
	EXPECT_EQ(smallimm::encode(0xfffffffeu), 30);
	EXPECT_EQ(smallimm::encode(16u), -1);
}

TEST(IsaSetupWords, VpmGenericSetup)
{
	// Table 32/33: NUM 23:20, STRIDE 17:12, HORIZ 11, LANED 10, SIZE 9:8, ADDR 7:0.
	VpmReadSetup r{.num = 4, .stride = 1, .horizontal = true, .laned = false,
	               .size = VpmSize::Bits32, .addr = 3};
	EXPECT_EQ(r.word(), 0x00401a03u);
	EXPECT_EQ(VpmReadSetup::fromWord(r.word()).word(), r.word());
	VpmWriteSetup w{.stride = 2, .horizontal = false, .laned = true, .size = VpmSize::Bits8, .addr = 0x10};
	EXPECT_EQ(w.word(), 0x00002410u);
}

TEST(IsaSetupWords, VcdDmaSetups)
{
	// Table 34: VDW ID=2, UNITS 29:23, DEPTH 22:16, HORIZ 14, VPMBASE 13:3, MODEW 2:0.
	VdwSetup w{.units = 16, .depth = 16, .horizontal = true, .vpm_base = VdwSetup::base32(2, 0), .modew = 0};
	EXPECT_EQ(w.word(), 0x88104000u | (0x20u << 3));
	// Table 35 with the addendum's 16-bit STRIDE.
	EXPECT_EQ(VdwStride{.stride = 0xfffe}.word(), 0xc000fffeu);
	// Table 36: VDR bit 31, MODEW 30:28, MPITCH 27:24, ROWLEN 23:20, NROWS 19:16,
	// VPITCH 15:12, VERT 11, ADDRXY 10:0.
	VdrSetup r{.modew = 0, .mpitch = 0, .rowlen = 0, .nrows = 8, .vpitch = 1, .vertical = false, .addrxy = 0x20};
	EXPECT_EQ(r.word(), 0x80081020u);
	EXPECT_EQ(VdrStride{.pitch = 640}.word(), 0x90000280u);
	EXPECT_EQ(vrSetupKind(r.word()), SetupKind::VdrBasic);
	EXPECT_EQ(vrSetupKind(0x90000280u), SetupKind::VdrStride);
	EXPECT_EQ(vwSetupKind(w.word()), SetupKind::VdwBasic);
	EXPECT_EQ(vwSetupKind(0xc0000000u), SetupKind::VdwStride);
}

TEST(IsaTables, ConditionAndPackCodes)
{
	// Table 1 cond_add/cond_mul; "Branches" cond_br; Tables 7-10 pack/unpack codes.
	EXPECT_EQ(static_cast<int>(Cond::Never), 0);
	EXPECT_EQ(static_cast<int>(Cond::ZSet), 2);
	EXPECT_EQ(static_cast<int>(Cond::NClear), 5);
	EXPECT_EQ(static_cast<int>(Cond::CClear), 7);
	EXPECT_EQ(static_cast<int>(BranchCond::AllZSet), 0);
	EXPECT_EQ(static_cast<int>(BranchCond::AnyNClear), 7);
	EXPECT_EQ(static_cast<int>(BranchCond::AnyCClear), 11);
	EXPECT_EQ(static_cast<int>(BranchCond::Always), 15);
	EXPECT_EQ(static_cast<int>(Unpack::B8DRep), 3);
	EXPECT_EQ(static_cast<int>(Unpack::B8D), 7);
	EXPECT_EQ(static_cast<int>(Pack::B8888), 3);
	EXPECT_EQ(static_cast<int>(Pack::Sat32), 8);
	EXPECT_EQ(static_cast<int>(Pack::B8DSat), 15);
	EXPECT_EQ(static_cast<int>(LoadMode::PerElementUnsigned), 3);
	EXPECT_EQ(static_cast<int>(Sig::LoadTmu1), 11);
	EXPECT_EQ(static_cast<int>(Sig::SmallImmediate), 13);
}

TEST(IsaTables, RegisterAddressMap)
{
	// Table 14 "Register Address Map" (reads and writes 32..63).
	EXPECT_EQ(raddr::uniform, 32);
	EXPECT_EQ(raddr::element_number, 38);
	EXPECT_EQ(raddr::nop, 39);
	EXPECT_EQ(raddr::vpm_read, 48);
	EXPECT_EQ(raddr::vdr_wait, 50);
	EXPECT_EQ(raddr::mutex_acquire, 51);
	EXPECT_EQ(waddr::r0, 32);
	EXPECT_EQ(waddr::tmu_noswap, 36);
	EXPECT_EQ(waddr::r5, 37);
	EXPECT_EQ(waddr::host_int, 38);
	EXPECT_EQ(waddr::uniforms_address, 40);
	EXPECT_EQ(waddr::vpm_write, 48);
	EXPECT_EQ(waddr::vpm_setup, 49);
	EXPECT_EQ(waddr::dma_address, 50);
	EXPECT_EQ(waddr::mutex_release, 51);
	EXPECT_EQ(waddr::sfu_recip, 52);
	EXPECT_EQ(waddr::sfu_log2, 55);
	EXPECT_EQ(waddr::tmu0_s, 56);
	EXPECT_EQ(waddr::tmu1_b, 63);
	// Names as vc4asm spells them, per file.
	EXPECT_EQ(readRegisterName(38, false), "elem_num");
	EXPECT_EQ(readRegisterName(38, true), "qpu_num");
	EXPECT_EQ(readRegisterName(49, false), "vr_busy");
	EXPECT_EQ(readRegisterName(50, true), "vw_wait");
	EXPECT_EQ(writeRegisterName(37, false), "r5quad");
	EXPECT_EQ(writeRegisterName(37, true), "r5rep");
	EXPECT_EQ(writeRegisterName(49, false), "vr_setup");
	EXPECT_EQ(writeRegisterName(50, true), "vw_addr");
	EXPECT_EQ(writeRegisterName(60, false), "t1s");
}

TEST(IsaTables, TextureConfigWords)
{
	// vc4_packet.h VC4_TEX_P0/P1: base 31:12, type 7:4; P1 type bit 4 at 31, height 30:20,
	// width 18:8, magfilt 7, minfilt 6:4, wrap_t 3:2, wrap_s 1:0.
	EXPECT_EQ((TexP0{.base = 0x12345000, .type = TextureType::Luminance}).word(), 0x12345050u);
	EXPECT_EQ((TexP1{.type = TextureType::Rgba32Raster, .height = 480, .width = 640, .mag_nearest = true,
	                 .min_filter = 1, .wrap_t = TextureWrap::Mirror, .wrap_s = TextureWrap::Clamp})
	              .word(),
	          0x80000000u | (480u << 20) | (640u << 8) | 0x80u | 0x10u | (2u << 2) | 1u);
}
