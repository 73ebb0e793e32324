// SPDX-License-Identifier: MIT
// The read stage: the candidates a trace found, each placed on the frame
// (or the frame halved into blocks for large cells), its corners refined,
// warped to the sample grid, binarised, decoded and verified; the markers
// kept once. A class of its own that owns its state (halved frames, the
// warp batch, the marker grids) and reads through the detector's settings,
// so that the detector holds one and nothing here reaches up into it.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "frappe/candidate_warp.h"
#include "frappe/config.h"
#include "frappe/dictionary.h"
#include "frappe/edge_map.h"
#include "frappe/detector.h"

#include "contour_trace.h"
#include "decode.h"
#include "point_grid.h"
#include "stage_timer.h"
#include "verify.h"

namespace frappe::detail {

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
inline int readBlock(float cell)
{
	int f = 1;
	while (2 * f <= kMaxReadBlock && cell >= static_cast<float>(2 * f) * kReadCell)
		f *= 2;
	return f;
}

class CandidateReader {
public:
	/* The detector's settings, by reference: they are set after the
	 * reader is made (Detector's constructor) and the warper may change
	 * (Detector::setWarper()). */
	CandidateReader(const Config &config, const Dictionary *const &dict, const std::unique_ptr<CodeBook> &codes,
			const DecodePolicy &policy, const DecodePolicy &logPolicy, const DecodePolicy &clipPolicy,
			const std::unique_ptr<CandidateWarper> &warper)
		: config(config), dict(dict), codes(codes), policy(policy), logPolicy(logPolicy),
		  clipPolicy(clipPolicy), warper(warper)
	{}
	CandidateReader(const CandidateReader &) = delete;
	CandidateReader &operator=(const CandidateReader &) = delete;

	/* Reads the candidates `quads` (traced at edges.scale; moved to full
	 * resolution and refined in place; `params`: what the front end made
	 * edges with, this frame's light floor) of `image` into result.markers,
	 * result.candidates and the read stages' times. */
	/* `known`: markers read before the trace (readTracked()), kept first;
	 * the candidates that would only read as them again are skipped. */
	void read(const ImageView &image, const EdgeMap &edges, const FrontEndParams &params, std::vector<Quad> &quads,
		  Result &result, std::span<const Marker> known = {})
	{
		Slot slot{ edges, params, quads, result, known };
		finish(image, slot);
	}

	/* Mode::Track: reads the marker `id` where its track predicts it
	 * (`predicted`, its corners in the marker's order), without a trace:
	 * its corners refined on `image` from the prediction, then read as a
	 * traced candidate is. False when refinement fails, it reads as
	 * another id or none, or its corners moved more than two searches
	 * from the prediction. Uses state of its own, not finish()'s. */
	bool readTracked(const ImageView &image, const EdgeMap &edges, const std::array<Point2f, 4> &predicted, int id,
			 Marker &m);

private:
	/* What finish() reads of the detector's frame. */
	struct Slot {
		const EdgeMap &edges;
		const FrontEndParams &params;
		std::vector<Quad> &quads;
		Result &result;
		std::span<const Marker> known = {};
	};

	const Config &config;
	const Dictionary *const &dict;
	const std::unique_ptr<CodeBook> &codes;
	const DecodePolicy &policy;
	/* policy on the log scale (Tone), the second read of a candidate. */
	const DecodePolicy &logPolicy;
	/* policy on the exponential scale, the last read of a candidate whose
	 * whites clip (linear: none). */
	const DecodePolicy &clipPolicy;
	const std::unique_ptr<CandidateWarper> &warper; /* nullptr: warp on the CPU, one by one */

	PointGrid markerGrid;    /* dropNestedMarkers()'s */
	PointGrid markerCentres; /* the frame's markers so far, for skipCandidate() */
	PointGrid knownCentres;  /* the first knownCount of them, read before the trace */
	std::size_t knownCount = 0;
	/* readTracked()'s candidate and its counts (not the frame's). */
	std::vector<Quad> trackQuads;
	Result trackResult;
	WarpedMarker warped;
	WarpMemo warpMemo;   /* one candidate's warps, for its later reads */
	DecodeCache decodes; /* the read stage's last decodes */
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
		bool inBatch = false;           /* refined and warped by refineAndWarpAll() */
		float minSide = 0.0f;           /* config.min_marker_side, in block pixels */
		std::array<Point2f, 4> outline; /* the traced one */
		bool refined = false;           /* then: and warped */
		bool readable = true;
		detail::Binarised b;
		const detail::WarpedMarker *samples = nullptr;
		bool counted = false; /* sampled for a read: one of Result::candidates */
		/* The inset outline (insetCorners()), measured once for every read:
		 * 0 not yet, 1 measured, -1 not measurable. */
		int inset = 0;
		std::array<Point2f, 4> insetCorners;
	};

	void finish(const ImageView &image, Slot &slot);
	bool refineQuad(const ImageView &image, const Slot &slot, Quad &q, float search, int block) const;
	void refineAndWarpAll(const ImageView &image, Slot &slot, float search);
	/* Reading one candidate, in finish()'s order. */
	bool readCandidate(const ImageView &image, Slot &slot, std::size_t k, float search, StageTimer &timer,
			   Marker &m);
	MarkerRead readRefined(Reading &r, Quad &q, std::size_t k, StageTimer &timer, Result &result);
	/* `mixed`: skipped for a mixed frame alone (an edge quad). */
	bool skipCandidate(const Quad &q, const std::array<Point2f, 4> &tracedOutline, const Slot &slot,
			   bool &mixed) const;
	/* Thresholds that follow the light let clutter's cells fall either
	 * way: only for dictionaries whose codes lie far enough apart to
	 * correct a bit by default (not the 4x4 families, where they made
	 * wrong ids on synth/images and blur). */
	bool readsInLight() const { return dict->defaultMaxHamming() > 0; }
	Binarised readInLight(const ImageView &view, const std::array<Point2f, 4> &corners, const DecodePolicy &pol);
	Reading placeCandidate(const ImageView &image, Quad &q, const std::array<Point2f, 4> &tracedOutline);
	void sampleRefined(Reading &r, const Quad &q, std::size_t k, const DecodePolicy &pol, StageTimer &timer);
	void readInset(Reading &r, Quad &q, const DecodePolicy &pol, StageTimer &timer);
	MarkerRead decodeCandidate(const Reading &r, Quad &q, const DecodePolicy &pol);
	/* A read's marker: q's corners back in frame pixels from the block
	 * of f pixels they were read on, the code's first corner first. */
	static void toMarker(Quad &q, int f, const BlockView &block, const MarkerRead &read, Marker &m);
	/* The same for a dictionary with a layout (layout_candidate.cpp). */
	bool refineLayoutQuad(const ImageView &image, Quad &q, float search) const;
	void refineAndWarpLayouts(const ImageView &image, Slot &slot, float search);
	/// The batch's quads warped in one call, `side` samples a side.
	void warpBatch(const ImageView &image, int side);
	bool readLayoutCandidate(const ImageView &image, Slot &slot, std::size_t k, float search, StageTimer &timer,
				 Marker &m);
	/* Border cells that make a white frame: three quarters of the
	 * 4(n+1). */
	int whiteFrame() const { return 3 * dict->bits + 3; }
};

} // namespace frappe::detail
