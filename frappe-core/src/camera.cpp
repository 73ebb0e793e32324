// SPDX-License-Identifier: MIT
// frappe::Camera: checks and scaling of a calibration.
#include "frappe/camera.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace frappe {

namespace {

[[noreturn]] void fail(const std::string &what)
{
	throw std::invalid_argument("camera: " + what);
}

std::string str(double v)
{
	std::ostringstream s;
	s << v;
	return s.str();
}

} // namespace

Camera Camera::pinhole(double fx, double fy, double cx, double cy, int width, int height)
{
	Camera c;
	c.width = width;
	c.height = height;
	c.matrix = { fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0 };
	return c;
}

bool Camera::valid() const
{
	try {
		validate();
		return true;
	} catch (const std::invalid_argument &) {
		return false;
	}
}

void Camera::validate() const
{
	for (std::size_t i = 0; i < matrix.size(); ++i)
		if (!std::isfinite(matrix[i]))
			fail("camera matrix entry " + std::to_string(i) + " is not finite");
	if (!(matrix[0] > 0.0))
		fail("fx must be positive, got " + str(matrix[0]));
	if (!(matrix[4] > 0.0))
		fail("fy must be positive, got " + str(matrix[4]));
	if (matrix[3] != 0.0 || matrix[6] != 0.0 || matrix[7] != 0.0 || matrix[8] != 1.0)
		fail("camera matrix: the last row must be 0 0 1 and [1][0] 0, got [1][0] " + str(matrix[3]) +
		     ", last row " + str(matrix[6]) + " " + str(matrix[7]) + " " + str(matrix[8]));
	const std::size_t n = distortion.size();
	if (n != 0 && n != 4 && n != 5 && n != 8)
		fail("distortion: " + std::to_string(n) + " coefficients, expected 0, 4, 5 or 8");
	for (std::size_t i = 0; i < n; ++i)
		if (!std::isfinite(distortion[i]))
			fail("distortion coefficient " + std::to_string(i) + " is not finite");
	if (width < 0 || height < 0)
		fail("negative size " + std::to_string(width) + "x" + std::to_string(height));
	if ((width == 0) != (height == 0))
		fail("size " + std::to_string(width) + "x" + std::to_string(height) +
		     ": give both the width and the height, or neither");
}

bool Camera::fits(int frame_width, int frame_height) const
{
	if (frame_width <= 0 || frame_height <= 0)
		return false;
	if (width <= 0 || height <= 0 || (width == frame_width && height == frame_height))
		return true;
	/* The same aspect, one side rounded: 1280x720 at 854x480. */
	const double h = static_cast<double>(height) * frame_width / width;
	const double w = static_cast<double>(width) * frame_height / height;
	return std::abs(h - frame_height) <= 0.5 || std::abs(w - frame_width) <= 0.5;
}

Camera Camera::scaledTo(int frame_width, int frame_height) const
{
	if (frame_width <= 0 || frame_height <= 0)
		throw std::invalid_argument("camera: frame size " + std::to_string(frame_width) + "x" +
					    std::to_string(frame_height) + " is not positive");
	if (width <= 0 || height <= 0 || (width == frame_width && height == frame_height))
		return *this;
	const double rx = static_cast<double>(frame_width) / width;
	const double ry = static_cast<double>(frame_height) / height;
	Camera c = *this;
	c.width = frame_width;
	c.height = frame_height;
	c.matrix[0] *= rx;
	c.matrix[1] *= rx;
	/* Pixel centres at integers: the left edge of the image, -0.5, stays put. */
	c.matrix[2] = (matrix[2] + 0.5) * rx - 0.5;
	c.matrix[4] *= ry;
	c.matrix[5] = (matrix[5] + 0.5) * ry - 0.5;
	return c;
}

} // namespace frappe
