// SPDX-License-Identifier: MIT
#include "model/zero_model.hpp"

#include <algorithm>
#include <deque>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <stdexcept>

namespace frappe::vc4::model {

Assumptions piZero()
{
	Assumptions a;
	a.cpi = { 1.2, 1.6, 2.5, "cycles/instruction",
		  "ARM1176JZF-S: single issue, so 1.0 at best; the one public PMU measurement on this core "
		  "(P. Drongowski, sandsoftwaresound.net, rpistat on a Pi 1) gave 9.5 for a cache-thrashing "
		  "matrix multiply, and its loop-interchanged form ran 2.7x faster (about 3.5); frappe's stages "
		  "stream rows and stay mostly in the 16 KB D-cache: 1.2-2.5, 1.6 central (uncalibrated)" };
	a.arm_hz = { 1e9, 1e9, 1e9, "Hz", "Pi Zero: arm_freq 1000 (raspberrypi/documentation, config.txt)" };
	a.v3d_hz = { 300e6, 250e6, 250e6, "Hz",
		     "v3d_freq: 250 MHz as the README's QPU figures and the paper's 24 GFLOPS; the firmware's "
		     "default for the Zero is 300 (fast end); vc4-probe reports the real one" };
	a.dram_bytes_s = { 3.0e9, 2.5e9, 1.8e9, "bytes/s",
			   "paper, footnote 3: LPDDR2 32 bit at 450 MHz is 3.6 GB/s peak, a VPU block read "
			   "reached 2.5 GB/s; shared with the ARM and the ISP (slow end)" };
	a.mailbox_s = { 50e-6, 100e-6, 150e-6, "s",
			"GPU_FFT (A. Holme, hello_fft/gpu_fft.txt): execute_qpu through the mailbox ioctl "
			"\"adds 100us overhead\" a call; the ARM sleeps in it" };
	a.launch_cpu_s = { 5e-6, 10e-6, 20e-6, "s", "estimate: one ioctl and a 12-job message on the ARM" };
	a.copy_bytes_s = { 500e6, 300e6, 200e6, "bytes/s",
			   "estimate: memcpy on a 1 GHz ARM1176 with LPDDR2, no published figure found" };
	a.sync_cycles = { 4, 6, 10, "cycles/line",
			  "Linux's ARMv6 cache maintenance by range: one MCR and a 3-instruction loop per "
			  "32-byte line (arch/arm/mm/cache-v6.S), more when the line is dirty" };
	return a;
}

const char *overlapName(Overlap o)
{
	return o == Overlap::Stages ? "staged" : o == Overlap::Frames ? "whole frames" : "unpipelined";
}

namespace {

struct Seg {
	bool gpu = false;
	double t = 0;
};
using Segs = std::vector<Seg>;

/* Seconds of the ARM for `insns` instructions. */
double cpuSeconds(double insns, const Assumptions &a, End e) { return insns * a.value(a.cpi, e) / a.value(a.arm_hz, e); }

double syncSeconds(uint64_t bytes, const Assumptions &a, End e)
{
	return static_cast<double>((bytes + 31) / 32) * a.value(a.sync_cycles, e) / a.value(a.arm_hz, e);
}

/* A launch: the ARM's part and the sync before (END), the run (the slower of the QPUs'
 * instructions and DRAM) with the mailbox round trip, the sync after (START). */
void addLaunch(Segs &s, const Launch &l, const Assumptions &a, End e)
{
	const double sync = syncSeconds(l.sync_bytes, a, e);
	s.push_back({ false, a.value(a.launch_cpu_s, e) + sync });
	const double run = std::max(static_cast<double>(l.cycles) / a.value(a.v3d_hz, e),
				    static_cast<double>(l.dram_bytes) / a.value(a.dram_bytes_s, e));
	s.push_back({ true, a.value(a.mailbox_s, e) + run });
	s.push_back({ false, sync });
}

Segs frontSegs(const FrameWork &f, const Assumptions &a, End e)
{
	Segs s{ { false, cpuSeconds(static_cast<double>(f.front_insns), a, e) } };
	for (const Launch &l : f.front_launches)
		addLaunch(s, l, a, e);
	s.push_back({ false, static_cast<double>(f.copy_bytes) / a.value(a.copy_bytes_s, e) });
	return s;
}

Segs traceSegs(const FrameWork &f, const Assumptions &a, End e)
{
	return { { false, cpuSeconds(static_cast<double>(f.trace_insns), a, e) } };
}

Segs finishSegs(const FrameWork &f, const Assumptions &a, End e)
{
	Segs s{ { false, cpuSeconds(static_cast<double>(f.finish_insns), a, e) } };
	for (const Launch &l : f.warp_launches)
		addLaunch(s, l, a, e);
	return s;
}

Segs concat(Segs a, const Segs &b)
{
	a.insert(a.end(), b.begin(), b.end());
	return a;
}

/* Flows of segments on one ARM core, shared evenly by the flows at a CPU segment, and one
 * GPU taking the flows at a GPU segment one at a time, first come first served. */
class Engine
{
public:
	using Done = std::function<void()>;

