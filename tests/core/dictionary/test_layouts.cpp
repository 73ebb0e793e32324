// SPDX-License-Identifier: MIT
// Marker layouts (frappe/layout.h): the layout type, dictionary files with
// `layout` rows, and AprilTag 3's five layout families found on rendered
// scenes with exact ids and corners, and never read from another family.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "frappe/frappe.h"
#include "frappe/layout.h"
#include "scene.h"

using namespace frappe;
using namespace frappe::test;

namespace {

const char *const kLayoutFamilies[] = { "apriltag_standard41h12", "apriltag_standard52h13", "apriltag_circle21h7",
					"apriltag_circle49h12", "apriltag_custom48h12" };

std::string expectInvalid(const std::string &text)
{
	try {
		parseDictionary(text, "test");
	} catch (const std::invalid_argument &e) {
		return e.what();
	}
	ADD_FAILURE() << "accepted:\n" << text;
	return {};
}

} // namespace

TEST(MarkerLayout, ClassicIsTodaysMarker)
{
	for (int n = 3; n <= 8; ++n) {
		const MarkerLayout l = MarkerLayout::classic(n);
		EXPECT_EQ(l.size, n + 2);
		EXPECT_EQ(l.square_start, 0);
		EXPECT_EQ(l.square_cells, n + 2);
		EXPECT_FALSE(l.reversed);
		EXPECT_EQ(l.code_bits, n * n);
		std::mt19937_64 rng(n);
		for (int k = 0; k < 50; ++k) {
			/* 8x8 takes all 64 bits: a shift by 64 is undefined. */
			const std::uint64_t mask =
				n * n == 64 ? ~std::uint64_t{ 0 } : (std::uint64_t{ 1 } << (n * n)) - 1;
			const std::uint64_t code = rng() & mask;
			EXPECT_EQ(l.rotate(code), rotateCode(code, n));
		}
		EXPECT_EQ(MarkerLayout::fromRows(l.rows()).cells, l.cells);
	}
}

TEST(MarkerLayout, AprilTagFamiliesBuiltIn)
{
	struct Want {
		const char *name;
		int size, start, cells, bits, codes, hamming;
	};
	const Want wants[] = {
		{ "apriltag_standard41h12", 9, 2, 5, 41, 2115, 12 }, { "apriltag_standard52h13", 10, 2, 6, 52, 48714, 13 },
		{ "apriltag_circle21h7", 9, 2, 5, 21, 38, 7 },        { "apriltag_circle49h12", 11, 3, 5, 49, 65535, 12 },
		{ "apriltag_custom48h12", 10, 2, 6, 48, 42211, 12 },
	};
	for (const Want &w : wants) {
		const Dictionary *d = findDictionary(w.name);
		ASSERT_NE(d, nullptr) << w.name;
		ASSERT_NE(d->layout, nullptr) << w.name;
		EXPECT_EQ(d->layout->size, w.size) << w.name;
		EXPECT_EQ(d->layout->square_start, w.start) << w.name;
		EXPECT_EQ(d->layout->square_cells, w.cells) << w.name;
		EXPECT_TRUE(d->layout->reversed) << w.name;
		EXPECT_EQ(d->codeBits(), w.bits) << w.name;
		EXPECT_EQ(d->bits + 2, w.cells) << w.name;
		EXPECT_EQ(d->size(), w.codes) << w.name;
		EXPECT_EQ(d->min_hamming, w.hamming) << w.name;
		/* Four quarter turns are none. */
		for (int id = 0; id < d->size(); id += 97) {
			const std::uint64_t c = d->codes[id];
			EXPECT_EQ(d->rotate(d->rotate(d->rotate(d->rotate(c)))), c);
			EXPECT_NE(d->rotate(c), c) << w.name << " id " << id;
		}
	}
	/* AprilTag's own names. */
	EXPECT_EQ(findDictionary("tagStandard41h12"), findDictionary("apriltag_standard41h12"));
	EXPECT_EQ(findDictionary("tagCircle21h7"), findDictionary("apriltag_circle21h7"));
	EXPECT_EQ(findDictionary("tagCustom48h12"), findDictionary("apriltag_custom48h12"));
}

