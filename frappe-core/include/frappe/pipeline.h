// SPDX-License-Identifier: MIT
// frappe/pipeline.h: the paper's pipelined mode for a stream of frames.
#pragma once

#include <memory>

#include "frappe/config.h"
#include "frappe/detector.h"
#include "frappe/image.h"

namespace frappe {

/// Runs a Detector over a stream with two threads, in three stages: while
/// the calling thread traces the contours of frame N, a worker thread runs
/// the front end of frame N+1 and then refines, warps and decodes frame N-1.
/// Results come out two frames late, in order.
///
/// Throughput is bounded by the slower of the trace and the rest, instead
/// of their sum. In AScale mode a frame's scale comes from the last frame
/// finished before its front end started (three frames earlier).
class Pipeline {
public:
	/// Throws std::invalid_argument like Detector's constructor.
	explicit Pipeline(const Config &config);
	~Pipeline();
	Pipeline(const Pipeline &) = delete;
	Pipeline &operator=(const Pipeline &) = delete;

	/// Starts `image`, which must stay valid until its result has been
	/// returned, and returns the result of the frame pushed two calls
	/// before, or nullptr for the first two frames. A returned Result stays
	/// valid until the next push() or flush(). Throws std::invalid_argument
	/// for a bad image, before starting it; the frames already in flight are
	/// unaffected.
	const Result *push(const ImageView &image);

	/// At the end of the stream: finishes the oldest frame in flight and
	/// returns its result, or nullptr when none is left. Call until nullptr.
	const Result *flush();

	/// Whether frames are in flight (pushed, results not yet returned).
	bool pending() const;

	Detector &detector();

private:
	struct Impl;
	std::unique_ptr<Impl> impl_;
};

} // namespace frappe
