// SPDX-License-Identifier: MIT
// Mode::Track: which parts of a frame the front end reads (the regions
// predicted from earlier frames' markers, a band of the rest, or all of it),
// the CPU front end over those regions into full-frame maps, and the tracks
// themselves.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

#include "frappe/edge_map.h"
#include "frappe/image.h"
#include "frappe/marker.h"
#include "front_end_rows.h"
#include "region_map.h"

namespace frappe::detail {

/// A rectangle of frame pixels, [x0, x1) x [y0, y1).
struct PixelRect {
	int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
	bool operator==(const PixelRect &) const = default;
	bool empty() const { return x1 <= x0 || y1 <= y0; }
	std::size_t area() const
	{
		return empty() ? 0 : static_cast<std::size_t>(x1 - x0) * static_cast<std::size_t>(y1 - y0);
	}
};

/// The CPU front end over rectangles of a frame, into maps of the whole
/// frame: inside each rectangle (once aligned, alignedRect()) the edge map
/// holds byte for byte what a run over the whole frame writes there (edges,
/// corners), zero elsewhere, and its tile mask says which tiles hold an
/// edge pixel. The region map (half resolution) is likewise exact inside
/// the rectangles and the search strips, zero elsewhere, or the whole
/// frame's; the shade map is exact inside the rectangles only. Each part
/// is read with a margin of kMargin pixels, which its filters need
/// (smoothing, Sobel, non-maximum suppression, the structure tensor: 3
/// pixels; the region map's threshold tiles: 8).
class RegionFrontEnd
{
public:
	/// Rectangles start and end on multiples of kAlign (or the frame's
	/// edges): word-sized copies.
	static constexpr int kAlign = 8;
	static constexpr int kMargin = 8;

	explicit RegionFrontEnd(const BandKernels &kernels = bestBandKernels());

	/// `r` grown to kAlign and clipped to a width x height frame.
	static PixelRect alignedRect(PixelRect r, int width, int height);

	/// Fills `out` for `image`: the edge, region and shade maps of the
	/// rectangles (aligned, alignedRect(); they may overlap) as a
	/// whole-frame run would, zero elsewhere, and the region map of the
	/// `search` strips too, or of the whole frame when one of them is the
	/// whole frame. Clears only what its last run on `out` wrote (all of it
	/// after invalidate()). Allocates nothing once it has run on a frame of
	/// this size.
	void run(const ImageView &image, std::span<const PixelRect> rects, std::span<const PixelRect> search,
		 const FrontEndParams &params, EdgeMap &out);
	/// `out` was filled by some other front end: clear it whole next time.
	void invalidate() { dirtyAll_ = true; }
	/// Bytes of the frame the last run read: the rectangles and the search
	/// strips with their margins, or the whole frame once for the region
	/// map.
	std::size_t bytesRead() const { return bytesRead_; }

private:
	void keepOnlyRects(TraceMap &m);

	std::unique_ptr<FrontEnd> cpu_; /* one thread: its output does not depend on it */
	EdgeMap sub_;
	RegionScratch scratch_;
	std::vector<std::uint8_t> row_;
	std::vector<PixelRect> written_; /* the rectangles of the last run, to clear */
	std::vector<PixelRect> halfWritten_; /* where the last run wrote the region and shade maps */
	bool halfWhole_ = false;             /* the last run made the whole frame's region map */
	TraceMap subRegions_, subShades_;    /* a search strip's */
	static void markHalfTiles(TraceMap &m, std::span<const PixelRect> rects);
	bool dirtyAll_ = true;
	const EdgeMap *last_ = nullptr; /* the map written_ is of (a Pipeline's slots take turns) */
	std::size_t bytesRead_ = 0;
};

/// Clears, in the edge, region and shade maps, the inside of each marker
/// read at its prediction (its quad moved `inset` pixels in): its code
/// cells' outlines, which the trace would follow only to skip them. No
/// other marker lies inside one; its neighbours' outlines lie outside.
void clearInsideMarkers(EdgeMap &maps, std::span<const Marker> markers, float inset);

/// The tracks of Mode::Track and the plan of each frame. plan() (the front
/// end's) and update() (the finish's) may run on different threads in a
/// Pipeline's Overlap::Stages: the tracks are under a lock.
class Tracker
{
public:
	/// k of Config::track_cover_frames.
	explicit Tracker(int coverFrames);

