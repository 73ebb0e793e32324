// SPDX-License-Identifier: MIT
// After the first frame of a given size, detect() allocates nothing, and
// neither does a Pipeline's push(): this binary counts every operator new.
#include <atomic>
#include <cstdlib>
#include <new>

#include <gtest/gtest.h>

#include "frappe/frappe.h"
#include "scene.h"

namespace {
std::atomic<long> gAllocations{ 0 };
}

/* GCC pairs the inlined replacement delete with the library's new and
 * warns; both sides here are malloc/free. */
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

void *operator new(std::size_t n)
{
	++gAllocations;
	if (void *p = std::malloc(n ? n : 1))
		return p;
	throw std::bad_alloc();
}
void operator delete(void *p) noexcept { std::free(p); }
void operator delete(void *p, std::size_t) noexcept { std::free(p); }

using namespace frappe;
using namespace frappe::test;

class NoAllocation : public ::testing::TestWithParam<int>
{
};

namespace {

/* Six small markers, six others, two large ones (read on frames of block
 * means, 2 x 2 and 4 x 4). */
std::vector<Image> scenes()
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	Image a(640, 480, 80), b(640, 480, 120);
	std::mt19937 rng(3);
	for (int k = 0; k < 6; ++k) {
		renderMarker(a.mut(), dict, k, squarePose(80.0f + 100.0f * k, 150.0f, 60.0f, 20.0f * k, 30.0f));
		renderMarker(b.mut(), dict, 10 + k, squarePose(80.0f + 100.0f * k, 330.0f, 70.0f, -15.0f * k, 20.0f));
	}
	Image c(640, 480, 100);
	renderMarker(c.mut(), dict, 20, squarePose(170.0f, 240.0f, 200.0f, 10.0f, 20.0f));
	renderMarker(c.mut(), dict, 21, squarePose(470.0f, 240.0f, 130.0f, -10.0f, 25.0f));
	addNoise(a, 3.0f, rng);
	addNoise(b, 3.0f, rng);
	addNoise(c, 3.0f, rng);
	std::vector<Image> out;
	out.push_back(std::move(a));
	out.push_back(std::move(b));
	out.push_back(std::move(c));
	return out;
}

} // namespace

TEST_P(NoAllocation, SecondFrameOfTheSameSizeAllocatesNothing)
{
	const std::vector<Image> s = scenes();
	const Image &a = s[0], &b = s[1], &c = s[2];
	Config config;
	config.threads = GetParam(); /* bands on persistent workers */
	Detector det(config);
	/* Warm up on both frames: buffers grow to what these scenes need. */
	det.detect(a.view());
	det.detect(b.view());
	det.detect(c.view());

	const long before = gAllocations.load();
	const std::size_t na = det.detect(a.view()).markers.size();
	const std::size_t nb = det.detect(b.view()).markers.size();
	const std::size_t nc = det.detect(c.view()).markers.size();
	const long after = gAllocations.load();
	EXPECT_EQ(na, 6u);
	EXPECT_EQ(nb, 6u);
	EXPECT_EQ(nc, 2u);
	EXPECT_EQ(after - before, 0) << "detect() allocated on a frame of a size it had seen";
}

/* A tiled wall, a candidate per tile, some beyond max_candidates: the
 * duplicate removal's grid and the cap reuse what the first frame grew. */
TEST_P(NoAllocation, FrameFullOfSquaresAllocatesNothingOnceWarm)
{
	Image wall(640, 480, 230);
	squareGrid(wall, 12, 20);
	renderMarker(wall.mut(), *findDictionary("aruco_mip_36h12"), 5, squarePose(320.0f, 240.0f, 110.0f, 0.0f, 0.0f));
	Config config;
	config.threads = GetParam();
	config.max_candidates = 300;
	Detector det(config);
	det.detect(wall.view());
	const long before = gAllocations.load();
	const Result &r = det.detect(wall.view());
	const long after = gAllocations.load();
	EXPECT_GT(r.candidates_dropped, 0);
	EXPECT_EQ(after - before, 0) << "detect() allocated on a frame of a size it had seen";
}

