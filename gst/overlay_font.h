/* SPDX-License-Identifier: MIT
 *
 * overlay_font.h: a stroke font for the overlay's labels, designed here:
 * digits, '-', and the letters of "id", as segments and circular arcs on a
 * cell 6 units wide and 10 tall, so a label draws at any height through the
 * canvas's anti-aliased strokes, outlined by their halo.
 */
#pragma once

#include <string_view>

#include "canvas.h"

namespace frappe::gst {

/// Whether `c` has a glyph (others are drawn as a space).
bool hasGlyph(char c);

/// The width of `text`'s glyph cells at cap height `height` pixels, from
/// the first cell's left to the last one's right; the ink and its halo
/// reach textPen()'s width / 2 + halo further on every side.
double textWidth(std::string_view text, double height);

/// Adds `text`'s strokes to `path`, its cells `height` pixels tall with the
/// top-left one at (left, top). False when the path had no room for all.
bool addText(Path &path, std::string_view text, double left, double top, double height);

/// The pen for text `height` pixels tall: strokes bold enough to survive
/// chroma subsampling and JPEG, a halo that outlines them on any
/// background.
Pen textPen(double height, Yuv ink);

} // namespace frappe::gst
