// SPDX-License-Identifier: MIT
// What the warp kernel (warp.hpp) computes: frappe-core's fixed-point warp
// (frappe/fixed_warp.h, where the arithmetic is defined), here named as the kernel
// sees it. warpParams() is frappe-core's quantiseWarp() plus the kernel's own limit:
// it computes the whole 16 x 16 grid whatever the marker's side, so the forms must
// stay in range there too. Quads it refuses are warped on the CPU by the same
// definition (frappe::makeCpuWarper()), so the samples never depend on where they ran.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "frappe/fixed_warp.h"
#include "frappe/image.h"

namespace frappe::vc4::kernels {

inline constexpr int kWarpSide = 16;        // samples per side the kernel computes
inline constexpr int kWarpSamples = kWarpSide * kWarpSide;
inline constexpr int kWarpFracBits = kFixedWarpFracBits;
inline constexpr int kWarpIntBits = kFixedWarpIntBits;
inline constexpr int kWarpDivisionSteps = kWarpIntBits + kWarpFracBits;
inline constexpr int kWarpMaxCandidates = 32;

using WarpForm = frappe::FixedWarpForm;
using WarpParams = frappe::FixedWarp;

// quantiseWarp(corners, side) when the kernel can run it (side <= 16, forms in range
// on the 16 x 16 grid); empty otherwise, with the reason in `why`.
std::optional<WarpParams> warpParams(const std::array<Point2f, 4> &corners, int side = kWarpSide,
                                     std::string *why = nullptr);

// The kernel's 16 x 16 samples, row-major, by frappe::fixedWarpSample(). The image must
// be at least 2 x 2 pixels.
void warpReference(const ImageView &image, const WarpParams &p, std::span<uint8_t, kWarpSamples> out);

} // namespace frappe::vc4::kernels
