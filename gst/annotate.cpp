/* SPDX-License-Identifier: MIT
 *
 * annotate.cpp: see annotate.h.
 */
#include "annotate.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "overlay_font.h"

namespace frappe::gst {

namespace {

struct Box {
	double x0, y0, x1, y1;
};

Box cornerBox(const std::array<Point2f, 4> &corners)
{
	Box b{ corners[0].x, corners[0].y, corners[0].x, corners[0].y };
	for (const Point2f &c : corners) {
		b.x0 = std::min<double>(b.x0, c.x);
		b.y0 = std::min<double>(b.y0, c.y);
		b.x1 = std::max<double>(b.x1, c.x);
		b.y1 = std::max<double>(b.y1, c.y);
	}
	return b;
}

double meanSide(const std::array<Point2f, 4> &corners)
{
	double side = 0.0;
	for (std::size_t k = 0; k < 4; ++k) {
		const Point2f a = corners[k], b = corners[(k + 1) & 3];
		side += std::hypot(a.x - b.x, a.y - b.y) / 4.0;
	}
	return side;
}

/* The outline's pen: thicker on bigger markers, as before. */
Pen outlinePen(double side)
{
	Pen pen;
	pen.width = std::max(1.5, side / 32.0);
	pen.halo = std::max(1.0, pen.width / 2.0);
	pen.ink = colours::outline;
	return pen;
}

/* How far a pen's ink and halo reach from the centre line. */
double reach(const Pen &pen)
{
	return pen.width / 2.0 + pen.halo;
}

/* Draws the strokes of all `paths` halos first, then inks: they meet, and
 * no halo may cut into a neighbour's ink. */
void strokeTogether(Canvas &canvas, std::span<const Path> paths, std::span<const Pen> pens)
{
	for (std::size_t i = 0; i < paths.size(); ++i)
		canvas.stroke(paths[i], pens[i], Canvas::Halo);
	for (std::size_t i = 0; i < paths.size(); ++i)
		canvas.stroke(paths[i], pens[i], Canvas::Ink);
}

void drawAxes(Canvas &canvas, const Pose &pose, double size, const Camera &camera, double side)
{
	const double h = size / 2.0;
	const std::array<std::array<double, 3>, 4> points{ { { 0, 0, 0 }, { h, 0, 0 }, { 0, h, 0 }, { 0, 0, h } } };
	std::array<Point2f, 4> p;
	projectPoints(points, pose, camera, p);
	if (!std::isfinite(p[0].x) || !std::isfinite(p[0].y))
		return;
	const std::array<Yuv, 3> inks{ colours::axisX, colours::axisY, colours::axisZ };
	std::array<Path, 3> paths;
	std::array<Pen, 3> pens;
	for (std::size_t a = 0; a < 3; ++a) {
		pens[a].width = std::max(2.0, side / 20.0);
		pens[a].halo = std::max(1.0, pens[a].width / 3.0);
		pens[a].ink = inks[a];
		/* An end behind the camera: no axis. */
		if (std::isfinite(p[a + 1].x) && std::isfinite(p[a + 1].y))
			paths[a].add(Stroke::segment(p[0].x, p[0].y, p[a + 1].x, p[a + 1].y));
	}
	strokeTogether(canvas, paths, pens);
}

} // namespace

Label placeLabel(const std::array<Point2f, 4> &corners, std::string_view text, int frameWidth, int frameHeight,
		 Yuv ink, std::span<const Marker> avoid)
{
	const double side = meanSide(corners);
	const double minHeight = std::max(12.0, frameHeight / 40.0);
	const double maxHeight = std::max(minHeight, frameHeight / 8.0);

	Label l;
	l.height = std::clamp(0.3 * side, minHeight, maxHeight);
	l.width = textWidth(text, l.height);
	l.pen = textPen(l.height, ink);

	/* Ink and halo around the cells; the gap keeps them off the outline's. */
	const double margin = reach(l.pen);
	const double gap = margin + reach(outlinePen(side)) + 1.0;
	const Box b = cornerBox(corners);
	const double W = frameWidth, H = frameHeight;

	/* Above, below, right, left of the marker. */
	const double cx = (b.x0 + b.x1 - l.width) / 2.0, cy = (b.y0 + b.y1 - l.height) / 2.0;
	const std::array<std::array<double, 2>, 4> spots{ {
		{ cx, b.y0 - gap - l.height },
		{ cx, b.y1 + gap },
		{ b.x1 + gap, cy },
		{ b.x0 - gap - l.width, cy },
	} };
	auto inside = [&](double left, double top) {
		return left - margin >= 0.0 && left + l.width + margin <= W - 1.0 && top - margin >= 0.0 &&
		       top + l.height + margin <= H - 1.0;
	};
	auto clear = [&](double left, double top) {
		for (const Marker &m : avoid) {
			const Box o = cornerBox(m.corners);
			const double r = reach(outlinePen(meanSide(m.corners))) + margin;
			if (left < o.x1 + r && left + l.width > o.x0 - r && top < o.y1 + r && top + l.height > o.y0 - r)
				return false;
		}
		return true;
	};
	auto clamped = [&](std::array<double, 2> p) {
		p[0] = std::max(margin, std::min(p[0], W - 1.0 - margin - l.width));
		p[1] = std::max(margin, std::min(p[1], H - 1.0 - margin - l.height));
		return p;
	};
	/* The first spot inside the frame and clear of every marker, else the
	 * first inside the frame, else above as far as the frame allows. A
	 * spot moves along its side into the frame, never across it. */
	std::optional<std::array<double, 2>> chosen;
	for (int pass = 0; pass < 2 && !chosen; ++pass) {
		for (std::size_t k = 0; k < spots.size() && !chosen; ++k) {
			const std::size_t across = k < 2 ? 1 : 0;
			std::array<double, 2> p = clamped(spots[k]);
			p[across] = spots[k][across];
			if (inside(p[0], p[1]) && (pass == 1 || clear(p[0], p[1])))
				chosen = p;
		}
	}
	const std::array<double, 2> p = chosen ? *chosen : clamped(spots[0]);
	l.left = p[0];
	l.top = p[1];
	return l;
}

void annotateMarkers(GstVideoFrame *frame, const Result &result, const std::vector<std::optional<Pose>> &poses,
		     const MarkerSizes &sizes, const Camera &camera, const BundleAxes &bundle)
{
	Canvas canvas(frame);
	double largest = 0.0; /* the largest marker's side, pixels */
	for (std::size_t i = 0; i < result.markers.size(); ++i) {
		const Marker &m = result.markers[i];
		const double side = meanSide(m.corners);

		/* The four sides as one shape: round joins, one halo. */
		Path outline;
		for (std::size_t k = 0; k < 4; ++k) {
			const Point2f a = m.corners[k], b = m.corners[(k + 1) & 3];
			outline.add(Stroke::segment(a.x, a.y, b.x, b.y));
		}
		canvas.stroke(outline, outlinePen(side));

		/* The first corner (top-left in the marker's orientation): a dot
		 * on the border, clear of the code cells. */
		Path dot;
		dot.add(Stroke::segment(m.corners[0].x, m.corners[0].y, m.corners[0].x, m.corners[0].y));
		Pen dotPen;
		dotPen.width = std::max(4.0, side / 12.0);
		dotPen.halo = 1.0;
		dotPen.ink = colours::firstCorner;
		canvas.stroke(dot, dotPen);

		if (i < poses.size() && poses[i] && sizes(m.id) > 0.0)
			drawAxes(canvas, *poses[i], sizes(m.id), camera, side);
		largest = std::max(largest, side);
	}
	if (bundle.pose)
		drawAxes(canvas, *bundle.pose, 2.0 * bundle.axis, camera, largest);

	/* Labels last: over the axes of any neighbour. */
	for (const Marker &m : result.markers) {
		char text[16];
		const auto end = std::to_chars(text, text + sizeof(text), m.id).ptr;
		const std::string_view id(text, static_cast<std::size_t>(end - text));
		const Label l = placeLabel(m.corners, id, canvas.width(), canvas.height(),
					   canvas.colour() ? colours::label : colours::white, result.markers);
		Path path;
		addText(path, id, l.left, l.top, l.height);
		canvas.stroke(path, l.pen);
	}
}

} // namespace frappe::gst
