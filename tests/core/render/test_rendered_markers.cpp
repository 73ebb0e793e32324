// SPDX-License-Identifier: MIT
// Markers of every dictionary rendered under known homographies, blur and
// noise: the detector must find each with the right id and corners within
// 0.3 px of the truth, in the canonical corner order.
#include <algorithm>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <random>

#include <gtest/gtest.h>

#include "frappe/frappe.h"
#include "scene.h"

using namespace frappe;
using namespace frappe::test;

namespace {

struct ScenePose {
	float side;  ///< pixels
	float roll;  ///< degrees in the image plane
	float tilt;  ///< degrees out of the plane
	float blur;  ///< Gaussian sigma, pixels
	float noise; ///< grey levels
};

/* From small and sharp to large, tilted and blurred. Sides are in cells of
 * at least 3.5 px: below that no decoder reads a code reliably. */
const ScenePose kPoses[] = {
	{ 0, 0, 0, 0.0f, 2.0f },    /* side filled in: 3.5 px per cell */
	{ 60, 17, 30, 0.6f, 3.0f },
	{ 90, -40, 45, 0.8f, 3.0f },
	{ 140, 120, 60, 1.0f, 4.0f },
	{ 300, 200, 20, 1.5f, 3.0f },
};

/* Every (id, corners) of the truth found, corners within `tolerance` px on
 * average. */
void expectAllFound(const Result &res, const std::vector<std::pair<int, std::array<Point2f, 4>>> &truth,
		    float tolerance)
{
	for (const auto &[id, q] : truth) {
		const Marker *m = findMarker(res.markers, id);
		ASSERT_NE(m, nullptr) << "id " << id;
		EXPECT_LT(meanCornerError(m->corners, q), tolerance) << "id " << id;
	}
}

} // namespace

class RenderedMarkers : public ::testing::TestWithParam<int> {};

TEST_P(RenderedMarkers, FoundWithExactIdAndSubPixelCorners)
{
	const Dictionary &dict = dictionaries()[GetParam()];
	Config cfg;
	cfg.dictionary = std::string(dict.name);
	Detector det(cfg);
	std::mt19937 rng(7 + GetParam());
	int poseIndex = 0;
	for (ScenePose pose : kPoses) {
		if (pose.side == 0)
			pose.side = 3.5f * (dict.bits + 2);
		const int id = (poseIndex * 37 + 11) % dict.size();
		const int size = static_cast<int>(pose.side * 1.8f) + 40;
		Image img(size, size, 60);
		const auto truth = squarePose(size / 2.0f + 0.3f, size / 2.0f - 0.2f, pose.side, pose.roll, pose.tilt);
		RenderOptions opt;
		opt.quiet_cells = 1;
		opt.black = 20;
		opt.white = 230;
		/* Under a blur of a pixel or more, 2x2 samples a pixel draw what
		 * 4x4 do to within the noise, at a quarter of the cost (the
		 * large poses' rendering was this test's minute under qemu). */
		opt.supersample = pose.blur >= 1.0f ? 2 : 4;
		renderMarker(img.mut(), dict, id, truth, opt);
		blur(img, pose.blur);
		addNoise(img, pose.noise, rng);

		const Result &res = det.detect(img.view());
		const Marker *m = findMarker(res.markers, id);
		ASSERT_NE(m, nullptr) << dict.name << " pose " << poseIndex << " (side " << pose.side
				      << ", tilt " << pose.tilt << ", blur " << pose.blur << ") not found; "
				      << res.markers.size() << " markers, " << res.candidates << " candidates";
		EXPECT_EQ(res.markers.size(), 1u) << dict.name << " pose " << poseIndex;
		const float err = meanCornerError(m->corners, truth);
		EXPECT_LT(err, 0.3f) << dict.name << " pose " << poseIndex;
		for (int k = 0; k < 4; ++k) {
			EXPECT_LT(std::hypot(m->corners[k].x - truth[k].x, m->corners[k].y - truth[k].y), 0.6f)
				<< dict.name << " pose " << poseIndex << " corner " << k;
		}
		++poseIndex;
	}
}

INSTANTIATE_TEST_SUITE_P(All, RenderedMarkers,
			 ::testing::Range(0, static_cast<int>(dictionaries().size())),
			 [](const auto &info) { return std::string(dictionaries()[info.param].name); });

