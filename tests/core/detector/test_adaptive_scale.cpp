// SPDX-License-Identifier: MIT
// ADAPTIVE_SCALE: scaled frames after a large marker, a full frame every
// max_scaled_frames + 1, and full frames when nothing was found.
#include <gtest/gtest.h>

#include "frappe/frappe.h"
#include "scene.h"

using namespace frappe;
using namespace frappe::test;

TEST(AdaptiveScale, ScalesDownAfterALargeMarkerAndReturnsToFullSize)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	Config cfg;
	cfg.mode = Mode::AScale;
	cfg.max_scaled_frames = 3;
	Detector det(cfg);
	Image img(640, 480, 70);
	const auto q = squarePose(320, 240, 160, 10, 0);
	renderMarker(img.mut(), dict, 5, q);

	std::vector<float> scales;
	for (int i = 0; i < 9; ++i) {
		const Result &r = det.detect(img.view());
		ASSERT_EQ(r.markers.size(), 1u) << "frame " << i;
		EXPECT_EQ(r.markers[0].id, 5);
		/* Refinement runs at full resolution: corners stay sub-pixel. */
		EXPECT_LT(meanCornerError(r.markers[0].corners, q), 0.35f) << "frame " << i;
		scales.push_back(r.scale);
	}
	/* Frame 0 is full size, then 3 scaled, one full, 3 scaled, one full. */
	EXPECT_EQ(scales[0], 1.0f);
	for (int i : { 1, 2, 3, 5, 6, 7 }) {
		EXPECT_LT(scales[i], 1.0f) << i;
		EXPECT_NEAR(scales[i], 28.0f / 160.0f, 0.03f) << i;
	}
	EXPECT_EQ(scales[4], 1.0f);
	EXPECT_EQ(scales[8], 1.0f);
}

TEST(AdaptiveScale, NormalModeNeverScalesAndResetForgets)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	Image img(320, 240, 70);
	renderMarker(img.mut(), dict, 9, squarePose(160, 120, 120, 0, 0));
	Detector normal(Config{});
	for (int i = 0; i < 3; ++i)
		EXPECT_EQ(normal.detect(img.view()).scale, 1.0f);

	Config cfg;
	cfg.mode = Mode::AScale;
	Detector det(cfg);
	det.detect(img.view());
	EXPECT_LT(det.detect(img.view()).scale, 1.0f);
	det.reset();
	EXPECT_EQ(det.detect(img.view()).scale, 1.0f);
	/* An empty frame sends the next one back to full size. */
	Image blank(320, 240, 70);
	det.detect(img.view());
	det.detect(blank.view());
	EXPECT_EQ(det.detect(img.view()).scale, 1.0f);
}
