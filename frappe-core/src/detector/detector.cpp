// SPDX-License-Identifier: MIT
// The Detector: runs the stages of Algorithm 1 in order and times each.
// Here: the set-up, the front end and the trace; the reading of the
// candidates is detail::CandidateReader's (read/candidate_reader.h), which
// the detector's state (detector_impl.h) holds.
#include "frappe/version.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <string>

#include "frappe/settings.h"

#include "detector_impl.h"
#include "front_end_rows.h"
#include "noise_floor.h"
#include "quad_geometry.h"

namespace frappe {

namespace {

/* The exponential scale of the read of clipped candidates (Tone::expScale):
 * the midpoint of a black at 60 and the ceiling lands near 220 grey levels.
 * 32 to 64 read the same on every subset at 200% light. */
constexpr float kClipScale = 48.0f;

using detail::quadArea;
using detail::StageTimer;
using detail::toFullResolution;

/* Reads a traced quad as a marker, so that the tracer can skip the
 * marker's inside: one sample at each cell's centre (a quarter of the warp
 * that finish() makes of the refined quad), then binarise's checks and an
 * exact codeword. A miss costs nothing but the skip: the quad stays a
 * candidate either way. */
class TracedMarkerProbe final : public detail::MarkerProbe
{
public:
	TracedMarkerProbe(const ImageView &image, float scale, const detail::CodeBook &codes, int maxHamming,
			  detail::DecodeCache &decodes)
		: image_(image), scale_(scale), codes_(codes), dict_(codes.dictionary()), maxHamming_(maxHamming),
		  decodes_(decodes)
	{
	}
	/* Notes in quad.probeRead how many border cells read white at the
	 * traced outline, and in quad.probeContrast the spread of its
	 * samples (finish() uses both before refining). */
	bool isMarker(detail::Quad &quad) override
	{
		/* A layout's square is read by finish() alone (layout_candidate.cpp). */
		if (dict_.layout)
			return false;
		std::array<Point2f, 4> corners;
		for (int i = 0; i < 4; ++i)
			corners[i] = toFullResolution(quad.corners[i], scale_);
		if (!detail::warpToGrid(image_, corners, dict_.bits + 2, cellCentres_, true))
			return false;
		const detail::Binarised b = detail::binarise(cellCentres_, dict_.bits);
		quad.probeRead = b.border_errors;
		quad.probeContrast = b.contrast;
		quad.probeLevel = b.threshold;
		/* Only an exact codeword: a wrong "yes" would hide whatever lies
		 * inside the quad (markers on a dark panel, say), and with a small
		 * dictionary and a generous max_hamming a third of all bit patterns
		 * are within reach of some codeword. */
		quad.probeReadable = detail::readable(b, dict_.bits);
		if (!quad.probeReadable)
			return false;
		if (decodes_.decode(codes_, b.code, 0).id >= 0)
			return true;
		/* Not sealed, but ranked before clutter when a frame has more
		 * candidates than it may read (capCandidates()). */
		quad.probeNearCode = maxHamming_ > 0 && decodes_.decode(codes_, b.code, maxHamming_).id >= 0;
		return false;
	}

private:
	const ImageView &image_;
	float scale_;
	const detail::CodeBook &codes_;
	const Dictionary &dict_;
	int maxHamming_;
	detail::DecodeCache &decodes_;
	detail::WarpedMarker cellCentres_;
};

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

void Detector::Impl::checkImage(const ImageView &image) const
{
	auto fail = [](const std::string &what) { throw std::invalid_argument("frappe::Detector: " + what); };
	if (image.width <= 0 || image.height <= 0)
		fail("image size must be positive, got " + std::to_string(image.width) + "x" +
		     std::to_string(image.height));
	if (image.width > kMaxImageSide || image.height > kMaxImageSide)
		fail("image side must be at most " + std::to_string(kMaxImageSide) + " pixels");
	if (static_cast<long long>(image.width) * image.height > config.max_pixels)
		fail("image of " + std::to_string(image.width) + "x" + std::to_string(image.height) +
		     " has more than max_pixels (" + std::to_string(config.max_pixels) + ") pixels");
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
	TracedMarkerProbe probe(slot.image, scale, *codes, maxHamming, traceDecodes);
	tracer.trace(edges, tp, quads, &probe);
	/* Region borders have no corner pixels: every closed one is fitted
	 * from its outline. Their quads join the edge ones in the edge map's
	 * coordinates; the shade map's after the region map's, so that a
	 * repeat of a region quad is dropped. */
	for (const TraceMap *regions : { &edges.regions, &edges.shades }) {
		if (regions->width == 0)
			continue;
		detail::TraceParams rtp = tp;
		rtp.min_clusters = 0;
		rtp.max_winding = 2.0f;
		rtp.holes = false;
		rtp.corners = false; /* kEdge alone marks a region pixel */
		rtp.min_side = std::max(4.0f, config.min_marker_side * regions->scale);
		TracedMarkerProbe regionProbe(slot.image, regions->scale, *codes, maxHamming, traceDecodes);
		regionTracer.trace(*regions, rtp, regionQuads, &regionProbe);
		const float toEdges = scale / regions->scale;
		for (detail::Quad q : regionQuads) {
			for (Point2f &p : q.corners)
				p = detail::toScaled(p, toEdges);
			q.fromRegion = true;
			q.fromShade = regions == &edges.shades;
			quads.push_back(q);
		}
	}
	detail::removeDuplicateQuads(quads, 2.5f, quadGrid);
	/* Smallest first: a marker's own outline decodes before the outline of
	 * its quiet zone, which can then be skipped. The shade map's quads
	 * last: they find the markers shadows hide from the others, and
	 * where a marker was read already its own candidates' corners are
	 * the better ones (finish() skips a shade quad around a marker). */
	std::sort(quads.begin(), quads.end(), [](const detail::Quad &a, const detail::Quad &b) {
		if (a.fromShade != b.fromShade)
			return b.fromShade;
		return quadArea(a.corners) < quadArea(b.corners);
	});
	slot.result.candidates_dropped = detail::capCandidates(quads, config.max_candidates);
}

Detector::Detector(const Config &config) : impl_(std::make_unique<Impl>())
{
	validate(config); /* frappe/settings.h: the table's ranges */
	/* A dictionary of the user's own wins over the name. */
	const Dictionary *d =
		config.custom_dictionary ? config.custom_dictionary.get() : findDictionary(config.dictionary);
	impl_->config = config;
	impl_->customDictionary = config.custom_dictionary;
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
	impl_->params.light_floor = std::min(FrontEndParams::kLightReference,
					     static_cast<int>(std::lround(config.light_floor * 255.0f)));
	impl_->noiseMultiplier = detail::noiseFloorMultiplier(config.light_floor_noise);
	/* The second look corrects only what a clear read may: on the log
	 * scale the weak cells of clutter and of other families' codes are
	 * many, and they made wrong ids. */
	impl_->logPolicy = impl_->policy;
	impl_->logPolicy.maxTotal = impl_->policy.maxHamming;
	if (impl_->params.light_floor < FrontEndParams::kLightReference) {
		impl_->logPolicy.tone.logFloor = static_cast<float>(std::max(1, impl_->params.light_floor));
		impl_->logPolicy.tone.fillTable(impl_->logTable.data());
		impl_->logPolicy.tone.table = impl_->logTable.data();
		impl_->clipPolicy = impl_->logPolicy;
		impl_->clipPolicy.tone = {};
		impl_->clipPolicy.tone.expScale = kClipScale;
		impl_->clipPolicy.tone.fillTable(impl_->clipTable.data());
		impl_->clipPolicy.tone.table = impl_->clipTable.data();
	}
	impl_->frontEnd = makeCpuFrontEnd(config.threads);
	if (config.mode == Mode::Track)
		impl_->tracker = std::make_unique<detail::Tracker>(config.track_cover_frames);
}

Detector::~Detector() = default;
Detector::Detector(Detector &&) noexcept = default;
Detector &Detector::operator=(Detector &&) noexcept = default;

const Result &Detector::detect(const ImageView &image)
{
	Impl &d = *impl_;
	d.mayRetry = d.tracker != nullptr;
	detail::DetectorStages::frontEnd(*this, image, 0);
	const Result &first = detail::DetectorStages::backEnd(*this, image, 0);
	d.mayRetry = false;
	if (!d.tracker || first.whole_frame || !d.tracker->retrying())
		return first;
	/* Track: a marker of the last frame was not where predicted. The
	 * same frame again, whole (the tracker planned it so), so that it
	 * does not drop out; the frame's time is both searches'. */
	const StageTimes partial = first.times;
	detail::DetectorStages::frontEnd(*this, image, 0);
	Result &again = const_cast<Result &>(detail::DetectorStages::backEnd(*this, image, 0));
	for (int i = 0; i < kStageCount; ++i)
		again.times.ms[i] += partial.ms[i];
	again.times.total_ms += partial.total_ms;
	return again;
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
	/* The light floor from the frame's own noise (noise_floor.h): a quiet
	 * sensor's dark frame keeps edges of 7-10 grey levels, a noisy one's
	 * noise stays under the configured floor. */
	s.params = d.params;
	if (d.noiseMultiplier > 0 && d.params.light_floor < FrontEndParams::kLightReference)
		s.params.light_floor =
			detail::noiseLightFloor(detail::noiseMedian(image), d.noiseMultiplier, d.params.light_floor);
	/* Track: the CPU front end over the regions the tracks predict and a
	 * band of the rest, or the whole frame. */
	bool regions = d.tracker && d.tracker->plan(image, std::string_view(d.frontEnd->name()) == "cpu");
	s.known.clear();
	if (regions) {
		/* Track: each marker first read where its track predicts it,
		 * its corners refined on this frame; only the others' regions
		 * go through the front end and the trace. */
		const auto predictions = d.tracker->predictions();
		d.readAtPrediction.assign(predictions.size(), 0);
		for (std::size_t i = 0; i < predictions.size(); ++i) {
			Marker m;
			if (!d.trackReader.readTracked(image, s.edges, predictions[i].corners, predictions[i].id, m))
				continue;
			m.tracked = true;
			s.known.push_back(m);
			d.readAtPrediction[i] = 1;
		}
		regions = d.tracker->placeRegions(d.readAtPrediction);
		if (!regions)
			s.known.clear();
	}
	s.result.whole_frame = !regions;
	s.result.bytes_read = static_cast<std::size_t>(image.width) * image.height;
	if (regions) {
		d.tracker->runRegions(image, s.params, s.edges);
		/* The markers read at their predictions need no trace. */
		detail::clearInsideMarkers(s.edges, s.known, 1.5f);
		s.result.bytes_read = d.tracker->bytesRead();
		s.result.scale = 1.0f;
		s.result.copy_bytes = 0;
		return;
	}
	if (d.tracker)
		d.tracker->ranWhole();
	d.frontEnd->run(image, scale, s.params, s.edges);
	if (!d.frontEnd->makesRegionMap()) {
		/* A front end without a region map (one of the caller's): the
		 * CPU's, from the full-resolution frame (the edge map's scale
		 * is taken into account when its quads are mapped); empty when
		 * region_contrast is 0. */
		detail::regionMap(image, 1.0f, s.params, s.edges.regions, s.edges.shades, d.regionScratch);
	} else if (s.params.makesShades() && !d.frontEnd->makesShadeMap()) {
		/* A front end with a region map but no shade map (the QPUs'
		 * today): the CPU's, from the frame the front end traced (its
		 * region map made again, unused), so the markers are the CPU
		 * front end's. */
		ImageView traced = image;
		if (s.edges.scale < 1.0f) {
			d.shadeFrame.resize(static_cast<std::size_t>(s.edges.width) * s.edges.height);
			detail::scaleNearest(image, s.edges.width, s.edges.height, d.shadeFrame.data());
			traced = ImageView(d.shadeFrame.data(), s.edges.width, s.edges.height, s.edges.width);
		}
		detail::regionMap(traced, s.edges.scale, s.params, d.shadeRegions, s.edges.shades, d.regionScratch);
	}
	s.result.scale = s.edges.scale;
	s.result.copy_bytes = d.frontEnd->lastCopyBytes();
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
	if (d.tracker)
		d.tracker->update(s.result.markers, image.width, image.height, !s.result.whole_frame, d.mayRetry);
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
	{
		std::lock_guard<std::mutex> lock(impl_->adaptiveLock);
		impl_->adaptive.reset();
	}
	if (impl_->tracker)
		impl_->tracker->reset();
}
const Config &Detector::config() const { return impl_->config; }
const Dictionary &Detector::dictionary() const { return *impl_->dict; }
int Detector::maxHamming() const { return impl_->maxHamming; }
FrontEndParams Detector::frontEndParams() const { return impl_->params; }

const char *version() { return FRAPPE_VERSION_STRING; }
const char *simdTarget() { return detail::simdTargetName(); }

} // namespace frappe
