// SPDX-License-Identifier: MIT
// ADAPTIVE_SCALE: choose the next frame's resolution from the last result.
#pragma once

#include "frappe/config.h"
#include "frappe/marker.h"

#include <span>

namespace frappe::detail {

/// The paper's adaptive scaling: r = beta / l_min, where l_min is the
/// shortest marker side seen in the previous frame, with a full-size frame
/// forced after max_scaled_frames scaled ones (so new small markers are
/// found) and whenever the previous frame found nothing.
class AdaptiveScale
{
public:
	/// Scale for the next frame (1 = full resolution).
	float next(const Config &config);
	/// Records what the frame processed at `scale` found.
	void update(std::span<const Marker> markers);
	void reset();

private:
	float shortestSide_ = 0.0f; ///< full-resolution pixels; 0 = nothing seen
	int scaledInRow_ = 0;
};

} // namespace frappe::detail
