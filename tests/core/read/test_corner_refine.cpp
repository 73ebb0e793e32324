// SPDX-License-Identifier: MIT
// CORNER_REFINE on rendered markers: from corners a pixel or two off, the
// refined ones lie within 0.15 px of the truth on average, and every Highway
// target (the side's columns are measured a lane each) gives the same bits.
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "corner_refine.h"
#include "every_target.h"
#include "frappe/frappe.h"
#include "frappe/render.h"
#include "scene.h"

using namespace frappe;
using namespace frappe::test;

namespace {

struct Case {
	Image image;
	std::array<Point2f, 4> truth, start;
	float search;
};

/* Markers from 40 to 200 px, rolled and tilted, some near the image border
 * (the clamped path), started up to 1.5 px off each corner. */
std::vector<Case> makeCases()
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	std::mt19937 rng(3);
	std::uniform_real_distribution<float> off(-1.5f, 1.5f);
	std::vector<Case> cases;
	const float sides[] = { 40.0f, 64.0f, 110.0f, 200.0f };
	for (int k = 0; k < 24; ++k) {
		const float side = sides[k % 4];
		const int size = static_cast<int>(side * 1.6f) + 20;
		Case c{ Image(size, size, 90), {}, {}, 2.5f };
		/* Every fourth case near the left border. */
		const float cx = (k % 4 == 3) ? side * 0.5f + 3.0f : size / 2.0f + 0.37f;
		c.truth = squarePose(cx, size / 2.0f - 0.21f, side, 13.0f * k, 8.0f * (k % 7));
		RenderOptions opt;
		opt.black = 30;
		opt.white = 210;
		renderMarker(c.image.mut(), dict, k, c.truth, opt);
		blur(c.image, 0.3f * (k % 4));
		addNoise(c.image, 2.0f, rng);
		for (int i = 0; i < 4; ++i)
			c.start[i] = { c.truth[i].x + off(rng), c.truth[i].y + off(rng) };
		cases.push_back(std::move(c));
	}
	return cases;
}

} // namespace

TEST(CornerRefine, ConvergesToTheTrueCorners)
{
	int refined = 0;
	for (const Case &c : makeCases()) {
		std::array<Point2f, 4> q = c.start;
		if (!detail::refineCorners(c.image.view(), q, c.search))
			continue;
		++refined;
		EXPECT_LT(meanCornerError(q, c.truth), 0.15f) << "case " << refined;
	}
	EXPECT_GE(refined, 22);
}

/* Markers smeared by 10 px of motion blur, from corners 2 px off: the
 * default window cuts the blurred sides' ramps short and stays near where
 * it started; the wide one takes in the whole profile. */
TEST(CornerRefine, AWideWindowStaysUnbiasedOnMotionBlur)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	std::mt19937 rng(5);
	std::uniform_real_distribution<float> off(-2.0f, 2.0f);
	const detail::RefineWindow wide{ 6, 64 };
	double errDefault = 0, errWide = 0;
	int both = 0;
	for (int k = 0; k < 16; ++k) {
		const float side = 80.0f + 6.0f * k;
		const int size = static_cast<int>(side * 1.6f) + 20;
		Image img(size, size, 100);
		const auto truth = squarePose(size / 2.0f + 0.3f, size / 2.0f - 0.2f, side, 11.0f * k, 6.0f * (k % 5));
		renderMarker(img.mut(), dict, k, truth);
		motionBlur(img, 10.0f, 0.4f * k);
		addNoise(img, 2.0f, rng);
		std::array<Point2f, 4> start;
		for (int i = 0; i < 4; ++i)
			start[i] = { truth[i].x + off(rng), truth[i].y + off(rng) };
		std::array<Point2f, 4> a = start, b = start;
		if (!detail::refineCorners(img.view(), a, 4.0f) || !detail::refineCorners(img.view(), b, 4.0f, wide))
			continue;
		++both;
		errDefault += meanCornerError(a, truth);
		errWide += meanCornerError(b, truth);
	}
	ASSERT_GE(both, 12);
	errDefault /= both;
	errWide /= both;
	std::printf("10 px motion blur: mean corner error %.3f px with the default window, %.3f with the wide one\n",
		    errDefault, errWide);
	EXPECT_LT(errWide, 0.8 * errDefault);
	EXPECT_LT(errWide, 0.35);
}

