// SPDX-License-Identifier: MIT
// Every mode gives, latency() frames late and in order, exactly what
// detect() gives frame by frame; bad frames are refused without losing the
// ones in flight; dropped frames leave nothing behind.
#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <memory>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>

#include "frappe/frappe.h"
#include "scene.h"

using namespace frappe;
using namespace frappe::test;

namespace {

std::vector<Image> sequence(int frames)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	std::vector<Image> out;
	std::mt19937 rng(21);
	for (int f = 0; f < frames; ++f) {
		Image img(320, 240, 100);
		/* A different set of ids per frame, so a swapped result shows. */
		for (int k = 0; k <= f % 3; ++k)
			renderMarker(img.mut(), dict, 7 * f + k,
				     squarePose(60.0f + 95.0f * k, 80.0f + 10.0f * f, 50.0f, 11.0f * f, 15.0f));
		addNoise(img, 2.0f, rng);
		out.push_back(std::move(img));
	}
	return out;
}

void expectSame(const Result &a, const Result &b, int frame)
{
	ASSERT_EQ(a.markers.size(), b.markers.size()) << "frame " << frame;
	for (std::size_t i = 0; i < a.markers.size(); ++i) {
		EXPECT_EQ(a.markers[i].id, b.markers[i].id) << "frame " << frame;
		for (int c = 0; c < 4; ++c) {
			EXPECT_EQ(a.markers[i].corners[c].x, b.markers[i].corners[c].x);
			EXPECT_EQ(a.markers[i].corners[c].y, b.markers[i].corners[c].y);
		}
	}
}

/* Pushes frames[from..] and flushes: the results are those of frames[next..]
 * in order, exactly as detect() gives them, each push returning one as soon
 * as more than latency() frames are in flight. */
void pushTheRest(Pipeline &pipeline, const std::vector<Image> &frames, std::size_t from, std::size_t next)
{
	Detector reference(Config{});
	for (std::size_t i = from; i < frames.size(); ++i) {
		const std::size_t inFlight = i + 1 - next;
		const Result *r = pipeline.push(frames[i].view());
		ASSERT_EQ(r != nullptr, inFlight > static_cast<std::size_t>(pipeline.latency())) << "push " << i;
		if (r) {
			expectSame(*r, reference.detect(frames[next].view()), static_cast<int>(next));
			++next;
		}
	}
	while (const Result *r = pipeline.flush()) {
		expectSame(*r, reference.detect(frames[next].view()), static_cast<int>(next));
		++next;
	}
	EXPECT_EQ(next, frames.size());
	EXPECT_FALSE(pipeline.pending());
}

} // namespace

/* A mode and its thread count (Config::threads), with the latency and the
 * detectors that go with them. */
struct Setup {
	Pipeline::Overlap mode;
	int threads;
	int latencyAsked;
	int latency;
	int detectors;
	const char *name;
};

Config configOf(const Setup &s)
{
	Config c;
	c.threads = s.threads;
	return c;
}

class PipelineModes : public ::testing::TestWithParam<Setup>
{
};

TEST_P(PipelineModes, SameMarkersAsDetectLatencyFramesLateInOrder)
{
	const std::vector<Image> frames = sequence(9);
	Detector reference(Config{});
	std::vector<Result> expected;
	for (const Image &f : frames)
		expected.push_back(reference.detect(f.view()));

	Pipeline pipeline(configOf(GetParam()), GetParam().mode, GetParam().latencyAsked);
	EXPECT_EQ(pipeline.latency(), GetParam().latency);
	EXPECT_EQ(pipeline.detectorCount(), GetParam().detectors);
	std::vector<Result> got;
	int pushes = 0;
	for (const Image &f : frames) {
		const Result *r = pipeline.push(f.view());
		EXPECT_EQ(r != nullptr, pushes >= pipeline.latency()) << "push " << pushes;
		if (r)
			got.push_back(*r);
		++pushes;
	}
	EXPECT_EQ(pipeline.pending(), pipeline.latency() > 0);
	while (const Result *r = pipeline.flush())
		got.push_back(*r);
	EXPECT_FALSE(pipeline.pending());
	EXPECT_EQ(pipeline.flush(), nullptr);

	ASSERT_EQ(got.size(), frames.size());
	for (std::size_t i = 0; i < frames.size(); ++i) {
		expectSame(got[i], expected[i], static_cast<int>(i));
		EXPECT_EQ(static_cast<int>(got[i].markers.size()), static_cast<int>(i % 3) + 1);
	}
}

/* A seek: the frames in flight go without results, and the stream goes on
 * from the next push as if the pipeline were new. */
TEST_P(PipelineModes, DropForgetsTheFramesInFlight)
{
	const std::vector<Image> frames = sequence(6);
	Pipeline pipeline(configOf(GetParam()), GetParam().mode, GetParam().latencyAsked);
	for (int i = 0; i < 3; ++i)
		pipeline.push(frames[static_cast<std::size_t>(i)].view());
	pipeline.drop();
	EXPECT_FALSE(pipeline.pending());
	EXPECT_EQ(pipeline.flush(), nullptr);
	pushTheRest(pipeline, frames, 3, 3);
}

