// SPDX-License-Identifier: MIT
// Disassembler printing the syntax of vc4asm (maazl/vc4asm, doc/instructions.html and
// doc/expressions.html) so that an independent assembler re-creates the same words.
//
// A word is printed as an instruction only when its text carries every field and vc4asm
// keeps each of them as written (it fills unused fields with its own defaults and rewrites
// a few forms, e.g. "sub r0, r1, r1" into "ldi r0, 0"); any other word, data included, is
// printed as ".int 0xLLLLLLLL, 0xHHHHHHHH" (two 32-bit words, low first, as vc4asm stores
// them; vc4asm's ".long" is 64 bits wide).
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "instr.hpp"

namespace frappe::vc4::isa {

// Register names as vc4asm spells them; `fileB` selects the B column.
std::string readRegisterName(uint8_t raddr, bool fileB);
std::string writeRegisterName(uint8_t waddr, bool fileB);

// True when the instruction text of `word` re-assembles (vc4asm, assembleText) to `word`.
bool printsAsInstruction(uint64_t word);

// One word: its instruction, or ".int" data for a word printsAsInstruction() refuses.
// Relative branch targets print as signed byte offsets.
std::string disassemble(uint64_t word);

// A whole program: branch targets inside it become labels (":L<byte address>"). With
// comments, every line ends in "# address: word", and an ".int" line also shows the
// instruction its bits would mean.
std::string disassembleProgram(std::span<const uint64_t> words, bool with_comments = true);

// Every field with its name and value, e.g. "sig=1 unpack=0 pm=0 ...".
std::string fieldDump(uint64_t word);

} // namespace frappe::vc4::isa
