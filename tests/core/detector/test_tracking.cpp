// SPDX-License-Identifier: MIT
// Mode::Track: the CPU front end over regions writes what a whole-frame run
// writes there, bit for bit; markers of a moving scene are tracked with
// measured corners, a new one is found within track_cover_frames frames, a
// marker that jumps is found on the same frame, a scene change searches the
// frame whole.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "frappe/frappe.h"
#include "front_end_rows.h"
#include "scene.h"
#include "tracker.h"

using namespace frappe;
using namespace frappe::test;
using detail::PixelRect;
using detail::RegionFrontEnd;

namespace {

/* A frame with everything the front end has a path for: texture, markers,
 * a dim corner (thresholds that follow the light, the shade map), blur. */
Image busyFrame(int w, int h, unsigned seed)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	Image img(w, h, 150);
	std::mt19937 rng(seed);
	std::uniform_int_distribution<int> px(0, w - 1), py(0, h - 1), grey(0, 255);
	for (int k = 0; k < 60; ++k) {
		const int x0 = px(rng), y0 = py(rng), s = 4 + grey(rng) % 30;
		const std::uint8_t v = static_cast<std::uint8_t>(grey(rng));
		for (int y = y0; y < std::min(h, y0 + s); ++y)
			for (int x = x0; x < std::min(w, x0 + s); ++x)
				img.at(x, y) = v;
	}
	for (int k = 0; k < 5; ++k)
		renderMarker(img.mut(), dict, 3 * k + 1,
			     squarePose(60.0f + 120.0f * k, 80.0f + 70.0f * (k % 4), 50.0f + 10.0f * k, 17.0f * k, 25.0f));
	/* A dim region: a fifth of the light. */
	for (int y = h / 2; y < h; ++y)
		for (int x = 0; x < w / 3; ++x)
			img.at(x, y) = static_cast<std::uint8_t>(img.at(x, y) / 5);
	blur(img, 0.8f);
	addNoise(img, 2.0f, rng);
	return img;
}

/* Whether frame pixel (x, y) lies in one of the aligned rectangles. */
bool inRects(const std::vector<PixelRect> &rects, int x, int y, int w, int h)
{
	for (PixelRect r : rects) {
		r = RegionFrontEnd::alignedRect(r, w, h);
		if (x >= r.x0 && x < r.x1 && y >= r.y0 && y < r.y1)
			return true;
	}
	return false;
}

/* Every pixel and tile of `part` against `whole`: equal inside the
 * rectangles (a map at `toMap` of the frame's resolution), zero outside. */
void expectSameInside(const TraceMap &whole, const TraceMap &part, const std::vector<PixelRect> &rects, int w,
		      int h, int div, const char *what)
{
	ASSERT_EQ(part.width, whole.width) << what;
	ASSERT_EQ(part.height, whole.height) << what;
	long inside = 0, differ = 0, stray = 0;
	for (int y = 0; y < whole.height; ++y)
		for (int x = 0; x < whole.width; ++x) {
			if (inRects(rects, x * div, y * div, w, h)) {
				++inside;
				differ += whole.at(x, y) != part.at(x, y);
			} else {
				stray += part.at(x, y) != 0;
			}
		}
	EXPECT_GT(inside, 0) << what;
	EXPECT_EQ(differ, 0) << what << ": pixels inside the regions that differ from the whole frame's";
	EXPECT_EQ(stray, 0) << what << ": pixels set outside the regions";
	/* A tile is marked exactly when one of its pixels is set. */
	const int t = TraceMap::kTile;
	for (int ty = 0; ty < whole.tiles_y; ++ty)
		for (int tx = 0; tx < whole.tiles_x; ++tx) {
			bool any = false;
			for (int y = ty * t; y < std::min(part.height, ty * t + t); ++y)
				for (int x = tx * t; x < std::min(part.width, tx * t + t); ++x)
					any = any || part.at(x, y) != 0;
			EXPECT_EQ(part.tiles[ty * part.tiles_x + tx], any ? 1 : 0) << what << " tile " << tx << "," << ty;
		}
}

} // namespace

