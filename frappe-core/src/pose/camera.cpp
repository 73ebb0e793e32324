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

namespace {

/* What is wrong with a camera, or "" when nothing is. valid() asks without
 * throwing: a plugin may sit in a C program, where throwing for an unset
 * camera on every caps change would be both slow and, under a preloaded
 * AddressSanitizer, fatal. */
std::string problem(const Camera &c)
{
	for (std::size_t i = 0; i < c.matrix.size(); ++i)
		if (!std::isfinite(c.matrix[i]))
			return "camera matrix entry " + std::to_string(i) + " is not finite";
	if (!(c.matrix[0] > 0.0))
		return "fx must be positive, got " + str(c.matrix[0]);
	if (!(c.matrix[4] > 0.0))
		return "fy must be positive, got " + str(c.matrix[4]);
	if (c.matrix[3] != 0.0 || c.matrix[6] != 0.0 || c.matrix[7] != 0.0 || c.matrix[8] != 1.0)
		return "camera matrix: the last row must be 0 0 1 and [1][0] 0, got [1][0] " + str(c.matrix[3]) +
		       ", last row " + str(c.matrix[6]) + " " + str(c.matrix[7]) + " " + str(c.matrix[8]);
	const std::size_t n = c.distortion.size();
	if (n != 0 && n != 4 && n != 5 && n != 8)
		return "distortion: " + std::to_string(n) + " coefficients, expected 0, 4, 5 or 8";
	for (std::size_t i = 0; i < n; ++i)
		if (!std::isfinite(c.distortion[i]))
			return "distortion coefficient " + std::to_string(i) + " is not finite";
	if (c.width < 0 || c.height < 0)
		return "negative size " + std::to_string(c.width) + "x" + std::to_string(c.height);
	if ((c.width == 0) != (c.height == 0))
		return "size " + std::to_string(c.width) + "x" + std::to_string(c.height) +
		       ": give both the width and the height, or neither";
	return {};
}

} // namespace

bool Camera::valid() const
{
	return problem(*this).empty();
}

void Camera::validate() const
{
	const std::string p = problem(*this);
	if (!p.empty())
		fail(p);
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
	/* A valid camera can scale past what a double holds: say so, rather
	 * than give a camera no pose can use. */
	if (!c.valid())
		throw std::invalid_argument("camera: scaled from " + std::to_string(width) + "x" + std::to_string(height) +
					    " to " + std::to_string(frame_width) + "x" + std::to_string(frame_height) +
					    " its matrix is no camera (fx " + std::to_string(c.matrix[0]) + ", fy " +
					    std::to_string(c.matrix[4]) + ")");
	return c;
}

} // namespace frappe
