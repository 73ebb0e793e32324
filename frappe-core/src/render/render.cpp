// SPDX-License-Identifier: MIT
#include "frappe/render.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "frappe/homography.h"
#include "quad_geometry.h"

namespace frappe {

namespace {

/* Beyond these, sizes overflow an int: supersample^2 samples a pixel, and
 * markerImage()'s side^2 pixels. */
constexpr int kMaxSupersample = 256;
constexpr long long kMaxMarkerImageSide = 1 << 15;
/* No quiet zone wider than the widest image: cells + 2 * quiet stays an int. */
constexpr int kMaxQuietCells = 1 << 15;

/* The cell a marker coordinate falls in (the square's first cell at u = 0),
 * clamped to one past the widest quiet zone: near the horizon a sample
 * maps arbitrarily far, or to NaN, which no cast to int may see. */
int cellOf(float u, const MarkerLayout &l)
{
	const double c = std::floor(static_cast<double>(u) * l.square_cells);
	constexpr double kFar = 4.0 * kMaxQuietCells;
	return c >= -kFar && c <= kFar ? static_cast<int>(c) + l.square_start : static_cast<int>(-kFar);
}

/* 1 = white, 0 = black; -1 outside the marker and its quiet zone. Cells of
 * no matter are drawn black, as AprilTag draws them. */
int cellValue(const MarkerLayout &l, std::uint64_t code, int cx, int cy, int quiet)
{
	if (cx < -quiet || cy < -quiet || cx >= l.size + quiet || cy >= l.size + quiet)
		return -1;
	if (cx < 0 || cy < 0 || cx >= l.size || cy >= l.size)
		return 1;
	const int c = l.at(cx, cy);
	return c >= 0 ? l.bit(code, c) : c == MarkerLayout::kWhite ? 1 : 0;
}

/* Appended piece by piece: GCC 12 warns falsely (-Wrestrict, its bug
 * 105329) on "(" + std::string. */
std::string pointText(Point2f p)
{
	std::string s = "(";
	s += std::to_string(p.x);
	s += ", ";
	s += std::to_string(p.y);
	s += ")";
	return s;
}

/* The arguments renderMarker() cannot draw from, refused before any of them
 * reaches an index, a cast to int or a division. */
void checkRenderArguments(const MutableImageView &image, const Dictionary &dict, int id,
			  const std::array<Point2f, 4> &corners, const RenderOptions &opt)
{
	auto fail = [](const std::string &what) { throw std::invalid_argument("renderMarker: " + what); };
	if (image.width < 0 || image.height < 0)
		fail("image size must not be negative, got " + std::to_string(image.width) + "x" +
		     std::to_string(image.height));
	if (image.width > 0 && image.height > 0 && !image.data)
		fail("image data is null");
	if (image.height > 1 && image.stride < image.width)
		fail("image stride (" + std::to_string(image.stride) + ") is smaller than its width (" +
		     std::to_string(image.width) + ")");
	if (opt.supersample < 1 || opt.supersample > kMaxSupersample)
		fail("supersample must be 1.." + std::to_string(kMaxSupersample) + ", got " +
		     std::to_string(opt.supersample));
	if (opt.quiet_cells < 0 || opt.quiet_cells > kMaxQuietCells)
		fail("quiet_cells must be 0.." + std::to_string(kMaxQuietCells) + ", got " +
		     std::to_string(opt.quiet_cells));
	if (id < 0 || id >= dict.size())
		throw std::out_of_range("renderMarker: id " + std::to_string(id) + " not in " + std::string(dict.name) +
					" (0.." + std::to_string(dict.size() - 1) + ")");
	for (int i = 0; i < 4; ++i)
		if (!std::isfinite(corners[i].x) || !std::isfinite(corners[i].y))
			fail("corner " + std::to_string(i) + " is not a finite point: " + pointText(corners[i]));
	/* A square seen in perspective is a convex quadrilateral: every three
	 * corners turn the same way. Collinear or coincident corners (a turn
	 * of 0), or a crossed outline, are no view of a square. */
	for (int i = 0; i < 4; ++i) {
		const Point2f a = corners[i], b = corners[(i + 1) & 3], c = corners[(i + 2) & 3];
		if (detail::turnSign(a, b, c) == 0)
			fail("corners " + std::to_string(i) + ", " + std::to_string((i + 1) & 3) + " and " +
			     std::to_string((i + 2) & 3) + " are collinear or coincide (" + pointText(a) + ", " +
			     pointText(b) + ", " + pointText(c) + "): no perspective of a square");
	}
	if (!detail::convexQuad(corners))
		fail("corners do not make a convex quadrilateral (the outline crosses itself or folds "
		     "in): no perspective of a square");
}

/* A pixel coordinate as an int clamped to [lo, hi]: the bounding box of a
 * strongly foreshortened quiet zone can reach far beyond the image. */
int clampedPixel(double v, int lo, int hi)
{
	return static_cast<int>(std::clamp(v, static_cast<double>(lo), static_cast<double>(hi)));
}

} // namespace

void renderMarker(MutableImageView image, const Dictionary &dict, int id,
		  const std::array<Point2f, 4> &corners, const RenderOptions &opt)
{
	checkRenderArguments(image, dict, id, corners, opt);
	const auto H = Homography::fromUnitSquare(corners);
	const auto Hinv = H ? H->inverse() : std::nullopt;
	if (!Hinv)
		throw std::invalid_argument("renderMarker: corners too close together for a perspective of a square");
	if (image.width == 0 || image.height == 0)
		return;
	const std::uint64_t code = dict.codes[id];
	const MarkerLayout classic = dict.layout ? MarkerLayout{} : MarkerLayout::classic(dict.bits);
	const MarkerLayout &layout = dict.layout ? *dict.layout : classic;
	const int q = opt.quiet_cells;

	/* Bounding box of the marker with its quiet zone: the unit square is
	 * the layout's square, cells square_start .. + square_cells. */
	const double cells = layout.square_cells;
	const double lo = -static_cast<double>(q + layout.square_start) / cells,
		     hi = layout.square_start == 0 && layout.size == layout.square_cells
				  ? 1.0 + static_cast<double>(q) / cells
				  : static_cast<double>(layout.size + q - layout.square_start) / cells;
	double minX = 1e18, minY = 1e18, maxX = -1e18, maxY = -1e18;
	bool beyondHorizon = false;
	for (double u : { lo, hi }) {
		for (double v : { lo, hi }) {
			/* w is 1 at the marker's first corner and positive over
			 * it: where it is not, the quiet zone's corner lies past
			 * the horizon and maps to the wrong side. */
			const auto &m = H->h;
			beyondHorizon |= !(m[6] * u + m[7] * v + m[8] > 0.0);
			const Point2f p = H->map(u, v);
			minX = std::min(minX, static_cast<double>(p.x));
			maxX = std::max(maxX, static_cast<double>(p.x));
			minY = std::min(minY, static_cast<double>(p.y));
			maxY = std::max(maxY, static_cast<double>(p.y));
		}
	}
	/* A quiet zone reaching the horizon maps to no finite box: then the
	 * whole image. */
	if (beyondHorizon || !std::isfinite(minX) || !std::isfinite(minY) || !std::isfinite(maxX) ||
	    !std::isfinite(maxY)) {
		minX = minY = 0.0;
		maxX = image.width;
		maxY = image.height;
	}
	const int x0 = clampedPixel(std::floor(minX) - 1.0, 0, image.width);
	const int y0 = clampedPixel(std::floor(minY) - 1.0, 0, image.height);
	const int x1 = clampedPixel(std::ceil(maxX) + 1.0, -1, image.width - 1);
	const int y1 = clampedPixel(std::ceil(maxY) + 1.0, -1, image.height - 1);
	const int ss = opt.supersample;
	const double inv = 1.0 / ss;
	for (int y = y0; y <= y1; ++y) {
		std::uint8_t *row = image.row(y);
		for (int x = x0; x <= x1; ++x) {
			double sum = 0.0;
			int inside = 0;
			for (int sy = 0; sy < ss; ++sy) {
				for (int sx = 0; sx < ss; ++sx) {
					const double px = x - 0.5 + (sx + 0.5) * inv;
					const double py = y - 0.5 + (sy + 0.5) * inv;
					const Point2f uv = Hinv->map(px, py);
					const int cx = cellOf(uv.x, layout);
					const int cy = cellOf(uv.y, layout);
					const int v = cellValue(layout, code, cx, cy, q);
					if (v < 0) {
						sum += row[x];
					} else {
						sum += v ? opt.white : opt.black;
						++inside;
					}
				}
			}
			if (inside)
				row[x] = static_cast<std::uint8_t>(std::lround(sum / (ss * ss)));
		}
	}
}

std::array<Point2f, 4> perspectiveSquare(float cx, float cy, float side, float roll, float tilt,
					 float distance)
{
	const double r = roll * M_PI / 180.0, t = tilt * M_PI / 180.0;
	const double xs[4] = { -0.5, 0.5, 0.5, -0.5 }, ys[4] = { -0.5, -0.5, 0.5, 0.5 };
	std::array<Point2f, 4> out;
	for (int i = 0; i < 4; ++i) {
		/* Tilt about the square's x axis, project, then roll. */
		const double Z = distance + ys[i] * std::sin(t);
		const double u = distance * xs[i] / Z, v = distance * ys[i] * std::cos(t) / Z;
		out[i] = { static_cast<float>(cx + side * (u * std::cos(r) - v * std::sin(r))),
			   static_cast<float>(cy + side * (u * std::sin(r) + v * std::cos(r))) };
	}
	return out;
}

std::vector<std::uint8_t> markerImage(const Dictionary &dict, int id, int cell_px, int quiet_cells,
				      int &side)
{
	auto fail = [](const std::string &what) { throw std::invalid_argument("markerImage: " + what); };
	if (cell_px < 1)
		fail("cell_px must be at least 1, got " + std::to_string(cell_px));
	if (quiet_cells < 0 || quiet_cells > kMaxQuietCells)
		fail("quiet_cells must be 0.." + std::to_string(kMaxQuietCells) + ", got " + std::to_string(quiet_cells));
	if (id < 0 || id >= dict.size())
		throw std::out_of_range("markerImage: id " + std::to_string(id) + " not in " + std::string(dict.name) +
					" (0.." + std::to_string(dict.size() - 1) + ")");
	/* The whole layout, the detected square within it. */
	const int size = dict.layout ? dict.layout->size : dict.bits + 2;
	const int start = dict.layout ? dict.layout->square_start : 0;
	const int square = dict.bits + 2;
	/* In 64 bits: the side, then its square, must not overflow. */
	const long long wide = (static_cast<long long>(size) + 2LL * quiet_cells) * cell_px;
	if (wide > kMaxMarkerImageSide)
		fail("the image would be " + std::to_string(wide) + " pixels a side, more than " +
		     std::to_string(kMaxMarkerImageSide) + " (cell_px " + std::to_string(cell_px) + ", quiet_cells " +
		     std::to_string(quiet_cells) + ")");
	const int cells = size + 2 * quiet_cells;
	side = cells * cell_px;
	std::vector<std::uint8_t> img(static_cast<std::size_t>(side) * side, 255);
	MutableImageView view{ img.data(), side, side, side };
	const float a = static_cast<float>((quiet_cells + start) * cell_px) - 0.5f;
	const float b = static_cast<float>((quiet_cells + start + square) * cell_px) - 0.5f;
	RenderOptions opt;
	opt.quiet_cells = quiet_cells;
	opt.supersample = 1;
	renderMarker(view, dict, id, { Point2f{ a, a }, { b, a }, { b, b }, { a, b } }, opt);
	return img;
}

} // namespace frappe
