// SPDX-License-Identifier: MIT
// Two threads over a stream. Stages: each call runs the front end of the new
// frame and the finish (refine, warp, decode) of the oldest on the worker,
// while the caller traces the frame in between. Frames: whole frames from a
// queue, taken by a worker with its own detector as soon as it is free, and
// by the caller only when it must return a frame that nobody has started.
#include "frappe/pipeline.h"

#include <condition_variable>
#include <exception>
#include <mutex>
#include <utility>

#include "worker.h"

namespace frappe {

namespace detail {

/// Mode::Frames. Frames wait in a ring; the worker drains it with its own
/// detector and runs on after push() returns; the caller runs a frame only
/// when the result it must return belongs to a frame nobody has started.
/// Results come out kLatency frames late, in order; each frame's Result is
/// copied into the ring (its vectors keep their capacity, so nothing is
/// allocated once warm) and swapped out to `returned_`.
class FrameQueue
{
public:
	static constexpr int kLatency = 2;

	FrameQueue(const Config &config, Detector &mine, Worker &worker)
		: mine_(mine), theirs_(config), worker_(worker)
	{
	}
	~FrameQueue()
	{
		{
			std::lock_guard<std::mutex> guard(lock_);
			stopping_ = true; /* the worker takes no new frame */
		}
		worker_.wait(); /* returns at once when nothing was posted */
	}

	const Result *push(const ImageView &image)
	{
		bool start = false;
		{
			std::lock_guard<std::mutex> guard(lock_);
			Entry &e = ring_[(head_ + count_) % kRing];
			e.image = image;
			e.state = State::Waiting;
			++count_;
			if (!draining_) {
				draining_ = true;
				start = true;
			}
		}
		if (start) {
			worker_.wait(); /* its last drain has returned or is returning */
			worker_.post(drain_);
		}
		return count_ > kLatency ? pop(kLatency) : nullptr;
	}

	/* The oldest frame's result once more than `keep` frames are in
	 * flight; runs waiting frames here rather than wait idle. */
	const Result *pop(int keep)
	{
		std::unique_lock<std::mutex> guard(lock_);
		if (count_ <= keep)
			return nullptr;
		Entry &oldest = ring_[head_];
		while (oldest.state != State::Done) {
			Entry *next = nextWaiting();
			if (!next) {
				done_.wait(guard, [&] { return oldest.state == State::Done; });
				break;
			}
			next->state = State::Running;
			guard.unlock();
			run(mine_, *next);
			guard.lock();
		}
		std::swap(returned_, oldest.result);
		head_ = (head_ + 1) % kRing;
		--count_;
		if (failure_)
			std::rethrow_exception(std::exchange(failure_, nullptr));
		return &returned_;
	}

	bool pending() const
	{
		std::lock_guard<std::mutex> guard(lock_);
		return count_ > 0;
	}

private:
	enum class State { Waiting, Running, Done };
	struct Entry {
		ImageView image;
		Result result;
		State state = State::Done;
	};
	static constexpr int kRing = kLatency + 1;

	/* The oldest frame nobody has started; lock held. */
	Entry *nextWaiting()
	{
		for (int i = 0; i < count_; ++i) {
			Entry &e = ring_[(head_ + i) % kRing];
			if (e.state == State::Waiting)
				return &e;
		}
		return nullptr;
	}

	/* Runs one frame, lock not held; a frame that fails (out of memory)
	 * comes out with no markers and the error is thrown by the pop. */
	void run(Detector &detector, Entry &e)
	{
		std::exception_ptr failed;
		try {
			e.result = detector.detect(e.image);
		} catch (...) {
			failed = std::current_exception();
		}
		std::lock_guard<std::mutex> guard(lock_);
		if (failed) {
			e.result.markers.clear();
			failure_ = failed;
		}
		e.state = State::Done;
		done_.notify_all();
	}

	/* The worker's task: frames until none waits. */
	struct Drain {
		FrameQueue *q;
		void operator()() const
		{
			std::unique_lock<std::mutex> guard(q->lock_);
			for (;;) {
				Entry *e = q->stopping_ ? nullptr : q->nextWaiting();
				if (!e) {
					q->draining_ = false;
					return;
				}
				e->state = State::Running;
				guard.unlock();
				q->run(q->theirs_, *e);
				guard.lock();
			}
		}
	} drain_{ this };

	Detector &mine_;
	Detector theirs_;
	Worker &worker_;
	mutable std::mutex lock_;
	std::condition_variable done_;
	Entry ring_[kRing];
	int head_ = 0, count_ = 0;
	bool draining_ = false, stopping_ = false;
	std::exception_ptr failure_;
	Result returned_;
};

} // namespace detail

struct FRAPPE_HIDDEN Pipeline::Impl {
	Impl(const Config &config, Mode mode) : detector(config)
	{
		if (mode == Mode::Frames)
			frameQueue = std::make_unique<detail::FrameQueue>(config, detector, worker);
	}
	~Impl()
	{
		/* Before the worker and the detectors it uses go. */
		frameQueue.reset();
	}

	struct Frame {
		ImageView image;
		int slot = 0;
		bool traced = false;
	};

	Detector detector;
	detail::Worker worker;

	/* Mode::Frames */
	std::unique_ptr<detail::FrameQueue> frameQueue;

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

const Result *Pipeline::push(const ImageView &image)
{
	Impl &d = *impl_;
	d.detector.checkImage(image);
	if (d.frameQueue)
		return d.frameQueue->push(image);

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
	if (d.frameQueue)
		return d.frameQueue->pop(0);
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
	return impl_->frameQueue ? impl_->frameQueue->pending() : impl_->count > 0;
}

int Pipeline::latency() const { return impl_->frameQueue ? detail::FrameQueue::kLatency : 2; }
Detector &Pipeline::detector() { return impl_->detector; }

} // namespace frappe
