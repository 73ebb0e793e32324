// SPDX-License-Identifier: MIT
#include "frontend/backend.hpp"

#include <stdexcept>

#include <sys/mman.h>
#include <unistd.h>

#include "frontend/qpu_context.hpp"
#include "frontend/vc4_front_end.hpp"
#include "frontend/vc4_warper.hpp"
#if FRAPPE_VC4_HAVE_RUNTIME
#include "runtime/gpu_device.hpp"
#endif

namespace frappe::vc4 {

namespace {

/* One device per detector: the front end and the warper share one context. */
void makeQpuPair(bool emulate, BackendChoice &choice)
{
	if (emulate) {
		auto context = makeEmuContext(FrontEndOptions{ .emulate = true });
		choice.frontEnd = makeFrontEnd(context);
		choice.warper = makeWarper(context);
		return;
	}
#if FRAPPE_VC4_HAVE_RUNTIME
	if (const std::string reason = probeGpu(); !reason.empty())
		throw std::runtime_error(reason);
	auto context = makeGpuContext(runtime::systemOs(), {});
	choice.frontEnd = makeFrontEnd(context);
	choice.warper = makeWarper(context);
#else
	throw std::runtime_error("the VideoCore IV runtime is only built for Linux.");
#endif
}

} // namespace

BackendChoice selectFrontEnd(std::string_view name, int threads)
{
	BackendChoice choice;
	if (name == "cpu") {
		choice.frontEnd = makeCpuFrontEnd(threads);
	} else if (name == "vc4" || name == "vc4-emu") {
		makeQpuPair(name == "vc4-emu", choice);
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
				makeQpuPair(false, choice);
			} catch (const std::exception &e) {
				choice.frontEnd.reset();
				choice.warper.reset();
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
	if (backend == "vc4") {
#if FRAPPE_VC4_HAVE_RUNTIME
		/* The heaps the runtime's own buffers come from: vcsm-cma imports them. */
		return runtime::allocateDmaHeapBuffer(runtime::systemOs(), runtime::DeviceOptions{}, bytes, why);
#else
		why = "the VideoCore IV runtime is only built for Linux";
		return -1;
#endif
	}
	if (backend != "vc4-emu") {
		why = "no QPU frame memory for backend '" + std::string(backend) + "'";
		return -1;
	}
	/* The emulator reads host memory: a memfd, mapped in place like a dma-buf. */
	const int fd = memfd_create("frappe-frame", MFD_CLOEXEC);
	if (fd < 0 || ftruncate(fd, static_cast<off_t>(bytes)) != 0) {
		why = "memfd_create failed";
		if (fd >= 0)
			close(fd);
		return -1;
	}
	return fd;
}

std::string_view copyReason(const frappe::FrontEnd &front_end)
{
	ContextInfo info;
	return contextInfo(front_end, info) ? info.copy_reason : std::string_view();
}

const void *contextOf(const frappe::FrontEnd &front_end)
{
	ContextInfo info;
	return contextInfo(front_end, info) ? info.context : nullptr;
}

} // namespace frappe::vc4
