// SPDX-License-Identifier: MIT
#include "frontend/backend.hpp"

#include <stdexcept>

#include <sys/mman.h>
#include <unistd.h>

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

int allocateFrameMemory(std::string_view backend, std::size_t bytes, std::string &why)
{
	/* First cut, for both: a memfd. The real GPU's dma-heap comes with
	 * the zero-copy path (issue 14). */
	if (backend != "vc4" && backend != "vc4-emu") {
		why = "no QPU frame memory for backend '" + std::string(backend) + "'";
		return -1;
	}
	const int fd = memfd_create("frappe-frame", MFD_CLOEXEC);
	if (fd < 0 || ftruncate(fd, static_cast<off_t>(bytes)) != 0) {
		why = "memfd_create failed";
		if (fd >= 0)
			close(fd);
		return -1;
	}
	return fd;
}

} // namespace frappe::vc4
