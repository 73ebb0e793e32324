// SPDX-License-Identifier: MIT
// Bad and unusual input: clear errors, nothing lost, no crash.
#include <stdexcept>

#include <gtest/gtest.h>

#include "frappe/frappe.h"
#include "scene.h"

using namespace frappe;
using namespace frappe::test;

namespace {

std::string errorOf(const std::function<void()> &f)
{
	try {
		f();
	} catch (const std::invalid_argument &e) {
		return e.what();
	}
	return "";
}

} // namespace

TEST(BadInput, UnknownDictionaryNamesTheKnownOnes)
{
	Config c;
	c.dictionary = "6x6_251";
	const std::string e = errorOf([&] { Detector d(c); });
	EXPECT_NE(e.find("unknown dictionary '6x6_251'"), std::string::npos) << e;
	EXPECT_NE(e.find("aruco_mip_36h12"), std::string::npos) << e;
}

TEST(BadInput, OutOfRangeParameters)
{
	Config c;
	c.edge_threshold = 0.0f;
	EXPECT_NE(errorOf([&] { Detector d(c); }).find("edge_threshold"), std::string::npos);
	c = Config{};
	c.max_hamming = 30;
	EXPECT_NE(errorOf([&] { Detector d(c); }).find("max_hamming"), std::string::npos);
	c = Config{};
	c.threads = -2;
	EXPECT_NE(errorOf([&] { Detector d(c); }).find("threads"), std::string::npos);
	c = Config{};
	c.max_pixels = 0;
	EXPECT_NE(errorOf([&] { Detector d(c); }).find("max_pixels"), std::string::npos);
	c = Config{};
	c.max_candidates = 0;
	EXPECT_NE(errorOf([&] { Detector d(c); }).find("max_candidates must be in [1, 2^20], got 0"), std::string::npos);
}

/* A frame beyond max_pixels is refused before any buffer grows to it (no
 * pixel is read: the view's data may be a lie); a frame at the limit runs. */
TEST(BadInput, FramesBeyondMaxPixelsAreRefused)
{
	std::vector<std::uint8_t> px(64 * 64, 100);
	Config c;
	c.max_pixels = 64 * 63;
	Detector det(c);
	const std::string e = errorOf([&] { det.detect(ImageView(px.data(), 64, 64, 64)); });
	EXPECT_NE(e.find("64x64 has more than max_pixels (4032)"), std::string::npos) << e;
	EXPECT_TRUE(det.detect(ImageView(px.data(), 64, 63, 64)).markers.empty());
	/* The default refuses 30000 x 30000 (a 900 MP image a small PNG can
	 * claim) without touching it. */
	Detector defaults(Config{});
	const std::uint8_t one = 0;
	EXPECT_NE(errorOf([&] { defaults.detect(ImageView(&one, 30000, 30000, 30000)); }).find("max_pixels"),
		  std::string::npos);
}

TEST(BadInput, ZeroSizesNullDataAndShortStride)
{
	Detector det(Config{});
	std::vector<std::uint8_t> px(100, 0);
	EXPECT_NE(errorOf([&] { det.detect(ImageView(px.data(), 0, 10, 10)); }).find("positive"), std::string::npos);
	EXPECT_NE(errorOf([&] { det.detect(ImageView(px.data(), 10, 0, 10)); }).find("positive"), std::string::npos);
	EXPECT_NE(errorOf([&] { det.detect(ImageView(px.data(), -3, 10, 10)); }).find("positive"), std::string::npos);
	EXPECT_NE(errorOf([&] { det.detect(ImageView(nullptr, 10, 10, 10)); }).find("null"), std::string::npos);
	const std::string e = errorOf([&] { det.detect(ImageView(px.data(), 10, 10, 9)); });
	EXPECT_NE(e.find("stride (9) is smaller than the width (10)"), std::string::npos) << e;
	/* The detector is still usable after an error. */
	EXPECT_TRUE(det.detect(ImageView(px.data(), 10, 10, 10)).markers.empty());
}

TEST(BadInput, TinyFramesGiveNothing)
{
	Detector det(Config{});
	for (int w : { 1, 2, 3, 7 }) {
		for (int h : { 1, 2, 5 }) {
			Image img(w, h, 200);
			EXPECT_TRUE(det.detect(img.view()).markers.empty()) << w << "x" << h;
		}
	}
}

TEST(BadInput, OddSizesAndPaddedStridesFindTheSameMarkers)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	Detector det(Config{});
	for (int w : { 97, 161, 333 }) {
		const int h = w * 3 / 4 + 1;
		for (int pad : { 0, 1, 13 }) {
			Image img(w, h, 40, pad);
			const float s = static_cast<float>(h) * 0.6f;
			const auto q = squarePose(w / 2.0f, h / 2.0f, s, 5, 10);
			renderMarker(img.mut(), dict, 3, q);
			const Result &res = det.detect(img.view());
			ASSERT_EQ(res.markers.size(), 1u) << w << "x" << h << " pad " << pad;
			EXPECT_EQ(res.markers[0].id, 3);
			EXPECT_LT(meanCornerError(res.markers[0].corners, q), 0.3f);
		}
	}
}

TEST(BadInput, EightKFrame)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	Detector det(Config{});
	Image img(7680, 4320, 100);
	const auto q = squarePose(6000.0f, 3500.0f, 200.0f, 30.0f, 20.0f);
	renderMarker(img.mut(), dict, 249, q);
	const Result &res = det.detect(img.view());
	ASSERT_EQ(res.markers.size(), 1u);
	EXPECT_EQ(res.markers[0].id, 249);
	EXPECT_LT(meanCornerError(res.markers[0].corners, q), 0.3f);
}

TEST(BadInput, SizeChangesBetweenFrames)
{
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	Detector det(Config{});
	for (int w : { 320, 640, 200, 640 }) {
		Image img(w, 240, 60);
		const auto q = squarePose(w / 2.0f, 120.0f, 100.0f, 0, 0);
		renderMarker(img.mut(), dict, 12, q);
		const Result &res = det.detect(img.view());
		ASSERT_EQ(res.markers.size(), 1u) << w;
		EXPECT_EQ(det.edgeMap().width, w);
	}
}
