/* SPDX-License-Identifier: MIT
 *
 * overlay_font.cpp: see overlay_font.h. The glyphs are round-ended strokes
 * in the spirit of DIN lettering: open counters and distinct silhouettes
 * (the 1 has a foot, the 3 a flat top, the 6 and 9 straight tails, the
 * 4 is open) so that
 * each digit still reads when a label is ten pixels tall.
 */
#include "overlay_font.h"

#include <algorithm>
#include <numbers>

namespace frappe::gst {

namespace {

constexpr double kCellWidth = 6.0;
constexpr double kCellHeight = 10.0;
constexpr double kAdvance = 9.0; ///< cell plus gap, in units

/* One stroke of a glyph, in units, y down: a line (x0, y0)-(x1, y1), or an
 * arc about (x0, y0) of radius x1 from y1 to a1 degrees (clockwise on
 * screen). */
struct Piece {
	char ch;
	bool arc;
	float x0, y0, x1, y1, a1;
};

constexpr Piece L(char c, float x0, float y0, float x1, float y1)
{
	return { c, false, x0, y0, x1, y1, 0.0f };
}

constexpr Piece A(char c, float cx, float cy, float r, float from, float to)
{
	return { c, true, cx, cy, r, from, to };
}

constexpr Piece kPieces[] = {
	/* 0: a stadium. */
	A('0', 3, 3, 3, 180, 360), A('0', 3, 7, 3, 0, 180), L('0', 0, 3, 0, 7), L('0', 6, 3, 6, 7),
	/* 1: stem, flag and foot. */
	L('1', 3.2f, 0, 3.2f, 10), L('1', 3.2f, 0, 1, 2), L('1', 1, 10, 5.4f, 10),
	/* 2: a hook, a diagonal, a base. */
	A('2', 3, 3, 3, 180, 390), L('2', 5.6f, 4.5f, 0, 10), L('2', 0, 10, 6, 10),
	/* 3: flat top, a diagonal, a bowl; no upper loop to mistake for an 8. */
	L('3', 0.4f, 0, 5.6f, 0), L('3', 5.6f, 0, 2.6f, 4), A('3', 3, 7, 3, 262, 505),
	/* 4: open at the top. */
	L('4', 4.4f, 10, 4.4f, 0), L('4', 4.4f, 0, 0, 7), L('4', 0, 7, 6, 7),
	/* 5: bar, stem, bowl. */
	L('5', 5.6f, 0, 1.2f, 0), L('5', 1.2f, 0, 1.0f, 4.4f), A('5', 3, 6.9f, 3.1f, 235, 505),
	/* 6: a loop with a straight tail. */
	A('6', 3, 7, 3, 0, 360), L('6', 0.35f, 5.6f, 4.4f, 0),
	/* 7 */
	L('7', 0, 0, 6, 0), L('7', 6, 0, 2, 10),
	/* 8: two loops, the lower one wider. */
	A('8', 3, 2.4f, 2.4f, 0, 360), A('8', 3, 7.4f, 2.6f, 0, 360),
	/* 9: the 6 turned round. */
	A('9', 3, 3, 3, 0, 360), L('9', 5.65f, 4.4f, 1.6f, 10),
	L('-', 1, 5.5f, 5, 5.5f),
	/* i: stem and dot. */
	L('i', 3, 4, 3, 10), L('i', 3, 1.2f, 3, 1.2f),
	/* d: bowl and ascender. */
	A('d', 2.9f, 7.1f, 2.9f, 0, 360), L('d', 5.8f, 0, 5.8f, 10),
};

constexpr double radians(double degrees)
{
	return degrees * std::numbers::pi / 180.0;
}

} // namespace

bool hasGlyph(char c)
{
	return std::any_of(std::begin(kPieces), std::end(kPieces), [c](const Piece &p) { return p.ch == c; });
}

double textWidth(std::string_view text, double height)
{
	if (text.empty())
		return 0.0;
	const double units = static_cast<double>(text.size() - 1) * kAdvance + kCellWidth;
	return units * height / kCellHeight;
}

bool addText(Path &path, std::string_view text, double left, double top, double height)
{
	const double s = height / kCellHeight;
	bool ok = true;
	for (std::size_t i = 0; i < text.size(); ++i) {
		const double ox = left + static_cast<double>(i) * kAdvance * s;
		for (const Piece &p : kPieces) {
			if (p.ch != text[i])
				continue;
			const Stroke stroke = p.arc ? Stroke::circleArc(ox + p.x0 * s, top + p.y0 * s, p.x1 * s,
									radians(p.y1), radians(p.a1))
						    : Stroke::segment(ox + p.x0 * s, top + p.y0 * s, ox + p.x1 * s,
								      top + p.y1 * s);
			ok = path.add(stroke) && ok;
		}
	}
	return ok;
}

Pen textPen(double height, Yuv ink)
{
	/* A stroke of 0.15 cap heights; never under 1.3 pixels, where the
	 * halo would swallow the ink. */
	Pen pen;
	pen.width = std::max(1.3, 0.15 * height);
	pen.halo = std::max(1.2, 0.08 * height);
	pen.ink = ink;
	return pen;
}

} // namespace frappe::gst