TEST(RenderedMarkers, ManyMarkersInOneFrame)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	Detector det(Config{});
	Image img(640, 480, 90);
	std::vector<std::pair<int, std::array<Point2f, 4>>> truth;
	for (int r = 0; r < 4; ++r) {
		for (int c = 0; c < 6; ++c) {
			const int id = r * 6 + c;
			const auto q = squarePose(60.0f + c * 104.0f, 65.0f + r * 115.0f, 56.0f, 10.0f * id - 100.0f,
						 static_cast<float>((id * 7) % 40));
			RenderOptions opt;
			renderMarker(img.mut(), dict, id, q, opt);
			truth.emplace_back(id, q);
		}
	}
	const Result &res = det.detect(img.view());
	EXPECT_EQ(res.markers.size(), 24u);
	expectAllFound(res, truth, 0.3f);
}

/* Sub-pixel placement: an upright marker slid across one pixel in tenths.
 * The corners must follow the true sides at every phase, not snap towards
 * the pixel grid (a peak-fitting refinement was off by a third of a pixel at
 * phases .1 and .9). The renderer's 16x supersampling is exact to 1/32 px. */
TEST(RenderedMarkers, CornersFollowSubPixelPhase)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	Detector det(Config{});
	RenderOptions opt;
	opt.supersample = 16;
	for (int i = 0; i < 10; ++i) {
		const float x = 40.0f + 0.1f * static_cast<float>(i), y = 30.0f + 0.07f * static_cast<float>(i);
		const float s = 120.0f;
		const std::array<Point2f, 4> q{ Point2f{ x, y }, { x + s, y }, { x + s, y + s }, { x, y + s } };
		Image img(220, 200, 128);
		renderMarker(img.mut(), dict, i + 3, q, opt);
		const Result &res = det.detect(img.view());
		const Marker *m = findMarker(res.markers, i + 3);
		ASSERT_NE(m, nullptr) << "phase " << i;
		for (int k = 0; k < 4; ++k) {
			EXPECT_NEAR(m->corners[k].x, q[k].x, 0.06f) << "phase " << i << " corner " << k;
			EXPECT_NEAR(m->corners[k].y, q[k].y, 0.06f) << "phase " << i << " corner " << k;
		}
	}
}

/* A batch warper (here the CPU's own, through the interface a QPU warper
 * implements) must give exactly the markers of the one-by-one path, on a
 * frame with many candidates, nested outlines and clutter. */
TEST(RenderedMarkers, BatchWarpGivesTheSameMarkers)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	/* Many small and middling markers; then large ones, whose cells are
	 * read on the frame halved, outside the batch. */
	for (int frame = 0; frame < 2; ++frame) {
		Image img(640, 480, 90);
		std::mt19937 rng(3);
		const int n = frame == 0 ? 18 : 2;
		for (int id = 0; id < n; ++id) {
			const auto q = frame == 0 ? squarePose(60.0f + (id % 6) * 104.0f, 80.0f + (id / 6) * 150.0f,
							       24.0f + 4.0f * id, 17.0f * id,
							       static_cast<float>((id * 11) % 55))
						  : squarePose(160.0f + 310.0f * id, 240.0f, 150.0f + 20.0f * id, 9.0f * id, 20.0f);
			RenderOptions opt;
			opt.quiet_cells = 1 + id % 3;
			renderMarker(img.mut(), dict, id, q, opt);
		}
		blur(img, frame == 0 ? 0.7f : 2.0f);
		addNoise(img, 3.0f, rng);

		Detector oneByOne(Config{});
		Detector batched(Config{});
		batched.setWarper(makeCpuWarper());
		ASSERT_NE(batched.warper(), nullptr);
		const Result a = oneByOne.detect(img.view());
		const Result &b = batched.detect(img.view());
		EXPECT_GE(a.markers.size(), frame == 0 ? 12u : 2u);
		ASSERT_EQ(a.markers.size(), b.markers.size());
		for (std::size_t i = 0; i < a.markers.size(); ++i) {
			EXPECT_EQ(a.markers[i].id, b.markers[i].id);
			EXPECT_EQ(a.markers[i].hamming, b.markers[i].hamming);
			for (int k = 0; k < 4; ++k) {
				EXPECT_EQ(a.markers[i].corners[k].x, b.markers[i].corners[k].x);
				EXPECT_EQ(a.markers[i].corners[k].y, b.markers[i].corners[k].y);
			}
		}
	}
}

