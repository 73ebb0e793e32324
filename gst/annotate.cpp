/* SPDX-License-Identifier: MIT
 *
 * annotate.cpp: see annotate.h.
 */
#include "annotate.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace frappe::gst {

namespace {

/* 3x5 digits, one row per byte, bit 2 = left column. */
constexpr std::array<std::array<std::uint8_t, 5>, 10> kDigits{ {
	{ 7, 5, 5, 5, 7 }, /* 0 */
	{ 2, 6, 2, 2, 7 }, /* 1 */
	{ 7, 1, 7, 4, 7 }, /* 2 */
	{ 7, 1, 3, 1, 7 }, /* 3 */
	{ 5, 5, 7, 1, 1 }, /* 4 */
	{ 7, 4, 7, 1, 7 }, /* 5 */
	{ 7, 4, 7, 5, 7 }, /* 6 */
	{ 7, 1, 2, 2, 2 }, /* 7 */
	{ 7, 5, 7, 5, 7 }, /* 8 */
	{ 7, 5, 7, 1, 7 }, /* 9 */
} };

} // namespace

Canvas::Canvas(GstVideoFrame *frame)
{
	width_ = GST_VIDEO_FRAME_COMP_WIDTH(frame, 0);
	height_ = GST_VIDEO_FRAME_COMP_HEIGHT(frame, 0);
	y_ = static_cast<std::uint8_t *>(GST_VIDEO_FRAME_COMP_DATA(frame, 0));
	yStride_ = GST_VIDEO_FRAME_COMP_STRIDE(frame, 0);
	if (GST_VIDEO_FRAME_N_COMPONENTS(frame) >= 3) {
		u_ = static_cast<std::uint8_t *>(GST_VIDEO_FRAME_COMP_DATA(frame, 1));
		v_ = static_cast<std::uint8_t *>(GST_VIDEO_FRAME_COMP_DATA(frame, 2));
		uvStride_ = GST_VIDEO_FRAME_COMP_STRIDE(frame, 1);
		uvPixelStride_ = GST_VIDEO_FRAME_COMP_PSTRIDE(frame, 1);
	}
}

void Canvas::plot(int x, int y, Yuv c)
{
	if (x < 0 || y < 0 || x >= width_ || y >= height_)
		return;
	y_[static_cast<std::ptrdiff_t>(y) * yStride_ + x] = c.y;
	if (u_) {
		/* All chroma formats accepted here are subsampled 2x2. */
		const std::ptrdiff_t o = static_cast<std::ptrdiff_t>(y / 2) * uvStride_ + (x / 2) * uvPixelStride_;
		u_[o] = c.u;
		v_[o] = c.v;
	}
}

void Canvas::fillRect(int x0, int y0, int x1, int y1, Yuv c)
{
	x0 = std::max(x0, 0);
	y0 = std::max(y0, 0);
	x1 = std::min(x1, width_ - 1);
	y1 = std::min(y1, height_ - 1);
	for (int y = y0; y <= y1; ++y)
		for (int x = x0; x <= x1; ++x)
			plot(x, y, c);
}

void Canvas::line(double x0, double y0, double x1, double y1, int thickness, Yuv c)
{
	if (!std::isfinite(x0) || !std::isfinite(y0) || !std::isfinite(x1) || !std::isfinite(y1))
		return;
	/* Keep absurd projections (points behind the camera) from looping for
	 * ever: clamp to a generous box around the frame. */
	const double lim = 4.0 * std::max(width_, height_) + 64.0;
	x0 = std::clamp(x0, -lim, lim);
	y0 = std::clamp(y0, -lim, lim);
	x1 = std::clamp(x1, -lim, lim);
	y1 = std::clamp(y1, -lim, lim);

	const double dx = x1 - x0, dy = y1 - y0;
	const int steps = std::max(1, static_cast<int>(std::ceil(std::max(std::abs(dx), std::abs(dy)))));
	const int lo = -(thickness - 1) / 2, hi = thickness / 2;
	for (int i = 0; i <= steps; ++i) {
		const int x = static_cast<int>(std::lround(x0 + dx * i / steps));
		const int y = static_cast<int>(std::lround(y0 + dy * i / steps));
		if (x + hi < 0 || y + hi < 0 || x + lo >= width_ || y + lo >= height_)
			continue;
		fillRect(x + lo, y + lo, x + hi, y + hi, c);
	}
}

