// SPDX-License-Identifier: MIT
// The detector's state, private to frappe-core and to detector.cpp (set-up,
// the front end and the trace): its settings, its slots, its tracers, and
// the read stage, a detail::CandidateReader that owns its own state and
// reads through these settings (nothing of the read stage includes this).
#pragma once

#include "frappe/detector.h"

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "adaptive_scale.h"
#include "candidate_reader.h"
#include "contour_trace.h"
#include "decode.h"
#include "detector_stages.h"
#include "front_end_rows.h"
#include "region_map.h"
#include "stage_timer.h"
#include "tracker.h"
#include "verify.h"

namespace frappe {

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
	std::array<float, 256> logTable; /* logPolicy.tone's value of each grey level */
	/* policy on the exponential scale, the last read of a candidate whose
	 * whites clip (none when light_floor keeps thresholds absolute). */
	detail::DecodePolicy clipPolicy;
	std::array<float, 256> clipTable;
	/* The configured front end's parameters; each frame's light floor
	 * follows its noise (Slot::params) when noiseMultiplier > 0. */
	FrontEndParams params;
	int noiseMultiplier = 0; /* detail::noiseFloorMultiplier(config.light_floor_noise) */
	std::unique_ptr<FrontEnd> frontEnd;
	std::unique_ptr<CandidateWarper> warper; /* nullptr: warp on the CPU, one by one */
	/* Read by the front end, written by the back end: in pipelined use
	 * they run on different threads. */
	std::mutex adaptiveLock;
	detail::AdaptiveScale adaptive;
	/* Mode::Track's tracks and regions (nullptr in the other modes); under
	 * its own lock. mayRetry: detect() may search a frame again whole. */
	std::unique_ptr<detail::Tracker> tracker;
	bool mayRetry = false;

	/* One frame in flight: its edges, its candidates, its result. */
	struct Slot {
		ImageView image; /* the frame, valid until its back end returns */
		/* params with the frame's light floor: what its maps were made
		 * with and its region candidates are judged by. */
		FrontEndParams params;
		EdgeMap edges;
		std::vector<detail::Quad> quads;
		/* Mode::Track: the markers read at their tracks' predictions
		 * before the front end (CandidateReader::readTracked()). */
		std::vector<Marker> known;
		Result result;
	};
	Slot slots[detail::DetectorStages::kSlots];

	/* Used by one stage each, so that stages of different slots can run
	 * at once: the tracer by trace(), the warp buffer by finish(). */
	detail::ContourTracer tracer;
	detail::ContourTracer regionTracer;
	std::vector<detail::Quad> regionQuads;
	detail::PointGrid quadGrid;          /* removeDuplicateQuads()'s, in trace() */
	detail::DecodeCache traceDecodes;    /* the marker probes' decodes, in trace() */
	detail::RegionScratch regionScratch; /* for a front end without a region map */
	/* For a front end without a shade map: the frame it traced, scaled, and
	 * the region map made beside the shades (not used). */
	std::vector<std::uint8_t> shadeFrame;
	TraceMap shadeRegions;
	/* The read stage's own state (halved frames, the warp batch, the
	 * marker grids), reading through the settings above. */
	detail::CandidateReader reader{ config, dict, codes, policy, logPolicy, clipPolicy, warper };

	void checkImage(const ImageView &image) const;
	void trace(Slot &slot);
	/* Mode::Track's reads at the predictions, in the front end's stage:
	 * state of their own, as the finish of another frame may run at
	 * once (Pipeline's Overlap::Stages); per prediction whether it read. */
	detail::CandidateReader trackReader{ config, dict, codes, policy, logPolicy, clipPolicy, warper };
	std::vector<std::uint8_t> readAtPrediction;

	void finish(const ImageView &image, Slot &slot)
	{
		reader.read(image, slot.edges, slot.params, slot.quads, slot.result, slot.known);
	}
	Slot &slotAt(int slot) { return const_cast<Slot &>(static_cast<const Impl *>(this)->slotAt(slot)); }
	const Slot &slotAt(int slot) const
	{
		constexpr int n = detail::DetectorStages::kSlots;
		if (slot < 0 || slot >= n)
			throw std::invalid_argument("frappe::Detector: slot must be 0.." + std::to_string(n - 1));
		return slots[slot];
	}
};

} // namespace frappe