/* The same blurred scene at 1x, 2x and 3x its resolution (each pixel
 * repeated): the same markers, with corners as close to the truth for their
 * size. Large cells are read on the frame halved, so refinement sees their
 * blurred edges at the scale it is made for; read on the frame itself, the
 * 2x and 3x corners were 0.6-0.8 of the scene's pixels off (0.01-0.02 now). */
TEST(RenderedMarkers, BlurredMarkersReadAlikeAtAnyResolution)
{
	const Dictionary &dict = *findDictionary("apriltag_36h11");
	Image img(320, 240, 120);
	std::array<std::array<Point2f, 4>, 2> truth;
	for (int id = 0; id < 2; ++id) {
		truth[id] = squarePose(85.0f + 150.0f * id, 120.0f, 80.0f + 20.0f * id, 15.0f + 20.0f * id, 25.0f);
		renderMarker(img.mut(), dict, 11 + id, truth[id]);
	}
	motionBlur(img, 5.0f, 0.4f);
	blur(img, 1.2f);
	std::mt19937 rng(2);
	addNoise(img, 2.0f, rng);
	Config cfg;
	cfg.dictionary = "apriltag_36h11";
	for (int s : { 1, 2, 3 }) {
		Image big(320 * s, 240 * s, 0);
		for (int y = 0; y < big.height; ++y)
			for (int x = 0; x < big.width; ++x)
				big.at(x, y) = img.at(x / s, y / s);
		Detector det(cfg);
		const Result &r = det.detect(big.view());
		for (int id = 0; id < 2; ++id) {
			const Marker *m = findMarker(r.markers, 11 + id);
			ASSERT_NE(m, nullptr) << s << "x, id " << 11 + id;
			std::array<Point2f, 4> c = m->corners;
			for (Point2f &p : c)
				p = { (p.x + 0.5f) / static_cast<float>(s) - 0.5f, (p.y + 0.5f) / static_cast<float>(s) - 0.5f };
			const float err = meanCornerError(c, truth[id]);
			std::printf("%dx id %d: corner error %.3f scene px\n", s, 11 + id, err);
			EXPECT_LT(err, 0.5f) << s << "x, id " << 11 + id;
		}
	}
}

/* A board: markers one cell apart, as on a calibration target. Each one's
 * inside is skipped once it decodes; its neighbours, a cell away, must not
 * be. */
TEST(RenderedMarkers, BoardWithOneCellGaps)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	Detector det(Config{});
	Image img(640, 480, 255);
	constexpr float kSide = 40.0f, kPitch = kSide * 9.0f / 8.0f; /* one cell of 5 px between */
	std::vector<std::pair<int, std::array<Point2f, 4>>> truth;
	for (int r = 0; r < 6; ++r) {
		for (int c = 0; c < 8; ++c) {
			const int id = 100 + r * 8 + c;
			const float x = 130.0f + c * kPitch, y = 100.0f + r * kPitch;
			const std::array<Point2f, 4> q = { Point2f{ x, y }, Point2f{ x + kSide, y },
							   Point2f{ x + kSide, y + kSide }, Point2f{ x, y + kSide } };
			/* The page is white: a drawn quiet zone would overlap the
			 * neighbour's border pixels. */
			RenderOptions opt;
			opt.quiet_cells = 0;
			renderMarker(img.mut(), dict, id, q, opt);
			truth.emplace_back(id, q);
		}
	}
	const Result &res = det.detect(img.view());
	EXPECT_EQ(res.markers.size(), truth.size());
	expectAllFound(res, truth, 0.1f);
}

/* The tracer skips the inside of a quad only when its traced outline reads
 * as an exact codeword. A dark panel whose cells read one bit away from a
 * codeword (max_hamming 2 would decode it) must not hide a small marker
 * lying in one of its white cells: with the skip allowed on any decodable
 * read, it was hidden. The panel stands on grey, without a quiet zone, so
 * that it is not reported itself: a marker inside a decoded marker's code
 * area is taken for a block of its code cells and dropped. */
