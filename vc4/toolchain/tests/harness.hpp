// SPDX-License-Identifier: MIT
// Runs assembled programs on the emulator for tests.
#pragma once

#include <memory>
#include <vector>

#include "asm/assembler.hpp"
#include "emu/v3d.hpp"

namespace frappe::vc4::test {

struct Run {
	explicit Run(emu::Config config = {}) : v3d(memory, config) {}
	emu::Memory memory;
	emu::V3d v3d;
	emu::LaunchStats stats;

	const emu::Qpu &qpu(unsigned n = 0) const { return v3d.qpu(n); }
};

// Loads `program` and runs it on `qpus` QPUs; uniforms[q] is QPU q's uniform stream
// (the last stream is reused for QPUs without their own).
inline std::unique_ptr<Run> run(const qasm::Program &program,
                                std::vector<std::vector<uint32_t>> uniforms = {{}},
                                unsigned qpus = 1, emu::Config config = {},
                                emu::LaunchOptions options = {})
{
	auto r = std::make_unique<Run>(config);
	const uint32_t code = r->memory.load(program.code);
	std::vector<emu::Job> jobs;
	for (unsigned q = 0; q < qpus; ++q) {
		const auto &u = uniforms[std::min<size_t>(q, uniforms.size() - 1)];
		jobs.push_back({r->memory.load(u), code});
	}
	r->stats = r->v3d.launch(jobs, options);
	return r;
}

} // namespace frappe::vc4::test
