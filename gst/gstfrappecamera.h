/* SPDX-License-Identifier: MIT
 *
 * gstfrappecamera.h: the camera of frappedetect's pose at the negotiated
 * frame size (a calibration made at another size is scaled, or refused
 * once with a warning), and a frame's poses with per-id marker sizes.
 */
#pragma once

#include <optional>
#include <vector>

#include <gst/gst.h>

#include <frappe/camera.h>
#include <frappe/marker.h>
#include <frappe/pose.h>

namespace frappe::gst {

using Poses = std::vector<std::optional<frappe::MarkerPose>>;

class PoseCamera
{
public:
	/* Fits `calibration` (nullptr: no pose) to frames of width x height:
	 * scaled when it was made at another size of the same aspect ratio
	 * (a GST_INFO line), else no pose and a GST_ELEMENT_WARNING. Called
	 * when the calibration or the frame size changes, so it warns once
	 * for each. */
	void fit(GstElement *element, const frappe::Camera *calibration, int width, int height);
	void reset() { fitted_ = false; }
	/* The camera fitted to the frames; nullptr when there is none. */
	const frappe::Camera *camera() const { return fitted_ ? &camera_ : nullptr; }
	/* The same, or an empty camera (for drawing without poses). */
	const frappe::Camera &fitted() const { return camera_; }

private:
	frappe::Camera camera_;
	bool fitted_ = false;
};

/* The poses of a frame's markers, in their order, into `poses` (its
 * capacity reused from frame to frame): none without a camera, none for a
 * marker whose size is 0 or whose corners give no pose. */
void estimatePoses(const std::vector<Marker> &markers, const frappe::MarkerSizes &sizes,
		   const frappe::Camera *camera, Poses &poses);

/* The best poses alone, for annotateMarkers(). */
void bestPoses(const Poses &poses, std::vector<std::optional<frappe::Pose>> &best);

} /* namespace frappe::gst */
