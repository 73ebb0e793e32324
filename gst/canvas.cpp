/* SPDX-License-Identifier: MIT
 *
 * canvas.cpp: see canvas.h.
 */
#include "canvas.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace frappe::gst {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

double clamp01(double v)
{
	return std::clamp(v, 0.0, 1.0);
}

std::uint8_t mix(std::uint8_t from, std::uint8_t to, double a)
{
	/* Rounded to nearest; from + (to - from) * a stays in [0, 255]. */
	return static_cast<std::uint8_t>(from + (to - from) * a + 0.5);
}

/* Where the drawn layers end, from the centre line. */
double outerEdge(const Pen &pen, unsigned layers)
{
	return pen.width / 2.0 + ((layers & Canvas::Halo) ? std::max(pen.halo, 0.0) : 0.0);
}

double segmentDistance(double px, double py, double x0, double y0, double x1, double y1)
{
	const double dx = x1 - x0, dy = y1 - y0;
	const double len2 = dx * dx + dy * dy;
	double t = len2 > 0.0 ? ((px - x0) * dx + (py - y0) * dy) / len2 : 0.0;
	t = std::clamp(t, 0.0, 1.0);
	const double ex = px - (x0 + t * dx), ey = py - (y0 + t * dy);
	return std::sqrt(ex * ex + ey * ey);
}

} // namespace

Stroke Stroke::segment(double x0, double y0, double x1, double y1)
{
	Stroke s;
	s.x0 = x0;
	s.y0 = y0;
	s.x1 = x1;
	s.y1 = y1;
	return s;
}

Stroke Stroke::circleArc(double cx, double cy, double r, double a0, double a1)
{
	Stroke s;
	s.arc = true;
	s.x0 = cx;
	s.y0 = cy;
	s.r = r;
	s.a0 = a0;
	s.a1 = a1;
	return s;
}

double Stroke::distance(double x, double y) const
{
	if (!arc)
		return segmentDistance(x, y, x0, y0, x1, y1);
	const double dx = x - x0, dy = y - y0;
	double rel = std::atan2(dy, dx) - a0;
	rel -= std::floor(rel / kTwoPi) * kTwoPi;
	if (rel <= a1 - a0)
		return std::abs(std::sqrt(dx * dx + dy * dy) - r);
	const double d0 = segmentDistance(x, y, x0 + r * std::cos(a0), y0 + r * std::sin(a0), x0 + r * std::cos(a0),
					  y0 + r * std::sin(a0));
	const double d1 = segmentDistance(x, y, x0 + r * std::cos(a1), y0 + r * std::sin(a1), x0 + r * std::cos(a1),
					  y0 + r * std::sin(a1));
	return std::min(d0, d1);
}

bool Stroke::xSpan(double yLo, double yHi, double &xLo, double &xHi) const
{
	if (arc) {
		if (y0 + r < yLo || y0 - r > yHi)
			return false;
		xLo = x0 - r;
		xHi = x0 + r;
		return true;
	}
	if (y0 == y1) {
		if (y0 < yLo || y0 > yHi)
			return false;
		xLo = std::min(x0, x1);
		xHi = std::max(x0, x1);
		return true;
	}
	/* The part of the segment between the two rows. */
	double ta = (yLo - y0) / (y1 - y0), tb = (yHi - y0) / (y1 - y0);
	if (ta > tb)
		std::swap(ta, tb);
	ta = std::max(ta, 0.0);
	tb = std::min(tb, 1.0);
	if (ta > tb)
		return false;
	const double xa = x0 + ta * (x1 - x0), xb = x0 + tb * (x1 - x0);
	xLo = std::min(xa, xb);
	xHi = std::max(xa, xb);
	return true;
}

void Stroke::bounds(double &xLo, double &yLo, double &xHi, double &yHi) const
{
	if (arc) {
		xLo = x0 - r;
		xHi = x0 + r;
		yLo = y0 - r;
		yHi = y0 + r;
		return;
	}
	xLo = std::min(x0, x1);
	xHi = std::max(x0, x1);
	yLo = std::min(y0, y1);
	yHi = std::max(y0, y1);
}

bool Path::add(const Stroke &stroke)
{
	if (size_ == kCapacity)
		return false;
	strokes_[size_++] = stroke;
	return true;
}

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
		subX_ = 1 << GST_VIDEO_FORMAT_INFO_W_SUB(frame->info.finfo, 1);
		subY_ = 1 << GST_VIDEO_FORMAT_INFO_H_SUB(frame->info.finfo, 1);
	}
}