TEST(RenderedMarkers, MarkerInsideANearCodewordPanelIsFound)
{
	const Dictionary &dict = *findDictionary("4x4_50");
	Config config;
	config.dictionary = "4x4_50";
	config.max_hamming = 2;
	Detector det(config);
	Image img(640, 480, 110);
	/* The panel: marker 0 drawn as 6 x 6 cells of 70 px, then one code cell
	 * flipped. */
	constexpr int kCell = 70, x0 = 110, y0 = 30;
	const std::array<Point2f, 4> panel = { Point2f{ x0, y0 }, Point2f{ x0 + 6 * kCell, y0 },
					       Point2f{ x0 + 6 * kCell, y0 + 6 * kCell }, Point2f{ x0, y0 + 6 * kCell } };
	RenderOptions quiet, bare;
	bare.quiet_cells = 0;
	renderMarker(img.mut(), dict, 0, panel, bare);
	auto cellIsWhite = [&](int cx, int cy) { return img.at(x0 + cx * kCell + kCell / 2, y0 + cy * kCell + kCell / 2) > 128; };
	auto fillCell = [&](int cx, int cy, std::uint8_t v) {
		for (int y = 0; y < kCell; ++y)
			for (int x = 0; x < kCell; ++x)
				img.at(x0 + cx * kCell + x, y0 + cy * kCell + y) = v;
	};
	/* A white code cell to hold the small marker, another cell to flip. */
	int hx = -1, hy = -1;
	for (int cy = 1; cy <= 4 && hx < 0; ++cy)
		for (int cx = 1; cx <= 4 && hx < 0; ++cx)
			if (cellIsWhite(cx, cy)) {
				hx = cx;
				hy = cy;
			}
	ASSERT_GE(hx, 1);
	const int fx = hx == 4 ? 3 : hx + 1, fy = hy;
	fillCell(fx, fy, cellIsWhite(fx, fy) ? 0 : 255);
	/* The small marker in the holder cell's corner, clear of its centre,
	 * where the panel's cell is sampled. */
	const float sx = static_cast<float>(x0 + hx * kCell + 8), sy = static_cast<float>(y0 + hy * kCell + 8);
	const std::array<Point2f, 4> small = { Point2f{ sx, sy }, Point2f{ sx + 24, sy }, Point2f{ sx + 24, sy + 24 },
					       Point2f{ sx, sy + 24 } };
	renderMarker(img.mut(), dict, 7, small, quiet);

	const Result &res = det.detect(img.view());
	EXPECT_EQ(findMarker(res.markers, 0), nullptr) << "the panel has no quiet zone";
	const Marker *m = findMarker(res.markers, 7);
	ASSERT_NE(m, nullptr) << "the marker inside the panel";
	EXPECT_LT(meanCornerError(m->corners, small), 0.3f);
}

/* A tiled wall (a candidate per tile) around two markers: over
 * max_candidates the tiles beyond it are dropped and counted, and the
 * markers, which the trace's quick read already decoded, are kept. Under
 * it, nothing is dropped. */
TEST(RenderedMarkers, CandidateCapKeepsTheMarkersAndCountsTheRest)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	Image img(640, 480, 230);
	squareGrid(img, 12, 20);
	for (int y = 150; y < 330; ++y)
		for (int x = 60; x < 580; ++x)
			img.at(x, y) = 230;
	renderMarker(img.mut(), dict, 3, squarePose(180.0f, 240.0f, 120.0f, 5.0f, 0.0f));
	renderMarker(img.mut(), dict, 4, squarePose(460.0f, 240.0f, 120.0f, -5.0f, 0.0f));

	Detector all{ Config{} };
	const Result &r = all.detect(img.view());
	EXPECT_EQ(r.candidates_dropped, 0);
	EXPECT_EQ(r.markers.size(), 2u);
	EXPECT_GT(r.candidates, 400); /* the tiles were candidates */

	Config capped;
	capped.max_candidates = 50;
	Detector few(capped);
	const Result &c = few.detect(img.view());
	/* Dropped: every traced quad beyond 50, at least those that reached
	 * decoding without a cap. */
	EXPECT_GE(c.candidates_dropped, r.candidates - 50);
	EXPECT_LE(c.candidates, 50);
	ASSERT_EQ(c.markers.size(), 2u);
	EXPECT_NE(findMarker(c.markers, 3), nullptr);
	EXPECT_NE(findMarker(c.markers, 4), nullptr);
}

