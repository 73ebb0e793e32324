// SPDX-License-Identifier: MIT
// The frame's own noise (issue 29), estimated once per frame before the
// front end, and the light floor it gives (Config::light_floor_noise). In
// exact integers, so that the floor a frame gets is the same on every
// machine; the front end then receives it in FrontEndParams::light_floor
// like any other floor, so its kernels (scalar, Highway, ARMv6, the QPU
// programs) need nothing new.
//
//   L  = 4 c - 2 (n + s + w + e) + (nw + ne + sw + se), the 3 x 3 Laplacian
//        (Immerkaer's mask: on white noise of deviation sigma, L has
//        deviation 6 sigma and a median |L| of 4.047 sigma; the frame's
//        edges and texture lie in the tail a median ignores)
//   at the pixels (1 + i sx, 1 + j sy), sx = max(1, (W - 2) / 64),
//   sy = max(1, (H - 2) / 64), i, j >= 0 while inside the outermost row and
//   column, skipping a pixel whose 3 x 3 window holds a 0 or a 255 (clipped:
//   its noise is cut);
//   M  = the least m with 2 #{|L| <= m} >= #samples, |L| counted as at most
//        kNoiseCap; -1 with fewer than kNoiseMinSamples samples.
//   floor = min(cap, max(cap / 2, (M * mult + 512) >> 10)) for M >= 0 and
//        cap < 128, else cap; cap = the configured light floor, mult =
//        round(1024 * light_floor_noise / 4.047).
#pragma once

#include <cstdint>

#include "frappe/image.h"

namespace frappe::detail {

/// |L| above this counts as this (an edge, not noise: the median of a
/// frame whose noise reaches it is far above any floor's cap).
constexpr int kNoiseCap = 63;
/// Fewer clip-free samples than this (a tiny or clipped frame): no estimate.
constexpr int kNoiseMinSamples = 64;
/// Samples a side: at most 64 x 64 a frame, whatever its size.
constexpr int kNoiseGrid = 64;

/// The median |L| of the frame's sample (the rule above), or -1.
int noiseMedian(const ImageView &image);

/// The integer multiplier of noiseMedian() for a floor of `perSigma` grey
/// levels per grey level of noise deviation.
int noiseFloorMultiplier(float perSigma);

/// The light floor of a frame of noise median `median` (noiseMedian()):
/// between half the cap and the cap.
int noiseLightFloor(int median, int multiplier, int cap);

} // namespace frappe::detail
