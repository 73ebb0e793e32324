// SPDX-License-Identifier: MIT
// The contour tracer's passes over whole rows, vectorised where Highway is
// built in: which pixels may start a border, and each pixel's neighbours as
// one byte, so that a step of a border reads its neighbourhood with one
// load instead of assembling it from three rows.
#pragma once

#include <cstddef>
#include <cstdint>

namespace frappe::detail {

/// Label values the tracer uses (bit 0 set on every non-zero one; see
/// contour_trace.cpp): an edge pixel not yet on a followed border, one on a
/// followed border, and one whose right neighbour was found to be background
/// while following it.
constexpr std::uint8_t kUnfollowed = 1, kFollowed = 9, kFollowedRightBg = 25;

/// Bit d of out[x], for x in [x0, x1), is bit 0 of the neighbour of row[x]
/// in direction d: right, up-right, up, up-left, left, down-left, down,
/// down-right (counter-clockwise on screen). The rows above and below and
/// columns x0 - 1 and x1 must be readable. Masks left of x0, down to column
/// max(1, x1 - 64), may be rewritten too, with the same values.
void neighbourMasks(const std::uint8_t *row, std::ptrdiff_t stride, int x0, int x1, std::uint8_t *out);

/// Bit x - x0 of `bits` (64 a word, lowest first) set where a border may
/// start in the label row: an unfollowed pixel with background on its left
/// (an outer border), or a non-zero one not marked kFollowedRightBg with
/// background on its right (a hole border). Reads labels from x0 - 1 to
/// x0 + 64 * words + 1; bits from x1 on are clear.
void borderStartBits(const std::uint8_t *labels, int x0, int x1, std::uint64_t *bits);

/// The same without SIMD, the references the vectorised forms are tested
/// against.
void neighbourMasksScalar(const std::uint8_t *row, std::ptrdiff_t stride, int x0, int x1, std::uint8_t *out);
void borderStartBitsScalar(const std::uint8_t *labels, int x0, int x1, std::uint64_t *bits);

} // namespace frappe::detail
