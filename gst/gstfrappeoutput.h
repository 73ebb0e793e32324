/* SPDX-License-Identifier: MIT
 *
 * gstfrappeoutput.h: what frappedetect makes of a frame's markers: the
 * metas on its buffer, the `frappedetect` element message and the `stats`
 * structure. The element's documentation block describes their fields.
 */
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <gst/gst.h>

#include <frappe/bundle.h>
#include <frappe/detector.h>

#include "gstfrappecamera.h"

namespace frappe::gst {

/* A GstFrappeMarkerMeta and a "fiducial" GstVideoRegionOfInterestMeta per
 * marker, on a writable buffer of a frame of width x height; `tracking`:
 * the detector ran Mode::Track (the metas' tracking and tracked). */
void attachMarkerMetas(GstBuffer *buffer, gint width, gint height, const Result &result, const Poses &poses,
		       const char *dictionary, bool tracking);

/* A frame's bundle pose: both set when bundle-file is and the bundle gave a
 * pose, else pose nullptr (no meta, no message field). */
struct BundleOutput {
	const frappe::Bundle *bundle = nullptr;
	const frappe::BundlePose *pose = nullptr;
};

/* A GstFrappeBundleMeta on a writable buffer when `bundle` has a pose. */
void attachBundleMeta(GstBuffer *buffer, const BundleOutput &bundle);

/* The `frappedetect` element message's structure; running and stream time
 * come from `segment` when it is in time; a `bundle` structure when
 * `bundle` has a pose. */
GstStructure *frameMessage(GstBuffer *buffer, const GstSegment &segment, const Result &result, const Poses &poses,
			   const char *dictionary, const BundleOutput &bundle = {});

/* The `stats` property's structure for the last frame; `copied-bytes`
 * is what the backend copied of it before reading (0: read in place),
 * `overlap` what the pipeline overlapped (none, frames, stages),
 * `qpu-contexts` the QPU contexts the element opened since it started. */
GstStructure *statsStructure(guint64 frames, const Result &result, double poseMs, const char *backend,
			     bool pipelined, const char *overlap, guint qpuContexts);

/* A frame full of squares (a tiled wall, a dot grid) had more candidates
 * than frappe::Config::max_candidates, and markers among those dropped may
 * be missed: a GST_ELEMENT_WARNING the first time in a stream (`warned`),
 * a debug line on every such frame. */
void reportDroppedCandidates(GstElement *element, guint64 frame, const Result &result, bool &warned);

/* Sums of the stage times over 100 frames, for one INFO line per 100
 * frames: GST_DEBUG=frappedetect:4 shows the speed without any tooling. */
class StatsWindow
{
public:
	/* Adds frame number `frames` (from 1); at every 100th, returns the
	 * average ms per frame of each stage, the pose and the total, and
	 * starts again. */
	std::optional<std::string> add(guint64 frames, const Result &result, double poseMs);
	void reset();

private:
	StageTimes times_;
	double poseMs_ = 0.0;
};

} /* namespace frappe::gst */
