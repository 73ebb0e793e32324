// SPDX-License-Identifier: MIT
// Disassembler printing the syntax of vc4asm (maazl/vc4asm, doc/instructions.html and
// doc/expressions.html) so that an independent assembler re-creates the same words.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "instr.hpp"

namespace frappe::vc4::isa {

// Register names as vc4asm spells them; `fileB` selects the B column.
std::string readRegisterName(uint8_t raddr, bool fileB);
std::string writeRegisterName(uint8_t waddr, bool fileB);

// One instruction. Relative branch targets print as signed byte offsets.
std::string disassemble(uint64_t word);

// A whole program: branch targets inside it become labels (":L<byte address>").
std::string disassembleProgram(std::span<const uint64_t> words, bool with_comments = true);

// Every field with its name and value, e.g. "sig=1 unpack=0 pm=0 ...".
std::string fieldDump(uint64_t word);

} // namespace frappe::vc4::isa
