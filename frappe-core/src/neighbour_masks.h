// SPDX-License-Identifier: MIT
// Which of a pixel's eight neighbours are non-zero, as one byte per pixel:
// the contour tracer reads a pixel's neighbourhood with one load instead of
// assembling it from three rows on every step of a border.
#pragma once

#include <cstddef>
#include <cstdint>

namespace frappe::detail {

/// Bit d of out[x], for x in [x0, x1), is bit 0 of the neighbour of row[x]
/// in direction d: right, up-right, up, up-left, left, down-left, down,
/// down-right (counter-clockwise on screen). The rows above and below and
/// columns x0 - 1 and x1 must be readable. Masks left of x0, down to column
/// max(1, x1 - 64), may be rewritten too, with the same values.
void neighbourMasks(const std::uint8_t *row, std::ptrdiff_t stride, int x0, int x1, std::uint8_t *out);

/// The same without SIMD, the reference the vectorised form is tested against.
void neighbourMasksScalar(const std::uint8_t *row, std::ptrdiff_t stride, int x0, int x1, std::uint8_t *out);

} // namespace frappe::detail