TEST(MarkerLayout, FileLoadsAsTheBuiltIn)
{
	for (const char *name : { "apriltag_standard41h12", "apriltag_circle21h7", "apriltag_circle49h12" }) {
		const auto d = loadDictionary(std::string(FRAPPE_SOURCE_ROOT) + "/frappe-core/dictionaries/" + name + ".txt");
		const Dictionary *b = findDictionary(name);
		ASSERT_NE(d->layout, nullptr);
		EXPECT_EQ(d->layout->cells, b->layout->cells) << name;
		EXPECT_EQ(d->bits, b->bits) << name;
		EXPECT_EQ(d->min_hamming, b->min_hamming) << name;
		ASSERT_EQ(d->size(), b->size()) << name;
		EXPECT_TRUE(std::equal(d->codes.begin(), d->codes.end(), b->codes.begin())) << name;
	}
}

TEST(MarkerLayout, SmallLayoutFileComputesItsDistance)
{
	/* tagCircle21h7's layout and three of its codes. */
	const std::string text = "# a test\n"
				 "layout b b b 0 1 2 b b b\nlayout b b b b b b b b b\nlayout b b w w w w w b b\n"
				 "layout 17 b w 3 4 8 w b 5\nlayout 16 b w 19 20 9 w b 6\nlayout 15 b w 18 14 13 w b 7\n"
				 "layout b b w w w w w b b\nlayout b b b b b b b b b\nlayout b b b 12 11 10 b b b\n"
				 "0x157863\n0x047e28\n0x1383ed\n";
	const auto d = parseDictionary(text, "three");
	ASSERT_NE(d->layout, nullptr);
	EXPECT_EQ(d->codeBits(), 21);
	EXPECT_EQ(d->bits, 3);
	EXPECT_GE(d->min_hamming, 7);
	EXPECT_EQ(d->size(), 3);
}

TEST(MarkerLayout, BadLayoutsSayWhy)
{
	const std::string ring = "layout b b b b b\nlayout b w w w b\n";
	const std::string tail = "layout b w w w b\nlayout b b b b b\n0x1\n";
	/* 5 x 5: black ring, white ring, one bit. */
	EXPECT_NO_THROW(parseDictionary(ring + "layout b w 0 w b\n" + tail, "ok"));
	EXPECT_NE(expectInvalid(ring + "layout b w q w b\n" + tail).find("'q' is none of b, w, x"), std::string::npos);
	EXPECT_NE(expectInvalid(ring + "layout b w 0 w\n" + tail).find("4 cells, not 5"), std::string::npos);
	EXPECT_NE(expectInvalid(ring + "layout b w w w b\n" + tail).find("without bits"), std::string::npos);
	EXPECT_NE(expectInvalid(ring + "layout b w 1 w b\n" + tail).find("bit 0 is missing"), std::string::npos);
	EXPECT_NE(expectInvalid(ring + "layout b w 0 0 b\n" + tail).find("bit 0 again"), std::string::npos);
	/* Truncated: a row short. */
	EXPECT_NE(expectInvalid(ring + "layout b w 0 w b\nlayout b b b b b\n0x1\n").find("a layout is square"),
		  std::string::npos);
	/* Not the same turned. */
	EXPECT_NE(expectInvalid("layout b b b b b\nlayout b w w w b\nlayout b 0 w 1 b\nlayout b w w w b\n"
				"layout b b b b b\n0x1\n")
			  .find("quarter turn"),
		  std::string::npos);
	/* No square to find. */
	EXPECT_NE(expectInvalid("layout w w w\nlayout w 0 w\nlayout w w w\n0x1\n").find("no square"), std::string::npos);
	/* Codes wider than the layout, rows after codes, a side header too. */
	EXPECT_NE(expectInvalid(ring + "layout b w 0 w b\n" + "layout b w w w b\nlayout b b b b b\n0x2\n")
			  .find("beyond the layout's 1"),
		  std::string::npos);
	EXPECT_NE(expectInvalid(ring + "layout b w 0 w b\nlayout b w w w b\n0x1\nlayout b b b b b\n").find("after the codes"),
		  std::string::npos);
	EXPECT_NE(expectInvalid("# marker_side_bits: 3\n" + ring + "layout b w 0 w b\n" + tail).find("layout gives the side"),
		  std::string::npos);
	/* The message names the first layout row's line. */
	EXPECT_NE(expectInvalid("# x\n" + ring + "layout b w 0 z b\n" + tail).find("test:2:"), std::string::npos);
}

