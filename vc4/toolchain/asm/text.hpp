// SPDX-License-Identifier: MIT
// Reads back listings in the vc4asm syntax our disassembler prints (one instruction per
// line, ":label" lines, "#" comments, ".int" 32-bit and ".long" 64-bit data, "read"
// operands, four-operand branches). A self-check of the disassembler: every word must
// survive disassemble -> assembleText unchanged.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace frappe::vc4::qasm {

// Throws AsmError with the line number on anything it does not understand.
std::vector<uint64_t> assembleText(const std::string &text);

} // namespace frappe::vc4::qasm