TEST_P(PipelineModes, FlushWithNothingInFlight)
{
	Pipeline pipeline(configOf(GetParam()), GetParam().mode, GetParam().latencyAsked);
	EXPECT_FALSE(pipeline.pending());
	EXPECT_EQ(pipeline.flush(), nullptr);
	/* A pipeline may be destroyed with frames in flight, in Frames mode
	 * with a worker still on one. */
	const std::vector<Image> frames = sequence(2);
	Pipeline other(configOf(GetParam()), GetParam().mode, GetParam().latencyAsked);
	other.push(frames[0].view());
	other.push(frames[1].view());
}

namespace {

/* The CPU front end, saying it copied stride * height bytes of each frame:
 * a value that differs per frame, so a Result carrying another frame's
 * count shows. */
class CountingFrontEnd : public FrontEnd
{
public:
	const char *name() const override { return "counting"; }
	void run(const ImageView &image, float scale, const FrontEndParams &params, EdgeMap &out) override
	{
		cpu_->run(image, scale, params, out);
		last_ = static_cast<std::size_t>(image.stride) * static_cast<std::size_t>(image.height);
	}
	std::size_t lastCopyBytes() const override { return last_; }

private:
	std::unique_ptr<FrontEnd> cpu_ = makeCpuFrontEnd(1);
	std::size_t last_ = 0;
};

} // namespace

/* The GStreamer element reports each frame's copied bytes from its Result:
 * in a pipeline the detector that ran a frame may be on the next one by the
 * time its result comes out, so the count travels with the result. */
TEST_P(PipelineModes, EachResultCarriesTheBytesItsFrontEndCopied)
{
	const std::vector<Image> frames = sequence(8);
	Pipeline pipeline(configOf(GetParam()), GetParam().mode, GetParam().latencyAsked);
	for (int i = 0; i < pipeline.detectorCount(); ++i)
		pipeline.detector(i).setFrontEnd(std::make_unique<CountingFrontEnd>());
	std::size_t next = 0;
	auto check = [&](const Result *r) {
		ASSERT_NE(r, nullptr);
		/* Frame i is pushed i rows short. */
		const std::size_t rows = static_cast<std::size_t>(frames[next].height) - next;
		EXPECT_EQ(r->copy_bytes, static_cast<std::size_t>(frames[next].stride) * rows) << "frame " << next;
		++next;
	};
	for (std::size_t i = 0; i < frames.size(); ++i) {
		ImageView v = frames[i].view();
		v.height -= static_cast<int>(i);
		if (const Result *r = pipeline.push(v))
			check(r);
	}
	while (const Result *r = pipeline.flush())
		check(r);
	EXPECT_EQ(next, frames.size());
}

namespace {

/* Fails the detection of one frame: its front end throws (the first stage),
 * or the warp of its candidates does (the last). */
class FailingFrontEnd : public FrontEnd
{
public:
	explicit FailingFrontEnd(int failAt) : failAt_(failAt) {}
	const char *name() const override { return "failing"; }
	void run(const ImageView &image, float scale, const FrontEndParams &params, EdgeMap &out) override
	{
		if (calls_++ == failAt_)
			throw std::runtime_error("front end failed");
		cpu_->run(image, scale, params, out);
	}

private:
	std::unique_ptr<FrontEnd> cpu_ = makeCpuFrontEnd(1);
	int failAt_, calls_ = 0;
};

class FailingWarper : public CandidateWarper
{
public:
	explicit FailingWarper(int failAt) : failAt_(failAt) {}
	const char *name() const override { return "failing"; }
	void warp(const ImageView &image, std::span<const std::array<Point2f, 4>> quads, int side,
		  std::span<CandidateSamples> out, std::span<std::uint8_t> ok) override
	{
		if (calls_++ == failAt_)
			throw std::runtime_error("warp failed");
		cpu_->warp(image, quads, side, out, ok);
	}

private:
	std::unique_ptr<CandidateWarper> cpu_ = makeCpuWarper();
	int failAt_, calls_ = 0;
};

} // namespace

/* The frame whose detection failed throws where its result would come
 * out, and only there: the frames before and after it come out in order
 * with their own markers (the element fails that frame's buffer). One
 * detector: its front end and warper run once a frame, in order. */
TEST_P(PipelineModes, AFailedFrameThrowsInItsOwnPlaceAndTheOthersGoOn)
{
	if (GetParam().detectors != 1)
		GTEST_SKIP() << "calls numbered per detector";
	const std::vector<Image> frames = sequence(7);
	Detector reference(Config{});
	for (const bool inWarp : { false, true }) {
		const std::size_t failed = 3;
		Pipeline pipeline(configOf(GetParam()), GetParam().mode, GetParam().latencyAsked);
		if (inWarp)
			pipeline.detector().setWarper(std::make_unique<FailingWarper>(static_cast<int>(failed)));
		else
			pipeline.detector().setFrontEnd(std::make_unique<FailingFrontEnd>(static_cast<int>(failed)));
		std::size_t next = 0;
		auto take = [&](auto call) {
			const Result *r = nullptr;
			if (next == failed) {
				EXPECT_THROW(r = call(), std::runtime_error) << (inWarp ? "warp" : "front end");
				++next;
				return true;
			}
			r = call();
			if (!r)
				return false;
			expectSame(*r, reference.detect(frames[next].view()), static_cast<int>(next));
			++next;
			return true;
		};
		for (const Image &f : frames)
			take([&] { return pipeline.push(f.view()); });
		while (pipeline.pending() && take([&] { return pipeline.flush(); })) {
		}
		EXPECT_EQ(next, frames.size()) << (inWarp ? "warp" : "front end");
		EXPECT_FALSE(pipeline.pending());
	}
}

