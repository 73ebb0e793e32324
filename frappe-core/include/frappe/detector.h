// SPDX-License-Identifier: MIT
// frappe/detector.h: the Frappe detector.
#pragma once

#include "frappe/export.h"

#include <array>
#include <cstddef>
#include <memory>
#include <string_view>
#include <vector>

#include "frappe/candidate_warp.h"
#include "frappe/config.h"
#include "frappe/dictionary.h"
#include "frappe/edge_map.h"
#include "frappe/image.h"
#include "frappe/marker.h"

namespace frappe {

namespace detail {
class DetectorStages;
}

/// The stages of the paper's Algorithm 1, in order.
enum class Stage {
	AdaptiveScale,
	FrontEnd,   ///< Sobel, non-maximum suppression, threshold, Shi-Tomasi, tile mask
	Trace,      ///< Suzuki border following, corner clustering, candidate checks
	Refine,     ///< sub-pixel corners on the full-resolution image
	Warp,       ///< perspective warp to the sample grid
	Decode,     ///< binarise and Hamming decode over four rotations
	Count,
};
constexpr int kStageCount = static_cast<int>(Stage::Count);

/// Short lowercase name of a stage ("front_end", "trace", ...).
FRAPPE_EXPORT std::string_view stageName(Stage stage);

/// Wall-clock milliseconds spent in each stage for one frame.
struct StageTimes {
	std::array<double, kStageCount> ms{};
	double total_ms = 0.0;
	double &operator[](Stage s) { return ms[static_cast<int>(s)]; }
	double operator[](Stage s) const { return ms[static_cast<int>(s)]; }
};

/// Everything one detect() call produced. Owned by the Detector (or the
/// Pipeline) and overwritten by its next frame.
struct Result {
	std::vector<Marker> markers;
	StageTimes times;
	float scale = 1.0f;     ///< resolution the frame was traced at
	int candidates = 0;     ///< quadrilaterals that reached decoding, each once: at most Config::max_candidates
	/// Candidate outlines the trace found beyond Config::max_candidates and
	/// left unread (the largest of those its quick read found least
	/// promising: Config::max_candidates): 0 unless the frame is full of
	/// squares (a tiled wall, a dot grid). Markers among them are missed; a caller may report it as a
	/// warning.
	int candidates_dropped = 0;
	/// Bytes of the frame its front end copied before reading it
	/// (FrontEnd::lastCopyBytes() of the detector that ran it): 0 when
	/// the frame was read in place. Carried here because in a Pipeline
	/// that detector may already be running a later frame.
	std::size_t copy_bytes = 0;
	/// Bytes of the frame the front end read: width x height (each pixel
	/// once) when it read the whole frame; in Mode::Track, on a frame read
	/// in regions, the regions' with the margins their filters need.
	std::size_t bytes_read = 0;
	/// Whether the whole frame was searched: always, but in Mode::Track,
	/// where only the first frame, a scene change, a marker lost or a
	/// frame whose regions would cover most of it is.
	bool whole_frame = true;
};

/// The longest image side detect() accepts (it throws
/// std::invalid_argument beyond, whatever Config::max_pixels allows): the
/// tracer's coordinates are 16-bit.
constexpr int kMaxImageSide = 1 << 15;

/// Finds markers of one dictionary in 8-bit luma images.
///
/// One instance is used by one thread at a time; separate instances share
/// nothing. After the first frame of a given size, detect() allocates no
/// memory (result vectors keep their capacity). To overlap the frames of a
/// stream on several threads, use a Pipeline.
class FRAPPE_EXPORT Detector {
public:
	/// Throws std::invalid_argument when the dictionary is unknown or a
	/// parameter is out of range; the message says which and why.
	explicit Detector(const Config &config);
	~Detector();
	Detector(Detector &&) noexcept;
	Detector &operator=(Detector &&) noexcept;
	Detector(const Detector &) = delete;
	Detector &operator=(const Detector &) = delete;

	/// Detects markers in one frame. Throws std::invalid_argument for a null
	/// image with a non-zero size, negative sizes, or a stride smaller than
	/// the width. Images too small to hold a marker give no markers.
	const Result &detect(const ImageView &image);

	/// Throws std::invalid_argument for an image detect() would refuse.
	void checkImage(const ImageView &image) const;

	/// Replaces the front end (for example with the VC4 one). The default
	/// is the CPU front end.
	void setFrontEnd(std::unique_ptr<FrontEnd> frontEnd);
	const FrontEnd &frontEnd() const;

	/// Hands the perspective warp to `warper` (for example the QPUs): the
	/// frame's candidates are then refined first and warped in one batch.
	/// nullptr (the default) warps each candidate on the CPU as it comes.
	void setWarper(std::unique_ptr<CandidateWarper> warper);
	/// The batch warper, or nullptr.
	const CandidateWarper *warper() const;

	/// The edge map of the last frame detect() ran, for visualisation and
	/// tests.
	const EdgeMap &edgeMap() const;

	/// Forgets what AScale and Track learned from earlier frames: the next
	/// frame is searched whole.
	void reset();

	const Config &config() const;
	/// Config::custom_dictionary when set (kept alive by the Detector),
	/// else the built-in named by Config::dictionary.
	const Dictionary &dictionary() const;
	int maxHamming() const;
	/// The front end's parameters as configured; a frame's light floor
	/// lies between half of this one and it (Config::light_floor_noise).
	FrontEndParams frontEndParams() const;

private:
	/* Pipeline runs the stages of different frames on different threads. */
	friend class detail::DetectorStages;
	struct Impl;
	std::unique_ptr<Impl> impl_;
};

} // namespace frappe
