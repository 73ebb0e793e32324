/* SPDX-License-Identifier: MIT
 *
 * frappe_backend.h: the front end a user names (the element's backend
 * property, the CLI's --backend) put into a detector, and the frame memory
 * its QPUs read in place. No GStreamer types, so that any program can call
 * it.
 */
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <span>
#include <string_view>

#include <frappe/pipeline.h>

namespace frappe {

/* Thrown for vc4 and vc4-emu when this build has no vc4/. */
class BackendNotBuilt : public std::runtime_error
{
public:
	using std::runtime_error::runtime_error;
};

/* A front end a user may name: the one list the element's backend enum,
 * the CLI's --backend and its --help are made from. */
struct BackendName {
	std::string_view name; /* "auto", "cpu", "vc4", "vc4-emu" */
	std::string_view doc;  /* one line */
};
std::span<const BackendName> backendNames();
/* "auto, cpu, vc4, vc4-emu". */
std::string backendNameList(std::string_view separator = ", ");

/*
 * Puts the front end named `name` into every detector of `pipeline`: "cpu"
 * keeps the CPU front end they have; "vc4", "vc4-emu" and "auto" go to
 * vc4/backend, which decides what runs ("auto" without vc4/ in the build
 * keeps the CPU). Each detector runs on one thread, so a CPU front end that
 * "auto" falls back to has one band.
 *
 * Returns why "auto" fell back to the CPU, in one sentence for a single
 * warning, or an empty string. Throws std::invalid_argument for an unknown
 * name, BackendNotBuilt, and std::runtime_error when the QPUs cannot be used.
 */
std::string selectBackend(Pipeline &pipeline, std::string_view name);

/*
 * The QPU contexts (devices: GPU memory, one set of buffers each) that the
 * detectors of `pipeline` hold: one per detector on the QPUs, 0 on CPUs.
 */
int qpuContexts(Pipeline &pipeline);

/*
 * Frame memory the QPUs of `backend` ("vc4" or "vc4-emu") read in place: a
 * dma-buf of at least `bytes`, for an upstream element to write frames into
 * (the element's pool of GPU-visible buffers). Returns its file descriptor,
 * which the caller owns, or -1 with `why` set in one sentence (any other
 * backend, or a build without vc4/). Never throws.
 */
int allocateFrameMemory(std::string_view backend, std::size_t bytes, std::string &why);

} /* namespace frappe */
