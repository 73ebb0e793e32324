// SPDX-License-Identifier: MIT
// Frames over several threads, results in order. Frames: whole frames from
// a ring, each taken by an idle worker with its own detector as soon as it
// is pushed, and by the caller only when it must return a frame nobody has
// started. Stages: each call runs the front end of the new frame on the
// worker while the caller traces the frame before it; the finish (refine,
// warp, decode) of the oldest runs after the front end on the worker
// (latency 2) or after the trace on the caller (latency 1).
#include "frappe/pipeline.h"

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "detector_stages.h"
#include "worker.h"

namespace frappe {

namespace detail {

namespace {

/* config.threads as a thread count: 0 is one per core. The detectors are
 * made with one thread each, so the range is checked here. */
int threadCount(const Config &config)
{
	if (config.threads < 0 || config.threads > 256)
		throw std::invalid_argument("frappe::Config: threads must be in [0, 256], got " +
					    std::to_string(config.threads));
	if (config.threads > 0)
		return config.threads;
	return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

} // namespace

/// Overlap::Frames. Frames wait in a ring of latency + 1 entries (a frame
/// in flight beyond those `threads` run gives a thread slack to start the
/// next while the caller waits for a slow one); each idle
/// worker drains it with its own detector and runs on after push() returns;
/// the caller runs a frame only when the result it must return belongs to
/// a frame nobody has started. Each frame's Result is copied into the ring
/// (its vectors keep their capacity, so nothing is allocated once warm) and
/// swapped out to `returned_`.
class FrameQueue
{
public:
	FrameQueue(const Config &config, int threads, int latency)
		: latency_(latency), ring_(static_cast<std::size_t>(latency) + 1)
	{
		Config single = config;
		single.threads = 1; /* the threads are here, not in the bands */
		for (int i = 0; i < threads; ++i)
			detectors_.push_back(std::make_unique<Detector>(single));
		for (int i = 1; i < threads; ++i)
			helpers_.push_back(std::make_unique<Helper>(this, *detectors_[static_cast<std::size_t>(i)]));
	}
	~FrameQueue()
	{
		stopHelpers(); /* before the detectors they use go */
	}

	const Result *push(const ImageView &image)
	{
		Helper *start = nullptr;
		{
			std::lock_guard<std::mutex> guard(lock_);
			Entry &e = at(count_);
			e.image = image;
			e.state = State::Waiting;
			++count_;
			for (auto &h : helpers_) {
				if (!h->draining) {
					h->draining = true;
					start = h.get();
					break;
				}
			}
		}
		if (start) {
			start->worker.wait(); /* its last drain has returned or is returning */
			start->worker.post(*start);
		}
		return pop(latency_);
	}

	/* The oldest frame's result once more than `keep` frames are in
	 * flight; runs waiting frames here rather than wait idle. */
	const Result *pop(int keep)
	{
		std::unique_lock<std::mutex> guard(lock_);
		if (count_ <= keep)
			return nullptr;
		Entry &oldest = at(0);
		while (oldest.state != State::Done) {
			Entry *next = nextWaiting();
			if (!next) {
				done_.wait(guard, [&] { return oldest.state == State::Done; });
				break;
			}
			next->state = State::Running;
			guard.unlock();
			run(*detectors_[0], *next);
			guard.lock();
		}
		std::swap(returned_, oldest.result);
		const std::exception_ptr failed = std::exchange(oldest.failure, nullptr);
		head_ = (head_ + 1) % ring_.size();
		--count_;
		if (failed)
			std::rethrow_exception(failed);
		return &returned_;
	}

	void drop()
	{
		stopHelpers();
		std::lock_guard<std::mutex> guard(lock_);
		for (Entry &e : ring_)
			e.failure = nullptr;
		head_ = 0;
		count_ = 0;
		stopping_ = false;
	}

	bool pending() const
	{
		std::lock_guard<std::mutex> guard(lock_);
		return count_ > 0;
	}

	int latency() const { return latency_; }
	int detectorCount() const { return static_cast<int>(detectors_.size()); }
	Detector &detector(int index) { return *detectors_.at(static_cast<std::size_t>(index)); }

private:
	enum class State { Waiting, Running, Done };
	struct Entry {
		ImageView image;
		Result result;
		State state = State::Done;
		std::exception_ptr failure; /* thrown when the entry is popped */
	};