TEST(RegionFrontEnd, BitIdenticalToTheWholeFrameInsideEachRegion)
{
	/* Odd sides: partial tiles at the right and bottom. */
	const int w = 645, h = 487;
	const Image img = busyFrame(w, h, 7);
	const FrontEndParams params = Detector(Config{}).frontEndParams();
	ASSERT_TRUE(params.makesShades());
	/* The reference: the scalar kernels over the whole frame. */
	EdgeMap whole;
	detail::makeCpuFrontEnd(1, detail::scalarBandKernels())->run(img.view(), 1.0f, params, whole);
	ASSERT_GT(whole.regions.width, 0);
	ASSERT_GT(whole.shades.width, 0);

	RegionFrontEnd regions;
	EdgeMap part;
	const std::vector<PixelRect> wholeFrame = { { 0, 0, w, h } };
	/* Each rectangle with its margin, from a tile's start. */
	auto readOf = [&](const std::vector<PixelRect> &rects) {
		std::size_t read = 0;
		for (PixelRect r : rects) {
			r = RegionFrontEnd::alignedRect(r, w, h);
			const int m = RegionFrontEnd::kMargin;
			read += PixelRect{ std::max(0, (r.x0 - m) / 16 * 16), std::max(0, (r.y0 - m) / 16 * 16),
					   std::min(w, r.x1 + m), std::min(h, r.y1 + m) }
					.area();
		}
		return read;
	};
	/* Runs on the same maps, each after another that wrote elsewhere: it
	 * must clear what the last one wrote outside its own regions.
	 * Regions at the frame's edges and corners, unaligned, overlapping,
	 * and one inside another; search strips along the frame's edges
	 * (the region map only there), or the whole frame's region map. */
	struct Run {
		std::vector<PixelRect> rects, search;
	};
	const std::vector<Run> runs = {
		{ { { 0, 0, 100, 70 }, { 300, 200, 420, 310 }, { 380, 250, 500, 330 }, { 600, 440, 645, 487 } },
		  wholeFrame },
		{ { { 13, 100, 645, 200 }, { 500, 300, 530, 333 }, { 0, 400, 90, 487 }, { 40, 120, 60, 150 } },
		  { { 0, 0, 101, 487 }, { 0, 390, 645, 487 } } },
		{ { { 0, 0, 100, 70 }, { 300, 200, 420, 310 } }, { { 547, 0, 645, 487 }, { 0, 0, 645, 77 } } },
		{ { { 200, 150, 330, 260 } }, wholeFrame },
		{ { { 200, 150, 330, 260 } }, {} },
	};
	for (const Run &run : runs) {
		const bool wholeRegions = run.search == wholeFrame;
		regions.run(img.view(), run.rects, run.search, params, part);
		EXPECT_EQ(part.scale, 1.0f);
		expectSameInside(whole, part, run.rects, w, h, 1, "edges");
		EXPECT_EQ(part.regions.width, whole.regions.width);
		EXPECT_EQ(part.regions.height, whole.regions.height);
		EXPECT_EQ(part.regions.scale, whole.regions.scale);
		EXPECT_EQ(part.shades.scale, whole.shades.scale);
		if (wholeRegions) {
			/* The region map the whole frame's. */
			EXPECT_EQ(part.regions.pixels, whole.regions.pixels);
			EXPECT_EQ(part.regions.tiles, whole.regions.tiles);
		} else {
			/* The region map the rectangles' and the strips'. */
			std::vector<PixelRect> both = run.rects;
			both.insert(both.end(), run.search.begin(), run.search.end());
			expectSameInside(whole.regions, part.regions, both, w, h, 2, "regions");
		}
		/* The shade map the rectangles' only. */
		expectSameInside(whole.shades, part.shades, run.rects, w, h, 2, "shades");
		EXPECT_EQ(regions.bytesRead(),
			  readOf(run.rects) + (wholeRegions ? static_cast<std::size_t>(w) * h : readOf(run.search)));
	}
	/* A region of the whole frame is the whole frame. */
	for (const std::vector<PixelRect> &search : { wholeFrame, std::vector<PixelRect>{} }) {
		regions.run(img.view(), wholeFrame, search, params, part);
		EXPECT_EQ(part.pixels, whole.pixels);
		EXPECT_EQ(part.tiles, whole.tiles);
		EXPECT_EQ(part.regions.pixels, whole.regions.pixels);
		EXPECT_EQ(part.regions.tiles, whole.regions.tiles);
		EXPECT_EQ(part.shades.pixels, whole.shades.pixels);
		EXPECT_EQ(part.shades.tiles, whole.shades.tiles);
	}
}