INSTANTIATE_TEST_SUITE_P(All, PipelineModes,
			 ::testing::Values(Setup{ Pipeline::Overlap::Stages, 1, -1, 2, 1, "Stages" },
					   Setup{ Pipeline::Overlap::Stages, 1, 1, 1, 1, "StagesLatencyOne" },
					   Setup{ Pipeline::Overlap::Frames, 1, -1, 0, 1, "FramesOneThread" },
					   Setup{ Pipeline::Overlap::Frames, 2, -1, 2, 2, "FramesTwoThreads" },
					   Setup{ Pipeline::Overlap::Frames, 2, 1, 1, 2, "FramesTwoThreadsLatencyOne" },
					   Setup{ Pipeline::Overlap::Frames, 3, -1, 3, 3, "FramesThreeThreads" }),
			 [](const auto &info) { return std::string(info.param.name); });

TEST(Pipeline, ThreadsAndLatencyAreCheckedAndZeroThreadsIsOnePerCore)
{
	Config c;
	c.threads = -1;
	EXPECT_THROW(Pipeline(c, Pipeline::Overlap::Frames), std::invalid_argument);
	c.threads = 257;
	EXPECT_THROW(Pipeline(c, Pipeline::Overlap::Frames), std::invalid_argument);
	c.threads = 0;
	Pipeline perCore(c, Pipeline::Overlap::Frames);
	EXPECT_EQ(perCore.threads(), static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
	EXPECT_EQ(perCore.latency(), perCore.threads() > 1 ? perCore.threads() : 0);
	/* Each detector of Overlap::Frames runs on its own thread only. */
	EXPECT_EQ(perCore.detector(0).config().threads, 1);
	EXPECT_THROW(Pipeline(Config{}, Pipeline::Overlap::Stages).detector(1), std::out_of_range);
	EXPECT_THROW(Pipeline(Config{}, Pipeline::Overlap::Stages, 0), std::invalid_argument);
	EXPECT_THROW(Pipeline(Config{}, Pipeline::Overlap::Stages, 3), std::invalid_argument);
	EXPECT_EQ(Pipeline(Config{}, Pipeline::Overlap::Stages, 1).latency(), 1);
	EXPECT_THROW(Pipeline(Config{}, Pipeline::Overlap::Frames, -2), std::invalid_argument);
	EXPECT_THROW(Pipeline(Config{}, Pipeline::Overlap::Frames, 257), std::invalid_argument);
}

TEST(Pipeline, BadFrameIsRefusedAndTheFrameInFlightSurvives)
{
	const std::vector<Image> frames = sequence(3);
	Detector reference(Config{});
	Pipeline pipeline(Config{}, Pipeline::Overlap::Stages);
	EXPECT_EQ(pipeline.push(frames[0].view()), nullptr);
	EXPECT_THROW(pipeline.push(ImageView(nullptr, 10, 10, 10)), std::invalid_argument);
	EXPECT_EQ(pipeline.push(frames[1].view()), nullptr);
	EXPECT_THROW(pipeline.push(ImageView(frames[1].pixels.data(), 320, 240, 100)), std::invalid_argument);
	const Result *r0 = pipeline.push(frames[2].view());
	ASSERT_NE(r0, nullptr);
	expectSame(*r0, reference.detect(frames[0].view()), 0);
	const Result *r1 = pipeline.flush();
	ASSERT_NE(r1, nullptr);
	expectSame(*r1, reference.detect(frames[1].view()), 1);
	const Result *r2 = pipeline.flush();
	ASSERT_NE(r2, nullptr);
	expectSame(*r2, reference.detect(frames[2].view()), 2);
	EXPECT_EQ(pipeline.flush(), nullptr);
}

/* Frames mode: a refused frame changes nothing in flight; frames come out
 * in order whichever thread ran them (which one does depends on timing, so
 * a long stream of frames of different cost exercises all three). */
TEST(Pipeline, FramesModeRefusesABadFrameAndKeepsTheOrder)
{
	const std::vector<Image> frames = sequence(24);
	Config three;
	three.threads = 3;
	Pipeline pipeline(three, Pipeline::Overlap::Frames);
	EXPECT_EQ(pipeline.push(frames[0].view()), nullptr);
	EXPECT_EQ(pipeline.push(frames[1].view()), nullptr);
	EXPECT_THROW(pipeline.push(ImageView(nullptr, 10, 10, 10)), std::invalid_argument);
	pushTheRest(pipeline, frames, 2, 0);
}

