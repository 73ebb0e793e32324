// SPDX-License-Identifier: MIT
// Bilinear sampling of an 8-bit image, pixel centres at integers.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

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

/// The fixed-point warp's position along one axis (frappe/fixed_warp.h):
/// origin 2^10 + q, q the quotient, clamped to [0, (extent - 1) 2^10].
inline std::int32_t fixedPosition(std::int64_t q, std::int32_t origin, int extent)
{
	const std::int64_t p = std::int64_t{ origin } * 1024 + q;
	return static_cast<std::int32_t>(std::clamp<std::int64_t>(p, 0, std::int64_t{ extent - 1 } * 1024));
}

/// The fixed-point warp's exact bilinear value v at (X, Y), 10 fraction
/// bits, both clamped to the image (width and height at least 2).
inline std::uint32_t fixedBilinear(const ImageView &img, std::int32_t X, std::int32_t Y)
{
	const int x0 = std::min(X >> 10, img.width - 2), y0 = std::min(Y >> 10, img.height - 2);
	const std::uint32_t fx = static_cast<std::uint32_t>(X - (x0 << 10));
	const std::uint32_t fy = static_cast<std::uint32_t>(Y - (y0 << 10));
	const std::uint8_t *r0 = img.row(y0) + x0;
	const std::uint8_t *r1 = img.row(y0 + 1) + x0;
	const std::uint32_t top = r0[0] * (1024 - fx) + r0[1] * fx;
	const std::uint32_t bot = r1[0] * (1024 - fx) + r1[1] * fx;
	return top * (1024 - fy) + bot * fy;
}

/// v as a sample: 8 bits, rounded, or fine (v 2^-20, exact but for the
/// float's rounding of v).
inline float fixedSample(std::uint32_t v, bool fine)
{
	return fine ? static_cast<float>(static_cast<std::int32_t>(v)) * (1.0f / 1048576.0f)
		    : static_cast<float>((v + (1u << 19)) >> 20);
}

} // namespace frappe::detail
