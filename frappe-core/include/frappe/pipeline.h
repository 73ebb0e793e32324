// SPDX-License-Identifier: MIT
// frappe/pipeline.h: a stream of frames on several threads, results in order.
#pragma once

#include "frappe/export.h"

#include <memory>

#include "frappe/config.h"
#include "frappe/detector.h"
#include "frappe/image.h"

namespace frappe {

/// Runs detection over a stream of frames, overlapping frames on several
/// threads; results come out in order, latency() frames after their push.
/// The only place in Frappe where frames overlap: the CLI and the GStreamer
/// element drive one.
///
/// Overlap::Frames (the default): whole frames, each on a detector of its own.
/// `config.threads` threads (0: one per core; 1: each frame on the calling
/// thread as it is pushed, latency 0). A frame starts on an idle worker as
/// soon as it is pushed and runs on after push() returns; the calling
/// thread runs a frame only when the result it must return belongs to a
/// frame nobody has started. Throughput approaches `threads` times a
/// detector's whatever the balance of the stages: with two threads on the
/// synth images 1.8x at the default latency (as many frames as threads),
/// 1.5x at latency 1, where a frame that takes longer than the one beside
/// it leaves the other thread idle. A detector's memory per thread. Each
/// detector runs single-threaded, and in AScale mode scales from the last
/// frame it ran.
///
/// Overlap::Stages (the paper's pipelined mode): one detector, two threads,
/// three stages: the front end (on a QPU backend, the QPU passes), the
/// contour trace, and the finish (refine, warp, decode). Latency 2 (the
/// default): while the calling thread traces frame N, a worker thread runs
/// the front end of frame N+1 and then finishes frame N-1; throughput is
/// bounded by the slower of the trace and the rest (1.3x on the synth
/// images). Latency 1: while the calling thread traces frame N, the worker
/// runs the front end of frame N+1; once both are done the calling thread
/// finishes frame N. What the paper proposes for the Pi Zero: the QPUs
/// work on the next frame while its one core traces this one, with one
/// frame held and never two launches on the GPU at once. `config.threads`
/// splits a CPU front end into row bands. In AScale mode a frame's scale
/// comes from the last frame finished before its front end started.
///
/// A frame whose detection fails (out of memory, a GPU that stopped
/// responding) throws from the push() or flush() that would return it, in
/// either mode; the frames beside it are unaffected.
class FRAPPE_EXPORT Pipeline {
public:
	/// What the pipeline overlaps (frappe::Mode is the detector's resolution:
	/// another thing, another name).
	enum class Overlap { Frames, Stages };

	/// The latency of a mode when none is asked for: Overlap::Frames as many
	/// frames as threads (none with one thread), Overlap::Stages 2.
	static constexpr int kDefaultLatency = -1;

	/// Throws std::invalid_argument like Detector's constructor, and for a
	/// latency other than 1 or 2 in Overlap::Stages or outside [0, 256] in
	/// Overlap::Frames (below threads - 1, threads are left idle).
	explicit Pipeline(const Config &config, Overlap overlap = Overlap::Frames, int latency = kDefaultLatency);
	~Pipeline();
	Pipeline(const Pipeline &) = delete;
	Pipeline &operator=(const Pipeline &) = delete;

	/// Starts `image`, which must stay valid until its result has been
	/// returned (or drop() has returned), and returns the result of the
	/// frame pushed latency() calls before, or nullptr while fewer frames
	/// are in flight. A returned Result stays valid until the next push() or
	/// flush(). Throws std::invalid_argument for a bad image, before
	/// starting it: the frames in flight are unaffected. When the detection
	/// of the frame to return failed (out of memory), throws its exception
	/// instead; that frame is gone, `image` and the others stay in flight.
	const Result *push(const ImageView &image);

	/// At the end of the stream: finishes the oldest frame in flight and
	/// returns its result, or nullptr when none is left. Call until nullptr.
	/// Throws like push() when that frame failed.
	const Result *flush();

	/// Forgets the frames in flight without their results (a seek, a
	/// stop), after waiting for the ones running.
	void drop();

	/// Forgets what AScale learned from earlier frames, on every detector.
	void reset();

	/// Whether frames are in flight (pushed, results not yet returned).
	bool pending() const;

	/// Frames between a push and its result.
	int latency() const;

	/// Threads that detect, the calling one included.
	int threads() const;

	/// The detectors, configured alike (Overlap::Frames has one per thread,
	/// detector 0 the calling thread's): to set a front end or a warper on
	/// each before the first push.
	int detectorCount() const;
	Detector &detector(int index = 0);

private:
	struct Impl;
	std::unique_ptr<Impl> impl_;
};

} // namespace frappe
