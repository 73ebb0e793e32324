// SPDX-License-Identifier: MIT
// The back end after the trace: each candidate, smallest first, placed on
// the frame (or the frame halved into blocks for large cells), its corners
// refined, warped to the sample grid, binarised, decoded and verified; the
// markers kept once: detail::CandidateReader (candidate_reader.h), whose
// read() the detector calls.
#include <algorithm>
#include <cmath>
#include <span>

#include "corner_refine.h"
#include "frappe/homography.h"
#include "candidate_reader.h"
#include "marker_set.h"
#include "quad_geometry.h"
#include "region_map.h" // halveImage()

namespace frappe {

namespace {

using detail::bigEnough;
using detail::cellSide;
using detail::kMaxReadBlock;
using detail::readBlock;
using detail::quadArea;
using detail::sidesAtLeast;
using detail::StageTimer;
using detail::toFullResolution;

/* Cells under 4 px along some side of the quad: there warpMarker's
 * samples, a quarter cell from the cell's edges, lie within a pixel of the
 * neighbouring cells, and blur of a pixel mixes them in. */
bool smallCells(const std::array<Point2f, 4> &q, int bits)
{
	return !sidesAtLeast(q, 4.0f * static_cast<float>(bits + 2));
}

/* The corner refinement window for cells large enough (refineQuad). */
constexpr detail::RefineWindow kBlurWindow{ 6, 64, true, 2 };

/* The traced outline lies within 2.5 traced pixels of the marker's. */
constexpr float kSearch = 2.5f;

} // namespace

/* Refines a candidate's corners in place. A region outline lies up to a
 * region pixel inside the marker's: a wider search. On cells of 6 px or
 * more, a wide window (RefineWindow{6, 64}: 3.5 px either side) stays on
 * the border's outer edge, away from the code's, and unlike the default one
 * it stays unbiased on strongly blurred edges (blur set: corner error 0.40
 * -> 0.35 px). It can fail to measure a side where the default one does
 * not (large blurred markers upsampled 3x): then the default one. `image`
 * is the frame or the frame halved to blocks of `block` pixels (finish()). */
bool detail::CandidateReader::refineQuad(const ImageView &image, const Slot &slot, detail::Quad &q, float search,
					 int block) const
{
	if (q.fromRegion)
		search = std::max(search, 2.0f / slot.edges.regions.scale / static_cast<float>(block));
	const float wideCell = 6.0f * static_cast<float>(dict->bits + 2);
	if (sidesAtLeast(q.corners, wideCell) && detail::refineCorners(image, q.corners, search, kBlurWindow))
		return true;
	return detail::refineCorners(image, q.corners, search);
}

/* `image` halved f (2, 4, 8) times, whole or the blocks of a patch
 * reaching `margin` pixels beyond the outline's box. */
detail::CandidateReader::BlockView detail::CandidateReader::blockView(const ImageView &image, int f,
								      const std::array<Point2f, 4> &outline,
								      float margin)
{
	const std::size_t frameArea = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
	if (image.width != blockSizedW || image.height != blockSizedH) {
		blockSizedW = image.width;
		blockSizedH = image.height;
		blockFrameOf.fill(0);
		std::size_t all = 0;
		for (int g = 2; g <= kMaxReadBlock; g *= 2) {
			blockFrameAt[static_cast<std::size_t>(g)] = all;
			all += static_cast<std::size_t>(image.width / g) * static_cast<std::size_t>(image.height / g);
		}
		blockFrames.resize(all);
		blockPatch.reserve(frameArea / 4);
		blockHalf.resize(frameArea / 4 + frameArea / 16);
	}
	/* The frame (or patch) halved log2(f) times: the first halvings into
	 * blockHalf (a quarter of the frame, then a sixteenth), the last into
	 * `out`. */
	auto halve = [&](const ImageView &src, std::uint8_t *out) {
		ImageView level = src;
		for (int g = 2; g < f; g *= 2) {
			const int w = level.width / 2, h = level.height / 2;
			std::uint8_t *dst = blockHalf.data() + (g == 2 ? 0 : frameArea / 4);
			detail::halveImage(level, dst);
			level = ImageView(dst, w, h, w);
		}
		detail::halveImage(level, out);
	};
	const int W = image.width / f, H = image.height / f;
	const auto [x0, y0, x1, y1] = detail::quadBox(outline);
	const float ff = static_cast<float>(f);
	const int bx0 = std::clamp(static_cast<int>(std::floor((x0 - margin) / ff)), 0, W);
	const int by0 = std::clamp(static_cast<int>(std::floor((y0 - margin) / ff)), 0, H);
	const int bx1 = std::clamp(static_cast<int>(std::ceil((x1 + margin) / ff)) + 1, bx0, W);
	const int by1 = std::clamp(static_cast<int>(std::ceil((y1 + margin) / ff)) + 1, by0, H);
	const int w = bx1 - bx0, h = by1 - by0;
	const std::size_t read = static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * static_cast<std::size_t>(f * f);
	const auto fi = static_cast<std::size_t>(f);
	BlockView b;
	if (blockFrameOf[fi] != finishedFrames && blockPatchRead + read <= frameArea) {
		blockPatchRead += read;
		blockPatch.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
		if (w > 0 && h > 0)
			halve(ImageView(image.row(by0 * f) + bx0 * f, w * f, h * f, image.stride), blockPatch.data());
		b.view = ImageView(blockPatch.data(), w, h, w);
		b.ox = bx0 * f;
		b.oy = by0 * f;
		return b;
	}
	std::uint8_t *frame = blockFrames.data() + blockFrameAt[fi];
	if (blockFrameOf[fi] != finishedFrames) {
		if (W > 0 && H > 0)
			halve(image, frame);
		blockFrameOf[fi] = finishedFrames;
	}
	b.view = ImageView(frame, W, H, W);
	return b;
}

/* Batch mode: every candidate refined, then all warped in one call. */
void detail::CandidateReader::refineAndWarpAll(const ImageView &image, Slot &slot, float search)
{
	const std::size_t n = slot.quads.size();
	batch.outlines.resize(n);
	batch.refined.resize(n);
	batch.place.resize(n);
	batch.quads.clear();
	StageTimer timer(slot.result.times, Stage::Refine);
	for (std::size_t k = 0; k < n; ++k) {
		std::array<Point2f, 4> &corners = slot.quads[k].corners;
		batch.outlines[k] = corners;
		batch.place[k] = -1;
		batch.refined[k] = 0;
		if (readBlock(cellSide(corners, dict->bits)) > 1)
			continue; /* read on a halved frame by finish() */
		/* What readCandidate() would refine, as it would: the same
		 * corners whichever way the warp runs. */
		batch.refined[k] = slot.quads[k].probeRead < whiteFrame() &&
				   refineQuad(image, slot, slot.quads[k], std::max(search, kSearch), 1);
		if (batch.refined[k] && bigEnough(corners, config.min_marker_side)) {
			batch.place[k] = static_cast<int>(batch.quads.size());
			batch.quads.push_back(corners);
		}
	}
	timer.lap(Stage::Warp);
	warpBatch(image, (dict->bits + 2) * detail::kSamplesPerCell);
}

void detail::CandidateReader::warpBatch(const ImageView &image, int side)
{
	const std::size_t m = batch.quads.size();
	batch.warpedOk.assign(m, 0);
	batch.samples.resize(std::max(batch.samples.size(), m));
	warper->warp(image, batch.quads, side, std::span(batch.samples).first(m), batch.warpedOk);
}

/* Candidates not worth refining: the outline of a decoded marker's quiet
 * zone, and clutter as the probe's read at the traced outline shows it. */
bool detail::CandidateReader::skipCandidate(const detail::Quad &q, const std::array<Point2f, 4> &tracedOutline,
					    const Slot &slot, bool &mixedOnly) const
{
	mixedOnly = false;
	const std::vector<Marker> &found = slot.result.markers;
	const int bits = dict->bits;
	const int traced = q.probeRead;
	const float area = quadArea(tracedOutline);
	if (detail::surroundsMarker(tracedOutline, area, q.fromShade ? -1 : traced, bits, found, markerCentres))
		return true;
	/* A marker read before the trace (readTracked()): its own outline
	 * too, which would only read as it again. */
	if (knownCount > 0 &&
	    detail::surroundsMarker(tracedOutline, area, -1, bits, std::span(found).first(knownCount), knownCentres))
		return true;
	/* The probe's read at the traced outline decides two things before
	 * refinement. A frame with more white cells than twice what decode
	 * forgives, on a quad of at least 4 px a cell (where the traced outline
	 * lies well within a cell of the refined one), is clutter: nothing to
	 * refine. A white frame goes straight to the inset read (readInset()),
	 * which starts from the traced outline anyway.
	 * A region outline lies inside the marker's, so its frame samples fall
	 * on the border cells at any size: a mixed frame is clutter there
	 * whatever the size. So is a region whose samples spread less than the
	 * contrast that made it a dark region: a patch of dark texture, not a
	 * code. (Together they drop two thirds of the region quads that used
	 * to be refined for nothing, at the cost of no marker.) */
	if (traced < 0)
		return false;
	/* Where the probe's brightest sample clips, its midpoint threshold is
	 * too dark (the true white lies above the ceiling): blur lifts a
	 * marker's black border over it, and the frame reads mixed. Such a
	 * frame is no evidence of clutter; the reads after refinement judge. */
	const bool clips = q.probeLevel + 0.5f * q.probeContrast >= detail::kClippedGrey;
	const int mixedFrame = 2 * detail::allowedBorderErrors(bits);
	const bool mixed = traced > mixedFrame && traced < whiteFrame() && !clips;
	if (q.fromRegion)
		return mixed ||
		       q.probeContrast < static_cast<float>(slot.params.relativeRegionContrast(
						 static_cast<int>(std::lround(q.probeLevel - 0.5f * q.probeContrast)),
						 static_cast<int>(std::lround(q.probeLevel + 0.5f * q.probeContrast))));
	mixedOnly = mixed && sidesAtLeast(tracedOutline, 4.0f * static_cast<float>(bits + 2));
	return mixedOnly;
}

/* Large cells are read on the frame halved f times, in its pixels
 * (readBlock()). The patch reaches what refinement reads across a side (its
 * search and profile: 13 pixels of the halved frame at most) and the reads'
 * ring a cell outside the border; a white frame is only read inside
 * (insetQuad()). Leaves q's corners in the block's pixels. */
detail::CandidateReader::Reading detail::CandidateReader::placeCandidate(const ImageView &image, detail::Quad &q,
									 const std::array<Point2f, 4> &tracedOutline)
{
	Reading r;
	const float cellPx = cellSide(tracedOutline, dict->bits);
	r.f = readBlock(cellPx);
	r.inBatch = warper != nullptr && r.f == 1;
	const float ff = static_cast<float>(r.f);
	r.block = r.f == 1 ? BlockView{ image }
			   : blockView(image, r.f, tracedOutline,
				       q.probeRead >= whiteFrame() ? ff : std::max(14.0f * ff, cellPx + 2.0f * ff));
	r.minSide = config.min_marker_side / ff;
	r.outline = tracedOutline;
	if (r.f > 1) {
		const Point2f origin{ static_cast<float>(r.block.ox), static_cast<float>(r.block.oy) };
		for (int i = 0; i < 4; ++i) {
			r.outline[i] = toFullResolution({ r.outline[i].x - origin.x, r.outline[i].y - origin.y }, ff);
			q.corners[i] = r.outline[i];
		}
	}
	return r;
}

/* Warps and binarises a refined candidate large enough to read, on the
 * policy's scale (a batch's samples are grey levels: a copy is rescaled). */
void detail::CandidateReader::sampleRefined(Reading &r, const detail::Quad &q, std::size_t k,
					    const detail::DecodePolicy &pol, StageTimer &timer)
{
	r.samples = &warped;
	if (!r.refined || !bigEnough(q.corners, r.minSide))
		return;
	r.counted = true;
	timer.lap(Stage::Warp);
	if (r.inBatch) {
		const int j = batch.place[k];
		r.refined = batch.warpedOk[static_cast<std::size_t>(j)] != 0;
		r.samples = &batch.samples[static_cast<std::size_t>(j)];
		if (r.refined && !pol.tone.linear()) {
			warped = *r.samples;
			pol.tone.apply(warped);
			r.samples = &warped;
		}
	} else {
		r.refined = detail::warpMarker(r.block.view, q.corners, dict->bits, warped, pol.tone, pol.memo);
	}
	timer.lap(Stage::Decode);
	if (r.refined)
		r.b = detail::binarise(*r.samples, dict->bits);
}

/* No dark frame inside the outline, or a white one: this may be the outline
 * of the quiet zone (the marker's own outline merged with its code's edges,
 * as on small or blurred markers). The marker would lie one cell inside. */
void detail::CandidateReader::readInset(Reading &r, detail::Quad &q, const detail::DecodePolicy &pol, StageTimer &timer)
{
	timer.lap(Stage::Refine);
	if (r.inset == 0) {
		r.insetCorners = r.outline;
		r.inset = detail::insetCorners(r.block.view, r.insetCorners, dict->bits) ? 1 : -1;
	}
	q.corners = r.inset > 0 ? r.insetCorners : r.outline;
	const bool inset =
		r.inset > 0 && detail::warpMarker(r.block.view, q.corners, dict->bits, warped, pol.tone, pol.memo);
	r.readable = inset && bigEnough(q.corners, r.minSide);
	if (!r.readable)
		return;
	r.counted = true;
	timer.lap(Stage::Decode);
	r.samples = &warped;
	r.b = detail::binarise(warped, dict->bits);
}

/* Decodes a sampled candidate, trying what else may read when its samples
 * do not; on a read at the traced outline, q takes that outline. */
detail::MarkerRead detail::CandidateReader::decodeCandidate(const Reading &r, detail::Quad &q,
							    const detail::DecodePolicy &pol)
{
	const ImageView &img = r.block.view;
	const int bits = dict->bits;
	detail::MarkerRead read;
	if (!r.readable)
		return read;
	if (smallCells(q.corners, bits)) {
		/* Quarter-cell samples of small cells lie within a pixel of
		 * their neighbours: read the cells at their centres, at the
		 * refined corners, else at the traced ones. */
		if (bigEnough(q.corners, r.minSide))
			read = detail::readCellCentres(img, q.corners, *codes, pol, warped);
		if (!read.ok() && r.refined && bigEnough(r.outline, r.minSide)) {
			read = detail::readCellCentres(img, r.outline, *codes, pol, warped);
			if (read.ok())
				q.corners = r.outline;
		}
		return read;
	}
	if (detail::readable(r.b, bits))
		read = detail::readMarker(img, q.corners, *codes, pol, *r.samples, r.b);
	if (!read.ok() && r.refined && r.b.border_errors < whiteFrame()) {
		/* Refinement can pull a blurred marker's sides onto its code's
		 * edges; the traced outline may still read. */
		if (detail::warpMarker(img, r.outline, bits, warped, pol.tone, pol.memo)) {
			const detail::Binarised bt = detail::binarise(warped, bits);
			if (detail::readable(bt, bits)) {
				read = detail::readMarker(img, r.outline, *codes, pol, warped, bt);
				if (read.ok())
					q.corners = r.outline;
			}
		}
	}
	if (!read.ok()) {
		/* Blur of about a cell (a blurred marker, or a small one
		 * upsampled) reaches the quarter-cell samples of cells of any
		 * size. */
		read = detail::readCellCentres(img, q.corners, *codes, pol, warped);
	}
	return read;
}

/* Whether a candidate's whites reach the sensor's ceiling (an eighth of
 * its samples: an overexposed marker's white cells, not a glint or the
 * brightest paper of an evenly lit frame, whose reads would only cost
 * time), so that the midpoint between black and white is too dark a
 * threshold (Tone's exponential scale). */
constexpr int kClippedShare = 8;
/* The widest of the clipped reads' outlines, in quarter cells. */
constexpr int kClipWidenings = 3;
namespace {
/* `q` widened by `out` of its side on every side (in the marker's own
 * plane: through its homography). False when degenerate. */
bool widenedQuad(const std::array<Point2f, 4> &q, float out, std::array<Point2f, 4> &widened)
{
	const auto H = Homography::fromUnitSquare(q);
	if (!H)
		return false;
	const double lo = -out, hi = 1.0 + out;
	widened = { H->map(lo, lo), H->map(hi, lo), H->map(hi, hi), H->map(lo, hi) };
	return true;
}

bool clipsWhite(const detail::WarpedMarker &w)
{
	int n = 0;
	for (int i = 0; i < w.side * w.side; ++i)
		n += w.samples[static_cast<std::size_t>(i)] >= detail::kClippedGrey;
	return n * kClippedShare >= w.side * w.side;
}
} // namespace

/* Reads candidate k: refine, warp, binarise; the inset read when that finds
 * no dark frame; then decoding and its fallbacks. A marker read is left in
 * `m`, its corners in frame pixels from the code's first. */
bool detail::CandidateReader::readCandidate(const ImageView &image, Slot &slot, std::size_t k, float search,
					    StageTimer &timer, Marker &m)
{
	if (dict->layout)
		return readLayoutCandidate(image, slot, k, search, timer, m);
	detail::Quad &q = slot.quads[k];
	const std::array<Point2f, 4> tracedOutline = warper ? batch.outlines[k] : q.corners;
	bool mixed = false;
	if (skipCandidate(q, tracedOutline, slot, mixed) && !mixed)
		return false;
	Reading r = placeCandidate(image, q, tracedOutline);
	/* A blind's stripes across a black border make the probe's frame read
	 * mixed against its one threshold: refined only if the border reads
	 * black against thresholds that follow the light (binariseInLight()). */
	if (mixed && (logPolicy.tone.linear() || !readsInLight() ||
		      !detail::readable(readInLight(r.block.view, r.outline, logPolicy), dict->bits)))
		return false;
	/* With at least the frame's search on a halved frame: blur spreads a
	 * large marker's edges over as many of its pixels as a small one's
	 * over the frame's. */
	const float ff = static_cast<float>(r.f);
	r.refined = r.inBatch ? batch.refined[k] != 0
			      : q.probeRead < whiteFrame() &&
					refineQuad(r.block.view, slot, q, std::max(search / ff, kSearch), r.f);
	const detail::MarkerRead read = readRefined(r, q, k, timer, slot.result);
	if (!read.ok())
		return false;
	toMarker(q, r.f, r.block, read, m);
	return true;
}

/* The quad warped on pol's scale into `warped` and read with thresholds
 * that follow the light across it (binariseInLight()); not readable() where
 * the quad is degenerate. */
detail::Binarised detail::CandidateReader::readInLight(const ImageView &view, const std::array<Point2f, 4> &corners,
						       const DecodePolicy &pol)
{
	if (!detail::warpMarker(view, corners, dict->bits, warped, pol.tone, pol.memo))
		return {};
	return detail::binariseInLight(view, corners, warped, dict->bits, pol.tone);
}

/* Read on grey levels; where that fails, once more on the log scale
 * (Tone), from the same refined corners: a marker under a shadow's stripes
 * or in a dim room; and where the first read's whites clipped, on the
 * exponential scale: an overexposed marker, whose blurred black cells the
 * midpoint below the ceiling reads white. */
detail::MarkerRead detail::CandidateReader::readRefined(Reading &r, detail::Quad &q, std::size_t k, StageTimer &timer,
							Result &result)
{
	const Reading refined = r;
	const std::array<Point2f, 4> refinedCorners = q.corners;
	/* Each read warps the corners the one before it did (a tone applies
	 * after the warp): the later ones copy its samples. */
	warpMemo.clear();
	DecodePolicy onGrey = policy, onLog = logPolicy, onClip = clipPolicy;
	onGrey.memo = onLog.memo = onClip.memo = &warpMemo;
	onGrey.decodes = onLog.decodes = onClip.decodes = &decodes;
	auto readWith = [&](const detail::DecodePolicy &pol) {
		sampleRefined(r, q, k, pol, timer);
		if (!r.refined || r.b.border_errors >= whiteFrame())
			readInset(r, q, pol, timer);
		timer.lap(Stage::Decode);
		return decodeCandidate(r, q, pol);
	};
	detail::MarkerRead read = readWith(onGrey);
	const bool counted = r.counted;
	/* Whites at the sensor's ceiling in what the first read sampled. */
	const bool clipped = !read.ok() && r.samples && clipsWhite(*r.samples);
	auto readAgain = [&](const detail::DecodePolicy &pol) {
		const int inset = r.inset;
		const std::array<Point2f, 4> insetCorners = r.insetCorners;
		r = refined;
		r.inset = inset;
		r.insetCorners = insetCorners;
		q.corners = refinedCorners;
		read = readWith(pol);
	};
	if (!read.ok() && !onLog.tone.linear()) {
		readAgain(onLog);
		/* Light that falls across the marker by more than black and white
		 * differ (a blind's stripe, a bright patch at one corner): one
		 * threshold splits the code into a lit and a dark part; one per
		 * cell, between the border's black and the quiet zone's white
		 * where the cell lies, follows it. Cells of 4 px or more (the
		 * quarter-cell grid); the log read's policy. */
		if (!read.ok() && readsInLight() && refined.refined && bigEnough(refinedCorners, refined.minSide) &&
		    !smallCells(refinedCorners, dict->bits)) {
			r = refined;
			q.corners = refinedCorners;
			timer.lap(Stage::Warp);
			const detail::Binarised b = readInLight(r.block.view, q.corners, onLog);
			timer.lap(Stage::Decode);
			if (detail::readable(b, dict->bits))
				read = detail::readMarker(r.block.view, q.corners, *codes, onLog, warped, b);
		}
	}
	if (!read.ok() && clipped && !onClip.tone.linear()) {
		readAgain(onClip);
		/* Where the whites clip, blur moves every visible edge towards the
		 * black: the border's outside inwards by the same amount its
		 * inside moves out, so the refined outline lies inside the true
		 * one by part of a cell, and its grid falls between the cells.
		 * The shift is unknown (how far above the ceiling the white
		 * lies): read the outline widened by a quarter cell at a time,
		 * up to three quarters (a cell's blur). No edge placed it, so a
		 * read there must be clear as well as pass every check (a crisp
		 * marker on paper at 255, widened, reads as another family's
		 * code with weak cells). */
		for (int quarters = 1; !read.ok() && refined.refined && quarters <= kClipWidenings; ++quarters) {
			const float out = 0.25f * static_cast<float>(quarters) / static_cast<float>(dict->bits + 2);
			if (!widenedQuad(refinedCorners, out, q.corners))
				break;
			const std::array<Point2f, 4> widened = q.corners;
			r = refined;
			r.inBatch = false;
			r.outline = widened;
			read = readWith(onClip);
			if (read.ok() && read.margin < onClip.weakMargin)
				read.rejection = Rejection::WeakRead;
		}
	}
	result.candidates += counted || r.counted;
	return read;
}

/* Mode::Track: a marker read where its track predicts it, before any
 * front end. Its corners are refined from the prediction at full
 * resolution as finish() refines a traced outline (on the frame halved
 * for large cells); every fallback read starts from the refined corners,
 * never from the prediction itself. It must read as `id` with its corners
 * within two searches of the predicted ones. */
bool detail::CandidateReader::readTracked(const ImageView &image, const EdgeMap &edges,
					  const std::array<Point2f, 4> &predicted, int id, Marker &m)
{
	if (dict->layout)
		return false;
	/* A prediction reaching out of the frame: the marker may be cut; its
	 * region's trace decides. */
	for (const Point2f &p : predicted)
		if (!(p.x >= 1.0f && p.y >= 1.0f && p.x <= static_cast<float>(image.width - 2) &&
		      p.y <= static_cast<float>(image.height - 2)))
			return false;
	trackQuads.assign(1, detail::Quad{});
	detail::Quad &q = trackQuads[0];
	q.corners = predicted;
	trackResult.candidates = 0;
	/* No clutter test here (skipCandidate()): no front end's parameters. */
	static const FrontEndParams kUnused{};
	Slot slot{ edges, kUnused, trackQuads, trackResult };
	StageTimer timer(trackResult.times, Stage::Refine);
	Reading r = placeCandidate(image, q, predicted);
	r.inBatch = false;
	if (!refineQuad(r.block.view, slot, q, kSearch, r.f))
		return false;
	r.refined = true;
	r.outline = q.corners;
	const detail::MarkerRead read = readRefined(r, q, 0, timer, trackResult);
	if (!read.ok() || read.decoded.id != id)
		return false;
	toMarker(q, r.f, r.block, read, m);
	const float bound = 2.0f * kSearch * static_cast<float>(r.f);
	for (int i = 0; i < 4; ++i)
		if (std::hypot(m.corners[i].x - predicted[i].x, m.corners[i].y - predicted[i].y) > bound)
			return false;
	return true;
}

void detail::CandidateReader::toMarker(detail::Quad &q, int f, const BlockView &block, const detail::MarkerRead &read,
				       Marker &m)
{
	if (f > 1) {
		const float ff = static_cast<float>(f);
		const Point2f origin{ static_cast<float>(block.ox), static_cast<float>(block.oy) };
		for (Point2f &p : q.corners) {
			p = toFullResolution(p, 1.0f / ff);
			p = { p.x + origin.x, p.y + origin.y };
		}
	}
	const detail::Decoded &d = read.decoded;
	m.id = d.id;
	m.hamming = d.hamming;
	m.margin = read.margin;
	for (int i = 0; i < 4; ++i)
		m.corners[i] = q.corners[(i + d.rotation) & 3];
}

/* The candidates in order, smallest first: each read, each marker kept
 * once. */
void detail::CandidateReader::finish(const ImageView &image, Slot &slot)
{
	Result &res = slot.result;
	res.markers.clear();
	res.candidates = 0;
	res.times[Stage::Refine] = res.times[Stage::Warp] = res.times[Stage::Decode] = 0.0;
	++finishedFrames; /* halved frames made before are stale */
	blockPatchRead = 0;
	const float scale = slot.edges.scale;
	const float search = kSearch / scale;
	{
		StageTimer timer(res.times, Stage::Refine);
		for (detail::Quad &q : slot.quads)
			for (Point2f &p : q.corners)
				p = toFullResolution(p, scale);
	}
	/* Each marker found filed at its centre for surroundsMarker(), once
	 * and again when replaced: at most two entries a candidate. Cells of
	 * 32 px; a large candidate's box spans many, and then the grid visits
	 * every entry instead. */
	markerCentres.reset(2 * slot.quads.size() + slot.known.size(), 32.0f);
	knownCentres.reset(slot.known.size(), 32.0f);
	knownCount = slot.known.size();
	for (const Marker &m : slot.known) {
		const int at = static_cast<int>(res.markers.size());
		res.markers.push_back(m);
		markerCentres.add(at, 0, detail::quadCentre(m.corners));
		knownCentres.add(at, 0, detail::quadCentre(m.corners));
	}
	if (warper && dict->layout)
		refineAndWarpLayouts(image, slot, search);
	else if (warper)
		refineAndWarpAll(image, slot, search);
	for (std::size_t k = 0; k < slot.quads.size(); ++k) {
		StageTimer timer(res.times, Stage::Refine);
		Marker m;
		if (!readCandidate(image, slot, k, search, timer, m))
			continue;
		/* A replaced marker is filed again at its new centre; its old
		 * entry only costs a test against it. */
		if (const int at = detail::keepMarker(res.markers, m); at >= 0)
			markerCentres.add(at, 0, detail::quadCentre(m.corners));
	}
	/* Smallest first, a block of a marker's code cells decoded before the
	 * marker around it did: now that both are known, drop it. */
	StageTimer timer(res.times, Stage::Decode);
	detail::dropNestedMarkers(res.markers, dict->bits, markerGrid);
}

} // namespace frappe