	/* A worker thread with its detector; the task it runs drains the ring
	 * until no frame waits. */
	struct Helper {
		Helper(FrameQueue *queue, Detector &det) : q(queue), detector(det) {}
		void operator()()
		{
			std::unique_lock<std::mutex> guard(q->lock_);
			for (;;) {
				Entry *e = q->stopping_ ? nullptr : q->nextWaiting();
				if (!e) {
					draining = false;
					return;
				}
				e->state = State::Running;
				guard.unlock();
				q->run(detector, *e);
				guard.lock();
			}
		}
		FrameQueue *q;
		Detector &detector;
		bool draining = false; /* under the queue's lock */
		Worker worker;
	};

	Entry &at(int i) { return ring_[(head_ + static_cast<std::size_t>(i)) % ring_.size()]; }

	/* The oldest frame nobody has started; lock held. */
	Entry *nextWaiting()
	{
		for (int i = 0; i < count_; ++i)
			if (at(i).state == State::Waiting)
				return &at(i);
		return nullptr;
	}

	/* Runs one frame, lock not held; a frame that fails (out of memory)
	 * keeps its exception for its pop. */
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
			e.failure = failed;
		}
		e.state = State::Done;
		done_.notify_all();
	}

	/* Lets the helpers finish the frames they run and take no new one. */
	void stopHelpers()
	{
		{
			std::lock_guard<std::mutex> guard(lock_);
			stopping_ = true;
		}
		for (auto &h : helpers_)
			h->worker.wait(); /* at once when nothing was posted */
	}

	const int latency_;
	std::vector<std::unique_ptr<Detector>> detectors_; /* [0]: the caller's */
	mutable std::mutex lock_;
	std::condition_variable done_;
	std::vector<Entry> ring_;
	std::size_t head_ = 0;
	int count_ = 0;
	bool stopping_ = false;
	Result returned_;
	std::vector<std::unique_ptr<Helper>> helpers_; /* last: they go first */
};

/// Overlap::Stages. One detector, each frame in a slot of its own, oldest
/// first. Latency 2: each push runs the new frame's front end and then the
/// finish (refine, warp, decode) of the oldest on the worker while the
/// caller traces the frame in between. Latency 1: the worker runs the new
/// frame's front end while the caller traces the frame before it, then the
/// caller finishes that frame once the front end is done (a QPU front end
/// and the QPU warp share one device, which never runs two launches at
/// once). A stage that throws fails its own frame, which skips its later
/// stages and throws when it would be returned; the others go on.
class StageQueue
{
public:
	StageQueue(const Config &config, int latency) : latency_(latency), detector_(config) {}
	~StageQueue() { worker_.wait(); }

	const Result *push(const ImageView &image)
	{
		frames_[count_] = { image, freeSlot(), false, nullptr };
		Frame &fresh = frames_[count_];
		/* The frame the caller traces: the newest one before `fresh`
		 * not yet traced. */
		Frame *toTrace = nullptr;
		for (int i = 0; i < count_; ++i)
			if (!frames_[i].traced)
				toTrace = &frames_[i];
		Frame *oldest = count_ > 0 ? &frames_[0] : nullptr;
		++count_;

		round_.start = &fresh;
		round_.finish = latency_ == 2 && oldest && oldest->traced ? oldest : nullptr;
		round_.finished = nullptr;
		worker_.post(round_);
		if (toTrace)
			trace(*toTrace);
		worker_.wait();
		if (latency_ == 2) {
			if (!round_.finish)
				return nullptr;
			return popOldest(round_.finished);
		}
		if (count_ <= latency_)
			return nullptr;
		return popOldest(finish(frames_[0]));
	}

	const Result *flush()
	{
		if (count_ == 0)
			return nullptr;
		Frame &oldest = frames_[0];
		if (!oldest.traced)
			trace(oldest);
		return popOldest(finish(oldest));
	}

	/* push() returns only once its round has, so nothing runs here. */
	void drop() { count_ = 0; }
	bool pending() const { return count_ > 0; }
	int latency() const { return latency_; }
	Detector &detector() { return detector_; }

private:
	struct Frame {
		ImageView image;
		int slot = 0;
		bool traced = false;
		std::exception_ptr failure; /* thrown when the frame is returned */
	};

