// SPDX-License-Identifier: MIT
// frappe/detector.h: the Frappe detector.
#pragma once

#include "frappe/export.h"

#include <array>
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

/// Everything one detect() call produced. Owned by the Detector and
/// overwritten by the next call on the same slot.
struct Result {
	std::vector<Marker> markers;
	StageTimes times;
	float scale = 1.0f;     ///< resolution the frame was traced at
	int candidates = 0;     ///< quadrilaterals that reached decoding
};

/// Finds markers of one dictionary in 8-bit luma images.
///
/// One instance is used by one thread at a time; separate instances share
/// nothing. After the first frame of a given size, detect() allocates no
/// memory (result vectors keep their capacity).
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

	/// Frames in flight at once in staged use.
	static constexpr int kSlots = 3;

	/// Staged use for pipelining: each frame goes through a slot (0 ..
	/// kSlots-1). runFrontEnd() fills the slot's edge map; runBackEnd() then
	/// traces it and refines, warps and decodes. Stages of different slots
	/// may run on different threads at once; the image must stay valid
	/// until the slot's back end (or runFinish()) returns. In AScale mode
	/// the scale of a frame comes from the last frame finished before its
	/// front end started. Throws std::invalid_argument for a bad slot.
	void runFrontEnd(const ImageView &image, int slot);
	const Result &runBackEnd(const ImageView &image, int slot);

	/// runBackEnd() in two halves, for a three-stage pipeline: the contour
	/// trace, then refinement, warp and decoding.
	void runTrace(int slot);
	const Result &runFinish(const ImageView &image, int slot);

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

	/// The edge map of a slot's last frame, for visualisation and tests.
	const EdgeMap &edgeMap(int slot = 0) const;

	/// Forgets what AScale learned from earlier frames.
	void reset();

	const Config &config() const;
	const Dictionary &dictionary() const;
	int maxHamming() const;
	FrontEndParams frontEndParams() const;

private:
	struct Impl;
	std::unique_ptr<Impl> impl_;
};

} // namespace frappe
