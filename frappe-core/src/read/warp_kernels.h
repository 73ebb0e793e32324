// SPDX-License-Identifier: MIT
// The perspective warp's sampling: a grid of points through a homography
// and a bilinear sample at each, vectorised where Highway is built in. The
// fixed-point form (frappe/fixed_warp.h) is the warp; the float form is its
// fallback for the quads the fixed point refuses.
#pragma once

#include "frappe/fixed_warp.h"
#include "frappe/homography.h"
#include "frappe/image.h"

namespace frappe::detail {

/// out[j * side + i] = fixedWarpSample(image, warp, i, j) for i, j in
/// [0, warp.side), as floats, or with `fine` fixedWarpValue() 2^-20. The
/// image is at least 2 x 2 pixels.
void warpFixedSamples(const ImageView &image, const FixedWarp &warp, bool fine, float *out);

/// The same without SIMD: the reference the vectorised form is tested
/// against. Its divisions are in double, which is exact here (the quotient
/// is below 2^21 and, unless an integer, at least 2^-20 from one: far more
/// than a double's rounding there), and fast on every CPU, the ARM1176
/// included, where a 64-bit integer division is a library call.
void warpFixedSamplesScalar(const ImageView &image, const FixedWarp &warp, bool fine, float *out);

/// out[j * side + i] = sampleBilinear(image, H(u, v)) for u = (i + 0.5) / side
/// and v = (j + 0.5) / side, i, j in [0, side). The point is evaluated in
/// double (as h0 u + (h1 v + h2), h3 u + (h4 v + h5) over h6 u + (h7 v + h8),
/// through the reciprocal of the denominator) and rounded to float, without
/// fused multiply-adds. `inside` says that every point lies in
/// [0, width - 2] x [0, height - 2], so that the scalar form may skip the
/// clamps; the vector form clamps regardless (it costs it next to nothing).
void warpSamples(const ImageView &image, const Homography &H, int side, bool inside, float *out);

/// The same without SIMD, the reference the vectorised form is tested
/// against.
void warpSamplesScalar(const ImageView &image, const Homography &H, int side, bool inside, float *out);

} // namespace frappe::detail
