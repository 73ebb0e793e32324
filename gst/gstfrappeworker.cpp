/* SPDX-License-Identifier: MIT
 *
 * gstfrappeworker.cpp: frappedetect's pipelined mode.
 */
#include "gstfrappeworker.h"

#include <utility>

namespace frappe::gst {

void Worker::submit(std::function<void()> job)
{
	std::unique_lock lock(mutex_);
	if (!thread_.joinable())
		thread_ = std::thread([this] { loop(); });
	job_ = std::move(job);
	busy_ = true;
	cv_.notify_all();
}

void Worker::wait()
{
	std::unique_lock lock(mutex_);
	cv_.wait(lock, [this] { return !busy_; });
}

void Worker::stop()
{
	{
		std::unique_lock lock(mutex_);
		if (!thread_.joinable())
			return;
		cv_.wait(lock, [this] { return !busy_; });
		quit_ = true;
		cv_.notify_all();
	}
	thread_.join();
	quit_ = false;
}

void Worker::loop()
{
	std::unique_lock lock(mutex_);
	for (;;) {
		cv_.wait(lock, [this] { return quit_ || busy_; });
		if (busy_) {
			auto job = std::move(job_);
			lock.unlock();
			job();
			lock.lock();
			busy_ = false;
			cv_.notify_all();
			continue;
		}
		if (quit_)
			return;
	}
}

void InFlight::discard()
{
	gst_video_frame_unmap(&frame);
	gst_buffer_unref(buffer);
	buffer = nullptr;
}

} /* namespace frappe::gst */
