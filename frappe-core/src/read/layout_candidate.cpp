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
	toMarker(q, f, block, read, m);
	return true;
}

} // namespace frappe
