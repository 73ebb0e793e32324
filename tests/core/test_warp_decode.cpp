// SPDX-License-Identifier: MIT
// Homographies, the perspective warp and binarisation on known inputs.
#include <gtest/gtest.h>

#include "decode.h"
#include "frappe/frappe.h"
#include "frappe/homography.h"
#include "frappe/render.h"
#include "scene.h"

using namespace frappe;
using frappe::test::Image;

TEST(Homography, MapsTheUnitSquareToTheQuad)
{
	const std::array<Point2f, 4> q = { Point2f{ 10, 20 }, { 110, 30 }, { 90, 140 }, { 5, 100 } };
	const auto H = Homography::fromUnitSquare(q);
	ASSERT_TRUE(H);
	const double u[4] = { 0, 1, 1, 0 }, v[4] = { 0, 0, 1, 1 };
	for (int i = 0; i < 4; ++i) {
		const Point2f p = H->map(u[i], v[i]);
		EXPECT_NEAR(p.x, q[i].x, 1e-4);
		EXPECT_NEAR(p.y, q[i].y, 1e-4);
	}
	const auto Hi = H->inverse();
	ASSERT_TRUE(Hi);
	const Point2f back = Hi->map(q[2].x, q[2].y);
	EXPECT_NEAR(back.x, 1.0, 1e-5);
	EXPECT_NEAR(back.y, 1.0, 1e-5);
	EXPECT_FALSE(Homography::fromUnitSquare({ Point2f{ 0, 0 }, { 1, 1 }, { 2, 2 }, { 3, 3 } }));
}

TEST(Warp, SamplesAtCellQuarterPoints)
{
	/* A linear ramp I(x, y) = x + 2y: bilinear sampling reproduces it
	 * exactly, so every sample's value says where it was taken. */
	Image img(200, 200);
	for (int y = 0; y < 200; ++y)
		for (int x = 0; x < 200; ++x)
			img.at(x, y) = static_cast<std::uint8_t>((x + 2 * y) / 3);
	Image ramp(200, 200);
	const std::array<Point2f, 4> q = { Point2f{ 20, 20 }, { 84, 20 }, { 84, 84 }, { 20, 84 } };
	detail::WarpedMarker w;
	ASSERT_TRUE(detail::warpMarker(img.view(), q, 6, w));
	ASSERT_EQ(w.side, 16);
	/* Sample i sits at 20 + 64 * (i + 0.5) / 16 = 22 + 4i. */
	for (int j = 0; j < 16; j += 5) {
		for (int i = 0; i < 16; i += 3) {
			const float x = 22.0f + 4.0f * i, y = 22.0f + 4.0f * j;
			const int xi = static_cast<int>(x), yi = static_cast<int>(y);
			EXPECT_EQ(w.at(i, j), static_cast<float>(img.at(xi, yi))) << i << "," << j;
		}
	}
}

TEST(Binarise, ReadsAnUprightMarker)
{
	const Dictionary &d = *findDictionary("aruco_mip_36h12");
	int side = 0;
	/* 8 px cells, one cell of quiet zone: the marker spans [8, 72). */
	std::vector<std::uint8_t> px = markerImage(d, 42, 8, 1, side);
	ASSERT_EQ(side, 80);
	const ImageView view(px.data(), side, side);
	const std::array<Point2f, 4> q = { Point2f{ 7.5f, 7.5f }, { 71.5f, 7.5f }, { 71.5f, 71.5f }, { 7.5f, 71.5f } };
	detail::WarpedMarker w;
	ASSERT_TRUE(detail::warpMarker(view, q, d.bits, w));
	const detail::Binarised b = detail::binarise(w, d.bits);
	EXPECT_EQ(b.code, d.codes[42]);
	EXPECT_EQ(b.border_errors, 0);
	EXPECT_NEAR(b.contrast, 255.0f, 1.0f);
	const detail::Decoded dec = detail::decode(d, b.code, 5);
	EXPECT_EQ(dec.id, 42);
	EXPECT_EQ(dec.rotation, 0);
	EXPECT_EQ(dec.hamming, 0);
}

TEST(Binarise, TheQuietZoneOutlineReadsAsAWhiteFrame)
{
	const Dictionary &d = *findDictionary("aruco_mip_36h12");
	int side = 0;
	std::vector<std::uint8_t> px = markerImage(d, 7, 8, 2, side);
	const ImageView view(px.data(), side, side);
	/* Outline one cell outside the marker: its frame is the white margin. */
	const float a = 7.5f, b = 87.5f;
	std::array<Point2f, 4> q = { Point2f{ a, a }, { b, a }, { b, b }, { a, b } };
	detail::WarpedMarker w;
	ASSERT_TRUE(detail::warpMarker(view, q, d.bits, w));
	EXPECT_EQ(detail::binarise(w, d.bits).border_errors, 28);
	/* One cell inside it lies the marker, which insetQuad recovers. */
	ASSERT_TRUE(detail::insetQuad(view, q, d.bits, w));
	EXPECT_NEAR(q[0].x, 15.5f, 0.2f);
	EXPECT_NEAR(q[2].y, 79.5f, 0.2f);
	EXPECT_EQ(detail::decode(d, detail::binarise(w, d.bits).code, 5).id, 7);
}
