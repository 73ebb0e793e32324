// SPDX-License-Identifier: MIT
// QPU instruction fields, bit positions and enumerations.
//
// Source: Broadcom "VideoCore IV 3D Architecture Reference Guide" (VideoCoreIV-AG100-R,
// 2013-09-16), section 3 "QPU Instruction Encoding": Figure 4 (instruction formats),
// Table 1 (ALU fields), Tables 2-4 (op codes, conditions), Table 5 (small immediates),
// Table 14/15 (register address map), Tables 7-10 (pack/unpack).
#pragma once

#include <cstdint>

namespace frappe::vc4::isa {

// A field occupying bits [lo, lo + width) of the 64-bit instruction word.
struct Field {
	unsigned lo;
	unsigned width;

	constexpr uint64_t mask() const { return ((uint64_t{1} << width) - 1) << lo; }
	constexpr uint64_t get(uint64_t word) const { return (word >> lo) & ((uint64_t{1} << width) - 1); }
	constexpr uint64_t put(uint64_t value) const { return (value << lo) & mask(); }
};

namespace field {
// Common to all formats (Figure 4).
inline constexpr Field sig{60, 4};
// ALU format (Table 1).
inline constexpr Field unpack{57, 3};
inline constexpr Field pm{56, 1};
inline constexpr Field pack{52, 4};
inline constexpr Field cond_add{49, 3};
inline constexpr Field cond_mul{46, 3};
inline constexpr Field sf{45, 1};
inline constexpr Field ws{44, 1};
inline constexpr Field waddr_add{38, 6};
inline constexpr Field waddr_mul{32, 6};
inline constexpr Field op_mul{29, 3};
inline constexpr Field op_add{24, 5};
inline constexpr Field raddr_a{18, 6};
inline constexpr Field raddr_b{12, 6};
inline constexpr Field add_a{9, 3};
inline constexpr Field add_b{6, 3};
inline constexpr Field mul_a{3, 3};
inline constexpr Field mul_b{0, 3};
// Load immediate / semaphore format (sig = 14).
inline constexpr Field ldi_mode{57, 3};
inline constexpr Field immediate{0, 32};
inline constexpr Field sema_number{0, 4};
inline constexpr Field sema_down{4, 1};
inline constexpr Field sema_rest{5, 27};
// Branch format (sig = 15).
inline constexpr Field br_unused{56, 4};
inline constexpr Field cond_br{52, 4};
inline constexpr Field br_rel{51, 1};
inline constexpr Field br_reg{50, 1};
inline constexpr Field br_raddr_a{45, 5};
} // namespace field

// Signalling bits (section 3, "Signaling Bits").
enum class Sig : uint8_t {
	Breakpoint = 0,
	None = 1,
	ThreadSwitch = 2,
	ProgramEnd = 3,
	WaitScoreboard = 4,
	ScoreboardUnlock = 5,
	LastThreadSwitch = 6,
	CoverageLoad = 7,
	ColourLoad = 8,
	ColourLoadEnd = 9,
	LoadTmu0 = 10,
	LoadTmu1 = 11,
	AlphaMaskLoad = 12,
	SmallImmediate = 13,
	LoadImmediate = 14,
	Branch = 15,
};

// Table 2 "ADD op codes".
enum class AddOp : uint8_t {
	Nop = 0, FAdd = 1, FSub = 2, FMin = 3, FMax = 4, FMinAbs = 5, FMaxAbs = 6, FtoI = 7,
	ItoF = 8, Add = 12, Sub = 13, Shr = 14, Asr = 15, Ror = 16, Shl = 17, Min = 18, Max = 19,
	And = 20, Or = 21, Xor = 22, Not = 23, Clz = 24, V8Adds = 30, V8Subs = 31,
};

// Table 3 "MUL op codes".
enum class MulOp : uint8_t {
	Nop = 0, FMul = 1, Mul24 = 2, V8Muld = 3, V8Min = 4, V8Max = 5, V8Adds = 6, V8Subs = 7,
};

// Table 1 cond_add / cond_mul (section 3 "Condition Codes").
enum class Cond : uint8_t {
	Never = 0, Always = 1, ZSet = 2, ZClear = 3, NSet = 4, NClear = 5, CSet = 6, CClear = 7,
};

// Branch conditions (section 3 "Branches", Table 4 cond_br).
enum class BranchCond : uint8_t {
	AllZSet = 0, AllZClear = 1, AnyZSet = 2, AnyZClear = 3, AllNSet = 4, AllNClear = 5,
	AnyNSet = 6, AnyNClear = 7, AllCSet = 8, AllCClear = 9, AnyCSet = 10, AnyCClear = 11,
	Always = 15,
};

// ALU input multiplexer values (Table 1 add_a ... mul_b).
enum class Mux : uint8_t { R0 = 0, R1 = 1, R2 = 2, R3 = 3, R4 = 4, R5 = 5, A = 6, B = 7 };

// Load immediate modes (section 3 "Load Immediate Instructions").
enum class LoadMode : uint8_t { Word = 0, PerElementSigned = 1, PerElementUnsigned = 3, Semaphore = 4 };

// Regfile-A unpack (Table 7) / r4 unpack when pm = 1 (Table 8).
enum class Unpack : uint8_t {
	None = 0, H16A = 1, H16B = 2, B8DRep = 3, B8A = 4, B8B = 5, B8C = 6, B8D = 7,
};

// Pack modes: pm = 0 regfile-A write pack (Table 9), pm = 1 MUL pack (Table 10).
enum class Pack : uint8_t {
	None = 0, H16A = 1, H16B = 2, B8888 = 3, B8A = 4, B8B = 5, B8C = 6, B8D = 7,
	Sat32 = 8, H16ASat = 9, H16BSat = 10, B8888Sat = 11, B8ASat = 12, B8BSat = 13,
	B8CSat = 14, B8DSat = 15,
};

// Read addresses 32..63 (Table 14 "Register Address Map").
namespace raddr {
inline constexpr uint8_t uniform = 32;
inline constexpr uint8_t varying = 35;
inline constexpr uint8_t element_number = 38; // file A
inline constexpr uint8_t qpu_number = 38;     // file B
inline constexpr uint8_t nop = 39;
inline constexpr uint8_t x_coord = 41;        // file A (y_coord on B)
inline constexpr uint8_t ms_flags = 42;       // file A (rev_flag on B)
inline constexpr uint8_t vpm_read = 48;
inline constexpr uint8_t vdr_busy = 49;       // file A (vdw_busy on B)
inline constexpr uint8_t vdr_wait = 50;       // file A (vdw_wait on B)
inline constexpr uint8_t mutex_acquire = 51;
} // namespace raddr

// Write addresses 32..63 (Table 14).
namespace waddr {
inline constexpr uint8_t r0 = 32;
inline constexpr uint8_t r1 = 33;
inline constexpr uint8_t r2 = 34;
inline constexpr uint8_t r3 = 35;
inline constexpr uint8_t tmu_noswap = 36;
inline constexpr uint8_t r5 = 37;             // A: r5quad, B: r5rep (addendum)
inline constexpr uint8_t host_int = 38;
inline constexpr uint8_t nop = 39;
inline constexpr uint8_t uniforms_address = 40;
inline constexpr uint8_t quad_xy = 41;
inline constexpr uint8_t ms_flags = 42;
inline constexpr uint8_t tlb_stencil = 43;
inline constexpr uint8_t tlb_z = 44;
inline constexpr uint8_t tlb_colour_ms = 45;
inline constexpr uint8_t tlb_colour_all = 46;
inline constexpr uint8_t tlb_alpha_mask = 47;
inline constexpr uint8_t vpm_write = 48;
inline constexpr uint8_t vpm_setup = 49;      // A: VPM read setup, B: VPM write setup
inline constexpr uint8_t dma_address = 50;    // A: VDR address, B: VDW address
inline constexpr uint8_t mutex_release = 51;
inline constexpr uint8_t sfu_recip = 52;
inline constexpr uint8_t sfu_recipsqrt = 53;
inline constexpr uint8_t sfu_exp2 = 54;
inline constexpr uint8_t sfu_log2 = 55;
inline constexpr uint8_t tmu0_s = 56;
inline constexpr uint8_t tmu0_t = 57;
inline constexpr uint8_t tmu0_r = 58;
inline constexpr uint8_t tmu0_b = 59;
inline constexpr uint8_t tmu1_s = 60;
inline constexpr uint8_t tmu1_t = 61;
inline constexpr uint8_t tmu1_r = 62;
inline constexpr uint8_t tmu1_b = 63;
} // namespace waddr

// Small immediate encodings (Table 5): raddr_b when sig = 13.
namespace smallimm {
inline constexpr uint8_t rotate_by_r5 = 48;
inline constexpr bool isRotation(uint8_t code) { return code >= 48; }
// Value seen by an ALU input; for 48..63 the addendum reports -16..-1.
uint32_t value(uint8_t code);
// Encoding for a 32-bit value, or -1 when no small immediate produces it.
int encode(uint32_t value);
} // namespace smallimm

bool isUnary(AddOp op);
bool isValid(AddOp op);

} // namespace frappe::vc4::isa
