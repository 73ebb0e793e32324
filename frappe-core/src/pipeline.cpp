// SPDX-License-Identifier: MIT
// The pipelined mode, three stages on two threads: each call runs the front
// end of the new frame and the finish (refine, warp, decode) of the oldest
// on the worker, while the caller traces the frame in between.
#include "frappe/pipeline.h"

#include <exception>
#include <utility>

#include "worker.h"

namespace frappe {

struct Pipeline::Impl {
	explicit Impl(const Config &config) : detector(config) {}

	struct Frame {
		ImageView image;
		int slot = 0;
		bool traced = false;
	};

	Detector detector;
	detail::Worker worker;
	/* Frames in flight, oldest first; at most one traced and one not. */
	Frame frames[Detector::kSlots];
	int count = 0;

	/* The worker's round: the new frame's front end, then the oldest
	 * frame's finish when there is one. A member, so posting it allocates
	 * nothing. */
	struct Round {
		Impl *self;
		const Frame *start = nullptr;
		const Frame *finish = nullptr;
		const Result *finished = nullptr;
		void operator()()
		{
			try {
				self->detector.runFrontEnd(start->image, start->slot);
				if (finish)
					finished = &self->detector.runFinish(finish->image, finish->slot);
			} catch (...) {
				self->failure = std::current_exception();
			}
		}
	} round{ this };
	std::exception_ptr failure;

	int freeSlot() const
	{
		for (int s = 0; s < Detector::kSlots; ++s) {
			bool used = false;
			for (int i = 0; i < count; ++i)
				used |= frames[i].slot == s;
			if (!used)
				return s;
		}
		return 0; /* not reached: at most kSlots - 1 frames wait */
	}

	void pop()
	{
		for (int i = 1; i < count; ++i)
			frames[i - 1] = frames[i];
		--count;
	}
};

Pipeline::Pipeline(const Config &config) : impl_(std::make_unique<Impl>(config)) {}

Pipeline::~Pipeline() = default;

const Result *Pipeline::push(const ImageView &image)
{
	Impl &d = *impl_;
	d.detector.checkImage(image);

	d.frames[d.count] = { image, d.freeSlot(), false };
	Impl::Frame &fresh = d.frames[d.count];
	Impl::Frame *oldest = d.count > 0 ? &d.frames[0] : nullptr;
	Impl::Frame *toTrace = nullptr;
	for (int i = 0; i < d.count; ++i)
		if (!d.frames[i].traced)
			toTrace = &d.frames[i];
	++d.count;

	d.round.start = &fresh;
	d.round.finish = oldest && oldest->traced ? oldest : nullptr;
	d.round.finished = nullptr;
	d.worker.post(d.round);
	if (toTrace) {
		d.detector.runTrace(toTrace->slot);
		toTrace->traced = true;
	}
	d.worker.wait();
	if (d.failure) {
		d.count = 0; /* out of memory mid-round: drop the frames in flight */
		std::rethrow_exception(std::exchange(d.failure, nullptr));
	}
	if (!d.round.finish)
		return nullptr;
	d.pop();
	return d.round.finished;
}

const Result *Pipeline::flush()
{
	Impl &d = *impl_;
	if (d.count == 0)
		return nullptr;
	const Impl::Frame oldest = d.frames[0];
	d.pop();
	if (!oldest.traced)
		d.detector.runTrace(oldest.slot);
	return &d.detector.runFinish(oldest.image, oldest.slot);
}

bool Pipeline::pending() const { return impl_->count > 0; }
Detector &Pipeline::detector() { return impl_->detector; }

} // namespace frappe