namespace {

/* The message of the exception of type E that f throws; fails the test
 * when it throws none or another. */
template<typename E, typename F>
std::string messageOf(F f)
{
	try {
		f();
	} catch (const E &e) {
		return e.what();
	} catch (const std::exception &e) {
		ADD_FAILURE() << "other exception: " << e.what();
		return {};
	}
	ADD_FAILURE() << "no exception";
	return {};
}

bool has(const std::string &message, const std::string &part)
{
	return message.find(part) != std::string::npos;
}

} // namespace

/* Corners no perspective maps a square onto are refused, naming them, and
 * the image is left as it was. */
TEST(RenderArguments, DegenerateCornersAreRefused)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	Image img(64, 64, 128);
	auto render = [&](std::array<Point2f, 4> c) { return [&, c] { renderMarker(img.mut(), dict, 0, c); }; };
	const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
	using Corners = std::array<Point2f, 4>;
	EXPECT_TRUE(has(messageOf<std::invalid_argument>(render(Corners{ Point2f{ 10, 10 }, { 50, 10 }, { 50, nan }, { 10, 50 } })),
			"corner 2 is not a finite point"));
	EXPECT_TRUE(has(messageOf<std::invalid_argument>(render(Corners{ Point2f{ inf, 10 }, { 50, 10 }, { 50, 50 }, { 10, 50 } })),
			"corner 0 is not a finite point"));
	/* Three collinear corners, two coincident, all four at one point. */
	EXPECT_TRUE(has(messageOf<std::invalid_argument>(render(Corners{ Point2f{ 10, 10 }, { 30, 10 }, { 50, 10 }, { 10, 50 } })),
			"collinear or coincide"));
	EXPECT_TRUE(has(messageOf<std::invalid_argument>(render(Corners{ Point2f{ 10, 10 }, { 10, 10 }, { 50, 50 }, { 10, 50 } })),
			"collinear or coincide"));
	EXPECT_TRUE(has(messageOf<std::invalid_argument>(render(Corners{ Point2f{ 5, 5 }, { 5, 5 }, { 5, 5 }, { 5, 5 } })),
			"collinear or coincide"));
	/* A crossed outline (a bow tie). */
	EXPECT_TRUE(has(messageOf<std::invalid_argument>(render(Corners{ Point2f{ 10, 10 }, { 50, 50 }, { 50, 10 }, { 10, 50 } })),
			"not make a convex quadrilateral"));
	EXPECT_TRUE(std::all_of(img.pixels.begin(), img.pixels.end(), [](std::uint8_t v) { return v == 128; }));
	/* A mirrored view (corners anticlockwise) is a perspective still. */
	renderMarker(img.mut(), dict, 0, Corners{ Point2f{ 10, 10 }, { 10, 50 }, { 50, 50 }, { 50, 10 } });
	EXPECT_EQ(img.at(12, 30), 0);
}

TEST(RenderArguments, BadImagesIdsAndOptionsAreRefused)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	Image img(64, 64, 128);
	const std::array<Point2f, 4> c{ Point2f{ 10, 10 }, { 50, 10 }, { 50, 50 }, { 10, 50 } };
	EXPECT_TRUE(has(messageOf<std::out_of_range>([&] { renderMarker(img.mut(), dict, dict.size(), c); }),
			"id " + std::to_string(dict.size()) + " not in aruco_mip_36h12"));
	EXPECT_TRUE(has(messageOf<std::out_of_range>([&] { renderMarker(img.mut(), dict, -1, c); }), "id -1"));
	MutableImageView view = img.mut();
	view.width = -4;
	EXPECT_TRUE(has(messageOf<std::invalid_argument>([&] { renderMarker(view, dict, 0, c); }), "must not be negative"));
	view = img.mut();
	view.data = nullptr;
	EXPECT_TRUE(has(messageOf<std::invalid_argument>([&] { renderMarker(view, dict, 0, c); }), "data is null"));
	view = img.mut();
	view.stride = 32;
	EXPECT_TRUE(has(messageOf<std::invalid_argument>([&] { renderMarker(view, dict, 0, c); }),
			"stride (32) is smaller than its width (64)"));
	RenderOptions opt;
	opt.supersample = 100000; /* 10^10 samples a pixel would overflow */
	EXPECT_TRUE(has(messageOf<std::invalid_argument>([&] { renderMarker(img.mut(), dict, 0, c, opt); }),
			"supersample must be 1..256, got 100000"));
	/* An empty image: nothing to draw, nothing refused. */
	EXPECT_NO_THROW(renderMarker(MutableImageView{}, dict, 0, c));
}