/* A marker read at its prediction: the maps lose the inside of its quad
 * (moved in by the inset), in each map's own pixels, and nothing else. */
TEST(RegionFrontEnd, ClearsOnlyInsideTheMarkersReadAtTheirPredictions)
{
	EdgeMap maps;
	maps.resize(200, 160);
	maps.scale = 1.0f;
	for (TraceMap *m : { &maps.regions, &maps.shades }) {
		m->resize(100, 80);
		m->scale = 0.5f;
	}
	for (TraceMap *m : { static_cast<TraceMap *>(&maps), &maps.regions, &maps.shades }) {
		std::fill(m->pixels.begin(), m->pixels.end(), 1);
		std::fill(m->tiles.begin(), m->tiles.end(), 1);
	}
	Marker mk;
	mk.corners = squarePose(100.0f, 80.0f, 60.0f, 20.0f, 10.0f);
	const float inset = 1.5f;
	detail::clearInsideMarkers(maps, std::span<const Marker>(&mk, 1), inset);
	/* Signed distances of a point from the quad's sides (inside > 0). */
	auto inside = [&](float x, float y) {
		float in = 1e9f;
		for (int i = 0; i < 4; ++i) {
			const Point2f a = mk.corners[i], b = mk.corners[(i + 1) % 4];
			const float len = std::hypot(b.x - a.x, b.y - a.y);
			const float cross = ((b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x)) / len;
			in = std::min(in, cross);
		}
		return in;
	};
	const float orientation = inside(100.0f, 80.0f) > 0 ? 1.0f : -1.0f;
	for (TraceMap *m : { static_cast<TraceMap *>(&maps), &maps.regions, &maps.shades }) {
		long cleared = 0;
		for (int y = 0; y < m->height; ++y)
			for (int x = 0; x < m->width; ++x) {
				/* The pixel's centre in frame pixels. */
				const float d = orientation * inside((x + 0.5f) / m->scale, (y + 0.5f) / m->scale);
				if (d > inset + 1.0f / m->scale) {
					EXPECT_EQ(m->at(x, y), 0) << "kept inside at " << x << "," << y;
				}
				if (d < 0.0f) {
					EXPECT_EQ(m->at(x, y), 1) << "cleared outside at " << x << "," << y;
				}
				cleared += m->at(x, y) == 0;
			}
		EXPECT_GT(cleared, static_cast<long>(0.8f * 55.0f * 55.0f * m->scale * m->scale));
	}
}

TEST(RegionFrontEnd, AlignsOutwardAndClips)
{
	static_assert(RegionFrontEnd::kAlign == 8);
	const PixelRect r = RegionFrontEnd::alignedRect({ -5, 33, 70, 500 }, 645, 487);
	EXPECT_EQ(r.x0, 0);
	EXPECT_EQ(r.y0, 32);
	EXPECT_EQ(r.x1, 72);
	EXPECT_EQ(r.y1, 487);
}

namespace {

struct Placed {
	int id;
	std::array<Point2f, 4> corners;
};

/* Frame `f` of a scene of markers moving a few pixels a frame over a
 * textured background that moves with them (a camera panning). */
Image movingFrame(int f, const std::vector<Placed> &markers)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	Image img(640, 480, 170);
	/* Texture: stripes and blocks that move with the scene. */
	for (int y = 0; y < img.height; ++y)
		for (int x = 0; x < img.width; ++x) {
			const int u = x - 3 * f, v = y - f;
			const int band = ((u / 37) + (v / 53)) & 3;
			img.at(x, y) = static_cast<std::uint8_t>(120 + 30 * band);
		}
	for (const Placed &m : markers)
		renderMarker(img.mut(), dict, m.id, m.corners);
	return img;
}

std::vector<Placed> sceneAt(int f, bool withNewcomer, int newcomerFrom)
{
	std::vector<Placed> s;
	s.push_back({ 7, squarePose(120.0f + 3.0f * f, 110.0f + 1.0f * f, 60.0f, 10.0f + 0.5f * f, 20.0f) });
	s.push_back({ 42, squarePose(430.0f + 3.0f * f, 150.0f + 1.0f * f, 80.0f, -20.0f, 30.0f) });
	s.push_back({ 99, squarePose(250.0f + 3.0f * f, 330.0f + 1.0f * f, 50.0f, 35.0f, 10.0f) });
	if (withNewcomer && f >= newcomerFrom)
		s.push_back({ 150, squarePose(520.0f, 380.0f, 55.0f, 5.0f, 15.0f) });
	return s;
}

} // namespace

