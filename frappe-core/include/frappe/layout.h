// SPDX-License-Identifier: MIT
// frappe/layout.h: a marker's cells as data. Which cells are always black,
// always white, of no matter, or a bit of the code, and the square the
// detector finds among them. Today's n x n families (bits inside a one-cell
// black border) are MarkerLayout::classic(n); AprilTag 3's newer families
// put bits outside a black ring and are found where that ring meets a white
// one (frappe-core/dictionaries/README.md).
//
// Since: 0.3
#pragma once

#include "frappe/export.h"

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace frappe {

struct FRAPPE_EXPORT MarkerLayout {
	/// What a cell that is not a bit of the code is.
	enum Cell : std::int8_t {
		kBlack = -1,
		kWhite = -2,
		kAny = -3, ///< carries nothing (a circle family's corners): drawn black, never read
	};
	int size = 0;         ///< cells a side of the whole marker
	int square_start = 0; ///< the row (and column) of the detected square's first cell
	int square_cells = 0; ///< the detected square's side in cells
	int code_bits = 0;    ///< bits of a code, at most 64
	/// The detected square's edge is black outside, white inside (a black
	/// ring around a white one); else black inside, white outside (today's
	/// families: the border against the quiet zone).
	bool reversed = false;
	/// size x size, row-major from the top-left cell: a bit's index (0 =
	/// the code's most significant bit; 1 = white) or a Cell.
	std::vector<std::int8_t> cells;
	/// A quarter turn clockwise moves bit from[k] to bit k.
	std::vector<std::int8_t> turn_from;

	int at(int x, int y) const { return cells[static_cast<std::size_t>(y) * size + x]; }
	/// The code as the marker would read after a quarter turn clockwise.
	std::uint64_t rotate(std::uint64_t code) const;
	/// The value (0 black, 1 white) of the code's bit `index` (0 = most significant).
	int bit(std::uint64_t code, int index) const { return static_cast<int>((code >> (code_bits - 1 - index)) & 1u); }
	/// Today's families: n x n bits (n = 1..8) inside a one-cell black
	/// border, read row-major; the square is the whole marker.
	static MarkerLayout classic(int bits);
	/// From rows of cells, top to bottom, each a line of words separated
	/// by blanks: `b` black, `w` white, `x` of no matter, or a bit's index.
	/// Each bit 0..code_bits-1 exactly once, the layout square and
	/// unchanged by a quarter turn (bits onto bits, fixed cells onto the
	/// same), and a square to find: a black ring just around a white one,
	/// else an all-black outermost ring. Throws std::invalid_argument
	/// naming the row and cell at fault.
	static MarkerLayout fromRows(std::span<const std::string> rows);
	/// The rows again, as fromRows() reads them.
	std::vector<std::string> rows() const;
};

} // namespace frappe
