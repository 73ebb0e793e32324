// SPDX-License-Identifier: MIT
// frappe/pipeline.h: the paper's pipelined mode for a stream of frames.
#pragma once

#include "frappe/export.h"

#include <memory>

#include "frappe/config.h"
#include "frappe/detector.h"
#include "frappe/image.h"

namespace frappe {

/// Runs detection over a stream with two threads, results in order.
///
/// Mode::Stages (the paper's pipelined mode), three stages: while the
/// calling thread traces the contours of frame N, a worker thread runs the
/// front end of frame N+1 and then refines, warps and decodes frame N-1.
/// Results come out two frames late. Throughput is bounded by the slower of
/// the trace and the rest, instead of their sum; one detector's memory. In
/// AScale mode a frame's scale comes from the last frame finished before its
/// front end started (three frames earlier).
///
/// Mode::Frames: whole frames on two detectors. Frames wait in a queue; a
/// worker thread with its own detector takes each as soon as it is free (it
/// runs on after push() returns), and the calling thread runs one only when
/// the result it must return belongs to a frame nobody has started. Results
/// come out two frames late. Throughput approaches twice a detector's
/// whatever the balance of the stages and the spread of frame costs (1.76x
/// on the synth images, where the staged mode gives 1.3x); twice the memory.
/// In AScale mode each detector scales from the last frame it ran.
class FRAPPE_EXPORT Pipeline {
public:
	enum class Mode { Stages, Frames };

	/// Throws std::invalid_argument like Detector's constructor.
	explicit Pipeline(const Config &config, Mode mode = Mode::Stages);
	~Pipeline();
	Pipeline(const Pipeline &) = delete;
	Pipeline &operator=(const Pipeline &) = delete;

	/// Starts `image`, which must stay valid until its result has been
	/// returned, and returns the result of the frame pushed latency() calls
	/// before, or nullptr for the first latency() frames. A returned Result stays
	/// valid until the next push() or flush(). Throws std::invalid_argument
	/// for a bad image, before starting it; the frames already in flight are
	/// unaffected.
	const Result *push(const ImageView &image);

	/// At the end of the stream: finishes the oldest frame in flight and
	/// returns its result, or nullptr when none is left. Call until nullptr.
	const Result *flush();

	/// Whether frames are in flight (pushed, results not yet returned).
	bool pending() const;

	/// Frames between a push and its result (2).
	int latency() const;

	/// The detector of the calling thread (Mode::Frames has a second one,
	/// configured alike, for the worker).
	Detector &detector();

private:
	struct Impl;
	std::unique_ptr<Impl> impl_;
};

} // namespace frappe
