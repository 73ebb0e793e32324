// SPDX-License-Identifier: MIT
// CandidateReader::finish() for a dictionary with a layout (frappe/layout.h): a candidate is
// the detected square, where a black ring meets a white one (or today's
// border against its quiet zone); its corners are refined with the edge's
// own polarity, the layout's whole grid is warped from them (on the QPUs in
// a batch: the grid is one more quad), and the cells are read against the
// two rings beside the edge.
#include <algorithm>
#include <cmath>

#include "candidate_reader.h"
#include "corner_refine.h"
#include "frappe/homography.h"
#include "layout_reader.h"
#include "marker_set.h"
#include "quad_geometry.h"

namespace frappe {

namespace {

using detail::bigEnough;
using detail::cellSide;
using detail::StageTimer;
using detail::toFullResolution;

/* Candidates of cells under this many pixels (were they the square) are
 * also read as the outline around a smaller square (readLayoutCandidate). */
constexpr float kInnerSquareCell = 6.0f;

/* The square of `share` of the quad's side at its centre, in the quad's
 * perspective. */
bool centredSquare(const std::array<Point2f, 4> &quad, float share, std::array<Point2f, 4> &out)
{
	const auto H = Homography::fromUnitSquare(quad);
	if (!H)
		return false;
	const double lo = 0.5 * (1.0 - share), hi = 0.5 * (1.0 + share);
	out = { H->map(lo, lo), H->map(hi, lo), H->map(hi, hi), H->map(lo, hi) };
	return true;
}

std::array<Point2f, 4> reversedOrder(const std::array<Point2f, 4> &q)
{
	return { q[0], q[3], q[2], q[1] };
}

/* A read layout marker's colour at cell (x, y): 1 white, 0 black, -1
 * outside the layout. */
int cellColour(const MarkerLayout &layout, std::uint64_t code, int x, int y)
{
	if (x < 0 || y < 0 || x >= layout.size || y >= layout.size)
		return -1;
	const int c = layout.at(x, y);
	if (c >= 0)
		return layout.bit(code, c);
	return c == MarkerLayout::kWhite ? 1 : 0;
}

/* Blur, as the steepest fall over two pixels (halved) across the sides of
 * `quad` (dark inwards, as refineCorners() is handed it) over the whole
 * step within 4 px: a Gaussian edge of sigma s gives Phi(1 / s) - 1/2 (with
 * the pixels' own width: 0.37 at the hard scenes' blur of 0.7, 0.29 at
 * 1.1). The median of 8 columns a side; 0 when too few have a step. */
float edgeSharpness(const ImageView &image, const std::array<Point2f, 4> &quad)
{
	float ratios[32];
	int n = 0;
	for (int k = 0; k < 4; ++k) {
		const Point2f a = quad[static_cast<std::size_t>(k)], b = quad[static_cast<std::size_t>((k + 1) & 3)];
		const float dx = b.x - a.x, dy = b.y - a.y;
		const bool flat = std::abs(dx) >= std::abs(dy);
		/* Inwards along the column (as fitSide()). */
		const int dir = (flat ? dx : -dy) > 0.0f ? 1 : -1;
		for (int i = 0; i < 8; ++i) {
			const float t = 0.2f + 0.6f * static_cast<float>(i) / 7.0f;
			const int x = static_cast<int>(std::lround(a.x + t * dx)),
				  y = static_cast<int>(std::lround(a.y + t * dy));
			auto p = [&](int j) {
				const int px = flat ? x : x + dir * j, py = flat ? y + dir * j : y;
				return static_cast<int>(image.data[std::clamp(py, 0, image.height - 1) * image.stride +
								   std::clamp(px, 0, image.width - 1)]);
			};
			int slope = 0, light = 0, dark = 255;
			for (int j = -1; j <= 1; ++j)
				slope = std::max(slope, p(j - 1) - p(j + 1));
			for (int j = -4; j <= 0; ++j)
				light = std::max(light, p(j));
			for (int j = 0; j <= 4; ++j)
				dark = std::min(dark, p(j));
			if (light - dark > 20)
				ratios[n++] = 0.5f * static_cast<float>(slope) / static_cast<float>(light - dark);
		}
	}
	if (n < 8)
		return 0.0f;
	std::nth_element(ratios, ratios + n / 2, ratios + n);
	return ratios[n / 2];
}

/* Where a cell beside the two rings is of the other colour than its ring,
 * its edge a cell away cancels the tail of the falls on that side, and a
 * column's crossing slides away from it: by up to 0.3 px at cells of 2 px
 * across and the hard scenes' blur (1.1 px), with the bits along a side
 * (the fitted side tilts: corners 0.5 px off). Measured on the hard scenes
 * as -0.33 px (towards the light) where the cell beyond the dark ring
 * differs and +0.24 px where the one beyond the light ring does, at 2 px
 * cells, falling as exp(-c^2 / 8) with the cell's width c across (0.05 px
 * at 4.5); at other blurs, c scaled to the same ratio to the blur. */
constexpr float kPullDark = -0.33f, kPullLight = 0.24f;
constexpr float kHardBlur = 1.24f; /* sigma from edgeSharpness() on the hard scenes */

/* SideOffsets for `quad` (the square as refineCorners() is handed it) of
 * a reversed layout's marker read as `code`, whose layout-ordered corners
 * are `square`. False when no column is pulled by as much as 0.01 px. */
bool patternPulls(const ImageView &image, const MarkerLayout &layout, std::uint64_t code,
		  const std::array<Point2f, 4> &square, const std::array<Point2f, 4> &quad, detail::SideOffsets &out)
{
	const auto H = Homography::fromUnitSquare(square);
	if (!H)
		return false;
	const auto Hi = H->inverse();
	const float r = edgeSharpness(image, quad);
	if (!Hi || r <= 0.0f)
		return false;
	/* sigma = 1 / PhiInverse(1/2 + r), by bisection. */
	const float target = 0.5f + std::clamp(r, 0.15f, 0.45f);
	float lo = 0.0f, hi = 5.0f;
	for (int it = 0; it < 24; ++it) {
		const float mid = 0.5f * (lo + hi);
		(0.5f * std::erfc(-mid / std::sqrt(2.0f)) < target ? lo : hi) = mid;
	}
	const float scale = kHardBlur * 0.5f * (lo + hi); /* c times this: c at the hard scenes' blur */
	const double s0 = layout.square_start, sc = layout.square_cells;
	bool any = false;
	for (int k = 0; k < 4; ++k) {
		const Point2f a = quad[static_cast<std::size_t>(k)], b = quad[static_cast<std::size_t>((k + 1) & 3)];
		const float len = std::hypot(b.x - a.x, b.y - a.y);
		if (len < 1.0f)
			return false;
		for (int j = 0; j < detail::SideOffsets::kSteps; ++j) {
			const float t = (static_cast<float>(j) + 0.5f) / detail::SideOffsets::kSteps;
			/* The pulls 0.7 px either way along the side too, as
			 * far as blur reaches. */
			float pull = 0.0f;
			for (const float along : { -0.7f, 0.0f, 0.7f }) {
				const float tt = t + along / len;
				const Point2f u = Hi->map(a.x + tt * (b.x - a.x), a.y + tt * (b.y - a.y));
				/* In cells; this side is the square's nearest. */
				const double lx = s0 + sc * u.x, ly = s0 + sc * u.y;
				const double d[4] = { ly - s0, s0 + sc - lx, s0 + sc - ly, lx - s0 };
				const auto e = std::min_element(d, d + 4) - d;
				/* Outwards, in cells: the dark ring's side. */
				const double nx = e == 1   ? 1.0
						  : e == 3 ? -1.0
							   : 0.0,
					     ny = e == 0   ? -1.0
						  : e == 2 ? 1.0
							   : 0.0;
				auto colour = [&](double off) {
					return cellColour(layout, code, static_cast<int>(std::floor(lx + off * nx)),
							  static_cast<int>(std::floor(ly + off * ny)));
				};
				const Point2f p0 = H->map((lx - s0) / sc, (ly - s0) / sc);
				const Point2f p1 = H->map((lx + nx - s0) / sc, (ly + ny - s0) / sc);
				const float c = scale * std::hypot(p1.x - p0.x, p1.y - p0.y);
				const float fall = std::min(1.5f, std::exp(-(c * c - 4.0f) / 8.0f));
				const int beyondDark = colour(1.5), beyondLight = colour(-1.5);
				pull += fall * ((beyondDark >= 0 && beyondDark != colour(0.5) ? kPullDark : 0.0f) +
						(beyondLight >= 0 && beyondLight != colour(-0.5) ? kPullLight : 0.0f));
			}
			pull /= 3.0f;
			any |= std::abs(pull) >= 0.01f;
			out.d[static_cast<std::size_t>(k)][static_cast<std::size_t>(j)] = pull;
		}
	}
	return any;
}

} // namespace

/* refineCorners() finds a light-to-dark step going inwards; a reversed
 * layout's square is dark outside: the quad is handed over anticlockwise,
 * which turns its normals outwards. */
bool detail::CandidateReader::refineLayoutQuad(const ImageView &image, detail::Quad &q, float search) const
{
	if (!dict->layout->reversed)
		return detail::refineCorners(image, q.corners, search);
	std::array<Point2f, 4> turned = reversedOrder(q.corners);
	if (!detail::refineCorners(image, turned, search))
		return false;
	q.corners = reversedOrder(turned);
	return true;
}

/* Batch mode: the candidates read on the frame refined, then their grids
 * warped in one call. */
void detail::CandidateReader::refineAndWarpLayouts(const ImageView &image, Slot &slot, float search)
{
	const MarkerLayout &layout = *dict->layout;
	const std::size_t n = slot.quads.size();
	batch.outlines.resize(n);
	batch.refined.resize(n);
	batch.place.resize(n);
	batch.quads.clear();
	StageTimer timer(slot.result.times, Stage::Refine);
	std::array<Point2f, 4> grid;
	for (std::size_t k = 0; k < n; ++k) {
		std::array<Point2f, 4> &corners = slot.quads[k].corners;
		batch.outlines[k] = corners;
		batch.place[k] = -1;
		batch.refined[k] = 0;
		if (detail::readBlock(cellSide(corners, dict->bits)) > 1)
			continue;
		batch.refined[k] = refineLayoutQuad(image, slot.quads[k], std::max(search, 2.5f));
		if (bigEnough(corners, config.min_marker_side) && detail::layoutGrid(corners, layout, grid)) {
			batch.place[k] = static_cast<int>(batch.quads.size());
			batch.quads.push_back(grid);
		}
	}
	timer.lap(Stage::Warp);
	warpBatch(image, detail::layoutGridSide(layout));
}

bool detail::CandidateReader::readLayoutCandidate(const ImageView &image, Slot &slot, std::size_t k, float search,
						  StageTimer &timer, Marker &m)
{
	const MarkerLayout &layout = *dict->layout;
	detail::Quad &q = slot.quads[k];
	const std::array<Point2f, 4> traced = warper ? batch.outlines[k] : q.corners;
	if (detail::surroundsMarker(traced, detail::quadArea(traced), -1, dict->bits, slot.result.markers,
				    markerCentres))
		return false;
	/* Large cells on the frame halved f times: a patch that holds the
	 * layout's grid around the square and refinement's reach. */
	const float cellPx = cellSide(traced, dict->bits);
	const int f = detail::readBlock(cellPx);
	const bool inBatch = warper != nullptr && f == 1;
	const float ff = static_cast<float>(f);
	const BlockView block =
		f == 1 ? BlockView{ image }
		       : blockView(image, f, traced, static_cast<float>(layout.square_start + 2) * cellPx + 14.0f * ff);
	const Point2f origin{ static_cast<float>(block.ox), static_cast<float>(block.oy) };
	std::array<Point2f, 4> outline = traced;
	if (f > 1) {
		for (int i = 0; i < 4; ++i) {
			outline[i] = toFullResolution({ outline[i].x - origin.x, outline[i].y - origin.y }, ff);
			q.corners[i] = outline[i];
		}
	}
	const float minSide = config.min_marker_side / ff;
	const bool refined = inBatch ? batch.refined[k] != 0
				     : refineLayoutQuad(block.view, q, std::max(search / ff, 2.5f));
	detail::MarkerRead read;
	bool counted = false;
	std::array<Point2f, 4> grid;
	/* Reads `square` with `pol`, from the batch's samples when it is the
	 * batch's refined square. */
	auto readSquare = [&](const std::array<Point2f, 4> &square, const detail::DecodePolicy &pol, bool batched) {
		if (!bigEnough(square, minSide))
			return false;
		timer.lap(Stage::Warp);
		const detail::WarpedMarker *samples = nullptr;
		if (batched && inBatch && batch.place[k] >= 0 &&
		    batch.warpedOk[static_cast<std::size_t>(batch.place[k])]) {
			samples = &batch.samples[static_cast<std::size_t>(batch.place[k])];
			if (!pol.tone.linear()) {
				warped = *samples;
				pol.tone.apply(warped);
				samples = &warped;
			}
		} else if (detail::layoutGrid(square, layout, grid) &&
			   detail::warpToGrid(block.view, grid, detail::layoutGridSide(layout), warped)) {
			pol.tone.apply(warped);
			samples = &warped;
		}
		if (!samples)
			return false;
		counted = true;
		timer.lap(Stage::Decode);
		read = detail::decodeLayout(
			detail::readLayoutCells(*samples, layout, pol.weakMargin, pol.tone.apply(detail::kClippedGrey)),
			*codes, pol);
		return read.ok();
	};
	/* The refined square first, then the traced one (refinement can
	 * slide onto a code cell's edge), each on grey levels, then on the
	 * log scale. */
	for (const detail::DecodePolicy *pol : { &policy, &logPolicy }) {
		if (pol == &logPolicy && logPolicy.tone.linear())
			break;
		if (readSquare(q.corners, *pol, true))
			break;
		if (refined && readSquare(outline, *pol, false)) {
			q.corners = outline;
			break;
		}
	}
	/* Refinement costs most: a guessed square is refined only where its
	 * rings read three quarters right before (most clutter's do not). */
	auto ringsNearlyThere = [&](const ImageView &view, const std::array<Point2f, 4> &square) {
		if (!layoutGrid(square, layout, grid) || !warpToGrid(view, grid, layoutGridSide(layout), warped))
			return false;
		return detail::ringsNearlyWhole(warped, layout);
	};
	/* A small marker's square may have no outline of its own: edges 2 or
	 * 3 pixels apart on both sides of its black ring join, and what is
	 * traced is the ring's outside or the whole layout's. The square then
	 * lies at the candidate's centre, square_cells of the ring's
	 * square_cells + 2 or of the layout's size: refined from there, it is
	 * read on grey levels. Its weak bits (cells of 2-3 px blur into their
	 * neighbours) are corrected as a traced square's are, but at most half
	 * the clear bits: no edge outlined it, and the whole clear budget with
	 * weak bits on top read a tagStandard52h13 marker as a tagCustom48h12
	 * id 3 bits away (the two layouts' rings alike); with none, small
	 * blurred markers guessed right went unread. */
	if (!read.ok() && f == 1 && cellPx < kInnerSquareCell) {
		detail::DecodePolicy guessed = policy;
		guessed.maxHamming = policy.maxHamming / 2;
		for (const int cells : { layout.square_cells + 2, layout.size }) {
			detail::Quad inner = q;
			if (!centredSquare(outline, static_cast<float>(layout.square_cells) / static_cast<float>(cells),
					   inner.corners) ||
			    !bigEnough(inner.corners, minSide) || !ringsNearlyThere(block.view, inner.corners) ||
			    !refineLayoutQuad(block.view, inner, 2.5f))
				continue;
			if (readSquare(inner.corners, guessed, false)) {
				q.corners = inner.corners;
				break;
			}
		}
	}
	slot.result.candidates += counted;
	if (!read.ok())
		return false;
	/* The pattern now known, the sides refitted without its pull. */
	if (f == 1 && layout.reversed) {
		const int rot = read.decoded.rotation;
		const std::array<Point2f, 4> square = { q.corners[static_cast<std::size_t>(rot & 3)],
							q.corners[static_cast<std::size_t>((rot + 1) & 3)],
							q.corners[static_cast<std::size_t>((rot + 2) & 3)],
							q.corners[static_cast<std::size_t>((rot + 3) & 3)] };
		std::array<Point2f, 4> turned = reversedOrder(q.corners);
		detail::SideOffsets pulls;
		if (patternPulls(block.view, layout, dict->codes[static_cast<std::size_t>(read.decoded.id)], square,
				 turned, pulls) &&
		    detail::refineCornersOffset(block.view, turned, 1.0f, pulls))
			q.corners = reversedOrder(turned);
	}
	toMarker(q, f, block, read, m);
	return true;
}

} // namespace frappe