	void start(Segs segs, Done done)
	{
		flows_.push_back({ std::move(segs), 0, 0, std::move(done) });
		enter(std::prev(flows_.end()));
	}

	/* Calls `what` at time `when` (not before now). */
	void at(double when, Done what) { timers_.emplace(std::max(when, now_), std::move(what)); }

	void run()
	{
		while (!flows_.empty() || !timers_.empty()) {
			if (flows_.empty() || (!timers_.empty() && timers_.begin()->first <= now_)) {
				/* Nothing runs until the next timer, or one is due. */
				auto next = timers_.begin();
				if (next->first > now_)
					now_ = next->first;
				Done what = std::move(next->second);
				timers_.erase(next);
				what();
				continue;
			}
			int cpu = 0;
			double step = -1;
			for (auto it = flows_.begin(); it != flows_.end(); ++it)
				if (!it->segs[it->k].gpu)
					++cpu;
			for (auto it = flows_.begin(); it != flows_.end(); ++it) {
				if (!it->segs[it->k].gpu) {
					const double t = it->left * cpu;
					step = step < 0 ? t : std::min(step, t);
				}
			}
			if (!gpuQueue_.empty())
				step = step < 0 ? gpuQueue_.front()->left : std::min(step, gpuQueue_.front()->left);
			if (step < 0)
				throw std::logic_error("model: flows without work");
			if (!timers_.empty())
				step = std::min(step, timers_.begin()->first - now_);
			now_ += step;
			if (cpu > 0)
				cpuBusy_ += step;
			if (!gpuQueue_.empty()) {
				gpuBusy_ += step;
				gpuQueue_.front()->left -= step;
			}
			for (auto &f : flows_)
				if (!f.segs[f.k].gpu)
					f.left -= step / cpu;
			/* Segments that ended move their flows on (finished flows call back, which may
			 * start others). */
			constexpr double kEps = 1e-15;
			for (auto it = flows_.begin(); it != flows_.end();) {
				const bool onGpu = it->segs[it->k].gpu;
				const bool served = !onGpu || (!gpuQueue_.empty() && gpuQueue_.front() == it);
				if (served && it->left <= kEps) {
					if (onGpu)
						gpuQueue_.pop_front();
					++it->k;
					auto cur = it++;
					enter(cur);
				} else {
					++it;
				}
			}
		}
	}

	double now() const { return now_; }
	double cpuBusy() const { return cpuBusy_; }
	double gpuBusy() const { return gpuBusy_; }

private:
	struct Flow {
		Segs segs;
		std::size_t k;
		double left;
		Done done;
	};
	using It = std::list<Flow>::iterator;

	/* The flow at segment k: skips empty segments, queues for the GPU, or ends. */
	void enter(It it)
	{
		while (it->k < it->segs.size() && it->segs[it->k].t <= 0)
			++it->k;
		if (it->k == it->segs.size()) {
			Done done = std::move(it->done);
			flows_.erase(it);
			if (done)
				done();
			return;
		}
		it->left = it->segs[it->k].t;
		if (it->segs[it->k].gpu)
			gpuQueue_.push_back(it);
	}

