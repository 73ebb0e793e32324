// SPDX-License-Identifier: MIT
// Test scenes: markers rendered under known homographies, blur and noise.
#pragma once

#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include "frappe/frappe.h"
#include "frappe/render.h"

namespace frappe::test {

/// An owned 8-bit image with an optional row padding.
struct Image {
	int width = 0, height = 0, stride = 0;
	std::vector<std::uint8_t> pixels;

	Image(int w, int h, std::uint8_t fill = 128, int padding = 0)
		: width(w), height(h), stride(w + padding),
		  pixels(static_cast<std::size_t>(w + padding) * h, fill) {}
	ImageView view() const { return { pixels.data(), width, height, stride }; }
	MutableImageView mut() { return { pixels.data(), width, height, stride }; }
	std::uint8_t &at(int x, int y) { return pixels[static_cast<std::size_t>(y) * stride + x]; }
};

/// Corners of a square of side `side` centred at (cx, cy), rotated by
/// `roll` degrees in the image plane and tilted by `tilt` degrees about its
/// horizontal axis, seen by a pinhole camera `distance` sides away.
std::array<Point2f, 4> squarePose(float cx, float cy, float side, float roll, float tilt,
				  float distance = 4.0f);

/// Gaussian blur with standard deviation `sigma` pixels (no-op when 0).
void blur(Image &img, float sigma);

/// Motion blur: each pixel the mean of the image along a segment of
/// `length` pixels through it at `angle` radians from the x axis (bilinear
/// samples a quarter pixel apart), as a camera moving during the exposure.
void motionBlur(Image &img, float length, float angle);

/// Adds Gaussian noise of standard deviation `sigma` grey levels.
void addNoise(Image &img, float sigma, std::mt19937 &rng);

/// Dark squares (`dark`) of `square` px, one every `pitch` px both ways, on
/// the whole image: a tiled wall, a candidate per square.
void squareGrid(Image &img, int square, int pitch, std::uint8_t dark = 25);

/// Mean distance between corresponding corners.
float meanCornerError(const std::array<Point2f, 4> &a, const std::array<Point2f, 4> &b);

/// The marker of `markers` with this id, or nullptr.
const Marker *findMarker(const std::vector<Marker> &markers, int id);

} // namespace frappe::test
