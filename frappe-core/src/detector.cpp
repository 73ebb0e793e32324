// SPDX-License-Identifier: MIT
// The Detector: runs the stages of Algorithm 1 in order and times each.
#include "frappe/detector.h"
#include "frappe/version.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <span>
#include <string>

#include "adaptive_scale.h"
#include "contour_trace.h"
#include "corner_refine.h"
#include "decode.h"
#include "detector_stages.h"
#include "front_end_rows.h"
#include "marker_set.h"
#include "quad_geometry.h"
#include "region_map.h"
#include "stage_timer.h"
#include "verify.h"

namespace frappe {

namespace {

using detail::bigEnough;
using detail::cellSide;
using detail::quadArea;
using detail::sidesAtLeast;
using detail::StageTimer;
using detail::toFullResolution;

void validate(const Config &c, const Dictionary &d)
{
	auto fail = [](const std::string &what) { throw std::invalid_argument("frappe::Config: " + what); };
	if (!(c.edge_threshold > 0.0f && c.edge_threshold <= 4.0f))
		fail("edge_threshold must be in (0, 4], got " + std::to_string(c.edge_threshold));
	if (!(c.corner_threshold >= 0.0f && c.corner_threshold <= 100.0f))
		fail("corner_threshold must be in [0, 100], got " + std::to_string(c.corner_threshold));
	if (c.max_hamming < -1 || c.max_hamming > d.bits * d.bits / 2)
		fail("max_hamming must be -1 (dictionary default) or 0.." + std::to_string(d.bits * d.bits / 2) +
		     " for " + std::string(d.name) + ", got " + std::to_string(c.max_hamming));
	if (!(c.weak_margin >= 0.0f && c.weak_margin <= 1.0f))
		fail("weak_margin must be in [0, 1], got " + std::to_string(c.weak_margin));
	if (!(c.scaled_size >= 8.0f && c.scaled_size <= 1000.0f))
		fail("scaled_size must be in [8, 1000] pixels, got " + std::to_string(c.scaled_size));
	if (c.max_scaled_frames < 0 || c.max_scaled_frames > 1000)
		fail("max_scaled_frames must be in [0, 1000], got " + std::to_string(c.max_scaled_frames));
	if (!(c.corner_cluster_radius >= 1.0f && c.corner_cluster_radius <= 32.0f))
		fail("corner_cluster_radius must be in [1, 32], got " + std::to_string(c.corner_cluster_radius));
	if (!(c.min_marker_side >= 4.0f))
		fail("min_marker_side must be at least 4 pixels, got " + std::to_string(c.min_marker_side));
	if (!(c.region_contrast >= 0.0f && c.region_contrast <= 1.0f))
		fail("region_contrast must be in [0, 1], got " + std::to_string(c.region_contrast));
	if (c.threads < 0 || c.threads > 256)
		fail("threads must be in [0, 256], got " + std::to_string(c.threads));
}

/* Cells under 4 px along some side of the quad: there warpMarker's
 * samples, a quarter cell from the cell's edges, lie within a pixel of the
 * neighbouring cells, and blur of a pixel mixes them in. */
bool smallCells(const std::array<Point2f, 4> &q, int bits)
{
	return !sidesAtLeast(q, 4.0f * static_cast<float>(bits + 2));
}

/* Candidates with cells of 2 kReadCell pixels or more are read on the frame
 * halved into blocks of f = 2, 4 or 8 pixels (the largest with cells of
 * kReadCell or more there). Corner refinement's windows and the reads'
 * sampling are sized for cells of a few pixels; on larger ones (a marker
 * close to the camera, a frame of high resolution) blur spans more pixels
 * than the windows, and the same scenes read at 3x their resolution lost
 * markers and placed corners 2-3 times as far off. Read at their own
 * scale, candidates of any size are read alike. */
constexpr float kReadCell = 6.0f;
constexpr int kMaxReadBlock = 8;

/* The block (1: the frame itself) a candidate with cells of `cell` pixels
 * is read at. */
int readBlock(float cell)
{
	int f = 1;
	while (2 * f <= kMaxReadBlock && cell >= static_cast<float>(2 * f) * kReadCell)
		f *= 2;
	return f;
}

/* Reads a traced quad as a marker, so that the tracer can skip the
 * marker's inside: one sample at each cell's centre (a quarter of the warp
 * that finish() makes of the refined quad), then binarise's checks and an
 * exact codeword. A miss costs nothing but the skip: the quad stays a
 * candidate either way. */
class TracedMarkerProbe final : public detail::MarkerProbe
{
public:
	TracedMarkerProbe(const ImageView &image, float scale, const detail::CodeBook &codes)
		: image_(image), scale_(scale), codes_(codes), dict_(codes.dictionary())
	{
	}
	/* Notes in quad.probeRead how many border cells read white at the
	 * traced outline, and in quad.probeContrast the spread of its
	 * samples (finish() uses both before refining). */
	bool isMarker(detail::Quad &quad) override
	{
		std::array<Point2f, 4> corners;
		for (int i = 0; i < 4; ++i)
			corners[i] = toFullResolution(quad.corners[i], scale_);
		if (!detail::warpToGrid(image_, corners, dict_.bits + 2, cellCentres_))
			return false;
		const detail::Binarised b = detail::binarise(cellCentres_, dict_.bits);
		quad.probeRead = b.border_errors;
		quad.probeContrast = b.contrast;
		/* Only an exact codeword: a wrong "yes" would hide whatever lies
		 * inside the quad (markers on a dark panel, say), and with a small
		 * dictionary and a generous max_hamming a third of all bit patterns
		 * are within reach of some codeword. */
		return detail::readable(b, dict_.bits) && codes_.decode(b.code, 0).id >= 0;
	}

private:
	const ImageView &image_;
	float scale_;
	const detail::CodeBook &codes_;
	const Dictionary &dict_;
	detail::WarpedMarker cellCentres_;
};

/* The corner refinement window for cells large enough (refineQuad). */
constexpr detail::RefineWindow kBlurWindow{ 6, 64, true, 2 };

/* The traced outline lies within 2.5 traced pixels of the marker's. */
constexpr float kSearch = 2.5f;

/* Largest image side accepted: contour coordinates are ints and buffers are
 * sized from width * height. */
constexpr int kMaxSide = 1 << 15;

} // namespace

std::string_view stageName(Stage stage)
{
	switch (stage) {
	case Stage::AdaptiveScale: return "adaptive_scale";
	case Stage::FrontEnd: return "front_end";
	case Stage::Trace: return "trace";
	case Stage::Refine: return "refine";
	case Stage::Warp: return "warp";
	case Stage::Decode: return "decode";
	case Stage::Count: break;
	}
	return "?";
}

struct FRAPPE_HIDDEN Detector::Impl {
	Config config;
	const Dictionary *dict = nullptr;
	std::unique_ptr<detail::CodeBook> codes;
	int maxHamming = 0;
	detail::DecodePolicy policy;
	FrontEndParams params;
	std::unique_ptr<FrontEnd> frontEnd;
	std::unique_ptr<CandidateWarper> warper; /* nullptr: warp on the CPU, one by one */
	/* Read by the front end, written by the back end: in pipelined use
	 * they run on different threads. */
	std::mutex adaptiveLock;
	detail::AdaptiveScale adaptive;

