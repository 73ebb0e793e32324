// SPDX-License-Identifier: MIT
// A hash grid of points, for the back end's suppression rules
// (suppression.h): an item is compared only with the items filed near it,
// not with all of them, so a frame of thousands of candidates or markers
// costs in proportion to them.
#pragma once

#include <cstddef>
#include <vector>

#include "frappe/image.h"

namespace frappe::detail {

/// Points filed under square cells `cell` wide, each with an item and a
/// tag of the caller's (a quad and which of its corners, say). Cells hash
/// to slots; a slot may hold several cells' points, so a visit may see
/// points outside the cells asked for: callers test each item exactly. The
/// vectors grow to the most points a frame has had and are reused: a warm
/// grid allocates nothing.
class PointGrid
{
public:
	/// Empties the grid for up to `points` points, cells `cell` wide.
	void reset(std::size_t points, float cell);
	void add(int item, int tag, Point2f p);
	/// Calls visit(item, tag) for every point filed in the cells that
	/// [x0, x1] x [y0, y1] touches (and maybe a few more), until it returns
	/// true; returns whether one did.
	template<typename Visit>
	bool anyIn(float x0, float y0, float x1, float y1, Visit visit) const
	{
		const int cx0 = cellOf(x0), cx1 = cellOf(x1), cy0 = cellOf(y0), cy1 = cellOf(y1);
		/* A box of more cells than slots: every point once is cheaper. */
		if ((static_cast<double>(cx1) - cx0 + 1) * (static_cast<double>(cy1) - cy0 + 1) >
		    static_cast<double>(mask_ + 1)) {
			for (const Entry &en : entries_)
				if (visit(en.item, en.tag))
					return true;
			return false;
		}
		for (int y = cy0; y <= cy1; ++y)
			for (int x = cx0; x <= cx1; ++x)
				for (int e = heads_[slot(x, y)]; e >= 0; e = entries_[static_cast<std::size_t>(e)].next) {
					const Entry &en = entries_[static_cast<std::size_t>(e)];
					if (visit(en.item, en.tag))
						return true;
				}
		return false;
	}

private:
	struct Entry {
		int item, tag, next;
	};
	int cellOf(float v) const;
	std::size_t slot(int x, int y) const;
	float invCell_ = 1.0f;
	std::size_t mask_ = 0;
	std::vector<int> heads_; ///< per slot, the last entry filed there, -1: none
	std::vector<Entry> entries_;
};

} // namespace frappe::detail
