// SPDX-License-Identifier: MIT
// Cameras and calibration files: checks, scaling to other frame sizes.
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "frappe/camera.h"

using namespace frappe;

namespace {

Camera camera640()
{
	Camera c = Camera::pinhole(700.0, 710.0, 319.5, 239.5, 640, 480);
	c.distortion = { -0.2, 0.05, 0.001, -0.002, 0.01 };
	return c;
}

} // namespace

TEST(Camera, Pinhole)
{
	const Camera c = Camera::pinhole(600.0, 610.0, 320.0, 240.0);
	const std::array<double, 9> m = { 600, 0, 320, 0, 610, 240, 0, 0, 1 };
	EXPECT_EQ(c.matrix, m);
	EXPECT_TRUE(c.distortion.empty());
	EXPECT_EQ(c.width, 0);
	EXPECT_EQ(c.height, 0);
	EXPECT_TRUE(c.valid());
}

TEST(Camera, ValidateSaysWhatIsWrong)
{
	const auto message = [](const Camera &c) {
		try {
			c.validate();
		} catch (const std::invalid_argument &e) {
			return std::string(e.what());
		}
		return std::string("(valid)");
	};
	Camera c = camera640();
	EXPECT_EQ(message(c), "(valid)");
	c.matrix[4] = -1.0;
	EXPECT_NE(message(c).find("fy must be positive"), std::string::npos) << message(c);
	c = camera640();
	c.matrix[2] = std::nan("");
	EXPECT_NE(message(c).find("entry 2 is not finite"), std::string::npos) << message(c);
	c = camera640();
	c.matrix[7] = 0.5;
	EXPECT_NE(message(c).find("last row"), std::string::npos) << message(c);
	c = camera640();
	c.distortion.resize(6);
	EXPECT_NE(message(c).find("6 coefficients"), std::string::npos) << message(c);
	c = camera640();
	c.distortion.resize(4);
	EXPECT_EQ(message(c), "(valid)");
	c.distortion.resize(8);
	EXPECT_EQ(message(c), "(valid)");
	c.distortion[7] = std::numeric_limits<double>::infinity();
	EXPECT_NE(message(c).find("coefficient 7 is not finite"), std::string::npos) << message(c);
	c = camera640();
	c.width = -640;
	EXPECT_NE(message(c).find("negative size"), std::string::npos) << message(c);
	c = camera640();
	c.height = 0;
	EXPECT_NE(message(c).find("both"), std::string::npos) << message(c);
}

/* A 640x480 calibration at 320x240 and 1280x960: the focal lengths scale,
 * the principal point keeps its place relative to the image's edges. */
TEST(Camera, ScaledToOtherSizes)
{
	const Camera c = camera640();
	EXPECT_TRUE(c.fits(640, 480));
	EXPECT_TRUE(c.fits(320, 240));
	EXPECT_TRUE(c.fits(1280, 960));
	EXPECT_TRUE(c.fits(854, 640)); /* 853.33 rounded */
	EXPECT_FALSE(c.fits(640, 360)); /* 16:9 from 4:3 */
	EXPECT_FALSE(c.fits(480, 480));
	EXPECT_FALSE(c.fits(0, 480));
	EXPECT_TRUE(Camera::pinhole(600, 600, 320, 240).fits(1920, 1080)); /* size unknown */

	const Camera half = c.scaledTo(320, 240);
	EXPECT_EQ(half.width, 320);
	EXPECT_EQ(half.height, 240);
	EXPECT_DOUBLE_EQ(half.matrix[0], 350.0);
	EXPECT_DOUBLE_EQ(half.matrix[4], 355.0);
	EXPECT_DOUBLE_EQ(half.matrix[2], 159.5); /* (319.5 + 0.5) / 2 - 0.5 */
	EXPECT_DOUBLE_EQ(half.matrix[5], 119.5);
	EXPECT_EQ(half.distortion, c.distortion);
	EXPECT_EQ(half.matrix[8], 1.0);

	const Camera twice = c.scaledTo(1280, 960);
	EXPECT_DOUBLE_EQ(twice.matrix[0], 1400.0);
	EXPECT_DOUBLE_EQ(twice.matrix[4], 1420.0);
	EXPECT_DOUBLE_EQ(twice.matrix[2], 639.5);
	EXPECT_DOUBLE_EQ(twice.matrix[5], 479.5);
	EXPECT_TRUE(twice.valid());

	const Camera same = c.scaledTo(640, 480);
	EXPECT_EQ(same.matrix, c.matrix);
	const Camera unknown = Camera::pinhole(600, 600, 320, 240);
	EXPECT_EQ(unknown.scaledTo(1920, 1080).matrix, unknown.matrix);
	EXPECT_THROW(c.scaledTo(0, 240), std::invalid_argument);
}