	/* One frame in flight: its edges, its candidates, its result. */
	struct Slot {
		ImageView image; /* the frame, valid until its back end returns */
		EdgeMap edges;
		std::vector<detail::Quad> quads;
		Result result;
	};
	Slot slots[detail::DetectorStages::kSlots];

	/* Used by one stage each, so that stages of different slots can run
	 * at once: the tracer by trace(), the warp buffer by finish(). */
	detail::ContourTracer tracer;
	detail::ContourTracer regionTracer;
	std::vector<detail::Quad> regionQuads;
	detail::RegionScratch regionScratch; /* for a front end without a region map */
	detail::WarpedMarker warped;
	/* Candidates with large cells are read on the frame halved into blocks
	 * of f pixels (readBlock()): a patch around the candidate, or the whole
	 * frame once the frame's patches would read more than it (then kept for
	 * its other candidates of that f). Sized at the first frame of a size:
	 * later frames allocate nothing. */
	struct BlockView {
		ImageView view;
		int ox = 0, oy = 0; /* the frame pixel at the top left of block (0, 0) */
	};
	std::array<std::uint64_t, kMaxReadBlock + 1> blockFrameOf{}; /* finishedFrames it was made for */
	std::array<std::size_t, kMaxReadBlock + 1> blockFrameAt{};
	std::vector<std::uint8_t> blockFrames, blockPatch, blockHalf;
	std::size_t blockPatchRead = 0; /* frame pixels the frame's patches read */
	int blockSizedW = 0, blockSizedH = 0;
	std::uint64_t finishedFrames = 0;
	BlockView blockView(const ImageView &image, int f, const std::array<Point2f, 4> &outline, float margin);
	/* With a batch warper (finish() only): per candidate its traced
	 * outline, whether it refined, and its place in the warped batch (-1
	 * when not warped); per warped candidate its corners and samples. */
	struct Batch {
		std::vector<std::array<Point2f, 4>> outlines, quads;
		std::vector<std::uint8_t> refined, warpedOk;
		std::vector<int> place;
		std::vector<CandidateSamples> samples;
	} batch;

