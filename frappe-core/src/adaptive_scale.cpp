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
	float shortest = 0.0f;
	for (const Marker &m : markers) {
		for (int i = 0; i < 4; ++i) {
			const Point2f a = m.corners[i], b = m.corners[(i + 1) & 3];
			const float s = std::hypot(a.x - b.x, a.y - b.y);
			if (shortest == 0.0f || s < shortest)
				shortest = s;
		}
	}
	shortestSide_ = shortest;
}

void AdaptiveScale::reset()
{
	shortestSide_ = 0.0f;
	scaledInRow_ = 0;
}

} // namespace frappe::detail