namespace {

struct Placed {
	int id;
	std::array<Point2f, 4> corners;
};

/* A scene of `count` markers of `dict` on a textured grey, in perspective,
 * blurred and noisy; the truth is the detected squares' corners. */
std::vector<Placed> renderScene(Image &img, const Dictionary &dict, int count, std::mt19937 &rng, float side0,
				float blurSigma, float noise)
{
	std::uniform_real_distribution<float> u(0.0f, 1.0f);
	std::vector<Placed> placed;
	const float sizeCells = static_cast<float>(dict.layout ? dict.layout->size : dict.bits + 2) + 2.0f;
	const float squareCells = static_cast<float>(dict.bits + 2);
	const int cols = std::max(1, count / 2 + count % 2), rows = count > 1 ? 2 : 1;
	const float cw = static_cast<float>(img.width) / cols, ch = static_cast<float>(img.height) / rows;
	for (int k = 0; k < count; ++k) {
		/* The whole layout and its quiet zone fit its slot. */
		const float side = std::min(side0 * (0.8f + 0.4f * u(rng)), 0.8f * std::min(cw, ch) * squareCells / sizeCells);
		const float cx = cw * (static_cast<float>(k % cols) + 0.5f), cy = ch * (static_cast<float>(k / cols) + 0.5f);
		/* One draw a statement, in the order x86 has drawn them: a call's
		 * arguments are evaluated in an unspecified order (GCC for ARM
		 * draws them in another, rendering other scenes). */
		const float tilt = 50.0f * u(rng);
		const float roll = 360.0f * u(rng);
		const float dy = u(rng);
		const float dx = u(rng);
		const auto q = squarePose(cx + dx - 0.5f, cy + dy - 0.5f, side, roll, tilt);
		/* Ids differ within a scene (tagCircle21h7 has 38). */
		int id = 0;
		do
			id = static_cast<int>(rng() % static_cast<unsigned>(dict.size()));
		while (std::any_of(placed.begin(), placed.end(), [&](const Placed &p) { return p.id == id; }));
		RenderOptions opt;
		opt.black = static_cast<std::uint8_t>(15 + 30 * u(rng));
		opt.white = static_cast<std::uint8_t>(200 + 40 * u(rng));
		opt.supersample = 2; // a quarter of the samples of the default 4: rendering is this test's cost
		renderMarker(img.mut(), dict, id, q, opt);
		placed.push_back({ id, q });
	}
	blur(img, blurSigma);
	addNoise(img, noise, rng);
	return placed;
}

Detector detectorFor(const Dictionary &dict)
{
	Config cfg;
	cfg.dictionary = std::string(dict.name);
	return Detector(cfg);
}

} // namespace

class LayoutScenes : public ::testing::TestWithParam<const char *> {};

/* Every marker found with its id, corners within 0.3 px on average, and
 * nothing else. */
TEST_P(LayoutScenes, FoundWithExactIdsAndCorners)
{
	const Dictionary &dict = *findDictionary(GetParam());
	Detector det = detectorFor(dict);
	std::mt19937 rng(3);
	double errSum = 0.0;
	int found = 0, total = 0;
	const float cellsides[] = { 4.0f, 6.0f, 10.0f, 20.0f };
	for (float cellPx : cellsides) {
		for (int rep = 0; rep < 3; ++rep) {
			Image img(800, 500, static_cast<std::uint8_t>(90 + 60 * rep));
			const auto truth =
				renderScene(img, dict, 6, rng, cellPx * static_cast<float>(dict.bits + 2), 0.5f + 0.3f * rep, 3.0f);
			const Result &res = det.detect(img.view());
			for (const Placed &p : truth) {
				++total;
				const Marker *m = findMarker(res.markers, p.id);
				if (!m) {
					ADD_FAILURE() << dict.name << " cell " << cellPx << " rep " << rep << ": id " << p.id
						      << " not found";
					continue;
				}
				++found;
				const float err = meanCornerError(m->corners, p.corners);
				EXPECT_LT(err, 0.5f) << dict.name << " cell " << cellPx << " id " << p.id;
				errSum += err;
			}
			for (const Marker &m : res.markers) {
				const bool known = std::any_of(truth.begin(), truth.end(), [&](const Placed &p) {
					return p.id == m.id && meanCornerError(m.corners, p.corners) < 2.0f;
				});
				EXPECT_TRUE(known) << dict.name << ": a marker " << m.id << " that is not there";
			}
		}
	}
	EXPECT_EQ(found, total);
	if (found) {
		EXPECT_LT(errSum / found, 0.25) << dict.name;
	}
}