	/* One candidate as finish() reads it, on the frame or on the frame
	 * halved into blocks of f pixels (readBlock()), in that image's
	 * pixels. */
	struct Reading {
		BlockView block;
		int f = 1;
		bool inBatch = false;   /* refined and warped by refineAndWarpAll() */
		float minSide = 0.0f;   /* config.min_marker_side, in block pixels */
		std::array<Point2f, 4> outline; /* the traced one */
		bool refined = false;   /* then: and warped */
		bool readable = true;
		detail::Binarised b;
		const detail::WarpedMarker *samples = nullptr;
	};

	void checkImage(const ImageView &image) const;
	void trace(Slot &slot);
	void finish(const ImageView &image, Slot &slot);
	bool refineQuad(const ImageView &image, const Slot &slot, detail::Quad &q, float search, int block) const;
	void refineAndWarpAll(const ImageView &image, Slot &slot, float search);
	/* Reading one candidate, in finish()'s order. */
	bool readCandidate(const ImageView &image, Slot &slot, std::size_t k, float search, StageTimer &timer,
			   Marker &m);
	bool skipCandidate(const detail::Quad &q, const std::array<Point2f, 4> &tracedOutline,
			   const std::vector<Marker> &found) const;
	Reading placeCandidate(const ImageView &image, detail::Quad &q, const std::array<Point2f, 4> &tracedOutline);
	void sampleRefined(Reading &r, const detail::Quad &q, std::size_t k, Result &res, StageTimer &timer);
	void readInset(Reading &r, detail::Quad &q, Result &res, StageTimer &timer);
	detail::MarkerRead decodeCandidate(const Reading &r, detail::Quad &q);
	/* Border cells that make a white frame: three quarters of the
	 * 4(n+1). */
	int whiteFrame() const { return 3 * dict->bits + 3; }
	Slot &slotAt(int slot)
	{
		return const_cast<Slot &>(static_cast<const Impl *>(this)->slotAt(slot));
	}
	const Slot &slotAt(int slot) const
	{
		constexpr int n = detail::DetectorStages::kSlots;
		if (slot < 0 || slot >= n)
			throw std::invalid_argument("frappe::Detector: slot must be 0.." + std::to_string(n - 1));
		return slots[slot];
	}
};

void Detector::Impl::checkImage(const ImageView &image) const
{
	auto fail = [](const std::string &what) { throw std::invalid_argument("frappe::Detector: " + what); };
	if (image.width <= 0 || image.height <= 0)
		fail("image size must be positive, got " + std::to_string(image.width) + "x" +
		     std::to_string(image.height));
	if (image.width > kMaxSide || image.height > kMaxSide)
		fail("image side must be at most " + std::to_string(kMaxSide) + " pixels");
	if (image.stride < image.width)
		fail("stride (" + std::to_string(image.stride) + ") is smaller than the width (" +
		     std::to_string(image.width) + ")");
	if (!image.data)
		fail("image data is null");
}

void Detector::Impl::trace(Slot &slot)
{
	const EdgeMap &edges = slot.edges;
	const float scale = edges.scale;
	std::vector<detail::Quad> &quads = slot.quads;
	slot.result.times[Stage::Trace] = 0.0;
	StageTimer timer(slot.result.times, Stage::Trace);
	detail::TraceParams tp;
	tp.cluster_radius = config.corner_cluster_radius;
	tp.min_side = std::max(4.0f, config.min_marker_side * scale);
	tp.border_margin = 1.0f;
	TracedMarkerProbe probe(slot.image, scale, *codes);
	tracer.trace(edges, tp, quads, &probe);
	const TraceMap &regions = edges.regions;
	if (regions.width > 0) {
		/* Region borders have no corner pixels: every closed one is
		 * fitted from its outline. Their quads join the edge ones in the
		 * edge map's coordinates. */
		detail::TraceParams rtp = tp;
		rtp.min_clusters = 0;
		rtp.max_winding = 2.0f;
		rtp.holes = false;
		rtp.min_side = std::max(4.0f, config.min_marker_side * regions.scale);
		TracedMarkerProbe regionProbe(slot.image, regions.scale, *codes);
		regionTracer.trace(regions, rtp, regionQuads, &regionProbe);
		const float toEdges = scale / regions.scale;
		for (detail::Quad q : regionQuads) {
			for (Point2f &p : q.corners)
				p = detail::toScaled(p, toEdges);
			q.fromRegion = true;
			quads.push_back(q);
		}
	}
	detail::removeDuplicateQuads(quads, 2.5f);
	/* Smallest first: a marker's own outline decodes before the outline of
	 * its quiet zone, which can then be skipped. */
	std::sort(quads.begin(), quads.end(), [](const detail::Quad &a, const detail::Quad &b) {
		return quadArea(a.corners) < quadArea(b.corners);
	});
}

/* Refines a candidate's corners in place. A region outline lies up to a
 * region pixel inside the marker's: a wider search. On cells of 6 px or
 * more, a wide window (RefineWindow{6, 64}: 3.5 px either side) stays on
 * the border's outer edge, away from the code's, and unlike the default one
 * it stays unbiased on strongly blurred edges (blur set: corner error 0.40
 * -> 0.35 px). It can fail to measure a side where the default one does
 * not (large blurred markers upsampled 3x): then the default one. `image`
 * is the frame or the frame halved to blocks of `block` pixels (finish()). */
bool Detector::Impl::refineQuad(const ImageView &image, const Slot &slot, detail::Quad &q, float search,
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
Detector::Impl::BlockView Detector::Impl::blockView(const ImageView &image, int f,
						   const std::array<Point2f, 4> &outline, float margin)
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
	float x0 = outline[0].x, x1 = x0, y0 = outline[0].y, y1 = y0;
	for (const Point2f &p : outline) {
		x0 = std::min(x0, p.x);
		x1 = std::max(x1, p.x);
		y0 = std::min(y0, p.y);
		y1 = std::max(y1, p.y);
	}
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
void Detector::Impl::refineAndWarpAll(const ImageView &image, Slot &slot, float search)
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
		batch.refined[k] = refineQuad(image, slot, slot.quads[k], search, 1);
		if (batch.refined[k] && bigEnough(corners, config.min_marker_side)) {
			batch.place[k] = static_cast<int>(batch.quads.size());
			batch.quads.push_back(corners);
		}
	}
	timer.lap(Stage::Warp);
	const std::size_t m = batch.quads.size();
	batch.warpedOk.assign(m, 0);
	batch.samples.resize(std::max(batch.samples.size(), m));
	warper->warp(image, batch.quads, (dict->bits + 2) * detail::kSamplesPerCell,
		     std::span(batch.samples).first(m), batch.warpedOk);
}