TEST(Tracking, FollowsMovingMarkersWithMeasuredCornersAndFindsANewOneWithinKFrames)
{
	Config cfg;
	cfg.mode = Mode::Track;
	ASSERT_EQ(cfg.track_cover_frames, 4);
	Detector det(cfg);
	const int newFrom = 9;
	int newFoundAt = -1, partialFrames = 0;
	for (int f = 0; f < 24; ++f) {
		const std::vector<Placed> truth = sceneAt(f, true, newFrom);
		const Image img = movingFrame(f, truth);
		const Result &r = det.detect(img.view());
		if (f == 0) {
			EXPECT_TRUE(r.whole_frame);
		}
		if (!r.whole_frame) {
			++partialFrames;
			/* The frame once (the region map), and less than 70% of it
			 * again (the edges of the regions). */
			EXPECT_LT(r.bytes_read, static_cast<std::size_t>(640 * 480) * 17 / 10) << "frame " << f;
		} else {
			EXPECT_EQ(r.bytes_read, static_cast<std::size_t>(640 * 480)) << "frame " << f;
		}
		for (const Placed &t : truth) {
			const Marker *m = findMarker(r.markers, t.id);
			if (t.id == 150 && !m)
				continue; /* the newcomer, until the band reaches it */
			ASSERT_NE(m, nullptr) << "frame " << f << " lost marker " << t.id;
			/* Measured on this frame: a prediction would be off by the
			 * change of speed of the roll. */
			EXPECT_LT(meanCornerError(m->corners, t.corners), 0.35f) << "frame " << f << " id " << t.id;
			if (t.id != 150) {
				EXPECT_EQ(m->tracked, f > 0) << "frame " << f << " id " << t.id;
			} else if (newFoundAt < 0) {
				newFoundAt = f;
				EXPECT_FALSE(m->tracked) << "the newcomer is found afresh";
			} else {
				EXPECT_TRUE(m->tracked) << "frame " << f << ": the newcomer, once found, is tracked";
			}
		}
		EXPECT_EQ(r.markers.size(), truth.size() - (newFoundAt < 0 && f >= newFrom ? 1 : 0)) << "frame " << f;
	}
	ASSERT_GE(newFoundAt, newFrom);
	EXPECT_LT(newFoundAt - newFrom, cfg.track_cover_frames) << "found " << newFoundAt - newFrom << " frames late";
	EXPECT_GE(partialFrames, 18) << "frames read in regions";
}

/* The band's schedule, with every track read at its prediction: the
 * front end's rectangles are a band of rows on every other round of k
 * frames (the edges and the shade map: every row within 2k frames, its
 * seams in new places), none on the others (the region map's rounds). */
TEST(Tracking, TheBandGoesThroughEveryMapOnEveryOtherRound)
{
	const int w = 640, h = 480, k = 4;
	detail::Tracker tracker(k);
	const Image img(w, h, 120);
	std::vector<Marker> markers(1);
	markers[0].id = 5;
	auto moveTo = [&](int f) {
		markers[0].corners = squarePose(200.0f + 2.0f * f, 200.0f + 1.0f * f, 50.0f, 0.0f, 0.0f);
	};
	moveTo(0);
	ASSERT_FALSE(tracker.plan(img.view(), true)) << "the first frame is whole";
	tracker.update(markers, w, h, false, false);
	/* Each full round's bands. */
	std::vector<std::vector<PixelRect>> bands;
	for (int f = 1; f <= 4 * k; ++f) {
		ASSERT_TRUE(tracker.plan(img.view(), true)) << "frame " << f;
		const std::uint8_t read = 1;
		ASSERT_TRUE(tracker.placeRegions(std::span(&read, 1))) << "frame " << f;
		const auto regions = tracker.regions();
		const int round = (f - 1) / k;
		if (round % 2 == 0) {
			ASSERT_EQ(regions.size(), 1u) << "frame " << f;
			int rows = 0;
			for (const PixelRect &r : regions) {
				EXPECT_EQ(r.x0, 0);
				EXPECT_EQ(r.x1, w);
				rows += r.y1 - r.y0;
			}
			/* A band and its overlaps; the first one of a round also
			 * takes the rows its seam moved down by (at most two
			 * thirds of a band), the last one gives them up. */
			EXPECT_GE(rows, h / (3 * k)) << "frame " << f;
			EXPECT_LE(rows, h / k + 2 * h / (3 * k) + 2 * RegionFrontEnd::kAlign + 8) << "frame " << f;
			bands.emplace_back(regions.begin(), regions.end());
		} else {
			EXPECT_TRUE(regions.empty()) << "frame " << f << ": the region map's round";
		}
		moveTo(f);
		tracker.update(markers, w, h, true, true);
	}
	/* Each full round covers every row; the second's seams are elsewhere. */
	ASSERT_EQ(bands.size(), static_cast<std::size_t>(2 * k));
	for (int r = 0; r < 2; ++r) {
		std::vector<int> covered(h, 0);
		for (int b = 0; b < k; ++b)
			for (const PixelRect &p : bands[static_cast<std::size_t>(r * k + b)])
				for (int y = p.y0; y < p.y1; ++y)
					covered[static_cast<std::size_t>(y)] = 1;
		EXPECT_EQ(std::count(covered.begin(), covered.end(), 1), h) << "full round " << r;
	}
	for (int b = 1; b < k; ++b)
		EXPECT_NE(bands[static_cast<std::size_t>(b)][0].y0, bands[static_cast<std::size_t>(k + b)][0].y0)
			<< "band " << b << "'s seam did not move";
}

