// SPDX-License-Identifier: MIT
// Small QPU programs that exercise the whole chain (assembler, TMU, VPM, VCD DMA, mutex,
// semaphores) and serve as templates for the kernels.
#pragma once

#include "asm/program.hpp"

namespace frappe::vc4::samples {

// out[i] = a[i] + b[i] over `vectors` 16-word vectors; TMU0 direct loads, VPM row
// qpu_num, VDW under the mutex. Uniforms: a, b, out, vectors.
qasm::Program vectorSum();

// All 16 lanes of out get the sum of the 16 words at in (rotations by 8, 4, 2, 1).
// Uniforms: in, out.
qasm::Program laneReduction();

// Copies a 64x16-byte tile with VDR (extended pitch), adds 1 to every byte through the
// VPM generic read/write path, and stores it with VDW (stride). VPM rows 0..15 are
// used under the mutex, so any number of QPUs can run it at once.
// Uniforms: src, dst, src_pitch, dst_pitch.
qasm::Program tileCopy();

// Fetches 16 texels of a raster RGBA32 texture at coordinates read from memory.
// Uniforms: s (16 floats), t (16 floats), p0, p1 (consumed by the TMU), out.
qasm::Program textureFetch();

// QPU 0 waits on semaphore 0 once per other QPU, then sums the words they stored.
// Uniforms: out (12 words), qpus.
qasm::Program semaphoreGather();

} // namespace frappe::vc4::samples
