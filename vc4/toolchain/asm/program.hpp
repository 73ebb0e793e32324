// SPDX-License-Identifier: MIT
// An assembled QPU program and the description of the uniforms it reads.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace frappe::vc4::qasm {

enum class UniformKind : uint8_t {
	Value,         // a plain 32-bit value
	Address,       // a bus address the runtime fills in
	TextureConfig, // a TMU config parameter consumed by the TMU, not the program
};

struct UniformSlot {
	std::string name;
	UniformKind kind = UniformKind::Value;
};

struct Program {
	std::string name;
	std::vector<uint64_t> code;
	// The uniform stream, in the order the program (and its TMU lookups) consume it.
	std::vector<UniformSlot> uniforms;

	size_t uniformIndex(const std::string &name) const;
};

} // namespace frappe::vc4::qasm
