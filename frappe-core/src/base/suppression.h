// SPDX-License-Identifier: MIT
// The back end's one rule for dropping repeats: a quad or marker found
// again is compared with those already kept, in the order they were kept.
#pragma once

#include <algorithm>
#include <span>

namespace frappe::detail {

/* The first of `kept` that `item` repeats (same(kept, item)), or nullptr.
 * Greedy, in arrival order: the back end meets its candidates in an order
 * that puts the one to keep first (the tracer's scan; then smallest first,
 * a marker's own outline before its quiet zone's), so the caller keeps the
 * earlier one unless it has a better reason (a lower Hamming distance).
 * What counts as a repeat is the caller's: a marker read twice
 * (keepMarker()), the outline of a decoded marker's quiet zone
 * (surroundsMarker(), which only passes it the markers filed near the
 * candidate). Quadratic in the items passed: keepMarker() passes all the
 * frame's markers, which Config::max_candidates bounds, and compares ids
 * first. The traced quads, one per square of a tiled wall, are too many
 * for that: removeDuplicateQuads() applies the same rule through a grid
 * of their corners (point_grid.h). Allocates nothing. */
template<typename Kept, typename Item, typename Same>
Kept *firstRepeated(std::span<Kept> kept, const Item &item, Same same)
{
	const auto it = std::ranges::find_if(kept, [&](const Kept &k) { return same(k, item); });
	return it == kept.end() ? nullptr : &*it;
}

} // namespace frappe::detail
