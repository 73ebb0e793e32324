// SPDX-License-Identifier: MIT
#include "worker.h"

#include <chrono>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace frappe::detail {

namespace {

/* How long either side polls before it sleeps: about one hand-over's worth
 * of work in the pipelined mode. Zero on a single core (the Pi Zero), where
 * polling would only take time from the thread it waits for. */
std::chrono::microseconds spinBudget()
{
	static const std::chrono::microseconds budget{ std::thread::hardware_concurrency() > 1 ? 100 : 0 };
	return budget;
}

void relax()
{
#if defined(__x86_64__) || defined(__i386__)
	_mm_pause();
#elif defined(__aarch64__) || (defined(__ARM_ARCH) && __ARM_ARCH >= 7)
	asm volatile("yield");
#endif
}

/* Polls `done` until it returns true or the spin budget runs out. */
template<typename F>
bool spinUntil(F done)
{
	const auto budget = spinBudget();
	if (budget.count() == 0)
		return done();
	const auto end = std::chrono::steady_clock::now() + budget;
	for (;;) {
		for (int i = 0; i < 64; ++i) {
			if (done())
				return true;
			relax();
		}
		if (std::chrono::steady_clock::now() >= end)
			return done();
	}
}

} // namespace

Worker::Worker() : thread_([this] { loop(); }) {}

Worker::~Worker()
{
	{
		std::lock_guard<std::mutex> guard(lock_);
		quit_ = true;
	}
	wake_.notify_one();
	thread_.join();
}

void Worker::post(TaskRef task)
{
	bool asleep;
	{
		std::lock_guard<std::mutex> guard(lock_);
		task_ = task;
		busy_ = true;
		busyFlag_.store(true, std::memory_order_release);
		asleep = workerAsleep_;
	}
	if (asleep)
		wake_.notify_one();
}

void Worker::wait()
{
	if (spinUntil([this] { return !busyFlag_.load(std::memory_order_acquire); }))
		return;
	std::unique_lock<std::mutex> guard(lock_);
	waiterAsleep_ = true;
	done_.wait(guard, [this] { return !busy_; });
	waiterAsleep_ = false;
}

void Worker::loop()
{
	for (;;) {
		/* In a stream the next task follows soon after the last one. */
		spinUntil([this] { return busyFlag_.load(std::memory_order_acquire); });
		std::unique_lock<std::mutex> guard(lock_);
		workerAsleep_ = true;
		wake_.wait(guard, [this] { return quit_ || (busy_ && task_); });
		workerAsleep_ = false;
		if (quit_)
			return;
		const TaskRef task = task_;
		guard.unlock();
		task();
		guard.lock();
		task_ = {};
		busy_ = false;
		busyFlag_.store(false, std::memory_order_release);
		const bool waiterAsleep = waiterAsleep_;
		guard.unlock();
		if (waiterAsleep)
			done_.notify_all();
	}
}

void WorkerPool::ensure(int workers)
{
	/* Threads are made once, on the first frame that needs them. */
	while (static_cast<int>(workers_.size()) < workers)
		workers_.push_back(std::make_unique<Worker>());
}

} // namespace frappe::detail
