/* SPDX-License-Identifier: MIT
 *
 * gstfrappeworker.h: frappedetect's pipelined mode: the buffer held between
 * its front end and its output, and the thread that runs its back end.
 */
#pragma once

#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include <gst/video/video.h>

#include <frappe/detector.h>

namespace frappe::gst {

/* One job at a time on a second thread: the back end of the held frame. */
class Worker
{
public:
	~Worker() { stop(); }

	void submit(std::function<void()> job);
	void wait();
	void stop();

private:
	void loop();

	std::mutex mutex_;
	std::condition_variable cv_;
	std::thread thread_;
	std::function<void()> job_;
	bool busy_ = false;
	bool quit_ = false;
};

/* A buffer between its front end and its output. */
struct InFlight {
	GstBuffer *buffer = nullptr;  /* writable, owned */
	GstVideoFrame frame{};        /* mapped until finished */
	bool writable = false;        /* mapped for annotation */
	int slot = 0;
	ImageView image;
	const Result *result = nullptr; /* set by the back end */
	std::string error;              /* set when the back end threw */

	/* Unmaps the frame and drops the buffer. */
	void discard();
};

} /* namespace frappe::gst */