/* A quiet zone reaching past the horizon (around a strongly foreshortened
 * square) has no bounding box from its corners: the marker is drawn all
 * the same, and no infinite box is cast to int. */
TEST(RenderArguments, QuietZoneBeyondTheHorizonStaysInTheImage)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	Image img(64, 64, 128);
	RenderOptions opt;
	opt.quiet_cells = 40;
	opt.supersample = 1;
	EXPECT_NO_THROW(renderMarker(img.mut(), dict, 0,
				     { Point2f{ 20, 20 }, { 44, 20 }, { 60, 40 }, { 4, 40 } }, opt));
	EXPECT_EQ(img.at(21, 21), 0);	/* the border, by its first corner */
	EXPECT_NE(img.at(32, 30), 128); /* the code */
}

/* Issue 34: quiet_cells = 2^31 - 1 overflowed an int (undefined
 * behaviour), and a negative quiet_cells or supersample was clamped
 * silently where markerImage() refused it. Both refuse what they cannot
 * draw, with the same words. */
TEST(RenderArguments, QuietCellsAndSupersampleOutOfRangeAreRefused)
{
	const Dictionary &dict = *findDictionary("4x4_50");
	Image img(64, 64, 128);
	const std::array<Point2f, 4> c{ Point2f{ 10, 10 }, { 50, 10 }, { 50, 50 }, { 10, 50 } };
	for (const int quiet : { -1, 32769, 2147483647 }) {
		RenderOptions opt;
		opt.quiet_cells = quiet;
		EXPECT_EQ(messageOf<std::invalid_argument>([&] { renderMarker(img.mut(), dict, 0, c, opt); }),
			  "renderMarker: quiet_cells must be 0..32768, got " + std::to_string(quiet));
		int side = 0;
		EXPECT_EQ(messageOf<std::invalid_argument>([&] { markerImage(dict, 0, 1, quiet, side); }),
			  "markerImage: quiet_cells must be 0..32768, got " + std::to_string(quiet));
	}
	for (const int ss : { 0, -7, 257 }) {
		RenderOptions opt;
		opt.supersample = ss;
		EXPECT_EQ(messageOf<std::invalid_argument>([&] { renderMarker(img.mut(), dict, 0, c, opt); }),
			  "renderMarker: supersample must be 1..256, got " + std::to_string(ss));
	}
	EXPECT_EQ(img.at(30, 30), 128) << "nothing drawn by a refused call";
	/* The widest quiet zone accepted is drawn, its cells computed in range. */
	RenderOptions widest;
	widest.quiet_cells = 32768;
	widest.supersample = 1;
	EXPECT_NO_THROW(renderMarker(img.mut(), dict, 0, c, widest));
	EXPECT_EQ(img.at(12, 12), 0);
	EXPECT_EQ(img.at(1, 1), 255) << "the quiet zone reaches the image's corner";
}

TEST(RenderArguments, MarkerImageRefusesBadSizesAndIds)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	int side = -1;
	EXPECT_TRUE(has(messageOf<std::invalid_argument>([&] { markerImage(dict, 0, 0, 1, side); }),
			"cell_px must be at least 1, got 0"));
	EXPECT_TRUE(has(messageOf<std::invalid_argument>([&] { markerImage(dict, 0, -3, 1, side); }), "got -3"));
	EXPECT_TRUE(has(messageOf<std::invalid_argument>([&] { markerImage(dict, 0, 4, -5, side); }),
			"quiet_cells must be 0..32768, got -5"));
	EXPECT_TRUE(has(messageOf<std::invalid_argument>([&] { markerImage(dict, 0, 1 << 28, 1, side); }),
			"more than 32768"));
	EXPECT_TRUE(has(messageOf<std::out_of_range>([&] { markerImage(dict, dict.size(), 4, 1, side); }), "not in"));
	EXPECT_EQ(side, -1); /* untouched by a refused call */
	const std::vector<std::uint8_t> px = markerImage(dict, 0, 4, 1, side);
	EXPECT_EQ(side, (dict.bits + 4) * 4);
	EXPECT_EQ(px.size(), static_cast<std::size_t>(side) * side);
}

