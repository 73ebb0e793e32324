// SPDX-License-Identifier: MIT
// Bilinear sampling of an 8-bit image, pixel centres at integers.
#pragma once

#include <algorithm>
#include <cmath>

#include "frappe/image.h"

namespace frappe::detail {

/// Intensity at (x, y), bilinear, clamped to the image (a NaN coordinate
/// to 0, where std::clamp would pass it on to an undefined conversion).
inline float sampleBilinear(const ImageView &img, float x, float y)
{
	x = x >= 0.0f ? std::min(x, static_cast<float>(img.width - 1)) : 0.0f;
	y = y >= 0.0f ? std::min(y, static_cast<float>(img.height - 1)) : 0.0f;
	const int x0 = std::min(static_cast<int>(x), img.width - 2 < 0 ? 0 : img.width - 2);
	const int y0 = std::min(static_cast<int>(y), img.height - 2 < 0 ? 0 : img.height - 2);
	const int x1 = std::min(x0 + 1, img.width - 1), y1 = std::min(y0 + 1, img.height - 1);
	const float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
	const std::uint8_t *r0 = img.row(y0);
	const std::uint8_t *r1 = img.row(y1);
	const float top = static_cast<float>(r0[x0]) + fx * static_cast<float>(r0[x1] - r0[x0]);
	const float bot = static_cast<float>(r1[x0]) + fx * static_cast<float>(r1[x1] - r1[x0]);
	return top + fy * (bot - top);
}

/// sampleBilinear for 0 <= x <= width - 2, 0 <= y <= height - 2, where its
/// clamps change nothing: the same result, without them.
inline float sampleInside(const ImageView &img, float x, float y)
{
	const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
	const float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
	const std::uint8_t *r0 = img.row(y0) + x0;
	const std::uint8_t *r1 = img.row(y0 + 1) + x0;
	const float top = static_cast<float>(r0[0]) + fx * static_cast<float>(r0[1] - r0[0]);
	const float bot = static_cast<float>(r1[0]) + fx * static_cast<float>(r1[1] - r1[0]);
	return top + fy * (bot - top);
}

} // namespace frappe::detail