/* Candidates not worth refining: the outline of a decoded marker's quiet
 * zone, and clutter as the probe's read at the traced outline shows it. */
bool Detector::Impl::skipCandidate(const detail::Quad &q, const std::array<Point2f, 4> &tracedOutline,
				   const std::vector<Marker> &found) const
{
	const int bits = dict->bits;
	const int traced = q.probeRead;
	if (detail::surroundsMarker(tracedOutline, quadArea(tracedOutline), traced, bits, found))
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
	const int mixedFrame = 2 * detail::allowedBorderErrors(bits);
	const bool mixed = traced > mixedFrame && traced < whiteFrame();
	if (q.fromRegion)
		return mixed || q.probeContrast < static_cast<float>(params.region_contrast);
	return mixed && sidesAtLeast(tracedOutline, 4.0f * static_cast<float>(bits + 2));
}

/* Large cells are read on the frame halved f times, in its pixels
 * (readBlock()). The patch reaches what refinement reads across a side (its
 * search and profile: 13 pixels of the halved frame at most) and the reads'
 * ring a cell outside the border; a white frame is only read inside
 * (insetQuad()). Leaves q's corners in the block's pixels. */
Detector::Impl::Reading Detector::Impl::placeCandidate(const ImageView &image, detail::Quad &q,
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

/* Warps and binarises a refined candidate large enough to read. */
void Detector::Impl::sampleRefined(Reading &r, const detail::Quad &q, std::size_t k, Result &res,
				   StageTimer &timer)
{
	r.samples = &warped;
	if (!r.refined || !bigEnough(q.corners, r.minSide))
		return;
	++res.candidates;
	timer.lap(Stage::Warp);
	if (r.inBatch) {
		const int j = batch.place[k];
		r.refined = batch.warpedOk[static_cast<std::size_t>(j)] != 0;
		r.samples = &batch.samples[static_cast<std::size_t>(j)];
	} else {
		r.refined = detail::warpMarker(r.block.view, q.corners, dict->bits, warped);
	}
	timer.lap(Stage::Decode);
	if (r.refined)
		r.b = detail::binarise(*r.samples, dict->bits);
}

/* No dark frame inside the outline, or a white one: this may be the outline
 * of the quiet zone (the marker's own outline merged with its code's edges,
 * as on small or blurred markers). The marker would lie one cell inside. */
void Detector::Impl::readInset(Reading &r, detail::Quad &q, Result &res, StageTimer &timer)
{
	timer.lap(Stage::Refine);
	q.corners = r.outline;
	const bool inset = detail::insetQuad(r.block.view, q.corners, dict->bits, warped);
	r.readable = inset && bigEnough(q.corners, r.minSide);
	if (!r.readable)
		return;
	++res.candidates;
	timer.lap(Stage::Decode);
	r.samples = &warped;
	r.b = detail::binarise(warped, dict->bits);
}

/* Decodes a sampled candidate, trying what else may read when its samples
 * do not; on a read at the traced outline, q takes that outline. */
detail::MarkerRead Detector::Impl::decodeCandidate(const Reading &r, detail::Quad &q)
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
			read = detail::readCellCentres(img, q.corners, *codes, policy, warped);
		if (!read.ok() && r.refined && bigEnough(r.outline, r.minSide)) {
			read = detail::readCellCentres(img, r.outline, *codes, policy, warped);
			if (read.ok())
				q.corners = r.outline;
		}
		return read;
	}
	if (detail::readable(r.b, bits))
		read = detail::readMarker(img, q.corners, *codes, policy, *r.samples, r.b);
	if (!read.ok() && r.refined && r.b.border_errors < whiteFrame()) {
		/* Refinement can pull a blurred marker's sides onto its code's
		 * edges; the traced outline may still read. */
		if (detail::warpMarker(img, r.outline, bits, warped)) {
			const detail::Binarised bt = detail::binarise(warped, bits);
			if (detail::readable(bt, bits)) {
				read = detail::readMarker(img, r.outline, *codes, policy, warped, bt);
				if (read.ok())
					q.corners = r.outline;
			}
		}
	}
	if (!read.ok()) {
		/* Blur of about a cell (a blurred marker, or a small one
		 * upsampled) reaches the quarter-cell samples of cells of any
		 * size. */
		read = detail::readCellCentres(img, q.corners, *codes, policy, warped);
	}
	return read;
}

