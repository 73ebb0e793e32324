/* SPDX-License-Identifier: MIT
 *
 * canvas.h: anti-aliased strokes with a dark halo, drawn straight into the
 * planes of a mapped 8-bit YUV/GRAY frame so the drawing survives any
 * encoder. A stroke is a segment or a circular arc with round ends; its
 * coverage of a pixel comes from the pixel centre's distance to it, so one
 * path draws at any size, sharp and without a bitmap.
 */
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include <gst/video/video.h>

namespace frappe::gst {

/// A colour as 8-bit Y, U, V (U and V are ignored on GRAY8).
struct Yuv {
	std::uint8_t y, u, v;
};

/// The halo's colour: video-range black.
constexpr Yuv kHalo{ 16, 128, 128 };

/// The centre line of a stroke: a segment from (x0, y0) to (x1, y1) (a dot
/// when they coincide), or an arc of radius r about (x0, y0) from angle a0
/// to a1 > a0 (radians from +x towards +y, i.e. clockwise on screen).
struct Stroke {
	bool arc = false;
	double x0 = 0.0, y0 = 0.0;
	double x1 = 0.0, y1 = 0.0;
	double r = 0.0, a0 = 0.0, a1 = 0.0;

	static Stroke segment(double x0, double y0, double x1, double y1);
	static Stroke circleArc(double cx, double cy, double r, double a0, double a1);

	/// Distance from (x, y) to the centre line.
	double distance(double x, double y) const;
	/// The x range of the centre line's points whose y is in [yLo, yHi];
	/// false when there is none. An arc answers with its circle's range.
	bool xSpan(double yLo, double yHi, double &xLo, double &xHi) const;
	/// The centre line's bounding box (an arc: its circle's).
	void bounds(double &xLo, double &yLo, double &xHi, double &yHi) const;
};

/// Strokes drawn as one shape: where they overlap the halo of one never
/// covers the ink of another. Fixed capacity, so drawing allocates nothing.
class Path {
public:
	static constexpr std::size_t kCapacity = 64;

	/// False (and the stroke dropped) when the path is full.
	bool add(const Stroke &stroke);
	std::span<const Stroke> strokes() const { return { strokes_.data(), size_ }; }

private:
	std::array<Stroke, kCapacity> strokes_{};
	std::size_t size_ = 0;
};

/// How a path is drawn: ink `width` pixels wide, inside a halo `halo`
/// pixels wide on each side.
struct Pen {
	double width = 1.0;
	double halo = 1.0;
	Yuv ink{ 235, 128, 128 };
};

/// Draws into the luma plane and, when present, the chroma planes of a frame
/// mapped for writing (GRAY8, I420, YV12, NV12, NV21).
class Canvas {
public:
	enum Layers : unsigned { Halo = 1, Ink = 2, Both = 3 };

	explicit Canvas(GstVideoFrame *frame);

	int width() const { return width_; }
	int height() const { return height_; }
	/// Whether the frame has chroma planes, i.e. whether colours show.
	bool colour() const { return u_ != nullptr; }

	/// Blends the path's halo and/or ink into the frame. Separate shapes
	/// that meet (the four sides of an outline) are drawn halos first,
	/// then inks, so no halo cuts into a neighbour's ink.
	void stroke(const Path &path, const Pen &pen, unsigned layers = Both);

private:
	/// A stroke that reaches a row of blocks, between columns lo and hi.
	struct Active {
		const Stroke *stroke;
		double lo, hi;
	};
	/// Blends one chroma block's pixels (subX_ x subY_ from (bx, by)) and
	/// its chroma sample.
	void blendBlock(int bx, int by, std::span<const Active> active, const Pen &pen, unsigned layers);
	void blendChroma(int x, int y, double halo, double ink, Yuv c);

	std::uint8_t *y_ = nullptr;
	int yStride_ = 0;
	std::uint8_t *u_ = nullptr;
	std::uint8_t *v_ = nullptr;
	int uvStride_ = 0;
	int uvPixelStride_ = 1; ///< 1 for planar, 2 for NV12/NV21
	int subX_ = 1;          ///< luma pixels per chroma sample, across
	int subY_ = 1;          ///< and down
	int width_ = 0;
	int height_ = 0;
};

} // namespace frappe::gst