INSTANTIATE_TEST_SUITE_P(Threads, NoAllocation, ::testing::Values(1, 2, 4));

/* Whole frames on several threads: which detector runs a frame depends on
 * timing, so each detector is warmed directly; the results' vectors then
 * circulate between the ring and the caller, each grown by the warm-up. */
TEST_P(NoAllocation, PipelinePushAllocatesNothingOnceWarm)
{
	const std::vector<Image> s = scenes();
	Config config;
	config.threads = GetParam();
	Pipeline pipeline(config, Pipeline::Overlap::Frames);
	for (int i = 0; i < pipeline.detectorCount(); ++i)
		for (const Image &img : s)
			pipeline.detector(i).detect(img.view());
	for (int k = 0; k < 12; ++k)
		pipeline.push(s[static_cast<std::size_t>(k) % 3].view());

	std::size_t markers = 0;
	const long before = gAllocations.load();
	for (int k = 12; k < 24; ++k)
		if (const Result *r = pipeline.push(s[static_cast<std::size_t>(k) % 3].view()))
			markers += r->markers.size();
	const long after = gAllocations.load();
	while (pipeline.flush()) {
	}
	EXPECT_EQ(markers, 4u * (6 + 6 + 2));
	EXPECT_EQ(after - before, 0) << "push() allocated on frames of a size it had seen";
}

/* One detector's stages, at either latency (the element's staged overlap is
 * latency 1): each slot is warmed by the frames that pass through it. */
TEST_P(NoAllocation, StagedPipelinePushAllocatesNothingOnceWarm)
{
	const std::vector<Image> s = scenes();
	Config config;
	config.threads = GetParam();
	for (int latency : { 1, 2 }) {
		Pipeline pipeline(config, Pipeline::Overlap::Stages, latency);
		for (int k = 0; k < 12; ++k)
			pipeline.push(s[static_cast<std::size_t>(k) % 3].view());

		std::size_t markers = 0;
		const long before = gAllocations.load();
		for (int k = 12; k < 24; ++k)
			if (const Result *r = pipeline.push(s[static_cast<std::size_t>(k) % 3].view()))
				markers += r->markers.size();
		const long after = gAllocations.load();
		while (pipeline.flush()) {
		}
		EXPECT_EQ(markers, 4u * (6 + 6 + 2)) << "latency " << latency;
		EXPECT_EQ(after - before, 0) << "push() allocated on frames of a size it had seen, latency " << latency;
	}
}

/* Mode::Track on a moving scene: the strips the motion places, the rows
 * joining them to the band, the band through the region map alone or
 * every map, allocate nothing the second time through the same video
 * (after reset(): the same frames, so no buffer meets a new high). */
TEST(NoAllocationTrack, AMovingSceneAllocatesNothingTheSecondTime)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	std::mt19937 rng(5);
	std::vector<Image> frames;
	for (int f = 0; f < 24; ++f) {
		Image img(640, 480, 110);
		for (int k = 0; k < 4; ++k)
			renderMarker(img.mut(), dict, k,
				     squarePose(120.0f + 120.0f * k + 2.0f * f, 140.0f + 60.0f * (k % 2) - 1.5f * f,
						60.0f, 10.0f * k, 20.0f));
		addNoise(img, 3.0f, rng);
		frames.push_back(std::move(img));
	}
	Config config;
	config.mode = Mode::Track;
	Detector det(config);
	for (const Image &img : frames)
		det.detect(img.view());
	det.reset();
	int regions = 0;
	const long before = gAllocations.load();
	for (const Image &img : frames) {
		const Result &r = det.detect(img.view());
		EXPECT_EQ(r.markers.size(), 4u);
		regions += r.whole_frame ? 0 : 1;
	}
	const long after = gAllocations.load();
	/* Both kinds of round: k = 4, 23 frames after the first. */
	EXPECT_GE(regions, 16);
	EXPECT_EQ(after - before, 0) << "detect() allocated in Mode::Track on a moving video it had seen";
}

/* Mode::Track: the regions, the tracks and the band allocate nothing once a
 * frame of the size was seen, whether a frame is read in regions or whole. */
/* A layout family (issue 32): small markers whose squares are read inside
 * the outline traced around them, and larger ones read from their own. */
