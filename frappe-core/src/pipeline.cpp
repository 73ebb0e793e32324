// SPDX-License-Identifier: MIT
// Two threads over a stream. Stages: each call runs the front end of the new
// frame and the finish (refine, warp, decode) of the oldest on the worker,
// while the caller traces the frame in between. Frames: whole frames, each
// to a second detector on the worker when it is free (it runs on after
// push() returns), else to the caller's.
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
		/* The worker may still be on a frame, with `second`. */
		if (onWorker)
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

	/* Mode::Frames: up to three frames in flight in a ring, oldest at
	 * `head`. A new frame goes to the worker's detector when the worker is
	 * free, else it runs here on `detector`; so a slow frame on one side is
	 * made up by the other taking the next ones. Results are copied into
	 * the frame's own Result (its vectors keep their capacity), and the
	 * returned one is swapped out to `returned`. */
	std::unique_ptr<Detector> second;
	struct InFlight {
		ImageView image;
		Result result;
		bool done = false;
	};
	static constexpr int kInFlight = 3;
	InFlight ring[kInFlight];
	int head = 0, inFlight = 0;
	InFlight *onWorker = nullptr;
	Result returned;
	struct WholeFrame {
		Impl *self;
		void operator()()
		{
			InFlight &f = *self->onWorker;
			try {
				f.result = self->second->detect(f.image);
			} catch (...) {
				f.result = Result{};
				self->failure = std::current_exception();
			}
		}
	} whole{ this };
	const Result *pushFrames(const ImageView &image);
	const Result *popFrames();
	void collectWorker();

	/* Mode::Stages: frames in flight, oldest first; at most one traced and
	 * one not. */
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

/* Waits for the worker's frame, if any, and marks it done. */
void Pipeline::Impl::collectWorker()
{
	if (!onWorker)
		return;
	worker.wait();
	onWorker->done = true;
	onWorker = nullptr;
	if (failure) /* that frame comes out with no markers */
		std::rethrow_exception(std::exchange(failure, nullptr));
}

/* The oldest frame's result, waiting for it when the worker has it. */
const Result *Pipeline::Impl::popFrames()
{
	if (inFlight == 0)
		return nullptr;
	InFlight &oldest = ring[head];
	if (!oldest.done)
		collectWorker();
	std::swap(returned, oldest.result);
	oldest.done = false;
	head = (head + 1) % kInFlight;
	--inFlight;
	return &returned;
}

const Result *Pipeline::Impl::pushFrames(const ImageView &image)
{
	if (onWorker && worker.finished())
		collectWorker();
	InFlight &fresh = ring[(head + inFlight) % kInFlight];
	fresh.image = image;
	fresh.done = false;
	++inFlight;
	if (!onWorker) {
		onWorker = &fresh;
		worker.post(whole);
	} else {
		try {
			fresh.result = detector.detect(image);
		} catch (...) { /* out of memory: this frame is lost, not the others */
			--inFlight;
			throw;
		}
		fresh.done = true;
	}
	return inFlight > 2 ? popFrames() : nullptr;
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
	if (d.mode == Mode::Frames)
		return d.popFrames();
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
	return impl_->mode == Mode::Frames ? impl_->inFlight > 0 : impl_->count > 0;
}

int Pipeline::latency() const { return 2; }
Detector &Pipeline::detector() { return impl_->detector; }

} // namespace frappe
