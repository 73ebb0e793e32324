// SPDX-License-Identifier: MIT
// A model of frappedetect on a Raspberry Pi Zero (issue 33): one ARM1176 core at 1 GHz
// beside the 12 QPUs, each frame's work given as counts (ARMv6 instructions of its CPU
// stages from scripts/arm-count.sh, slowest-QPU cycles and DRAM bytes of its QPU launches
// from the emulator, bytes copied and cache-synced by the host), turned into times by the
// figures of `Assumptions` and played through the element's three ways of driving
// frappe::Pipeline. Nothing here measures: it is arithmetic, checked by
// tests/zero_model_test.cpp, to compare a first run on a Pi against (BRINGUP.md).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace frappe::vc4::model {

// A figure of the model at its fast end, its central value and its slow end, and where it
// comes from.
struct Figure {
	double fast = 0, mid = 0, slow = 0;
	const char *unit = "";
	const char *source = "";
};

// Which value of every Figure a run takes.
enum class End { Fast, Mid, Slow };

struct Assumptions {
	Figure cpi;            // ARM1176 cycles per instruction of frappe's CPU stages
	Figure arm_hz;         // the ARM's clock
	Figure v3d_hz;         // the QPUs' clock
	Figure dram_bytes_s;   // DRAM bandwidth the QPUs get
	Figure mailbox_s;      // one execute_qpu round trip beside the programs' run
	Figure launch_cpu_s;   // the ARM's own time in one launch (ioctl, message)
	Figure copy_bytes_s;   // the ARM's memcpy
	Figure sync_cycles;    // ARM cycles to clean or invalidate one 32-byte cache line
	double value(const Figure &f, End end) const { return end == End::Fast ? f.fast : end == End::Slow ? f.slow : f.mid; }
};

// The figures and their sources (printed by vc4-zero-model).
Assumptions piZero();

// One launch of QPU programs (12 at most): the slowest QPU's cycles, the bytes that must
// cross DRAM, and the bytes of buffers the runtime cache-syncs around it (END before, START
// after: each counted once here, the sync done twice).
struct Launch {
	uint64_t cycles = 0;
	uint64_t dram_bytes = 0;
	uint64_t sync_bytes = 0;
};

// One frame's work, split as the element's stages run it. The front end stage (on
// Pipeline's worker when staged) is the adaptive scale and the QPU launches of the front
// end, then the host's copies (the edge and region maps read back; the frame copied in
// when not read in place); the trace stage the contour trace; the finish stage refine,
// decode and the detector's glue, then the warp's launches.
struct FrameWork {
	uint64_t front_insns = 0;   // ARMv6 instructions on the CPU in the front-end stage
	uint64_t trace_insns = 0;
	uint64_t finish_insns = 0;
	uint64_t copy_bytes = 0;    // memcpy by the ARM in the front-end stage
	std::vector<Launch> front_launches;
	std::vector<Launch> warp_launches;
};

// How the element drives frappe::Pipeline: not pipelined (each frame whole on the
// streaming thread), pipelined over whole frames (two detectors on two threads, one frame
// held), pipelined over stages (one detector: the next frame's front end on the worker
// while the streaming thread traces this frame, then finishes it).
enum class Overlap { None, Frames, Stages };
const char *overlapName(Overlap o);

// When each frame went in and came out, in seconds from the first push: with a source that
// is never the bottleneck, its push (as soon as the element takes it); with a camera, its
// capture (the push may come later when the element is behind).
struct Timeline {
	std::vector<double> in, out;
	double cpuBusy = 0; // seconds the ARM worked
	double gpuBusy = 0; // seconds the QPUs (or the mailbox) worked
};

// Plays `frames` through the element. The ARM is one core shared evenly by the threads
// that have CPU work; the GPU runs one launch at a time, in the order they come. `period`
// > 0: a camera captures frame i at i * period seconds; 0: frames come as fast as taken.
Timeline simulate(const std::vector<FrameWork> &frames, Overlap overlap, const Assumptions &a, End end,
		  double period = 0);

// Seconds of one frame's stages on their own (no overlap), for the stage shares.
struct StageTimes {
	double front_cpu = 0, front_gpu = 0, trace = 0, finish_cpu = 0, warp_gpu = 0, sync = 0, copies = 0,
	       mailbox = 0;
	double total() const { return front_cpu + front_gpu + trace + finish_cpu + warp_gpu; }
};
StageTimes stageTimes(const FrameWork &f, const Assumptions &a, End end);

// Mean frame time (the interval between outputs, from the first output on), and latency
// (push to output) percentiles, in seconds.
struct Summary {
	double frame_time = 0;
	double latency_p50 = 0, latency_p90 = 0, latency_max = 0;
};
Summary summarise(const Timeline &t);

} // namespace frappe::vc4::model