TEST(NoAllocationLayout, SmallLayoutMarkersAllocateNothingOnceWarm)
{
	const Dictionary &dict = *findDictionary("apriltag_standard41h12");
	Image img(640, 480, 110);
	std::mt19937 rng(5);
	for (int k = 0; k < 6; ++k) {
		renderMarker(img.mut(), dict, k, squarePose(70.0f + 100.0f * k, 140.0f, 12.0f + k, 15.0f * k, 40.0f));
		renderMarker(img.mut(), dict, 10 + k, squarePose(70.0f + 100.0f * k, 340.0f, 40.0f, -10.0f * k, 20.0f));
	}
	addNoise(img, 3.0f, rng);
	Config config;
	config.dictionary = "apriltag_standard41h12";
	Detector det(config);
	det.detect(img.view());
	const long before = gAllocations.load();
	const std::size_t n = det.detect(img.view()).markers.size();
	const long after = gAllocations.load();
	EXPECT_EQ(n, 12u); /* 11 without the read inside the outline */
	EXPECT_EQ(after - before, 0) << "detect() allocated on a frame of a size it had seen";
}

TEST(NoAllocationTrack, FramesReadInRegionsAllocateNothingOnceWarm)
{
	const std::vector<Image> s = scenes();
	Config config;
	config.mode = Mode::Track;
	Detector det(config);
	for (int k = 0; k < 12; ++k) /* a six times, b six times: scene changes and tracked frames */
		det.detect(s[static_cast<std::size_t>(k / 6) % 2].view());
	int regions = 0;
	const long before = gAllocations.load();
	for (int k = 12; k < 24; ++k) {
		const Result &r = det.detect(s[static_cast<std::size_t>(k / 6) % 2].view());
		EXPECT_EQ(r.markers.size(), 6u) << k;
		regions += r.whole_frame ? 0 : 1;
	}
	const long after = gAllocations.load();
	EXPECT_GE(regions, 6);
	EXPECT_EQ(after - before, 0) << "detect() allocated in Mode::Track on frames of a size it had seen";
}

/* A bundle's pose with a BundleScratch and a BundlePose kept between
 * frames (what the element does): nothing allocated once they have grown,
 * and the same pose as estimateBundlePose() without them. */
TEST(NoAllocationBundle, PoseWithScratchAllocatesNothingOnceWarm)
{
	const Bundle board = Bundle::grid(3, 4, 0.05, 0.01);
	const Camera cam = Camera::pinhole(900.0, 900.0, 639.5, 359.5, 1280, 720);
	Pose truth;
	truth.rvec = { 2.9, 0.2, 0.3 };
	truth.tvec = { -0.1, -0.05, 0.8 };
	std::vector<Marker> seen;
	for (const BundleMarker &m : board.markers) {
		const std::vector<Point2f> px = projectPoints(m.corners, truth, cam);
		Marker mk;
		mk.id = m.id;
		for (std::size_t k = 0; k < 4; ++k)
			mk.corners[k] = px[k];
		seen.push_back(mk);
	}
	seen[5].corners[0].x += 9.0f; /* a marker moved: rejected */
	BundleScratch scratch;
	BundlePose pose;
	ASSERT_TRUE(estimateBundlePose(board, seen, cam, pose, scratch));
	const long before = gAllocations.load();
	for (int i = 0; i < 3; ++i)
		ASSERT_TRUE(estimateBundlePose(board, seen, cam, pose, scratch));
	EXPECT_EQ(gAllocations.load() - before, 0);
	const long fresh = gAllocations.load();
	const auto alone = estimateBundlePose(board, seen, cam);
	EXPECT_GT(gAllocations.load() - fresh, 0); /* without them it allocates: the count sees it */
	ASSERT_TRUE(alone.has_value());
	EXPECT_EQ(pose.pose.rvec, alone->pose.rvec);
	EXPECT_EQ(pose.pose.tvec, alone->pose.tvec);
	EXPECT_EQ(pose.pose.error, alone->pose.error);
	EXPECT_EQ(pose.used, alone->used);
	EXPECT_EQ(pose.rejected, std::vector<int>{ 5 });
}
