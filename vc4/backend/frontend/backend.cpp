// SPDX-License-Identifier: MIT
#include "frontend/backend.hpp"

#include <stdexcept>

#include "frontend/vc4_front_end.hpp"
#include "frontend/vc4_warper.hpp"

namespace frappe::vc4 {

BackendChoice selectFrontEnd(std::string_view name, int threads)
{
	BackendChoice choice;
	if (name == "cpu") {
		choice.frontEnd = makeCpuFrontEnd(threads);
	} else if (name == "vc4" || name == "vc4-emu") {
		const FrontEndOptions options{ .emulate = name == "vc4-emu" };
		choice.frontEnd = makeFrontEnd(options);
		choice.warper = makeWarper(options);
	} else if (name == "auto") {
#if !defined(__arm__) && !defined(__aarch64__)
		/* No VideoCore IV outside a Raspberry Pi: nothing to probe or say. */
		choice.frontEnd = makeCpuFrontEnd(threads);
		return choice;
#endif
		/* Probe once; a Pi whose QPUs cannot be used runs the CPU front
		 * end, and says why once. */
		const std::string reason = probeGpu();
		if (reason.empty()) {
			try {
				choice.frontEnd = makeFrontEnd(FrontEndOptions{ .emulate = false });
				choice.warper = makeWarper(FrontEndOptions{ .emulate = false });
			} catch (const std::exception &e) {
				choice.frontEnd.reset();
				choice.fallback = e.what();
			}
		} else {
			choice.fallback = reason;
		}
		if (!choice.frontEnd)
			choice.frontEnd = makeCpuFrontEnd(threads);
	} else {
		throw std::invalid_argument("unknown backend '" + std::string(name) + "'; known: " +
					    std::string(kBackendNames));
	}
	return choice;
}

} // namespace frappe::vc4
