// SPDX-License-Identifier: MIT
// Persistent worker threads for the front end's bands and the pipelined
// mode: started once per detector, handed work without allocating.
#pragma once

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

namespace frappe::detail {

/// A reference to a callable, valid while the callable lives (no copy, no
/// allocation): what a Worker runs.
class TaskRef
{
public:
	TaskRef() = default;
	template<typename F>
		requires(!std::is_same_v<std::remove_cv_t<F>, TaskRef>)
	TaskRef(F &f) : object_(&f), call_([](void *o) { (*static_cast<F *>(o))(); }) {}
	void operator()() const { call_(object_); }
	explicit operator bool() const { return call_ != nullptr; }

private:
	void *object_ = nullptr;
	void (*call_)(void *) = nullptr;
};

/// One thread that runs one posted task at a time.
class Worker
{
public:
	Worker();
	~Worker();
	Worker(const Worker &) = delete;
	Worker &operator=(const Worker &) = delete;

	/// Starts `task` on the worker; the previous task must have been waited for.
	void post(TaskRef task);
	/// Blocks until the posted task has finished.
	void wait();

private:
	void loop();

	std::mutex lock_;
	std::condition_variable wake_, done_;
	TaskRef task_;
	bool busy_ = false;
	bool quit_ = false;
	/* Who sleeps on a condition variable, so that the other side only
	 * notifies when someone is there to wake. */
	bool workerAsleep_ = false;
	bool waiterAsleep_ = false;
	/* busy_, readable without the lock: both sides poll it briefly before
	 * sleeping, because a wake-up through the kernel costs tens of
	 * microseconds on virtual machines, a noticeable share of a 1 ms frame. */
	std::atomic<bool> busyFlag_{ false };
	std::thread thread_;
};

/// Runs `count` numbered tasks on the calling thread and count-1 workers.
class WorkerPool
{
public:
	/// Runs body(i) for i in [0, count); task 0 on the calling thread.
	template<typename F>
	void run(int count, F &body)
	{
		ensure(count - 1);
		struct Task {
			F *body;
			int index;
			void operator()() const { (*body)(index); }
		};
		Task tasks[kMaxTasks];
		for (int i = 1; i < count; ++i) {
			tasks[i] = { &body, i };
			workers_[i - 1]->post(tasks[i]);
		}
		body(0);
		for (int i = 1; i < count; ++i)
			workers_[i - 1]->wait();
	}

	static constexpr int kMaxTasks = 64;

private:
	void ensure(int workers);
	std::vector<std::unique_ptr<Worker>> workers_;
};

} // namespace frappe::detail
