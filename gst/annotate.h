/* SPDX-License-Identifier: MIT
 *
 * annotate.h: drawing marker outlines, ids and pose axes straight into the
 * planes of a mapped 8-bit YUV/GRAY frame, so the drawing survives any
 * encoder. No OpenCV, a tiny built-in digit font.
 */
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <gst/video/video.h>

#include <frappe/camera.h>
#include <frappe/detector.h>
#include <frappe/pose.h>

namespace frappe::gst {

/// A colour as 8-bit Y, U, V (U and V are ignored on GRAY8).
struct Yuv {
	std::uint8_t y, u, v;
};

/// Draws into the luma plane and, when present, the chroma planes of a frame
/// mapped for writing (GRAY8, I420, YV12, NV12, NV21).
class Canvas {
public:
	explicit Canvas(GstVideoFrame *frame);

	int width() const { return width_; }
	int height() const { return height_; }

	void plot(int x, int y, Yuv c);
	void fillRect(int x0, int y0, int x1, int y1, Yuv c);
	/// A line of the given thickness (pixels), clipped to the frame.
	void line(double x0, double y0, double x1, double y1, int thickness, Yuv c);
	/// A line with a dark halo one pixel wide on each side, visible on any
	/// background.
	void haloLine(double x0, double y0, double x1, double y1, int thickness, Yuv c);
	/// Decimal digits of `value` centred on (cx, cy), `cell` pixels per font
	/// cell (the font is 3x5 cells), white on a black box.
	void number(int value, double cx, double cy, int cell);

private:
	std::uint8_t *y_ = nullptr;
	int yStride_ = 0;
	std::uint8_t *u_ = nullptr;
	std::uint8_t *v_ = nullptr;
	int uvStride_ = 0;
	int uvPixelStride_ = 1; ///< 1 for planar, 2 for NV12/NV21
	int width_ = 0;
	int height_ = 0;
};

/// Colours used by frappedetect.
namespace colours {
constexpr Yuv outline{ 235, 44, 21 };   // bright green
constexpr Yuv firstCorner{ 82, 90, 240 }; // red
constexpr Yuv black{ 16, 128, 128 };
constexpr Yuv white{ 235, 128, 128 };
constexpr Yuv axisX{ 82, 90, 240 };   // red
constexpr Yuv axisY{ 145, 54, 34 };   // green
constexpr Yuv axisZ{ 41, 240, 110 };  // blue
} // namespace colours

/// What frappedetect's annotate property draws for a frame's markers:
/// outlines, first corners, ids and, where `poses` has one, the axes of a
/// marker of its side in `sizes` (metres).
void annotateMarkers(GstVideoFrame *frame, const Result &result,
		     const std::vector<std::optional<frappe::Pose>> &poses, const frappe::MarkerSizes &sizes,
		     const frappe::Camera &camera);

} // namespace frappe::gst