/* Reads candidate k: refine, warp, binarise; the inset read when that finds
 * no dark frame; then decoding and its fallbacks. A marker read is left in
 * `m`, its corners in frame pixels from the code's first. */
bool Detector::Impl::readCandidate(const ImageView &image, Slot &slot, std::size_t k, float search,
				   StageTimer &timer, Marker &m)
{
	detail::Quad &q = slot.quads[k];
	const std::array<Point2f, 4> tracedOutline = warper ? batch.outlines[k] : q.corners;
	if (skipCandidate(q, tracedOutline, slot.result.markers))
		return false;
	Reading r = placeCandidate(image, q, tracedOutline);
	/* With at least the frame's search on a halved frame: blur spreads a
	 * large marker's edges over as many of its pixels as a small one's
	 * over the frame's. */
	const float ff = static_cast<float>(r.f);
	r.refined = r.inBatch ? batch.refined[k] != 0
			      : q.probeRead < whiteFrame() &&
					refineQuad(r.block.view, slot, q, std::max(search / ff, kSearch), r.f);
	sampleRefined(r, q, k, slot.result, timer);
	if (!r.refined || r.b.border_errors >= whiteFrame())
		readInset(r, q, slot.result, timer);
	timer.lap(Stage::Decode);
	const detail::MarkerRead read = decodeCandidate(r, q);
	if (!read.ok())
		return false;
	if (r.f > 1) {
		const Point2f origin{ static_cast<float>(r.block.ox), static_cast<float>(r.block.oy) };
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
	return true;
}

/* The candidates in order, smallest first: each read, each marker kept
 * once. */
void Detector::Impl::finish(const ImageView &image, Slot &slot)
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
	if (warper)
		refineAndWarpAll(image, slot, search);
	for (std::size_t k = 0; k < slot.quads.size(); ++k) {
		StageTimer timer(res.times, Stage::Refine);
		Marker m;
		if (readCandidate(image, slot, k, search, timer, m))
			detail::keepMarker(res.markers, m);
	}
	/* Smallest first, a block of a marker's code cells decoded before the
	 * marker around it did: now that both are known, drop it. */
	StageTimer timer(res.times, Stage::Decode);
	detail::dropNestedMarkers(res.markers, dict->bits);
}