/* Issue 34: past max_candidates the cap kept the exact reads, then the
 * smallest: a 360 px marker with one damaged bit in a 1080p frame of a 16 px
 * grid of squares (a perforated sheet: some 7,000 candidates) was dropped
 * first. The trace's quick read now ranks a near codeword before the
 * tiles, so it is read; the frame's time stays that of its candidates. */
TEST(RenderedMarkers, DamagedMarkerInClutterIsNotDropped)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	Image img(1920, 1080, 230);
	squareGrid(img, 12, 16);
	const int cx = 1200, cy = 520, side = 360, cell = side / (dict.bits + 2);
	for (int y = cy - 260; y < cy + 260; ++y)
		for (int x = cx - 260; x < cx + 260; ++x)
			img.at(x, y) = 230;
	const int id = 5;
	renderMarker(img.mut(), dict, id, squarePose(static_cast<float>(cx), static_cast<float>(cy), side, 0.0f, 0.0f));
	/* One code cell flipped: one bit away from id 5's codeword. */
	const int x0 = cx - side / 2, y0 = cy - side / 2, bx = 3, by = 2;
	const std::uint8_t was = img.at(x0 + bx * cell + cell / 2, y0 + by * cell + cell / 2);
	for (int y = 0; y < cell; ++y)
		for (int x = 0; x < cell; ++x)
			img.at(x0 + bx * cell + x, y0 + by * cell + y) = was < 128 ? 255 : 0;

	Detector det{ Config{} };
	const auto t0 = std::chrono::steady_clock::now();
	const Result &r = det.detect(img.view());
	const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
	std::printf("1080p, %d candidates read, %d dropped: %.1f ms\n", r.candidates, r.candidates_dropped, ms);
	EXPECT_GT(r.candidates_dropped, 1000) << "the tiles overflow the cap";
	EXPECT_LE(r.candidates, Config{}.max_candidates);
	ASSERT_EQ(r.markers.size(), 1u);
	EXPECT_EQ(r.markers[0].id, id);
	EXPECT_EQ(r.markers[0].hamming, 1);
	EXPECT_LT(meanCornerError(r.markers[0].corners, squarePose(static_cast<float>(cx), static_cast<float>(cy), side,
								      0.0f, 0.0f)),
		  1.0f);
}

/* Issue 34: the candidates stat counted a quad twice when it was read at
 * its outline and then inset, and could exceed max_candidates. Scenes of
 * random grey rectangles (one of these went 6 over a cap of 5). */
TEST(RenderedMarkers, CandidatesNeverExceedTheCap)
{
	std::mt19937 rng(1);
	int over = 0;
	Config c5, c20;
	c5.max_candidates = 5;
	c20.max_candidates = 20;
	Detector capped[] = { Detector(c5), Detector(c20) };
	for (int trial = 0; trial < 32; ++trial) {
		Image img(640, 480, trial % 2 ? 230 : 40);
		std::uniform_int_distribution<int> x(0, img.width - 1), y(0, img.height - 1), side(8, 80), grey(0, 255);
		for (int k = 0; k < 50 + trial; ++k) {
			const int x0 = x(rng), y0 = y(rng), w = side(rng), h = side(rng);
			const auto g = static_cast<std::uint8_t>(grey(rng));
			for (int yy = y0; yy < std::min(img.height, y0 + h); ++yy)
				for (int xx = x0; xx < std::min(img.width, x0 + w); ++xx)
					img.at(xx, yy) = g;
		}
		/* Drawn for every trial, the same scenes as ever; detected on
		 * the last eight (trial 25 went over). */
		if (trial < 24)
			continue;
		for (Detector &det : capped) {
			const int cap = det.config().max_candidates;
			const Result &r = det.detect(img.view());
			EXPECT_LE(r.candidates, cap) << "trial " << trial;
			over += r.candidates > cap;
		}
	}
	EXPECT_EQ(over, 0);
}