/* A marker that the scene's motion (3 px a frame to the right) brings in
 * over the frame's left edge: the search strip on that side finds it on
 * the frame NORMAL first does, wherever the band is. */
TEST(Tracking, AMarkerEnteringAtTheEdgeIsFoundOnItsFirstWholeFrame)
{
	Config cfg;
	Config trackCfg = cfg;
	trackCfg.mode = Mode::Track;
	Detector normal(cfg), track(trackCfg);
	int normalAt = -1, trackAt = -1, partial = 0;
	for (int f = 0; f < 30 && (normalAt < 0 || trackAt < 0); ++f) {
		std::vector<Placed> s = sceneAt(f, false, 0);
		s.push_back({ 150, squarePose(-45.0f + 3.0f * f, 250.0f + 1.0f * f, 56.0f, 5.0f, 12.0f) });
		const Image img = movingFrame(f, s);
		if (normalAt < 0 && findMarker(normal.detect(img.view()).markers, 150))
			normalAt = f;
		const Result &r = track.detect(img.view());
		partial += r.whole_frame ? 0 : 1;
		if (trackAt < 0 && findMarker(r.markers, 150)) {
			trackAt = f;
			EXPECT_FALSE(r.whole_frame) << "found by the search, not a whole frame";
			EXPECT_FALSE(findMarker(r.markers, 150)->tracked);
		}
	}
	ASSERT_GT(normalAt, 5);
	EXPECT_EQ(trackAt, normalAt);
	EXPECT_EQ(partial, trackAt);
}

TEST(Tracking, AMarkerThatJumpsIsFoundOnTheSameFrameByAWholeSearch)
{
	Config cfg;
	cfg.mode = Mode::Track;
	Detector det(cfg);
	for (int f = 0; f < 6; ++f) {
		std::vector<Placed> s = sceneAt(f, false, 0);
		if (f == 5) /* far beyond its predicted region */
			s[2].corners = squarePose(560.0f, 80.0f, 50.0f, 35.0f, 10.0f);
		const Image img = movingFrame(f, s);
		const Result &r = det.detect(img.view());
		ASSERT_EQ(r.markers.size(), 3u) << "frame " << f;
		const Marker *m = findMarker(r.markers, 99);
		ASSERT_NE(m, nullptr) << "frame " << f;
		EXPECT_LT(meanCornerError(m->corners, s[2].corners), 0.35f) << "frame " << f;
		if (f == 5) {
			EXPECT_TRUE(r.whole_frame) << "the lost marker's frame is searched again, whole";
			EXPECT_FALSE(m->tracked) << "far from its prediction: found afresh";
			EXPECT_TRUE(findMarker(r.markers, 7)->tracked);
		} else if (f > 0) {
			EXPECT_FALSE(r.whole_frame) << "frame " << f;
		}
	}
}

