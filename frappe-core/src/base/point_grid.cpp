// SPDX-License-Identifier: MIT
#include "point_grid.h"

#include <algorithm>
#include <cstdint>

namespace frappe::detail {

void PointGrid::reset(std::size_t points, float cell)
{
	/* At least twice as many slots as points: chains of about one entry. */
	std::size_t slots = 64;
	while (slots < 2 * points)
		slots *= 2;
	mask_ = slots - 1;
	if (heads_.size() < slots)
		heads_.resize(slots);
	std::fill_n(heads_.begin(), slots, -1);
	entries_.clear();
	entries_.reserve(points);
	invCell_ = 1.0f / cell;
}

int PointGrid::cellOf(float v) const
{
	/* Clamped, which keeps the order (NaN to 0): cells beyond only share
	 * slots, which costs comparisons, never a missed point. The floor by
	 * hand: std::floor is a library call on the Pi Zero's ARMv6, a
	 * conversion to int one instruction. */
	const float c = v * invCell_;
	if (!(c > -1e9f))
		return c != c ? 0 : -1000000000;
	if (c > 1e9f)
		return 1000000000;
	const int i = static_cast<int>(c); /* towards zero */
	return c < static_cast<float>(i) ? i - 1 : i;
}

std::size_t PointGrid::slot(int x, int y) const
{
	const auto h = static_cast<std::uint32_t>(x) * 0x9E3779B1u ^ static_cast<std::uint32_t>(y) * 0x85EBCA77u;
	return (h ^ h >> 15) & mask_;
}

void PointGrid::add(int item, int tag, Point2f p)
{
	const std::size_t s = slot(cellOf(p.x), cellOf(p.y));
	entries_.push_back({ item, tag, heads_[s] });
	heads_[s] = static_cast<int>(entries_.size() - 1);
}

} // namespace frappe::detail
