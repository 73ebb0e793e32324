// SPDX-License-Identifier: MIT
// Choosing a front end by the name a user gives it (the CLI's --backend, the
// element's backend property): auto, cpu, vc4, vc4-emu. The caller sees only
// frappe::FrontEnd; what runs behind it stays in vc4/.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>

#include "frappe/candidate_warp.h"
#include "frappe/edge_map.h"

namespace frappe::vc4 {

struct BackendChoice {
	std::unique_ptr<frappe::FrontEnd> frontEnd;
	/// The QPU warp of the candidates for vc4 and vc4-emu; nullptr for the CPU.
	std::unique_ptr<frappe::CandidateWarper> warper;
	/// Set when "auto" fell back to the CPU: why the QPUs were not used, in
	/// one sentence, for a single warning.
	std::string fallback;
};

/// The names selectFrontEnd() takes, for usage texts.
inline constexpr std::string_view kBackendNames = "auto, cpu, vc4, vc4-emu";

/// "vc4" and "vc4-emu" share one device between the front end and the warper, and the
/// warper reads the frame the front end imported or copied (lastCopyBytes() counts both).
/// "cpu": the reference CPU front end with `threads` bands. "vc4": the QPU
/// kernels (front end and candidate warp) on the real GPU; throws std::runtime_error with the probe's reason
/// when it cannot be used. "vc4-emu": the same kernels on the emulator, bit
/// for bit what the GPU computes (slow: for tests and estimates). "auto": vc4
/// when the probe succeeds, else the CPU with `fallback` set. Throws
/// std::invalid_argument for any other name.
BackendChoice selectFrontEnd(std::string_view name, int threads);

/// Frame memory the QPUs of `backend` ("vc4" or "vc4-emu") read in place: a
/// dma-buf of at least `bytes`, for an upstream element to write camera frames
/// into (the element offers a pool of them in the ALLOCATION query). "vc4":
/// from the dma-heap the runtime uses; "vc4-emu": a memfd, as the emulator
/// reads host memory. Returns the file descriptor (the caller owns it) or -1
/// with `why` set in one sentence. Never throws.
int allocateFrameMemory(std::string_view backend, std::size_t bytes, std::string &why);

/// Why the last frame was copied into GPU memory (front_end.lastCopyBytes() > 0: a
/// system-memory frame, a stride the QPUs cannot gather from, an import the kernel
/// refused), in one sentence for a debug line; empty when the QPUs read it in place or
/// `front_end` is not a QPU one. Valid until the next frame.
std::string_view copyReason(const frappe::FrontEnd &front_end);

/// The QPU context (one device and its buffers) `front_end` runs on, as an identity to
/// compare (a front end and the warper sharing it give the same); nullptr when it is not
/// a QPU front end.
const void *contextOf(const frappe::FrontEnd &front_end);

} // namespace frappe::vc4
