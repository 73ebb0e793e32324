// SPDX-License-Identifier: MIT
// vc4-fe-listing LISTING: writes the QPU programs of the vc4 backends, the front end's two
// passes and the region map's two (kernels/kernels.hpp) and the candidate warp (kernels/warp.hpp), as one
// vc4asm-syntax listing, with their uniform streams, for review and for re-assembly by
// vc4asm. Run by meson at build time (vc4_frontend.dis in the build directory).
#include <cstdio>
#include <exception>
#include <fstream>

#include "isa/disasm.hpp"
#include "kernels/kernels.hpp"
#include "kernels/warp.hpp"

int main(int argc, char **argv)
{
	using namespace frappe::vc4;
	if (argc != 2) {
		std::fprintf(stderr, "usage: vc4-fe-listing LISTING\n");
		return 2;
	}
	try {
		std::ofstream listing(argv[1]);
		for (const kernels::Built &b : {kernels::gradientPass(), kernels::edgePass(), kernels::regionMeansPass(),
		                                kernels::regionDarkPass()}) {
			listing << "# " << b.program.name << ": " << b.program.code.size() << " instructions; uniforms per tile or block:";
			for (const auto &u : b.program.uniforms)
				listing << " " << u.name;
			listing << "\n" << isa::disassembleProgram(b.program.code, true) << "\n";
		}
		const qasm::Program warp = kernels::warpKernel();
		listing << "# " << warp.name << ": " << warp.code.size() << " instructions; uniforms: "
			<< kernels::kWarpProgramUniforms << " a program, then " << kernels::kWarpCandidateUniforms
			<< " a candidate (kernels/warp.hpp)\n"
			<< isa::disassembleProgram(warp.code, true) << "\n";
		return listing ? 0 : 1;
	} catch (const std::exception &e) {
		std::fprintf(stderr, "vc4-fe-listing: %s\n", e.what());
		return 1;
	}
}
