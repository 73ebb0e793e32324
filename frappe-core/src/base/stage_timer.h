// SPDX-License-Identifier: MIT
// StageTimer: the wall-clock time of a piece of the detector, added to the
// stage it belongs to.
#pragma once

#include <chrono>

#include "frappe/detector.h"

namespace frappe::detail {

/* Counts from its construction towards one stage of a frame's StageTimes
 * and adds what it counted when it goes out of scope, so that no early
 * return or `continue` leaves a stage untimed. lap() closes the count of
 * the current stage and goes on counting for another: reading a candidate
 * passes from refinement to warping to decoding and back without a scope
 * for each. Holds a reference and two words; allocates nothing. */
class StageTimer
{
public:
	using Clock = std::chrono::steady_clock;

	StageTimer(StageTimes &times, Stage stage)
		: times_(times), stage_(stage), start_(Clock::now())
	{
	}
	~StageTimer() { times_[stage_] += since(Clock::now()); }

	StageTimer(const StageTimer &) = delete;
	StageTimer &operator=(const StageTimer &) = delete;

	/* From now on the time counts towards `next`. */
	void lap(Stage next)
	{
		if (next == stage_)
			return;
		const Clock::time_point now = Clock::now();
		times_[stage_] += since(now);
		start_ = now;
		stage_ = next;
	}

private:
	double since(Clock::time_point now) const
	{
		return std::chrono::duration<double, std::milli>(now - start_).count();
	}

	StageTimes &times_;
	Stage stage_;
	Clock::time_point start_;
};

} // namespace frappe::detail
