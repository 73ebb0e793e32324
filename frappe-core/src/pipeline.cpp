// SPDX-License-Identifier: MIT
// Two threads over a stream. Stages: each call runs the front end of the new
// frame and the finish (refine, warp, decode) of the oldest on the worker,
// while the caller traces the frame in between. Frames: odd frames go whole
// to a second detector on the worker, which runs on after push() returns;
// even frames run on the caller while the worker finishes the odd one before.
#include "frappe/pipeline.h"

#include <exception>
#include <utility>

#include "worker.h"

namespace frappe {

struct Pipeline::Impl {
	Impl(const Config &config, Mode m) : mode(m), detector(config)
	{
		if (mode == Mode::Frames)
			second = std::make_unique<Detector>(config);
	}
	~Impl()
	{
		/* The worker may still be on an odd frame, with `second`. */
		if (workerBusy)
			worker.wait();
	}

	struct Frame {
		ImageView image;
		int slot = 0;
		bool traced = false;
	};

	Mode mode;
	Detector detector;
	detail::Worker worker;

	/* Mode::Frames: the odd frames' detector and the worker's round; the
	 * caller's last result not yet returned; frames pushed. */
	std::unique_ptr<Detector> second;
	struct WholeFrame {
		Impl *self;
		ImageView image;
		const Result *result = nullptr;
		void operator()()
		{
			try {
				result = &self->second->detect(image);
			} catch (...) {
				self->failure = std::current_exception();
			}
		}
	} whole{ this, {} };
	bool workerBusy = false;
	const Result *held = nullptr;
	long pushed = 0;
	const Result *pushFrames(const ImageView &image);
	const Result *waitWorker();
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

Pipeline::Pipeline(const Config &config, Mode mode) : impl_(std::make_unique<Impl>(config, mode)) {}

Pipeline::~Pipeline() = default;

const Result *Pipeline::Impl::waitWorker()
{
	worker.wait();
	workerBusy = false;
	if (failure)
		std::rethrow_exception(std::exchange(failure, nullptr));
	return whole.result;
}

const Result *Pipeline::Impl::pushFrames(const ImageView &image)
{
	if (pushed++ % 2 == 1) {
		/* Odd: to the worker, which runs on after we return the even
		 * frame before it. */
		whole.image = image;
		worker.post(whole);
		workerBusy = true;
		return std::exchange(held, nullptr);
	}
	/* Even: here, while the worker finishes the odd frame before. */
	const Result *mine = nullptr;
	std::exception_ptr mineFailed;
	try {
		mine = &detector.detect(image);
	} catch (...) {
		mineFailed = std::current_exception();
	}
	if (mineFailed) { /* out of memory: this frame is lost, not the one before */
		if (workerBusy)
			held = waitWorker();
		std::rethrow_exception(mineFailed);
	}
	held = mine;
	return workerBusy ? waitWorker() : nullptr;
}

const Result *Pipeline::push(const ImageView &image)
{
	Impl &d = *impl_;
	d.detector.checkImage(image);
	if (d.mode == Mode::Frames)
		return d.pushFrames(image);

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
	if (d.mode == Mode::Frames) {
		if (d.held)
			return std::exchange(d.held, nullptr);
		return d.workerBusy ? d.waitWorker() : nullptr;
	}
	if (d.count == 0)
		return nullptr;
	const Impl::Frame oldest = d.frames[0];
	d.pop();
	if (!oldest.traced)
		d.detector.runTrace(oldest.slot);
	return &d.detector.runFinish(oldest.image, oldest.slot);
}

bool Pipeline::pending() const
{
	return impl_->mode == Mode::Frames ? impl_->held || impl_->workerBusy : impl_->count > 0;
}

int Pipeline::latency() const { return impl_->mode == Mode::Frames ? 1 : 2; }
Detector &Pipeline::detector() { return impl_->detector; }

} // namespace frappe