TEST(Tracking, NothingExtrapolatedASceneChangeSearchesWholeAndResetForgets)
{
	Config cfg;
	cfg.mode = Mode::Track;
	Detector det(cfg);
	for (int f = 0; f < 4; ++f)
		det.detect(movingFrame(f, sceneAt(f, false, 0)).view());
	/* A marker covered: never reported from its track. */
	std::vector<Placed> s = sceneAt(4, false, 0);
	s.erase(s.begin());
	const Result &r = det.detect(movingFrame(4, s).view());
	EXPECT_EQ(r.markers.size(), 2u);
	EXPECT_EQ(findMarker(r.markers, 7), nullptr);

	/* Another scene altogether. */
	const Image other = busyFrame(640, 480, 11);
	const Result &c = det.detect(other.view());
	EXPECT_TRUE(c.whole_frame);
	EXPECT_EQ(c.markers.size(), 5u);
	const Result &c2 = det.detect(other.view());
	EXPECT_FALSE(c2.whole_frame);
	EXPECT_EQ(c2.markers.size(), 5u);
	for (const Marker &m : c2.markers)
		EXPECT_TRUE(m.tracked) << m.id;
	det.reset();
	EXPECT_TRUE(det.detect(other.view()).whole_frame);
}

namespace {

/* A front end that cannot run on regions (its name is not the CPU's). */
class OtherFrontEnd final : public FrontEnd
{
public:
	const char *name() const override { return "other"; }
	void run(const ImageView &image, float scale, const FrontEndParams &params, EdgeMap &out) override
	{
		cpu_->run(image, scale, params, out);
	}
	bool makesRegionMap() const override { return true; }
	bool makesShadeMap() const override { return true; }

private:
	std::unique_ptr<FrontEnd> cpu_ = makeCpuFrontEnd(1);
};

} // namespace

TEST(Tracking, FrontEndsWithoutRegionsSearchEveryFrameWhole)
{
	Config cfg;
	cfg.mode = Mode::Track;
	Detector det(cfg);
	det.setFrontEnd(std::make_unique<OtherFrontEnd>());
	for (int f = 0; f < 5; ++f) {
		const Result &r = det.detect(movingFrame(f, sceneAt(f, false, 0)).view());
		EXPECT_TRUE(r.whole_frame);
		EXPECT_EQ(r.markers.size(), 3u);
		for (const Marker &m : r.markers)
			EXPECT_EQ(m.tracked, f > 0);
	}
}

/* The paper's pipelined mode: the next frame's front end (its plan from
 * the tracks) runs while this frame finishes (updating them), on two
 * threads; the tracks are under a lock. Every frame keeps its markers. */
TEST(Tracking, StagedPipelineTracksEveryFrame)
{
	Config cfg;
	cfg.mode = Mode::Track;
	for (int latency : { 1, 2 }) {
		Pipeline pipeline(cfg, Pipeline::Overlap::Stages, latency);
		std::vector<Image> frames;
		for (int f = 0; f < 12; ++f)
			frames.push_back(movingFrame(f, sceneAt(f, false, 0)));
		int out = 0, regions = 0;
		auto take = [&](const Result *r) {
			if (!r)
				return;
			const std::vector<Placed> truth = sceneAt(out, false, 0);
			EXPECT_EQ(r->markers.size(), truth.size()) << "latency " << latency << " frame " << out;
			for (const Placed &t : truth) {
				const Marker *m = findMarker(r->markers, t.id);
				ASSERT_NE(m, nullptr) << "latency " << latency << " frame " << out << " id " << t.id;
				EXPECT_LT(meanCornerError(m->corners, t.corners), 0.35f);
			}
			regions += r->whole_frame ? 0 : 1;
			++out;
		};
		for (const Image &img : frames)
			take(pipeline.push(img.view()));
		while (const Result *r = pipeline.flush())
			take(r);
		EXPECT_EQ(out, 12);
		EXPECT_GE(regions, 6) << "latency " << latency;
	}
}

TEST(Tracking, CoverFramesOutOfRangeIsRefused)
{
	Config cfg;
	cfg.mode = Mode::Track;
	cfg.track_cover_frames = 0;
	EXPECT_THROW(Detector{ cfg }, std::invalid_argument);
	cfg.track_cover_frames = 1001;
	EXPECT_THROW(Detector{ cfg }, std::invalid_argument);
	cfg.track_cover_frames = 1; /* every frame whole, with Marker::tracked */
	Detector det(cfg);
	for (int f = 0; f < 3; ++f)
		EXPECT_TRUE(det.detect(movingFrame(f, sceneAt(f, false, 0)).view()).whole_frame);
}
