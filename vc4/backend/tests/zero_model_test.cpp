// SPDX-License-Identifier: MIT
// The Pi Zero model's arithmetic (model/zero_model.hpp): timelines worked out by hand for
// one ARM core shared by the threads with CPU work and one GPU taking launches in turn, in
// the element's three ways of driving the pipeline; the figures turned into times.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "model/zero_model.hpp"

using namespace frappe::vc4::model;

namespace {

/* 1 instruction = 1 ns, a launch of 250,000 cycles = 1 ms, nothing else costs. */
Assumptions unit()
{
	Assumptions a;
	auto flat = [](double v) { return Figure{ v, v, v }; };
	a.cpi = flat(1);
	a.arm_hz = flat(1e9);
	a.v3d_hz = flat(250e6);
	a.dram_bytes_s = flat(1e9);
	a.mailbox_s = flat(0);
	a.launch_cpu_s = flat(0);
	a.copy_bytes_s = flat(1e9);
	a.sync_cycles = flat(0);
	return a;
}

/* Front end: 1 ms on the ARM, then 2 ms of QPUs; trace 3 ms; finish 1 ms. */
FrameWork frame()
{
	FrameWork f;
	f.front_insns = 1'000'000;
	f.front_launches.push_back({ 500'000, 0, 0 });
	f.trace_insns = 3'000'000;
	f.finish_insns = 1'000'000;
	return f;
}

void expectTimes(const std::vector<double> &got, const std::vector<double> &wantMs, const char *what)
{
	ASSERT_EQ(got.size(), wantMs.size()) << what;
	for (std::size_t i = 0; i < got.size(); ++i)
		EXPECT_NEAR(got[i] * 1e3, wantMs[i], 1e-9) << what << " frame " << i;
}

} // namespace

TEST(ZeroModel, UnpipelinedFramesOneAfterAnother)
{
	const Timeline t = simulate(std::vector<FrameWork>(4, frame()), Overlap::None, unit(), End::Mid);
	expectTimes(t.in, { 0, 7, 14, 21 }, "in");
	expectTimes(t.out, { 7, 14, 21, 28 }, "out");
	const Summary s = summarise(t);
	EXPECT_NEAR(s.frame_time, 7e-3, 1e-12);
	EXPECT_NEAR(s.latency_p50, 7e-3, 1e-12);
	EXPECT_NEAR(t.cpuBusy, 20e-3, 1e-12); /* 5 ms of ARM a frame */
	EXPECT_NEAR(t.gpuBusy, 8e-3, 1e-12);
}

/* push(i): frame i's front end (1 ms ARM shared with the trace, so 2 ms, then 2 ms of
 * QPUs) beside frame i-1's trace (3 ms ARM: half speed for 2 ms, then alone to 4 ms), then
 * frame i-1's finish: 5 ms a frame instead of 7. */
TEST(ZeroModel, StagedHidesTheQpuPassesUnderTheTrace)
{
	const Timeline t = simulate(std::vector<FrameWork>(4, frame()), Overlap::Stages, unit(), End::Mid);
	/* Frame 0's front end alone (3 ms); then 5 ms a push; the flush traces and finishes frame 3. */
	expectTimes(t.in, { 0, 3, 8, 13 }, "in");
	expectTimes(t.out, { 8, 13, 18, 22 }, "out");
	const Summary s = summarise(t);
	EXPECT_NEAR(s.frame_time, 14e-3 / 3, 1e-12);
	EXPECT_NEAR(s.latency_max, 10e-3, 1e-12);
	EXPECT_NEAR(t.cpuBusy, 20e-3, 1e-12); /* the same ARM work, 2 ms idle: frame 0's QPUs */
	EXPECT_NEAR(t.gpuBusy, 8e-3, 1e-12);
}

/* Two whole frames at once on one core: both front ends share the ARM (done at 2 ms), the
 * QPUs take frame 0 then frame 1 (2-4, 4-6), their traces and finishes share the ARM. */
TEST(ZeroModel, WholeFramesShareTheOneCore)
{
	const Timeline t = simulate(std::vector<FrameWork>(4, frame()), Overlap::Frames, unit(), End::Mid);
	expectTimes(t.in, { 0, 0, 10, 13 }, "in");
	expectTimes(t.out, { 10, 13, 20, 22 }, "out");
	EXPECT_NEAR(summarise(t).frame_time, 4e-3, 1e-12);
}

TEST(ZeroModel, OneFrameInEachOverlap)
{
	for (Overlap o : { Overlap::None, Overlap::Frames, Overlap::Stages }) {
		const Timeline t = simulate({ frame() }, o, unit(), End::Mid);
		expectTimes(t.out, { 7 }, overlapName(o));
	}
}

/* A launch costs the mailbox round trip beside the slower of the QPUs' cycles and the
 * DRAM bytes, and the ARM a sync of its buffers before and after; copies at memcpy speed. */
TEST(ZeroModel, LaunchesCopiesAndSyncsTurnIntoTime)
{
	Assumptions a = unit();
	a.mailbox_s = { 50e-6, 100e-6, 200e-6 };
	a.sync_cycles = { 2, 4, 8 };
	a.dram_bytes_s = { 4e9, 2e9, 1e9 };
	FrameWork f;
	f.front_launches.push_back({ 250'000, 4'000'000, 32'000 }); /* 1 ms of cycles, 2 ms of DRAM at 2 GB/s */
	f.warp_launches.push_back({ 25'000, 0, 3200 });             /* 0.1 ms */
	f.copy_bytes = 300'000;                                     /* 0.3 ms at 1 GB/s */
	const StageTimes s = stageTimes(f, a, End::Mid);
	EXPECT_NEAR(s.front_gpu, 100e-6 + 2e-3, 1e-12);
	EXPECT_NEAR(s.warp_gpu, 100e-6 + 100e-6, 1e-12);
	EXPECT_NEAR(s.mailbox, 200e-6, 1e-12);
	/* 1000 lines at 4 cycles, twice; 100 lines at 4 cycles, twice. */
	EXPECT_NEAR(s.sync, 2 * 4e-6 + 2 * 0.4e-6, 1e-12);
	EXPECT_NEAR(s.copies, 0.3e-3, 1e-12);
	EXPECT_NEAR(s.front_cpu, 8e-6 + 0.3e-3, 1e-12);
	EXPECT_NEAR(s.finish_cpu, 0.8e-6, 1e-12);
	/* The fast end: cycles bound the launch (1 ms > 4 MB at 4 GB/s = 1 ms: equal). */
	EXPECT_NEAR(stageTimes(f, a, End::Fast).front_gpu, 50e-6 + 1e-3, 1e-12);
	EXPECT_NEAR(stageTimes(f, a, End::Slow).front_gpu, 200e-6 + 4e-3, 1e-12);
	/* Unpipelined, the frame is the sum of its parts. */
	const Timeline t = simulate({ f }, Overlap::None, a, End::Mid);
	EXPECT_NEAR(t.out[0], s.total(), 1e-12);
}

TEST(ZeroModel, TheFiguresHaveSourcesAndOrderedEnds)
{
	const Assumptions a = piZero();
	for (const Figure *f : { &a.cpi, &a.arm_hz, &a.v3d_hz, &a.dram_bytes_s, &a.mailbox_s, &a.launch_cpu_s,
				 &a.copy_bytes_s, &a.sync_cycles }) {
		EXPECT_GT(std::string(f->source).size(), 10u);
		EXPECT_GT(f->mid, 0);
		/* Costs grow from fast to slow; speeds shrink. */
		const bool speed = f == &a.arm_hz || f == &a.v3d_hz || f == &a.dram_bytes_s || f == &a.copy_bytes_s;
		if (speed) {
			EXPECT_GE(f->fast, f->mid);
			EXPECT_GE(f->mid, f->slow);
		} else {
			EXPECT_LE(f->fast, f->mid);
			EXPECT_LE(f->mid, f->slow);
		}
	}
}

/* A camera at 100 Hz (10 ms a frame) feeds the element. Staged: frame 0's front end runs
 * alone (done at 3 ms); at each capture the new frame's front end runs beside the trace of
 * the frame before (4 ms), whose finish (1 ms) brings it out: 15 ms after its capture. */
TEST(ZeroModel, ACameraPacesTheFramesAndLatencyCountsFromCapture)
{
	const Timeline t = simulate(std::vector<FrameWork>(3, frame()), Overlap::Stages, unit(), End::Mid, 10e-3);
	expectTimes(t.in, { 0, 10, 20 }, "in");
	/* The flush traces and finishes the last frame after frame 1 came out: 25 + 4. */
	expectTimes(t.out, { 15, 25, 29 }, "out");
	const Timeline u = simulate(std::vector<FrameWork>(3, frame()), Overlap::None, unit(), End::Mid, 10e-3);
	expectTimes(u.out, { 7, 17, 27 }, "unpipelined out");
	EXPECT_NEAR(summarise(u).latency_max, 7e-3, 1e-12);
}