Detector::Detector(const Config &config) : impl_(std::make_unique<Impl>())
{
	const Dictionary *d = findDictionary(config.dictionary);
	if (!d)
		throw std::invalid_argument("frappe::Config: unknown dictionary '" + config.dictionary +
					    "'; known: " + dictionaryNames());
	validate(config, *d);
	impl_->config = config;
	impl_->dict = d;
	impl_->codes = std::make_unique<detail::CodeBook>(*d);
	impl_->maxHamming = config.max_hamming >= 0 ? config.max_hamming : d->defaultMaxHamming();
	impl_->policy.maxHamming = impl_->maxHamming;
	impl_->policy.weakMargin = config.weak_margin;
	impl_->policy.maxTotal =
		config.weak_margin > 0.0f ? std::max(impl_->maxHamming, d->weakMaxHamming()) : impl_->maxHamming;
	const double e = static_cast<double>(config.edge_threshold) * 255.0;
	impl_->params.edge_threshold_sq = static_cast<std::int64_t>(std::floor(e * e));
	impl_->params.corner_threshold =
		static_cast<std::int64_t>(std::floor(static_cast<double>(config.corner_threshold) * 255.0 * 255.0));
	impl_->params.region_contrast = static_cast<int>(std::lround(config.region_contrast * 255.0f));
	if (config.region_contrast > 0.0f)
		impl_->params.region_contrast = std::max(1, impl_->params.region_contrast);
	impl_->frontEnd = makeCpuFrontEnd(config.threads);
}

