// SPDX-License-Identifier: MIT
// The pipelined mode: the front end of the next frame on a worker thread,
// the back end of the current one on the caller's.
#include "frappe/pipeline.h"

#include <exception>
#include <utility>

#include "worker.h"

namespace frappe {

struct Pipeline::Impl {
	explicit Impl(const Config &config) : detector(config) {}

	Detector detector;
	detail::Worker worker;
	/* The frame whose front end was started last, and its slot. */
	ImageView inFlight;
	int slot = 0;
	bool pending = false;

	/* What the worker runs; a member so that posting it allocates nothing. */
	struct FrontEndTask {
		Impl *self;
		void operator()() const
		{
			try {
				self->detector.runFrontEnd(self->inFlight, self->slot);
			} catch (...) {
				self->failure = std::current_exception();
			}
		}
	} frontEndTask{ this };
	std::exception_ptr failure;

	/* Waits for the worker and hands on what it threw (out of memory). */
	void join()
	{
		worker.wait();
		if (failure) {
			pending = false;
			std::rethrow_exception(std::exchange(failure, nullptr));
		}
	}
};

Pipeline::Pipeline(const Config &config) : impl_(std::make_unique<Impl>(config)) {}

Pipeline::~Pipeline()
{
	if (impl_->pending)
		impl_->worker.wait();
}

const Result *Pipeline::push(const ImageView &image)
{
	Impl &d = *impl_;
	d.detector.checkImage(image);
	if (!d.pending) {
		d.inFlight = image;
		d.worker.post(d.frontEndTask);
		d.pending = true;
		return nullptr;
	}
	/* Frame N's front end is done once the worker is idle; start N+1's in
	 * the other slot and trace N here meanwhile. */
	d.join();
	const ImageView previous = d.inFlight;
	const int previousSlot = d.slot;
	d.inFlight = image;
	d.slot ^= 1;
	d.worker.post(d.frontEndTask);
	return &d.detector.runBackEnd(previous, previousSlot);
}

const Result *Pipeline::flush()
{
	Impl &d = *impl_;
	if (!d.pending)
		return nullptr;
	d.join();
	d.pending = false;
	const Result *result = &d.detector.runBackEnd(d.inFlight, d.slot);
	d.slot ^= 1;
	return result;
}

bool Pipeline::pending() const { return impl_->pending; }
Detector &Pipeline::detector() { return impl_->detector; }

} // namespace frappe
