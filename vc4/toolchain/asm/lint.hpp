// SPDX-License-Identifier: MIT
// Static hazard check over encoded programs: the restrictions of reference guide section 3
// "Summary of Instruction Restrictions" and the vc4asm addendum constraints.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "tmu_depth.hpp"

namespace frappe::vc4::qasm {

enum class Hazard {
	RegfileReadAfterWrite,   // regfile location read right after it was written
	RotateAfterWrite,        // rotating an accumulator written by the previous instruction
	RotateR5AfterWrite,      // rotation by r5 right after writing r5
	UniformAfterAddressWrite,// unif read within 2 instructions of a uniforms-address write
	TmuAfterNoSwap,          // TMU write within 3 instructions of tmu_noswap
	SfuResultTooEarly,       // r4 read (or r4-writing signal) within 2 of an SFU write
	R4ReadWithLdtmu,         // r4 read in the instruction carrying ldtmu
	DoubleAccess,            // two TMU/SFU/mutex/VPM-setup writes in one instruction
	ConditionalPeripheral,   // conditional write to a TMU/VPM/VCD/SFU register
	SameDestinationBothPipes,// ADD and MUL write the same register
	BranchTooClose,          // fewer than 2 non-branch instructions between branches
	ProgramEndWritesRegfile, // thread end instruction writes regfile A or B
	ProgramEndAccess,        // unif/VPM access in the thread end instruction or its slots
	ProgramEndTooShort,      // program ends before the two thread-end delay slots
	BranchInProgramEnd,      // branch in the thread-end delay slots
	VpmConcurrentAccess,     // VPM setup together with another VPM access in one instruction
	VpmReadWithoutSetup,     // VPM read with no read setup earlier in the program
	DmaWithoutSetup,         // VDR/VDW address write with no setup earlier in the program
	LdtmuWithoutRequest,     // ldtmu with no TMU request outstanding (program order)
	TmuTooManyOutstanding,   // more than tmu_depth TMU requests outstanding on one QPU
};

struct Diagnostic {
	size_t index;
	Hazard hazard;
	std::string message;

	std::string text() const;
};

// `tmu_depth`: TMU requests allowed in flight per QPU, both TMUs together (the count is
// static, in program order, so a loop must balance its requests and pops).
std::vector<Diagnostic> lint(std::span<const uint64_t> code, unsigned tmu_depth = kTmuDepth);

} // namespace frappe::vc4::qasm
