// SPDX-License-Identifier: MIT
// Both two-thread modes give, latency() frames late and in order, exactly
// what detect() gives frame by frame; bad frames are refused without losing
// the ones in flight.
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

} // namespace

class PipelineModes : public ::testing::TestWithParam<Pipeline::Mode>
{
};

TEST_P(PipelineModes, SameMarkersAsDetectLatencyFramesLateInOrder)
{
	const std::vector<Image> frames = sequence(9);
	Detector reference(Config{});
	std::vector<Result> expected;
	for (const Image &f : frames)
		expected.push_back(reference.detect(f.view()));

	Pipeline pipeline(Config{}, GetParam());
	EXPECT_EQ(pipeline.latency(), 2);
	std::vector<Result> got;
	int pushes = 0;
	for (const Image &f : frames) {
		const Result *r = pipeline.push(f.view());
		EXPECT_EQ(r != nullptr, pushes >= pipeline.latency()) << "push " << pushes;
		if (r)
			got.push_back(*r);
		++pushes;
	}
	EXPECT_TRUE(pipeline.pending());
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

TEST(Pipeline, BadFrameIsRefusedAndTheFrameInFlightSurvives)
{
	const std::vector<Image> frames = sequence(3);
	Detector reference(Config{});
	Pipeline pipeline(Config{});
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

TEST_P(PipelineModes, FlushWithNothingInFlight)
{
	Pipeline pipeline(Config{}, GetParam());
	EXPECT_FALSE(pipeline.pending());
	EXPECT_EQ(pipeline.flush(), nullptr);
	/* A pipeline may be destroyed with frames in flight, in Frames mode
	 * with the worker still on one. */
	const std::vector<Image> frames = sequence(2);
	Pipeline other(Config{}, GetParam());
	EXPECT_EQ(other.push(frames[0].view()), nullptr);
	other.push(frames[1].view());
}

/* Frames mode: a refused frame changes nothing in flight; frames come out
 * in order whichever thread ran them (which one does depends on timing, so
 * a long stream of frames of different cost exercises both). */
TEST(Pipeline, FramesModeRefusesABadFrameAndKeepsTheOrder)
{
	const std::vector<Image> frames = sequence(24);
	Detector reference(Config{});
	Pipeline pipeline(Config{}, Pipeline::Mode::Frames);
	EXPECT_EQ(pipeline.push(frames[0].view()), nullptr);
	EXPECT_EQ(pipeline.push(frames[1].view()), nullptr);
	EXPECT_THROW(pipeline.push(ImageView(nullptr, 10, 10, 10)), std::invalid_argument);
	std::size_t next = 0;
	for (std::size_t i = 2; i < frames.size(); ++i) {
		const Result *r = pipeline.push(frames[i].view());
		ASSERT_NE(r, nullptr);
		expectSame(*r, reference.detect(frames[next].view()), static_cast<int>(next));
		++next;
	}
	while (const Result *r = pipeline.flush()) {
		expectSame(*r, reference.detect(frames[next].view()), static_cast<int>(next));
		++next;
	}
	EXPECT_EQ(next, frames.size());
	EXPECT_FALSE(pipeline.pending());
}

INSTANTIATE_TEST_SUITE_P(Both, PipelineModes,
			 ::testing::Values(Pipeline::Mode::Stages, Pipeline::Mode::Frames),
			 [](const auto &info) {
				 return std::string(info.param == Pipeline::Mode::Stages ? "Stages" : "Frames");
			 });