	/* The worker's round: the new frame's front end, then (latency 2) the
	 * oldest frame's finish when there is one. A member, so posting it
	 * allocates nothing. */
	struct Round {
		StageQueue *self;
		Frame *start = nullptr;
		Frame *finish = nullptr;
		const Result *finished = nullptr;
		void operator()()
		{
			try {
				DetectorStages::frontEnd(self->detector_, start->image, start->slot);
			} catch (...) {
				start->failure = std::current_exception();
			}
			if (finish)
				finished = self->finish(*finish);
		}
	};

	void trace(Frame &f)
	{
		if (!f.failure) {
			try {
				DetectorStages::trace(detector_, f.slot);
			} catch (...) {
				f.failure = std::current_exception();
			}
		}
		f.traced = true;
	}

	/* The frame's result, or nullptr when a stage failed it. */
	const Result *finish(Frame &f)
	{
		if (f.failure)
			return nullptr;
		try {
			return &DetectorStages::finish(detector_, f.image, f.slot);
		} catch (...) {
			f.failure = std::current_exception();
			return nullptr;
		}
	}

	int freeSlot() const
	{
		for (int s = 0; s < DetectorStages::kSlots; ++s) {
			bool used = false;
			for (int i = 0; i < count_; ++i)
				used |= frames_[i].slot == s;
			if (!used)
				return s;
		}
		return 0; /* not reached: at most kSlots - 1 frames wait */
	}

	/* Takes the oldest frame out; returns its result or throws its failure. */
	const Result *popOldest(const Result *result)
	{
		std::exception_ptr failed = std::exchange(frames_[0].failure, nullptr);
		for (int i = 1; i < count_; ++i)
			frames_[i - 1] = std::move(frames_[i]);
		frames_[count_ - 1].failure = nullptr;
		--count_;
		if (failed)
			std::rethrow_exception(failed);
		return result;
	}

	const int latency_;
	Detector detector_;
	Frame frames_[DetectorStages::kSlots];
	int count_ = 0;
	Round round_{ this };
	Worker worker_; /* last: it goes first */
};

} // namespace detail

struct FRAPPE_HIDDEN Pipeline::Impl {
	std::unique_ptr<detail::FrameQueue> frames; /* Overlap::Frames */
	std::unique_ptr<detail::StageQueue> stages; /* Overlap::Stages */
};

Pipeline::Pipeline(const Config &config, Overlap mode, int latency) : impl_(std::make_unique<Impl>())
{
	auto fail = [](const std::string &what) { throw std::invalid_argument("frappe::Pipeline: " + what); };
	if (mode == Overlap::Stages) {
		if (latency == kDefaultLatency)
			latency = 2;
		if (latency != 1 && latency != 2)
			fail("Overlap::Stages has a latency of 1 or 2, not " + std::to_string(latency));
		impl_->stages = std::make_unique<detail::StageQueue>(config, latency);
		return;
	}
	const int threads = detail::threadCount(config);
	if (latency == kDefaultLatency)
		latency = threads > 1 ? threads : 0;
	if (latency < 0 || latency > 256)
		fail("latency must be in [0, 256], got " + std::to_string(latency));
	impl_->frames = std::make_unique<detail::FrameQueue>(config, threads, latency);
}

Pipeline::~Pipeline() = default;

const Result *Pipeline::push(const ImageView &image)
{
	Impl &d = *impl_;
	detector().checkImage(image);
	return d.frames ? d.frames->push(image) : d.stages->push(image);
}

const Result *Pipeline::flush()
{
	Impl &d = *impl_;
	return d.frames ? d.frames->pop(0) : d.stages->flush();
}

void Pipeline::drop()
{
	Impl &d = *impl_;
	if (d.frames)
		d.frames->drop();
	else
		d.stages->drop();
}

void Pipeline::reset()
{
	for (int i = 0; i < detectorCount(); ++i)
		detector(i).reset();
}

bool Pipeline::pending() const
{
	return impl_->frames ? impl_->frames->pending() : impl_->stages->pending();
}

int Pipeline::latency() const
{
	return impl_->frames ? impl_->frames->latency() : impl_->stages->latency();
}

int Pipeline::threads() const { return impl_->frames ? impl_->frames->detectorCount() : 2; }

int Pipeline::detectorCount() const { return impl_->frames ? impl_->frames->detectorCount() : 1; }

Detector &Pipeline::detector(int index)
{
	Impl &d = *impl_;
	if (d.frames)
		return d.frames->detector(index);
	if (index != 0)
		throw std::out_of_range("frappe::Pipeline: one detector in Overlap::Stages");
	return d.stages->detector();
}

} // namespace frappe
