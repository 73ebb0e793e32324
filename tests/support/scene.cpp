// SPDX-License-Identifier: MIT
#include "scene.h"

#include <algorithm>
#include <cmath>

namespace frappe::test {

std::array<Point2f, 4> squarePose(float cx, float cy, float side, float roll, float tilt,
				  float distance)
{
	return perspectiveSquare(cx, cy, side, roll, tilt, distance);
}

void blur(Image &img, float sigma)
{
	if (sigma <= 0.0f)
		return;
	const int radius = std::max(1, static_cast<int>(std::ceil(3.0f * sigma)));
	std::vector<float> k(2 * radius + 1);
	float sum = 0;
	for (int i = -radius; i <= radius; ++i)
		sum += k[i + radius] = std::exp(-0.5f * i * i / (sigma * sigma));
	for (float &v : k)
		v /= sum;
	std::vector<float> tmp(static_cast<std::size_t>(img.width) * img.height);
	for (int y = 0; y < img.height; ++y)
		for (int x = 0; x < img.width; ++x) {
			float acc = 0;
			for (int i = -radius; i <= radius; ++i)
				acc += k[i + radius] * img.at(std::clamp(x + i, 0, img.width - 1), y);
			tmp[static_cast<std::size_t>(y) * img.width + x] = acc;
		}
	for (int y = 0; y < img.height; ++y)
		for (int x = 0; x < img.width; ++x) {
			float acc = 0;
			for (int i = -radius; i <= radius; ++i)
				acc += k[i + radius] * tmp[static_cast<std::size_t>(std::clamp(y + i, 0, img.height - 1)) * img.width + x];
			img.at(x, y) = static_cast<std::uint8_t>(std::clamp(std::lround(acc), 0L, 255L));
		}
}

void motionBlur(Image &img, float length, float angle)
{
	if (length <= 0.0f)
		return;
	const Image src = img;
	const int n = std::max(1, static_cast<int>(std::ceil(4.0f * length)));
	const float dx = std::cos(angle), dy = std::sin(angle);
	auto at = [&](float x, float y) {
		x = std::clamp(x, 0.0f, static_cast<float>(src.width - 1));
		y = std::clamp(y, 0.0f, static_cast<float>(src.height - 1));
		const int x0 = std::min(static_cast<int>(x), src.width - 2), y0 = std::min(static_cast<int>(y), src.height - 2);
		const float fx = x - x0, fy = y - y0;
		const auto p = [&](int xx, int yy) { return static_cast<float>(src.pixels[static_cast<std::size_t>(yy) * src.stride + xx]); };
		return (1 - fy) * ((1 - fx) * p(x0, y0) + fx * p(x0 + 1, y0)) + fy * ((1 - fx) * p(x0, y0 + 1) + fx * p(x0 + 1, y0 + 1));
	};
	for (int y = 0; y < img.height; ++y)
		for (int x = 0; x < img.width; ++x) {
			float acc = 0;
			for (int i = 0; i < n; ++i) {
				const float t = length * ((i + 0.5f) / n - 0.5f);
				acc += at(x + t * dx, y + t * dy);
			}
			img.at(x, y) = static_cast<std::uint8_t>(std::clamp(std::lround(acc / n), 0L, 255L));
		}
}

void addNoise(Image &img, float sigma, std::mt19937 &rng)
{
	std::normal_distribution<float> n(0.0f, sigma);
	for (int y = 0; y < img.height; ++y)
		for (int x = 0; x < img.width; ++x)
			img.at(x, y) = static_cast<std::uint8_t>(std::clamp(std::lround(img.at(x, y) + n(rng)), 0L, 255L));
}

void squareGrid(Image &img, int square, int pitch, std::uint8_t dark)
{
	for (int y = 0; y < img.height; ++y)
		for (int x = 0; x < img.width; ++x)
			if (x % pitch < square && y % pitch < square)
				img.at(x, y) = dark;
}

float meanCornerError(const std::array<Point2f, 4> &a, const std::array<Point2f, 4> &b)
{
	float e = 0;
	for (int i = 0; i < 4; ++i)
		e += std::hypot(a[i].x - b[i].x, a[i].y - b[i].y);
	return e / 4;
}

const Marker *findMarker(const std::vector<Marker> &markers, int id)
{
	for (const Marker &m : markers)
		if (m.id == id)
			return &m;
	return nullptr;
}

} // namespace frappe::test