void Canvas::haloLine(double x0, double y0, double x1, double y1, int thickness, Yuv c)
{
	line(x0, y0, x1, y1, thickness + 2, colours::black);
	line(x0, y0, x1, y1, thickness, c);
}

void Canvas::number(int value, double cx, double cy, int cell)
{
	const std::string text = std::to_string(value);
	cell = std::max(cell, 1);
	const int n = static_cast<int>(text.size());
	const int w = (4 * n - 1) * cell, h = 5 * cell;
	const int left = static_cast<int>(std::lround(cx)) - w / 2;
	const int top = static_cast<int>(std::lround(cy)) - h / 2;
	fillRect(left - cell, top - cell, left + w + cell - 1, top + h + cell - 1, colours::black);
	for (int i = 0; i < n; ++i) {
		const char ch = text[static_cast<std::size_t>(i)];
		if (ch < '0' || ch > '9') {
			/* A minus sign. */
			fillRect(left + 4 * i * cell, top + 2 * cell, left + (4 * i + 3) * cell - 1,
				 top + 3 * cell - 1, colours::white);
			continue;
		}
		const auto &glyph = kDigits[static_cast<std::size_t>(ch - '0')];
		for (int r = 0; r < 5; ++r)
			for (int col = 0; col < 3; ++col)
				if (glyph[static_cast<std::size_t>(r)] & (4 >> col))
					fillRect(left + (4 * i + col) * cell, top + r * cell,
						 left + (4 * i + col + 1) * cell - 1, top + (r + 1) * cell - 1,
						 colours::white);
	}
}

void annotateMarkers(GstVideoFrame *frame, const Result &result,
		     const std::vector<std::optional<frappe::Pose>> &poses, const frappe::MarkerSizes &sizes,
		     const frappe::Camera &camera)
{
	Canvas canvas(frame);
	for (std::size_t i = 0; i < result.markers.size(); ++i) {
		const Marker &m = result.markers[i];
		double side = 0.0;
		for (int k = 0; k < 4; ++k) {
			const auto a = m.corners[static_cast<std::size_t>(k)];
			const auto b = m.corners[static_cast<std::size_t>((k + 1) & 3)];
			side += std::hypot(a.x - b.x, a.y - b.y) / 4.0;
		}
		const int thickness = std::max(1, static_cast<int>(side / 32.0));
		for (int k = 0; k < 4; ++k) {
			const auto a = m.corners[static_cast<std::size_t>(k)];
			const auto b = m.corners[static_cast<std::size_t>((k + 1) & 3)];
			canvas.haloLine(a.x, a.y, b.x, b.y, thickness, colours::outline);
		}
		/* The first corner (top-left in the marker's orientation). */
		const int r = std::max(2, static_cast<int>(side / 24.0));
		const int cx = static_cast<int>(std::lround(m.corners[0].x));
		const int cy = static_cast<int>(std::lround(m.corners[0].y));
		canvas.fillRect(cx - r - 1, cy - r - 1, cx + r + 1, cy + r + 1, colours::black);
		canvas.fillRect(cx - r, cy - r, cx + r, cy + r, colours::firstCorner);

		if (poses[i]) {
			const double h = sizes(m.id) / 2.0;
			const std::array<std::array<double, 3>, 4> axes{
				{ { 0, 0, 0 }, { h, 0, 0 }, { 0, h, 0 }, { 0, 0, h } }
			};
			const auto p = frappe::projectPoints(axes, *poses[i], camera);
			if (p.size() == 4) {
				canvas.haloLine(p[0].x, p[0].y, p[1].x, p[1].y, thickness, colours::axisX);
				canvas.haloLine(p[0].x, p[0].y, p[2].x, p[2].y, thickness, colours::axisY);
				canvas.haloLine(p[0].x, p[0].y, p[3].x, p[3].y, thickness, colours::axisZ);
			}
		}

		/* The id between the centre and the first corner: the quadrant of
		 * the marker frame (-x, +y) that the axes leave free. */
		double mx = 0.0, my = 0.0;
		for (const auto &c : m.corners) {
			mx += c.x / 4.0;
			my += c.y / 4.0;
		}
		mx = (mx * 3.0 + m.corners[0].x * 2.0) / 5.0;
		my = (my * 3.0 + m.corners[0].y * 2.0) / 5.0;
		canvas.number(m.id, mx, my, std::max(1, static_cast<int>(side / 24.0)));
	}
}

} // namespace frappe::gst