	/// Where a track predicts its marker on this frame, and the
	/// rectangle its front end reads when it is not read there directly.
	struct Prediction {
		int id = -1;
		std::array<Point2f, 4> corners{};
		PixelRect rect;
	};

	/// Decides whether this frame is read whole: false when the whole
	/// frame (the first frame, a new size, a scene change, a lost
	/// marker), true when in parts: then predictions() holds the tracks'
	/// predictions, and placeRegions() the parts. `regionsPossible`:
	/// whether the detector's front end is the CPU's; otherwise every
	/// frame is whole.
	bool plan(const ImageView &image, bool regionsPossible);
	std::span<const Prediction> predictions() const { return predictions_; }
	/// The rectangles of the predictions not `read` at their prediction
	/// (one flag each; CandidateReader::readTracked()), this frame's band,
	/// and the strips where the region map searches for markers entering
	/// the frame. False when they would cover most of the frame: read it
	/// whole.
	bool placeRegions(std::span<const std::uint8_t> read);
	/// The rectangles plan() chose (aligned, merged).
	std::span<const PixelRect> regions() const { return regions_; }
	/// The CPU front end over regions() into `out`.
	void runRegions(const ImageView &image, const FrontEndParams &params, EdgeMap &out);
	/// `out` was filled whole by the detector's own front end.
	void ranWhole() { regionFrontEnd_.invalidate(); }
	std::size_t bytesRead() const { return regionFrontEnd_.bytesRead(); }

	/// Matches a frame's markers with the tracks (Marker::tracked) and
	/// moves the tracks on. `partial`: the frame was read in regions.
	/// With `mayRetry`, when a marker found on the last frame is missing
	/// inside the frame, nothing is recorded and it returns true: the
	/// caller searches the same frame again whole (plan() then says
	/// whole) and calls update() with that frame's markers.
	bool update(std::vector<Marker> &markers, int width, int height, bool partial, bool mayRetry);
	/// Whether the last update() asked for its frame again, whole.
	bool retrying() const { return retry_; }
	void reset();

	/// A mean absolute difference of the frame's samples from the last
	/// frame's (grey levels) above which the scene changed.
	static constexpr int kSceneChange = 40;

private:
	struct Track {
		int id = -1;
		std::array<Point2f, 4> now{}, before{};
		bool moving = false; /* before holds the frame before */
		int missed = 0;      /* frames in a row it was not found */
	};
	std::array<Point2f, 4> predict(const Track &t) const;
	bool sceneChanged(const ImageView &image);

	int coverFrames_;
	std::mutex lock_;
	std::vector<Track> tracks_, next_;
	std::vector<PixelRect> regions_;
	std::vector<Prediction> predictions_; /* plan()'s, for the front end's thread only */
	std::vector<PixelRect> strips_;       /* the region map's search strips (placeStrips()) */
	/* The search strips: kStrip of the frame's larger side; a mean motion
	 * under kStill pixels a frame along an axis brings nothing in. */
	static constexpr float kStrip = 0.15f, kStill = 0.25f;
	/* The band goes through every map on one round of these, through
	 * the region map alone on the others (placeRegions()). */
	static constexpr int kFullBandRounds = 2;
	Point2f motion_{}; /* the moving tracks' mean motion, pixels a frame */
	bool haveMotion_ = false;
	void placeStrips();
	RegionFrontEnd regionFrontEnd_;
	/* The scene-change test's samples: a fixed grid, whatever the size. */
	static constexpr int kSamplesX = 32, kSamplesY = 24;
	std::array<std::uint8_t, kSamplesX * kSamplesY> samples_{};
	bool haveSamples_ = false;
	int width_ = 0, height_ = 0;
	int sinceWhole_ = 0; /* frames read in regions since the last whole one: the band */
	bool wholeNext_ = true;
	bool retry_ = false;
	std::vector<int> matched_; /* per track, the marker that continues it, or -1 */
	/* Frames a track is kept, its region searched, after it was last found. */
	static constexpr int kKeepMissed = 2;
	/* A predicted outline's margin in its region: kRoom of its side, at
	 * least kMinRoom pixels, plus half its speed. */
	static constexpr float kRoom = 0.12f, kMinRoom = 6.0f;
};

} // namespace frappe::detail
