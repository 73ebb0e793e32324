/* SPDX-License-Identifier: MIT
 *
 * annotate.h: what frappedetect's annotate property draws into a frame:
 * each marker's outline and first corner, its id in an outlined stroke
 * font beside it (never over its code), and its pose axes, straight into
 * the Y (and U/V) planes so the drawing survives any encoder.
 */
#pragma once

#include <array>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include <gst/video/video.h>

#include <frappe/camera.h>
#include <frappe/detector.h>
#include <frappe/pose.h>

#include "canvas.h"

namespace frappe::gst {

/// Colours used by frappedetect (BT.601 video range).
namespace colours {
constexpr Yuv outline{ 235, 44, 21 };     // bright green
constexpr Yuv firstCorner{ 82, 90, 240 }; // red
constexpr Yuv label{ 210, 16, 146 };      // yellow
constexpr Yuv white{ 235, 128, 128 };     // labels on GRAY8
constexpr Yuv axisX{ 82, 90, 240 };       // red
constexpr Yuv axisY{ 145, 54, 34 };       // green
constexpr Yuv axisZ{ 41, 240, 110 };      // blue
} // namespace colours

/// A label's place: its glyph cells (overlay_font.h) from (left, top),
/// `width` x `height` pixels, and the pen; the ink and halo reach
/// pen.width / 2 + pen.halo further.
struct Label {
	double left = 0.0, top = 0.0, width = 0.0, height = 0.0;
	Pen pen;
};

/// Where annotateMarkers() writes `text` for the marker at `corners` in a
/// frame `frameWidth` x `frameHeight`: a cap height of 0.3 marker sides,
/// between max(12, frame height / 40) and frame height / 8 pixels; centred
/// above the marker's bounding box, clear of its outline, else below it,
/// else right or left of it, moved along that side to be inside the frame;
/// the first such place clear of the markers in `avoid` (their bounding
/// boxes and outlines), else the first inside the frame. Only a marker too
/// big for all four leaves its label on it.
Label placeLabel(const std::array<Point2f, 4> &corners, std::string_view text, int frameWidth, int frameHeight,
		 Yuv ink, std::span<const Marker> avoid = {});

/// A bundle's pose to draw: its frame's axes, `axis` metres long.
struct BundleAxes {
	const Pose *pose = nullptr;
	double axis = 0.0;
};

/// Draws the frame's markers: outlines, first corners, ids and, where
/// `poses` has one and `sizes` a positive side for the id, the axes (x red,
/// y green, z blue, half a side long) projected through `camera`; with
/// `bundle.pose`, the bundle frame's axes too (as thick as the largest
/// marker's). Ids are yellow on colour formats, white on GRAY8, outlined in
/// black.
void annotateMarkers(GstVideoFrame *frame, const Result &result, const std::vector<std::optional<Pose>> &poses,
		     const MarkerSizes &sizes, const Camera &camera, const BundleAxes &bundle = {});

} // namespace frappe::gst
