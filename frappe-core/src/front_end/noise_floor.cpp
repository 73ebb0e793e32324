// SPDX-License-Identifier: MIT
// The frame's noise and its light floor: the rule is at the top of
// noise_floor.h.
#include "noise_floor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>

#include "frappe/edge_map.h"

namespace frappe::detail {

int noiseMedian(const ImageView &image)
{
	const int w = image.width, h = image.height;
	if (w < 3 || h < 3)
		return -1;
	const int sx = std::max(1, (w - 2) / kNoiseGrid), sy = std::max(1, (h - 2) / kNoiseGrid);
	/* At most 65 x 65 samples: a histogram on the stack, no allocation. */
	std::array<int, kNoiseCap + 1> hist{};
	int n = 0;
	for (int y = 1; y < h - 1; y += sy) {
		const std::uint8_t *a = image.row(y - 1), *b = image.row(y), *c = image.row(y + 1);
		for (int x = 1; x < w - 1; x += sx) {
			const int nw = a[x - 1], nn = a[x], ne = a[x + 1];
			const int ww = b[x - 1], cc = b[x], ee = b[x + 1];
			const int sw = c[x - 1], ss = c[x], se = c[x + 1];
			/* A 0 or a 255 in the window: (v + 1) & 255 <= 1 for one of
			 * them, one chain of minima and no branch. */
			auto up = [](int v) { return (v + 1) & 255; };
			const int lo =
				std::min({ up(nw), up(nn), up(ne), up(ww), up(cc), up(ee), up(sw), up(ss), up(se) });
			const int clear = lo > 1;
			const int l = 4 * cc - 2 * (nn + ss + ww + ee) + (nw + ne + sw + se);
			hist[static_cast<std::size_t>(std::min(std::abs(l), kNoiseCap))] += clear;
			n += clear;
		}
	}
	if (n < kNoiseMinSamples)
		return -1;
	int below = 0;
	for (int m = 0; m <= kNoiseCap; ++m) {
		below += hist[static_cast<std::size_t>(m)];
		if (2 * below >= n)
			return m;
	}
	return kNoiseCap;
}

int noiseFloorMultiplier(float perSigma)
{
	/* Median |L| = 6 sigma times the median of |N(0, 1)|, 0.67449. */
	return static_cast<int>(std::lround(1024.0 * static_cast<double>(perSigma) / 4.0469));
}

int noiseLightFloor(int median, int multiplier, int cap)
{
	if (median < 0 || multiplier <= 0 || cap >= FrontEndParams::kLightReference)
		return cap;
	const int floor = (median * multiplier + 512) >> 10;
	return std::min(cap, std::max(cap / 2, floor));
}

} // namespace frappe::detail
