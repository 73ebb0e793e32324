// SPDX-License-Identifier: MIT
#include "worker.h"

namespace frappe::detail {

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
	{
		std::lock_guard<std::mutex> guard(lock_);
		task_ = task;
		busy_ = true;
	}
	wake_.notify_one();
}

void Worker::wait()
{
	std::unique_lock<std::mutex> guard(lock_);
	done_.wait(guard, [this] { return !busy_; });
}

void Worker::loop()
{
	std::unique_lock<std::mutex> guard(lock_);
	for (;;) {
		wake_.wait(guard, [this] { return quit_ || (busy_ && task_); });
		if (quit_)
			return;
		const TaskRef task = task_;
		guard.unlock();
		task();
		guard.lock();
		task_ = {};
		busy_ = false;
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