Detector::~Detector() = default;
Detector::Detector(Detector &&) noexcept = default;
Detector &Detector::operator=(Detector &&) noexcept = default;

const Result &Detector::detect(const ImageView &image)
{
	detail::DetectorStages::frontEnd(*this, image, 0);
	return detail::DetectorStages::backEnd(*this, image, 0);
}

namespace detail {

void DetectorStages::frontEnd(Detector &detector, const ImageView &image, int slot)
{
	Detector::Impl &d = *detector.impl_;
	d.checkImage(image);
	Detector::Impl::Slot &s = d.slotAt(slot);
	s.result.times = {};
	StageTimer timer(s.result.times, Stage::AdaptiveScale);
	float scale;
	{
		std::lock_guard<std::mutex> lock(d.adaptiveLock);
		scale = d.adaptive.next(d.config);
	}
	/* Never scale a frame so small that a marker could not survive it. */
	if (scaledLength(image.width, scale) < 32 || scaledLength(image.height, scale) < 32)
		scale = 1.0f;
	s.image = image;
	timer.lap(Stage::FrontEnd);
	d.frontEnd->run(image, scale, d.params, s.edges);
	if (!d.frontEnd->makesRegionMap()) {
		/* A front end without a region map (the QPUs, for now): the
		 * CPU's, from the full-resolution frame (the edge map's scale
		 * is taken into account when its quads are mapped); empty when
		 * region_contrast is 0. */
		detail::regionMap(image, 1.0f, d.params.region_contrast, s.edges.regions, d.regionScratch);
	}
	s.result.scale = s.edges.scale;
}

void DetectorStages::trace(Detector &detector, int slot)
{
	Detector::Impl &d = *detector.impl_;
	d.trace(d.slotAt(slot));
}

const Result &DetectorStages::finish(Detector &detector, const ImageView &image, int slot)
{
	Detector::Impl &d = *detector.impl_;
	Detector::Impl::Slot &s = d.slotAt(slot);
	d.finish(image, s);
	{
		std::lock_guard<std::mutex> lock(d.adaptiveLock);
		d.adaptive.update(s.result.markers);
	}
	double total = 0;
	for (double ms : s.result.times.ms)
		total += ms;
	s.result.times.total_ms = total;
	return s.result;
}

} // namespace detail

void Detector::checkImage(const ImageView &image) const
{
	impl_->checkImage(image);
}

void Detector::setFrontEnd(std::unique_ptr<FrontEnd> frontEnd)
{
	if (!frontEnd)
		throw std::invalid_argument("frappe::Detector: null front end");
	impl_->frontEnd = std::move(frontEnd);
}

const FrontEnd &Detector::frontEnd() const { return *impl_->frontEnd; }
void Detector::setWarper(std::unique_ptr<CandidateWarper> warper) { impl_->warper = std::move(warper); }
const CandidateWarper *Detector::warper() const { return impl_->warper.get(); }
const EdgeMap &Detector::edgeMap() const { return impl_->slots[0].edges; }
void Detector::reset()
{
	std::lock_guard<std::mutex> lock(impl_->adaptiveLock);
	impl_->adaptive.reset();
}
const Config &Detector::config() const { return impl_->config; }
const Dictionary &Detector::dictionary() const { return *impl_->dict; }
int Detector::maxHamming() const { return impl_->maxHamming; }
FrontEndParams Detector::frontEndParams() const { return impl_->params; }

const char *version() { return FRAPPE_VERSION_STRING; }
const char *simdTarget() { return detail::simdTargetName(); }

} // namespace frappe
