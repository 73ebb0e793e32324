// SPDX-License-Identifier: MIT
// MarkerLayout: a marker's cells as data (frappe/layout.h).
#include "frappe/layout.h"

#include <algorithm>
#include <charconv>
#include <stdexcept>

namespace frappe {

namespace {

[[noreturn]] void fail(const std::string &what)
{
	throw std::invalid_argument(what);
}

/* Which ring a cell lies on, 0 the outermost. */
int ringOf(int size, int x, int y)
{
	return std::min(std::min(x, y), std::min(size - 1 - x, size - 1 - y));
}

bool ringIs(const MarkerLayout &l, int ring, int kind)
{
	for (int y = 0; y < l.size; ++y)
		for (int x = 0; x < l.size; ++x)
			if (ringOf(l.size, x, y) == ring && l.at(x, y) != kind)
				return false;
	return true;
}

/* The square the detector finds, and the quarter turn as a permutation of
 * the bits; checks what the reader relies on. */
void complete(MarkerLayout &l)
{
	const int n = l.size;
	/* The innermost black ring just around a white one; else a black
	 * outermost ring, today's border. */
	l.square_cells = 0;
	for (int ring = 0; 2 * (ring + 1) < n; ++ring) {
		if (ringIs(l, ring, MarkerLayout::kBlack) && ringIs(l, ring + 1, MarkerLayout::kWhite)) {
			l.square_start = ring + 1;
			l.square_cells = n - 2 * (ring + 1);
			l.reversed = true;
		}
	}
	if (!l.square_cells) {
		if (!ringIs(l, 0, MarkerLayout::kBlack))
			fail("no square to find: neither a black ring just around a white ring nor an all-black "
			     "outermost ring");
		l.square_start = 0;
		l.square_cells = n;
		l.reversed = false;
	}
	if (l.square_cells < 3)
		fail("the square to find is under 3 cells wide");
	l.turn_from.assign(static_cast<std::size_t>(l.code_bits), -1);
	for (int y = 0; y < n; ++y) {
		for (int x = 0; x < n; ++x) {
			/* After a quarter turn clockwise, cell (x, y) shows what was at
			 * (y, n - 1 - x). */
			const int to = l.at(x, y), from = l.at(y, n - 1 - x);
			if ((to >= 0) != (from >= 0) || (to < 0 && to != from))
				fail("not the same after a quarter turn: cell (row " + std::to_string(y + 1) + ", column " +
				     std::to_string(x + 1) + ")");
			if (to >= 0)
				l.turn_from[static_cast<std::size_t>(to)] = static_cast<std::int8_t>(from);
		}
	}
}

} // namespace

std::uint64_t MarkerLayout::rotate(std::uint64_t code) const
{
	std::uint64_t out = 0;
	for (int k = 0; k < code_bits; ++k)
		out = out << 1 | static_cast<std::uint64_t>(bit(code, turn_from[static_cast<std::size_t>(k)]));
	return out;
}

MarkerLayout MarkerLayout::classic(int bits)
{
	if (bits < 1 || bits > 8)
		fail("MarkerLayout::classic: bits must be 1..8, got " + std::to_string(bits));
	MarkerLayout l;
	l.size = bits + 2;
	l.code_bits = bits * bits;
	l.cells.assign(static_cast<std::size_t>(l.size * l.size), kBlack);
	for (int y = 0; y < bits; ++y)
		for (int x = 0; x < bits; ++x)
			l.cells[static_cast<std::size_t>((y + 1) * l.size + x + 1)] = static_cast<std::int8_t>(y * bits + x);
	complete(l);
	return l;
}

MarkerLayout MarkerLayout::fromRows(std::span<const std::string> rows)
{
	MarkerLayout l;
	l.size = static_cast<int>(rows.size());
	if (l.size < 3 || l.size > 14)
		fail("a layout has 3 to 14 rows (the sample grid holds 16 cells a side with the ring around), got " +
		     std::to_string(l.size));
	std::vector<int> seenAt(64, 0);
	for (int y = 0; y < l.size; ++y) {
		std::string_view row = rows[static_cast<std::size_t>(y)];
		int x = 0;
		const std::string where = "layout row " + std::to_string(y + 1);
		while (true) {
			const std::size_t start = row.find_first_not_of(" \t");
			if (start == std::string_view::npos)
				break;
			row.remove_prefix(start);
			const std::string_view word = row.substr(0, row.find_first_of(" \t"));
			row.remove_prefix(word.size());
			if (x == l.size)
				fail(where + ": more than " + std::to_string(l.size) + " cells (a layout is square)");
			std::int8_t cell = 0;
			if (word == "b")
				cell = kBlack;
			else if (word == "w")
				cell = kWhite;
			else if (word == "x")
				cell = kAny;
			else {
				int bit = -1;
				const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), bit);
				if (ec != std::errc() || end != word.data() + word.size() || bit < 0 || bit > 63)
					fail(where + ", cell " + std::to_string(x + 1) + ": '" + std::string(word.substr(0, 20)) +
					     "' is none of b, w, x or a bit 0..63");
				if (seenAt[static_cast<std::size_t>(bit)])
					fail(where + ", cell " + std::to_string(x + 1) + ": bit " + std::to_string(bit) +
					     " again (first in row " + std::to_string(seenAt[static_cast<std::size_t>(bit)]) + ")");
				seenAt[static_cast<std::size_t>(bit)] = y + 1;
				cell = static_cast<std::int8_t>(bit);
			}
			l.cells.push_back(cell);
			++x;
		}
		if (x != l.size)
			fail(where + ": " + std::to_string(x) + " cells, not " + std::to_string(l.size) +
			     " (a layout is square)");
	}
	l.code_bits = static_cast<int>(std::count_if(seenAt.begin(), seenAt.end(), [](int s) { return s != 0; }));
	for (int k = 0; k < l.code_bits; ++k)
		if (!seenAt[static_cast<std::size_t>(k)])
			fail("bit " + std::to_string(k) + " is missing (bits are numbered 0.." + std::to_string(l.code_bits - 1) +
			     ")");
	if (l.code_bits == 0)
		fail("a layout without bits");
	complete(l);
	return l;
}

std::vector<std::string> MarkerLayout::rows() const
{
	std::vector<std::string> out;
	for (int y = 0; y < size; ++y) {
		std::string row;
		for (int x = 0; x < size; ++x) {
			const int c = at(x, y);
			if (x)
				row += ' ';
			row += c == kBlack ? "b" : c == kWhite ? "w" : c == kAny ? "x" : std::to_string(c);
		}
		out.push_back(std::move(row));
	}
	return out;
}

} // namespace frappe