	std::list<Flow> flows_;
	std::deque<It> gpuQueue_;
	std::multimap<double, Done> timers_;
	double now_ = 0, cpuBusy_ = 0, gpuBusy_ = 0;
};

} // namespace

Timeline simulate(const std::vector<FrameWork> &frames, Overlap overlap, const Assumptions &a, End e, double period)
{
	const std::size_t n = frames.size();
	Timeline t;
	t.in.assign(n, 0);
	t.out.assign(n, 0);
	if (n == 0)
		return t;
	Engine eng;
	std::vector<char> done(n, 0);
	std::function<void(std::size_t)> push, start;
	/* Frame i is captured at i * period and pushed once the element takes it. */
	auto next = [&](std::size_t i) {
		if (period > 0 && static_cast<double>(i) * period > eng.now())
			eng.at(static_cast<double>(i) * period, [&, i] { start(i); });
		else
			start(i);
	};
	/* Whole frames: the frame whose result the caller waits for, and what it does then
	 * (here, as the flows call back after this function's blocks). */
	std::size_t awaiting = n;
	std::function<void(std::size_t)> got, waitFor;

	if (overlap == Overlap::None) {
		push = [&](std::size_t i) {
			t.in[i] = eng.now();
			const FrameWork &f = frames[i];
			eng.start(concat(concat(frontSegs(f, a, e), traceSegs(f, a, e)), finishSegs(f, a, e)), [&, i] {
				t.out[i] = eng.now();
				if (i + 1 < n)
					next(i + 1);
			});
		};
	} else if (overlap == Overlap::Frames) {
		/* push(i) starts frame i and returns frame i-1's result once that is done, so
		 * frames i-1 and i run at once; the flush waits for the last. */
		waitFor = [&](std::size_t j) {
			if (done[j]) {
				t.out[j] = eng.now();
				got(j);
			} else {
				awaiting = j;
			}
		};
		got = [&](std::size_t j) {
			if (j + 2 < n)
				next(j + 2);
			else if (j + 1 < n)
				waitFor(j + 1);
		};
		push = [&](std::size_t i) {
			t.in[i] = eng.now();
			const FrameWork &f = frames[i];
			eng.start(concat(concat(frontSegs(f, a, e), traceSegs(f, a, e)), finishSegs(f, a, e)), [&, i] {
				done[i] = 1;
				if (awaiting == i) {
					awaiting = n;
					t.out[i] = eng.now();
					got(i);
				}
			});
			if (i == 0 && n > 1)
				next(1);
			else
				waitFor(i == 0 ? 0 : i - 1);
		};
	} else {
		/* push(i): the worker runs frame i's front end while the caller traces frame i-1;
		 * then the caller finishes frame i-1 and returns it. */
		push = [&](std::size_t i) {
			t.in[i] = eng.now();
			auto joined = std::make_shared<int>(i > 0 ? 2 : 1);
			auto bothDone = [&, i, joined] {
				if (--*joined > 0)
					return;
				if (i == 0) {
					if (n > 1)
						next(1);
					else
						eng.start(concat(traceSegs(frames[0], a, e), finishSegs(frames[0], a, e)),
							  [&] { t.out[0] = eng.now(); });
					return;
				}
				eng.start(finishSegs(frames[i - 1], a, e), [&, i] {
					t.out[i - 1] = eng.now();
					if (i + 1 < n) {
						next(i + 1);
					} else {
						/* flush: the last frame's trace and finish */
						eng.start(concat(traceSegs(frames[i], a, e), finishSegs(frames[i], a, e)),
							  [&, i] { t.out[i] = eng.now(); });
					}
				});
			};
			eng.start(frontSegs(frames[i], a, e), bothDone);
			if (i > 0)
				eng.start(traceSegs(frames[i - 1], a, e), bothDone);
		};
	}
	/* A frame's latency counts from its capture, its push may come later. */
	start = [&](std::size_t i) { push(i); };
	next(0);
	eng.run();
	if (period > 0)
		for (std::size_t i = 0; i < n; ++i)
			t.in[i] = static_cast<double>(i) * period;
	t.cpuBusy = eng.cpuBusy();
	t.gpuBusy = eng.gpuBusy();
	return t;
}

StageTimes stageTimes(const FrameWork &f, const Assumptions &a, End e)
{
	StageTimes s;
	s.front_cpu = cpuSeconds(static_cast<double>(f.front_insns), a, e);
	auto launches = [&](const std::vector<Launch> &ls, double &cpu, double &gpu) {
		for (const Launch &l : ls) {
			const double sync = 2 * syncSeconds(l.sync_bytes, a, e);
			cpu += a.value(a.launch_cpu_s, e) + sync;
			s.sync += sync;
			const double run = std::max(static_cast<double>(l.cycles) / a.value(a.v3d_hz, e),
						    static_cast<double>(l.dram_bytes) / a.value(a.dram_bytes_s, e));
			gpu += a.value(a.mailbox_s, e) + run;
			s.mailbox += a.value(a.mailbox_s, e);
		}
	};
	launches(f.front_launches, s.front_cpu, s.front_gpu);
	s.copies = static_cast<double>(f.copy_bytes) / a.value(a.copy_bytes_s, e);
	s.front_cpu += s.copies;
	s.trace = cpuSeconds(static_cast<double>(f.trace_insns), a, e);
	s.finish_cpu = cpuSeconds(static_cast<double>(f.finish_insns), a, e);
	launches(f.warp_launches, s.finish_cpu, s.warp_gpu);
	return s;
}

Summary summarise(const Timeline &t)
{
	Summary s;
	const std::size_t n = t.out.size();
	if (n == 0)
		return s;
	s.frame_time = n > 1 ? (t.out[n - 1] - t.out[0]) / static_cast<double>(n - 1) : t.out[0] - t.in[0];
	std::vector<double> lat(n);
	for (std::size_t i = 0; i < n; ++i)
		lat[i] = t.out[i] - t.in[i];
	std::sort(lat.begin(), lat.end());
	auto at = [&](double q) {
		const double pos = q * static_cast<double>(n - 1);
		const std::size_t lo = static_cast<std::size_t>(pos);
		const std::size_t hi = std::min(lo + 1, n - 1);
		return lat[lo] + (lat[hi] - lat[lo]) * (pos - static_cast<double>(lo));
	};
	s.latency_p50 = at(0.5);
	s.latency_p90 = at(0.9);
	s.latency_max = lat[n - 1];
	return s;
}

} // namespace frappe::vc4::model
