/* SPDX-License-Identifier: MIT
 *
 * gstfrappecamera.cpp: see gstfrappecamera.h.
 */
#include "gstfrappecamera.h"

#include <exception>

GST_DEBUG_CATEGORY_EXTERN(gst_frappe_detect_debug);
#define GST_CAT_DEFAULT gst_frappe_detect_debug

namespace frappe::gst {

void PoseCamera::fit(GstElement *element, const frappe::Camera *calibration, int width, int height)
{
	fitted_ = false;
	camera_ = {};
	if (!calibration || width <= 0 || height <= 0)
		return;
	if (!calibration->fits(width, height)) {
		GST_ELEMENT_WARNING(element, RESOURCE, SETTINGS,
				    ("The calibration is for %dx%d frames, not %dx%d: no pose", calibration->width,
				     calibration->height, width, height),
				    ("another aspect ratio: a crop or another sensor mode needs its own calibration"));
		return;
	}
	try {
		camera_ = calibration->scaledTo(width, height);
		fitted_ = true;
	} catch (const std::exception &e) {
		GST_ELEMENT_WARNING(element, RESOURCE, SETTINGS, ("The calibration cannot be used: no pose"),
				    ("%s", e.what()));
		return;
	}
	if (calibration->width != 0 && (calibration->width != width || calibration->height != height))
		GST_INFO_OBJECT(element, "calibration of %dx%d scaled to %dx%d: fx %.3f fy %.3f cx %.3f cy %.3f",
				calibration->width, calibration->height, width, height, camera_.matrix[0],
				camera_.matrix[4], camera_.matrix[2], camera_.matrix[5]);
}

void estimatePoses(const std::vector<Marker> &markers, const frappe::MarkerSizes &sizes,
		   const frappe::Camera *camera, Poses &poses)
{
	poses.clear();
	for (const Marker &m : markers) {
		const double size = sizes(m.id);
		std::optional<frappe::MarkerPose> pose;
		if (camera && size > 0.0) {
			try {
				pose = frappe::estimatePose(m.corners, size, *camera);
			} catch (const std::exception &e) {
				/* Not reached: sizes and camera were checked when set. */
				GST_WARNING("marker %d: %s", m.id, e.what());
			}
		}
		poses.push_back(pose);
	}
}

void bestPoses(const Poses &poses, std::vector<std::optional<frappe::Pose>> &best)
{
	best.clear();
	for (const auto &p : poses)
		best.push_back(p ? std::optional<frappe::Pose>(p->pose) : std::nullopt);
}

} /* namespace frappe::gst */
