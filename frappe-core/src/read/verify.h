// SPDX-License-Identifier: MIT
// The checks a decoded candidate passes before it is reported: a codeword
// alone is weak evidence (a third of all 4x4 patterns are within one bit of
// some 4x4_250 code), so the marker's other features must be there too.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "decode.h"
#include "frappe/dictionary.h"
#include "frappe/image.h"
#include "frappe/marker.h"
#include "point_grid.h"

namespace frappe::detail {

/// How the cells of a warped candidate read, beyond their bits.
struct CellRead {
	/// Cells, border included, whose 2x2 samples lie clearly on both sides
	/// of the threshold: a grid that does not sit on real cells (the inner
	/// square of a larger marker, say) splits them.
	int straddling = 0;
	/// The weakest code cell: the smallest distance of a code cell's mean
	/// from the threshold, as a fraction of half the contrast, in [0, 1].
	float margin = 0.0f;
	/// The code cells read weakly (margin below the policy's weak_margin),
	/// one bit each in the code's order.
	std::uint64_t weak = 0;
};

/// Reads the cells of `w` against b's threshold and contrast; code cells
/// with a margin below `weakMargin` are weak. Glare: where a border cell
/// (black ink) clips, so may any code cell, and every code cell that clips
/// is unknown (weak, margin 0), left to the code's distance. `tone` is the
/// scale the samples are on.
CellRead readCells(const WarpedMarker &w, int bits, const Binarised &b, float weakMargin, Tone tone = {});

/// The bits corrected to reach d's codeword that were read clearly (not
/// weak).
int clearErrors(const Dictionary &dict, std::uint64_t code, std::uint64_t weak, const Decoded &d);

/// The ring of cells just outside the black border, where the marker's
/// quiet zone lies.
struct QuietZone {
	int light = 0; ///< ring cells lighter than the threshold
	int dark = 0;  ///< ring cells clearly darker than it, as dark as a black cell
	int seen = 0;  ///< ring cells inside the image (all others are unknown)
	float brightest = 0.0f; ///< the lightest ring cell, in grey levels whatever the tone
};

/// Samples the centre of each of the 4 (bits + 3) cells one cell outside
/// the border of the quad `corners`, against b's threshold and contrast.
QuietZone readQuietZone(const ImageView &image, const std::array<Point2f, 4> &corners, int bits,
			const Binarised &b, Tone tone = {});

/// binarise() with a threshold per cell that follows the light across the
/// marker: halfway between a plane fitted to the border cells (black ink)
/// and one fitted to the ring of cells outside them (the quiet zone's
/// paper), both in the marker's cell coordinates on the samples' scale
/// (`tone`: on the log scale light that falls across the marker is a slope
/// there). Threshold and contrast stay the whole payload's (the checks after
/// decoding use them). Returns a contrast of 0 (not readable()) where the
/// planes do not lie at least kMinContrast apart at every code cell, or too
/// little of the ring is in the image.
Binarised binariseInLight(const ImageView &image, const std::array<Point2f, 4> &corners, const WarpedMarker &w,
			  int bits, Tone tone);

/// Border cells that may read white before a candidate is rejected: blur
/// and small cells brighten the frame next to the quiet zone, a corner may
/// be occluded; a patch of code has more.
int allowedBorderErrors(int bits);

/// The border cells that read white are at most allowedBorderErrors().
bool borderIsBlack(const Binarised &b, int bits);

/// Worth decoding: the payload spans at least 10 grey levels and the
/// border is black. The detector's rule for every read (the tracer's
/// probe, readMarker's callers, readCellCentres).
bool readable(const Binarised &b, int bits);

/// How much a read needs its frame and cells to vouch for it. A code that
/// chance alone reads often (every 4x4 code, or a 6x6 code three bits
/// away) is only believed on a clean frame; a strong code is also believed
/// on a marker printed up to the edge of its card or half covered.
enum class Scrutiny {
	Tolerant,
	Strict,
};

/// The scrutiny a read of `dict` corrected by `hamming` bits needs: strict
/// when a random pattern would read as well with a chance above 1e-4.
Scrutiny scrutinyFor(const Dictionary &dict, int hamming);

/// Most of the ring around the border that lies in the image is lighter
/// than the threshold: two thirds (one side may be cut by a card's edge or
/// covered), under strict scrutiny three quarters with at most one cell in
/// sixteen clearly dark (blur greys a one-cell quiet zone, it does not
/// blacken it; black cells around a block of code cells stay black).
/// Always true when too little of the ring is in the image.
bool quietZoneIsLight(const QuietZone &q, Scrutiny scrutiny = Scrutiny::Strict);

/// On the log scale (Tone), where a light grey beside black ink reads as
/// white, the ring's lightest cell must also be at least half as light, in
/// grey levels, as the code's lightest sample (Binarised::lightest where
/// sharpening overshot it); always true on grey levels.
bool quietZoneIsPaper(const QuietZone &q, const Binarised &b, Tone tone);

/// Few cells read on both sides of the threshold: one in eight of the
/// code's number of cells, one in four under tolerant scrutiny (small
/// cells at the edge of a marker's sharpness).
bool cellsAgree(const CellRead &c, int bits, Scrutiny scrutiny = Scrutiny::Strict);

/// The nearest other id is clearly further than the decoded one.
bool unambiguous(const Decoded &d, const Dictionary &dict);

/// Whether the quad `inner` lies within the code area of the marker whose
/// outer corners are `marker` (inside its black border, to half a cell):
/// where no other marker can be.
bool insideCodeArea(const std::array<Point2f, 4> &inner, const std::array<Point2f, 4> &marker, int bits);

/// Drops the markers that lie inside another marker's code area: blocks of
/// code cells that read as a marker. In place, without allocating. Not a
/// repeat of the kind suppression.h drops (what it drops is no copy of
/// the marker around it, and is known only once every candidate is read):
/// it runs once on the frame's whole marker set. A marker is tested only
/// against those whose first corner lies in its box (`grid`, reused: a
/// warm one allocates nothing), so a frame of thousands of markers costs
/// in proportion to them.
void dropNestedMarkers(std::vector<Marker> &markers, int bits, PointGrid &grid);
/// The same with a grid of its own, which it allocates: for tests.
void dropNestedMarkers(std::vector<Marker> &markers, int bits);

/// What a detector corrects.
struct DecodePolicy {
	int maxHamming = 0;       ///< bits read clearly that may be corrected
	int maxTotal = 0;         ///< bits corrected in all, weak reads included
	float weakMargin = 0.0f;  ///< a code cell's margin below this is a weak read
	Tone tone;                ///< the scale samples are read on
	/// Where the warps of this candidate's earlier reads are kept (none:
	/// every warp samples the frame).
	WarpMemo *memo = nullptr;
	/// Where this stage's last decodes are kept (none: every code is
	/// looked up).
	DecodeCache *decodes = nullptr;
};

/// Why a candidate is not a marker.
enum class Rejection {
	None,
	NoCode,         ///< no codeword within policy.maxTotal, or a tie
	Ambiguous,      ///< another id nearly as near
	BorderNotBlack,
	TooManyClearErrors,
	CellsDisagree,
	NoQuietZone,
	WeakRead, ///< readCellCentres: too few cells read clearly to single out the code
	PlainShape, ///< a plain codeword (plainCode()) read less clearly than kPlainMargin
};

/// A candidate read as a marker, or the reason it is not one.
struct MarkerRead {
	Decoded decoded;
	Rejection rejection = Rejection::NoCode;
	float margin = 0.0f;
	bool ok() const { return rejection == Rejection::None; }
};

/// Decodes a binarised candidate and runs every check on it, the cheapest
/// first; `corners` are the quad `w` was warped from. When `w` holds one
/// sample per cell (warpCellCentres), the cells' agreement of a read under
/// strict scrutiny is judged from a warpMarker grid of the same quad.
MarkerRead readMarker(const ImageView &image, const std::array<Point2f, 4> &corners, const CodeBook &codes,
		      const DecodePolicy &policy, const WarpedMarker &w, const Binarised &b);

/// Reads a candidate whose cells are small at their centres, sharpened
/// against their neighbours (warpCellCentres, into `scratch`), and runs
/// readMarker's checks on that read. Also rejects a read whose payload does
/// not reach both sides of the grey level halfway between the black border
/// and the ring outside it (a dark square or patch of texture around
/// noise), and one whose clearly read cells alone would match some code by
/// chance too often (WeakRead).
MarkerRead readCellCentres(const ImageView &image, const std::array<Point2f, 4> &corners, const CodeBook &codes,
			   const DecodePolicy &policy, WarpedMarker &scratch);

} // namespace frappe::detail
