// SPDX-License-Identifier: MIT
// Operands of the embedded assembler: what a source reads and where a result goes.
#pragma once

#include <cstdint>
#include <string>

#include "isa/fields.hpp"

namespace frappe::vc4::qasm {

using isa::Pack;
using isa::Unpack;

// A read operand. FileA/FileB name one register file; Either is a peripheral that both
// files map (e.g. the uniform FIFO), and the assembler picks a free read port.
struct Src {
	enum class Kind : uint8_t { Acc, FileA, FileB, Either, SmallImm };
	Kind kind = Kind::Acc;
	uint8_t value = 0;      // accumulator number, raddr, or small immediate code
	Unpack unpack = Unpack::None;

	Src operator[](Unpack u) const { Src s = *this; s.unpack = u; return s; }
	bool operator==(const Src &) const = default;
	std::string name() const;
};

// A write operand; Either is a peripheral or accumulator reachable from both files.
struct Dst {
	enum class Kind : uint8_t { FileA, FileB, Either };
	Kind kind = Kind::Either;
	uint8_t waddr = isa::waddr::nop;
	Pack pack = Pack::None;

	Dst operator[](Pack p) const { Dst d = *this; d.pack = p; return d; }
	bool operator==(const Dst &) const = default;
};

inline constexpr Src acc(uint8_t n) { return {Src::Kind::Acc, n, Unpack::None}; }
inline constexpr Src ra(uint8_t n) { return {Src::Kind::FileA, n, Unpack::None}; }
inline constexpr Src rb(uint8_t n) { return {Src::Kind::FileB, n, Unpack::None}; }
inline constexpr Dst wa(uint8_t n) { return {Dst::Kind::FileA, n, Pack::None}; }
inline constexpr Dst wb(uint8_t n) { return {Dst::Kind::FileB, n, Pack::None}; }
// Small immediate from Table 5; throws when the value has no encoding.
Src imm(int32_t value);
Src imm(float value);

// Accumulators: the same object reads as a source and writes as a destination.
struct Accumulator {
	uint8_t n;
	constexpr operator Src() const { return acc(n); }
	constexpr operator Dst() const { return {Dst::Kind::Either, static_cast<uint8_t>(32 + n), Pack::None}; }
	Src operator[](Unpack u) const { return Src(*this)[u]; }
	Dst operator[](Pack p) const { return Dst(*this)[p]; }
};
inline constexpr Accumulator r0{0}, r1{1}, r2{2}, r3{3};
inline constexpr Src r4 = acc(4);
inline constexpr Src r5 = acc(5);

namespace reg {
using namespace isa;
inline constexpr Src unif{Src::Kind::Either, raddr::uniform, Unpack::None};
inline constexpr Src vary{Src::Kind::Either, raddr::varying, Unpack::None};
inline constexpr Src elem_num = ra(raddr::element_number);
inline constexpr Src qpu_num = rb(raddr::qpu_number);
inline constexpr Src vpm{Src::Kind::Either, raddr::vpm_read, Unpack::None};
inline constexpr Src vr_busy = ra(raddr::vdr_busy);
inline constexpr Src vw_busy = rb(raddr::vdr_busy);
inline constexpr Src vr_wait = ra(raddr::vdr_wait);
inline constexpr Src vw_wait = rb(raddr::vdr_wait);
inline constexpr Src mutex_acq{Src::Kind::Either, raddr::mutex_acquire, Unpack::None};

inline constexpr Dst nop{Dst::Kind::Either, waddr::nop, Pack::None};
inline constexpr Dst r5quad = wa(waddr::r5);
inline constexpr Dst r5rep = wb(waddr::r5);
inline constexpr Dst tmu_noswap{Dst::Kind::Either, waddr::tmu_noswap, Pack::None};
inline constexpr Dst host_int{Dst::Kind::Either, waddr::host_int, Pack::None};
inline constexpr Dst unif_addr = wa(waddr::uniforms_address);
inline constexpr Dst vpm_write{Dst::Kind::Either, waddr::vpm_write, Pack::None};
inline constexpr Dst vr_setup = wa(waddr::vpm_setup);
inline constexpr Dst vw_setup = wb(waddr::vpm_setup);
inline constexpr Dst vr_addr = wa(waddr::dma_address);
inline constexpr Dst vw_addr = wb(waddr::dma_address);
inline constexpr Dst mutex_rel{Dst::Kind::Either, waddr::mutex_release, Pack::None};
inline constexpr Dst sfu_recip{Dst::Kind::Either, waddr::sfu_recip, Pack::None};
inline constexpr Dst sfu_recipsqrt{Dst::Kind::Either, waddr::sfu_recipsqrt, Pack::None};
inline constexpr Dst sfu_exp2{Dst::Kind::Either, waddr::sfu_exp2, Pack::None};
inline constexpr Dst sfu_log2{Dst::Kind::Either, waddr::sfu_log2, Pack::None};
inline constexpr Dst tmu0_s{Dst::Kind::Either, waddr::tmu0_s, Pack::None};
inline constexpr Dst tmu0_t{Dst::Kind::Either, waddr::tmu0_t, Pack::None};
inline constexpr Dst tmu0_r{Dst::Kind::Either, waddr::tmu0_r, Pack::None};
inline constexpr Dst tmu0_b{Dst::Kind::Either, waddr::tmu0_b, Pack::None};
inline constexpr Dst tmu1_s{Dst::Kind::Either, waddr::tmu1_s, Pack::None};
inline constexpr Dst tmu1_t{Dst::Kind::Either, waddr::tmu1_t, Pack::None};
} // namespace reg

} // namespace frappe::vc4::qasm
