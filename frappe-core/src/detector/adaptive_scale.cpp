// SPDX-License-Identifier: MIT
#include "adaptive_scale.h"

#include <algorithm>
#include <cmath>

namespace frappe::detail {

float AdaptiveScale::next(const Config &config)
{
	if (config.mode != Mode::AScale || shortestSide_ <= 0.0f ||
	    scaledInRow_ >= config.max_scaled_frames) {
		scaledInRow_ = 0;
		return 1.0f;
	}
	const float r = config.scaled_size / shortestSide_;
	if (r >= 1.0f) {
		scaledInRow_ = 0;
		return 1.0f;
	}
	++scaledInRow_;
	/* Below 1/8 the front end would see a thumbnail: nothing to gain. */
	return std::max(r, 0.125f);
}

void AdaptiveScale::update(std::span<const Marker> markers)
{
	/* Squared lengths and one square root: hypot is a libm call, dear on
	 * ARMv6. */
	float shortest2 = 0.0f;
	for (const Marker &m : markers) {
		for (int i = 0; i < 4; ++i) {
			const Point2f a = m.corners[i], b = m.corners[(i + 1) & 3];
			const float dx = a.x - b.x, dy = a.y - b.y;
			const float s2 = dx * dx + dy * dy;
			if (shortest2 == 0.0f || s2 < shortest2)
				shortest2 = s2;
		}
	}
	shortestSide_ = std::sqrt(shortest2);
}

void AdaptiveScale::reset()
{
	shortestSide_ = 0.0f;
	scaledInRow_ = 0;
}

} // namespace frappe::detail