void Canvas::blendChroma(int x, int y, double halo, double ink, Yuv c)
{
	const std::ptrdiff_t o = static_cast<std::ptrdiff_t>(y / subY_) * uvStride_ + (x / subX_) * uvPixelStride_;
	u_[o] = mix(mix(u_[o], kHalo.u, halo), c.u, ink);
	v_[o] = mix(mix(v_[o], kHalo.v, halo), c.v, ink);
}

void Canvas::stroke(const Path &path, const Pen &pen, unsigned layers)
{
	const auto strokes = path.strokes();
	if (strokes.empty())
		return;
	/* Past `reach` from the centre line a pixel is untouched. */
	const double reach = outerEdge(pen, layers) + 0.5;

	double by0 = std::numeric_limits<double>::infinity(), by1 = -by0;
	for (const Stroke &s : strokes) {
		double a, b, c, d;
		s.bounds(a, b, c, d);
		if (!std::isfinite(a) || !std::isfinite(b) || !std::isfinite(c) || !std::isfinite(d))
			return;
		by0 = std::min(by0, b);
		by1 = std::max(by1, d);
	}
	/* Whole chroma blocks, so each chroma sample sees all its pixels. */
	const double top = std::clamp(std::floor(by0 - reach), 0.0, static_cast<double>(height_));
	const double bottom = std::clamp(std::ceil(by1 + reach), -1.0, static_cast<double>(height_ - 1));
	const int yStart = static_cast<int>(top) / subY_ * subY_;
	const int yEnd = static_cast<int>(bottom);

	std::array<Active, Path::kCapacity> active;
	/* Runs of chroma blocks a row of blocks needs, disjoint. */
	std::array<std::array<int, 2>, Path::kCapacity> runs;
	for (int by = yStart; by <= yEnd; by += subY_) {
		/* The strokes that reach these rows, and where across. */
		std::size_t n = 0;
		for (const Stroke &s : strokes) {
			double lo, hi;
			if (!s.xSpan(by - reach, by + subY_ - 1 + reach, lo, hi))
				continue;
			lo = std::clamp(std::floor(lo - reach), 0.0, static_cast<double>(width_));
			hi = std::clamp(std::ceil(hi + reach), -1.0, static_cast<double>(width_ - 1));
			if (lo <= hi)
				active[n++] = { &s, lo, hi };
		}
		/* Only the blocks near a stroke: not the inside of an outline. */
		std::sort(active.begin(), active.begin() + static_cast<std::ptrdiff_t>(n),
			  [](const Active &a, const Active &b) { return a.lo < b.lo; });
		std::size_t nRuns = 0;
		for (std::size_t i = 0; i < n; ++i) {
			const int b0 = static_cast<int>(active[i].lo) / subX_, b1 = static_cast<int>(active[i].hi) / subX_;
			if (nRuns && b0 <= runs[nRuns - 1][1] + 1)
				runs[nRuns - 1][1] = std::max(runs[nRuns - 1][1], b1);
			else
				runs[nRuns++] = { b0, b1 };
		}
		for (std::size_t r = 0; r < nRuns; ++r)
			for (int bx = runs[r][0] * subX_; bx <= runs[r][1] * subX_; bx += subX_)
				blendBlock(bx, by, { active.data(), n }, pen, layers);
	}
}

void Canvas::blendBlock(int bx, int by, std::span<const Active> active, const Pen &pen, unsigned layers)
{
	const double inner = pen.width / 2.0;
	const double outer = outerEdge(pen, layers);
	double haloSum = 0.0, inkSum = 0.0;
	int count = 0;
	for (int y = by; y < by + subY_ && y < height_; ++y) {
		for (int x = bx; x < bx + subX_ && x < width_; ++x) {
			double d = std::numeric_limits<double>::infinity();
			for (const Active &a : active)
				if (x >= a.lo && x <= a.hi)
					d = std::min(d, a.stroke->distance(x, y));
			const double h = (layers & Halo) ? clamp01(outer - d + 0.5) : 0.0;
			const double k = (layers & Ink) ? clamp01(inner - d + 0.5) : 0.0;
			++count;
			if (h <= 0.0 && k <= 0.0)
				continue;
			std::uint8_t &p = y_[static_cast<std::ptrdiff_t>(y) * yStride_ + x];
			p = mix(mix(p, kHalo.y, h), pen.ink.y, k);
			haloSum += h;
			inkSum += k;
		}
	}
	if (u_ && (haloSum > 0.0 || inkSum > 0.0))
		blendChroma(bx, by, haloSum / count, inkSum / count, pen.ink);
}

} // namespace frappe::gst