INSTANTIATE_TEST_SUITE_P(AprilTag3, LayoutScenes, ::testing::ValuesIn(kLayoutFamilies),
			 [](const auto &info) { return std::string(info.param); });

namespace {

/* Six scenes of 8 small markers of `dict`, cells of cell0 + 0.2 rep px:
 * the markers found with their ids, each within `maxErr` px on average,
 * and nothing else found; their corners' errors summed into `errSum`. */
int smallMarkersFound(const Dictionary &dict, std::mt19937 &rng, float cell0, float blurSigma, float noise,
		      float maxErr, double *errSum = nullptr)
{
	Detector det = detectorFor(dict);
	int found = 0;
	for (int rep = 0; rep < 6; ++rep) {
		Image img(640, 360, static_cast<std::uint8_t>(100 + 20 * (rep % 3)));
		const float cellPx = cell0 + 0.2f * static_cast<float>(rep);
		const auto truth =
			renderScene(img, dict, 8, rng, cellPx * static_cast<float>(dict.bits + 2), blurSigma, noise);
		const Result &res = det.detect(img.view());
		for (const Placed &p : truth) {
			const Marker *m = findMarker(res.markers, p.id);
			if (!m)
				continue;
			++found;
			const float err = meanCornerError(m->corners, p.corners);
			EXPECT_LT(err, maxErr) << dict.name << " cell " << cellPx << " id " << p.id;
			if (errSum)
				*errSum += err;
		}
		for (const Marker &m : res.markers) {
			const bool known = std::any_of(truth.begin(), truth.end(), [&](const Placed &p) {
				return p.id == m.id && meanCornerError(m.corners, p.corners) < 2.0f;
			});
			EXPECT_TRUE(known) << dict.name << ": a marker " << m.id << " that is not there";
		}
	}
	return found;
}

} // namespace

/* Small markers (cells of 2.2 to 3.4 px, blurred, tilted): a black ring of
 * 2-3 px joins the edges on both its sides and the square has no outline
 * of its own; read inside the traced ring or layout outline instead.
 * Exact ids, corners within 0.5 px on average, nothing else. */
TEST_P(LayoutScenes, SmallMarkersFoundInsideTheirOutline)
{
	const Dictionary &dict = *findDictionary(GetParam());
	std::mt19937 rng(7);
	const int found = smallMarkersFound(dict, rng, 2.2f, 0.6f, 3.0f, 0.5f), total = 48;
	std::printf("%s: %d of %d small markers found\n", dict.name.data(), found, total);
	/* 44-48 of the 48 of each family; 33-42 when only traced squares
	 * were read. */
	EXPECT_GE(found, total * 11 / 12) << dict.name;
}

/* Small markers blurred over a cell (sigma 1.2 at cells of 2.4-3.4 px):
 * their squares, guessed inside the traced outline, read with weak bits
 * that are corrected (at most half the clear bits a traced square may).
 * Exact ids, corners within 0.8 px (a third of a cell) on average,
 * nothing else; 193 of the 240 of the five families found (190 when
 * every plain corner cell counted), 180 when a guessed square corrected
 * no weak bit. */
TEST(LayoutScenes, SmallBlurredMarkersCorrectWeakBits)
{
	int found = 0;
	for (const char *family : kLayoutFamilies) {
		const Dictionary &dict = *findDictionary(family);
		std::mt19937 rng(17);
		const int here = smallMarkersFound(dict, rng, 2.4f, 1.2f, 4.0f, 0.8f);
		std::printf("%s: %d of 48 small blurred markers found\n", dict.name.data(), here);
		found += here;
	}
	EXPECT_GE(found, 186) << "of 240";
}

/* Small circle-family markers blurred over a cell (sigma 1.2 at cells of
 * 2-3 px): their plain corner cells read as a mixture (4 light, 16 dark
 * on a tagCircle21h7 marker whose bits read exactly), and only the clear
 * ones are evidence of another family. Exact ids, corners within 0.8 px
 * on average, nothing else; 116 of the 192 found, 109 when every plain
 * cell counted. */
TEST(LayoutScenes, SmallBlurredCirclesDespiteTheirCorners)
{
	int found = 0;
	for (const char *family : { "apriltag_circle21h7", "apriltag_circle49h12" }) {
		const Dictionary &dict = *findDictionary(family);
		for (const float cell0 : { 2.0f, 2.2f }) {
			std::mt19937 rng(34);
			const int here = smallMarkersFound(dict, rng, cell0, 1.2f, 4.0f, 0.8f);
			std::printf("%s: %d of 48 small blurred markers from %.1f px cells found\n", dict.name.data(),
				    here, static_cast<double>(cell0));
			found += here;
		}
	}
	EXPECT_GE(found, 114) << "of 192";
}

