// SPDX-License-Identifier: MIT
// frappe/pipeline.h: the paper's pipelined mode for a stream of frames.
#pragma once

#include <memory>

#include "frappe/config.h"
#include "frappe/detector.h"
#include "frappe/image.h"

namespace frappe {

/// Runs a Detector over a stream with two threads: the front end of frame
/// N+1 runs on a worker thread while the calling thread traces, refines and
/// decodes frame N. Results come out one frame late, in order.
///
/// Throughput is bounded by the slower of the two halves instead of their
/// sum. In AScale mode frame N+1's scale comes from frame N-1, the last one
/// whose back end had completed.
class Pipeline {
public:
	/// Throws std::invalid_argument like Detector's constructor.
	explicit Pipeline(const Config &config);
	~Pipeline();
	Pipeline(const Pipeline &) = delete;
	Pipeline &operator=(const Pipeline &) = delete;

	/// Starts `image`, which must stay valid until its result has been
	/// returned, and returns the result of the frame pushed before it, or
	/// nullptr for the first frame. A returned Result stays valid until the
	/// next push() or flush(). Throws std::invalid_argument for a bad image,
	/// before starting it; the frames already in flight are unaffected.
	const Result *push(const ImageView &image);

	/// At the end of the stream: finishes the frame in flight and returns its
	/// result, or nullptr when there is none.
	const Result *flush();

	/// Whether a frame is in flight (pushed, result not yet returned).
	bool pending() const;

	Detector &detector();

private:
	struct Impl;
	std::unique_ptr<Impl> impl_;
};

} // namespace frappe
