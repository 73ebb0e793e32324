// SPDX-License-Identifier: MIT
// frappe/bundle.h: one pose from many markers of a known rigid set (a board,
// a bundle, a carrier with a marker on each leg). Far steadier than any one
// marker's: a small marker seen face on can flip its tilt; a set spread over
// the image cannot.
//
// Bundle frame: the file's. Each marker's corners in it, in Marker::corners'
// order (top-left, top-right, bottom-right, bottom-left of the marker in its
// canonical orientation); for a marker placed by a pose, its own frame is
// frappe/pose.h's (x right, y up, z out of the marker).
//
// Since: 0.3
#pragma once

#include "frappe/export.h"

#include <array>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "frappe/camera.h"
#include "frappe/marker.h"
#include "frappe/pose.h"

namespace frappe {

struct FRAPPE_EXPORT BundleMarker {
	int id = -1;
	double size = 0.0; ///< side, metres
	std::array<std::array<double, 3>, 4> corners{}; ///< in the bundle frame, metres
};

struct FRAPPE_EXPORT Bundle {
	std::string name;
	std::vector<BundleMarker> markers; ///< by id, each id once

	/// The marker of `id`, or nullptr.
	const BundleMarker *find(int id) const;
	/// A marker of side `size` whose centre sits at `position` in the
	/// bundle frame, turned by the unit quaternion (qw, qx, qy, qz) (its
	/// frame to the bundle's), as apriltag_ros's bundles give them.
	static BundleMarker placed(int id, double size, std::array<double, 3> position,
				   std::array<double, 4> quaternion);
	/// OpenCV's GridBoard: rows x cols markers of side `size` with `gap`
	/// between them, ids row-major from `first_id` at the top-left; the
	/// origin at the board's bottom-left corner, x right, y up, z out of
	/// the board (as cv::aruco::GridBoard, so poses compare with
	/// estimatePoseBoard's). Throws std::invalid_argument for a count
	/// under 1, a size not positive or a gap negative.
	static Bundle grid(int rows, int cols, double size, double gap, int first_id = 0);
};

/// Reads a bundle, told by its content:
/// - apriltag_ros's tags.yaml: `tag_bundles: [{name: ..., layout: [{id:
///   0, size: 0.05, x: .., y: .., z: .., qw: .., qx: .., qy: .., qz: ..},
///   ...]}]` (the first bundle; standalone_tags are ignored);
/// - a grid board: `board: grid`, `rows`, `cols`, `size`, `gap` (metres),
///   optional `first_id` (Bundle::grid()).
/// Throws std::runtime_error when the file cannot be read and
/// std::invalid_argument naming the file and line when it is no bundle (a
/// missing or unknown key, a number that does not parse, a quaternion far
/// from unit length, an id given twice, no markers).
FRAPPE_EXPORT Bundle loadBundle(const std::string &path);
/// The same from a file's text; `origin` names it in messages.
FRAPPE_EXPORT Bundle parseBundle(std::string_view text, std::string_view origin = "bundle");

/// The bundle's pose from the markers seen of it.
struct FRAPPE_EXPORT BundlePose {
	Pose pose;               ///< bundle frame to camera frame; error: RMS over the used corners, pixels
	std::vector<int> used;     ///< ids whose corners made the pose
	std::vector<int> rejected; ///< ids seen but left out: corners that disagree (a marker moved, a wrong read)
};

/// One pose from every marker of `bundle` among `markers` (distorted
/// pixels, as the detector reports them): each marker's own two poses
/// (IPPE) as starting points, the one most markers agree with kept, then
/// Levenberg-Marquardt over every agreeing corner through the lens model;
/// markers whose corners then lie further than max(2 px, 4% of their side)
/// RMS are rejected and the rest refined again. An id seen twice is
/// rejected. std::nullopt when no marker of the bundle is seen or none
/// gives a pose. Throws std::invalid_argument for a camera that fails
/// Camera::validate().
FRAPPE_EXPORT std::optional<BundlePose> estimateBundlePose(const Bundle &bundle, std::span<const Marker> markers,
							   const Camera &camera);

/// estimateBundlePose()'s working memory, for a caller that poses a bundle
/// every frame (the GStreamer element): kept between calls, its vectors
/// keep their capacity, so once they have grown to the most markers seen a
/// pose allocates nothing. One per thread.
class FRAPPE_EXPORT BundleScratch {
public:
	BundleScratch();
	~BundleScratch();
	BundleScratch(BundleScratch &&) noexcept;
	BundleScratch &operator=(BundleScratch &&) noexcept;
	struct Impl; ///< the library's
	Impl &impl() { return *impl_; }

private:
	std::unique_ptr<Impl> impl_;
};

/// The same pose into `out` (its vectors' capacity reused) with `scratch`'s
/// memory: true with a pose, false where the other returns std::nullopt
/// (`out` then holds no pose: its vectors are empty but for `rejected`).
/// The same results, to the bit.
FRAPPE_EXPORT bool estimateBundlePose(const Bundle &bundle, std::span<const Marker> markers, const Camera &camera,
				      BundlePose &out, BundleScratch &scratch);

} // namespace frappe