/* Small markers blurred as the hard scenes are (sigma 1.1 at cells of
 * 2.6-3.6 px): a cell beside the two rings of the other colour pulls the
 * sides' crossings by up to 0.3 px, with the bits along each side. With
 * the decoded pattern's pull taken out, the corners of the 212 markers of
 * the five families found are 0.203 px off on average (0.258 with the pull
 * left in; the rest is mostly rendering at 2 samples a pixel). */
TEST(LayoutScenes, SmallBlurredCornersWithoutTheirBitsPull)
{
	int found = 0;
	double errSum = 0.0;
	for (const char *family : kLayoutFamilies) {
		const Dictionary &dict = *findDictionary(family);
		std::mt19937 rng(41);
		double here = 0.0;
		const int n = smallMarkersFound(dict, rng, 2.6f, 1.1f, 4.0f, 0.8f, &here);
		std::printf("%s: %d of 48 found, corners %.3f px\n", dict.name.data(), n, n ? here / n : 0.0);
		found += n;
		errSum += here;
	}
	ASSERT_GT(found, 0);
	std::printf("corners %.4f px over %d markers\n", errSum / found, found);
	EXPECT_LT(errSum / found, 0.225);
}

/* Each layout family's detector over scenes of every other family (the
 * layouts and today's): nothing. Each scene is rendered once and shown to
 * every family's detector (rendering, not detecting, is what this test
 * spends: under qemu on the Pis' CPUs most of all). */
TEST(LayoutScenes, NoMarkersOfAnotherFamily)
{
	std::vector<std::string> others(std::begin(kLayoutFamilies), std::end(kLayoutFamilies));
	for (const char *n : { "aruco_mip_36h12", "apriltag_36h11", "4x4_50", "apriltag_16h5", "7x7_1000" })
		others.emplace_back(n);
	std::vector<Detector> detectors;
	for (const char *family : kLayoutFamilies) {
		Config cfg;
		cfg.dictionary = family;
		detectors.emplace_back(cfg);
	}
	std::mt19937 rng(11);
	for (const std::string &other : others) {
		const Dictionary &od = *findDictionary(other);
		for (float cellPx : { 5.0f, 12.0f }) {
			Image img(800, 500, 120);
			renderScene(img, od, 8, rng, cellPx * static_cast<float>(od.bits + 2), 0.6f, 3.0f);
			for (std::size_t f = 0; f < detectors.size(); ++f) {
				const char *family = kLayoutFamilies[f];
				if (other == family)
					continue;
				const Result &res = detectors[f].detect(img.view());
				EXPECT_TRUE(res.markers.empty())
					<< family << " on " << other << " cell " << cellPx << ": " << res.markers.size()
					<< " markers, the first id " << res.markers[0].id;
			}
		}
	}
}

/* The batch warp (every candidate's grid in one call, as the QPUs take it)
 * reads what the one-by-one warp reads. */
TEST(LayoutScenes, BatchWarpReadsTheSame)
{
	for (const char *family : kLayoutFamilies) {
		const Dictionary &dict = *findDictionary(family);
		std::mt19937 rng(5);
		Image img(800, 500, 110);
		renderScene(img, dict, 6, rng, 7.0f * static_cast<float>(dict.bits + 2), 0.7f, 3.0f);
		Config cfg;
		cfg.dictionary = family;
		Detector one(cfg);
		Detector batch(cfg);
		batch.setWarper(makeCpuWarper());
		const std::vector<Marker> a = one.detect(img.view()).markers;
		const std::vector<Marker> &b = batch.detect(img.view()).markers;
		ASSERT_EQ(a.size(), b.size()) << family;
		EXPECT_EQ(a.size(), 6u) << family;
		for (std::size_t k = 0; k < a.size(); ++k) {
			EXPECT_EQ(a[k].id, b[k].id) << family;
			for (int i = 0; i < 4; ++i) {
				EXPECT_EQ(a[k].corners[i].x, b[k].corners[i].x) << family;
				EXPECT_EQ(a[k].corners[i].y, b[k].corners[i].y) << family;
			}
		}
	}
}