/* Markers with a one-cell white margin on a dark panel, defocused (sigma
 * 0.3 cell): each side's fall from the margin to the frame is cut short on
 * the outside by the margin's own outer edge, and a plain window's
 * centroid moves into the marker; the symmetric window cuts both sides the
 * same and moves back towards the edge (0.25 -> 0.22 px; what remains is
 * the overlap of the two edges' blur, which no window undoes). */
TEST(CornerRefine, ASymmetricWindowStaysOnEdgesBetweenNarrowBands)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	std::mt19937 rng(9);
	std::uniform_real_distribution<float> off(-1.5f, 1.5f);
	const detail::RefineWindow plain{ 6, 64 }, symmetric{ 6, 64, true, 2 };
	double errPlain = 0, errSymmetric = 0;
	int both = 0;
	for (int k = 0; k < 16; ++k) {
		const float side = 56.0f + 4.0f * k; /* cells of 7 to 14.5 px */
		const int size = static_cast<int>(side * 1.6f) + 20;
		Image img(size, size, 15);
		const auto truth = squarePose(size / 2.0f - 0.3f, size / 2.0f + 0.4f, side, 17.0f * k, 7.0f * (k % 5));
		RenderOptions opt;
		opt.black = 15;
		opt.white = 235;
		renderMarker(img.mut(), dict, k, truth, opt);
		blur(img, 0.3f * side / 8.0f);
		addNoise(img, 2.0f, rng);
		std::array<Point2f, 4> start;
		for (int i = 0; i < 4; ++i)
			start[i] = { truth[i].x + off(rng), truth[i].y + off(rng) };
		std::array<Point2f, 4> a = start, b = start;
		if (!detail::refineCorners(img.view(), a, 2.5f, plain) ||
		    !detail::refineCorners(img.view(), b, 2.5f, symmetric))
			continue;
		++both;
		errPlain += meanCornerError(a, truth);
		errSymmetric += meanCornerError(b, truth);
	}
	ASSERT_GE(both, 12);
	errPlain /= both;
	errSymmetric /= both;
	std::printf("one-cell margin on a dark panel, blurred: mean corner error %.3f px with the plain window, %.3f "
		    "with the symmetric one\n",
		    errPlain, errSymmetric);
	EXPECT_LT(errSymmetric, 0.9 * errPlain);
}

/* Every Highway target (the vector kernel) gives the scalar reference's
 * corners to the bit, with every window; so does a build without Highway
 * (the ARMv6 one), which runs the reference itself. */
TEST(CornerRefine, EveryTargetGivesTheScalarReferenceBits)
{
	const std::vector<Case> cases = makeCases();
	for (const detail::RefineWindow window :
	     { detail::RefineWindow{}, detail::RefineWindow{ 6, 64 }, detail::RefineWindow{ 6, 64, true, 2 } }) {
		std::vector<std::array<Point2f, 4>> reference;
		std::vector<int> referenceOk;
		int refined = 0;
		for (const Case &c : cases) {
			std::array<Point2f, 4> q = c.start;
			referenceOk.push_back(
				detail::refineCorners(c.image.view(), q, c.search, window, detail::RefineKernels::Scalar));
			reference.push_back(q);
			refined += referenceOk.back();
		}
		/* The comparison means something only where the corners moved. */
		ASSERT_GE(refined, static_cast<int>(cases.size()) * 3 / 4);
		onEveryTarget([&](const char *target) {
			for (std::size_t k = 0; k < cases.size(); ++k) {
				std::array<Point2f, 4> q = cases[k].start;
				const bool ok = detail::refineCorners(cases[k].image.view(), q, cases[k].search, window);
				ASSERT_EQ(ok, referenceOk[k] != 0) << target << " case " << k;
				ASSERT_EQ(std::memcmp(&q, &reference[k], sizeof q), 0) << target << " case " << k;
			}
		});
	}
}
