// SPDX-License-Identifier: MIT
// The detector's state, private to frappe-core: what detector.cpp (set-up,
// the front end and the trace) and candidate_reader.cpp (refine, warp and
// decode each candidate) share.
#pragma once

#include "frappe/detector.h"

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "adaptive_scale.h"
#include "contour_trace.h"
#include "decode.h"
#include "detector_stages.h"
#include "front_end_rows.h"
#include "region_map.h"
#include "stage_timer.h"
#include "verify.h"

namespace frappe {

namespace detail {

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

} // namespace detail

struct FRAPPE_HIDDEN Detector::Impl {
	Config config;
	const Dictionary *dict = nullptr;
	/* Config::custom_dictionary, held here whatever becomes of the
	 * config: dict and codes point into it. */
	std::shared_ptr<const Dictionary> customDictionary;
	std::unique_ptr<detail::CodeBook> codes;
	int maxHamming = 0;
	detail::DecodePolicy policy;
	/* policy on the log scale (Tone), the second read of a candidate;
	 * grey levels (no second read) when light_floor keeps thresholds absolute. */
	detail::DecodePolicy logPolicy;
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
	detail::PointGrid quadGrid;   /* removeDuplicateQuads()'s, in trace() */
	detail::PointGrid markerGrid; /* dropNestedMarkers()'s, in finish() */
	detail::PointGrid markerCentres; /* the frame's markers so far, for skipCandidate() */
	detail::RegionScratch regionScratch; /* for a front end without a region map */
	/* For a front end without a shade map: the frame it traced, scaled, and
	 * the region map made beside the shades (not used). */
	std::vector<std::uint8_t> shadeFrame;
	TraceMap shadeRegions;
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
	std::array<std::uint64_t, detail::kMaxReadBlock + 1> blockFrameOf{}; /* finishedFrames it was made for */
	std::array<std::size_t, detail::kMaxReadBlock + 1> blockFrameAt{};
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
		bool counted = false;   /* sampled for a read: one of Result::candidates */
	};

	void checkImage(const ImageView &image) const;
	void trace(Slot &slot);
	void finish(const ImageView &image, Slot &slot);
	bool refineQuad(const ImageView &image, const Slot &slot, detail::Quad &q, float search, int block) const;
	void refineAndWarpAll(const ImageView &image, Slot &slot, float search);
	/* Reading one candidate, in finish()'s order. */
	bool readCandidate(const ImageView &image, Slot &slot, std::size_t k, float search, detail::StageTimer &timer,
			   Marker &m);
	bool skipCandidate(const detail::Quad &q, const std::array<Point2f, 4> &tracedOutline,
			   const std::vector<Marker> &found) const;
	Reading placeCandidate(const ImageView &image, detail::Quad &q, const std::array<Point2f, 4> &tracedOutline);
	void sampleRefined(Reading &r, const detail::Quad &q, std::size_t k, const detail::DecodePolicy &pol,
			   detail::StageTimer &timer);
	void readInset(Reading &r, detail::Quad &q, const detail::DecodePolicy &pol, detail::StageTimer &timer);
	detail::MarkerRead decodeCandidate(const Reading &r, detail::Quad &q, const detail::DecodePolicy &pol);
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

} // namespace frappe
