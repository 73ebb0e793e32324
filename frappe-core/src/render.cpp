// SPDX-License-Identifier: MIT
#include "frappe/render.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "frappe/homography.h"

namespace frappe {

namespace {

/* 1 = white, 0 = black; -1 outside the marker and its quiet zone. */
int cellValue(const Dictionary &dict, std::uint64_t code, int cx, int cy, int quiet)
{
	const int n = dict.bits, cells = n + 2;
	if (cx < -quiet || cy < -quiet || cx >= cells + quiet || cy >= cells + quiet)
		return -1;
	if (cx < 0 || cy < 0 || cx >= cells || cy >= cells)
		return 1;
	if (cx == 0 || cy == 0 || cx == cells - 1 || cy == cells - 1)
		return 0;
	const int bit = n * n - 1 - ((cy - 1) * n + (cx - 1));
	return static_cast<int>((code >> bit) & 1u);
}

} // namespace

void renderMarker(MutableImageView image, const Dictionary &dict, int id,
		  const std::array<Point2f, 4> &corners, const RenderOptions &opt)
{
	if (id < 0 || id >= dict.size())
		throw std::out_of_range("renderMarker: id " + std::to_string(id) + " not in " +
					std::string(dict.name));
	const auto H = Homography::fromUnitSquare(corners);
	if (!H)
		throw std::invalid_argument("renderMarker: degenerate corners");
	const auto Hinv = H->inverse();
	if (!Hinv)
		throw std::invalid_argument("renderMarker: degenerate corners");
	const std::uint64_t code = dict.codes[id];
	const int cells = dict.bits + 2;
	const int q = std::max(0, opt.quiet_cells);

	/* Bounding box of the marker with its quiet zone. */
	const double lo = -static_cast<double>(q) / cells, hi = 1.0 + static_cast<double>(q) / cells;
	double minX = 1e18, minY = 1e18, maxX = -1e18, maxY = -1e18;
	for (double u : { lo, hi }) {
		for (double v : { lo, hi }) {
			const Point2f p = H->map(u, v);
			minX = std::min(minX, static_cast<double>(p.x));
			maxX = std::max(maxX, static_cast<double>(p.x));
			minY = std::min(minY, static_cast<double>(p.y));
			maxY = std::max(maxY, static_cast<double>(p.y));
		}
	}
	const int x0 = std::max(0, static_cast<int>(std::floor(minX)) - 1);
	const int y0 = std::max(0, static_cast<int>(std::floor(minY)) - 1);
	const int x1 = std::min(image.width - 1, static_cast<int>(std::ceil(maxX)) + 1);
	const int y1 = std::min(image.height - 1, static_cast<int>(std::ceil(maxY)) + 1);
	const int ss = std::max(1, opt.supersample);
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
					const int cx = static_cast<int>(std::floor(uv.x * cells));
					const int cy = static_cast<int>(std::floor(uv.y * cells));
					const int v = cellValue(dict, code, cx, cy, q);
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
	const int cells = dict.bits + 2 + 2 * quiet_cells;
	side = cells * cell_px;
	std::vector<std::uint8_t> img(static_cast<std::size_t>(side) * side, 255);
	MutableImageView view{ img.data(), side, side, side };
	const float a = static_cast<float>(quiet_cells * cell_px) - 0.5f;
	const float b = static_cast<float>((cells - quiet_cells) * cell_px) - 0.5f;
	RenderOptions opt;
	opt.quiet_cells = quiet_cells;
	opt.supersample = 1;
	renderMarker(view, dict, id, { Point2f{ a, a }, { b, a }, { b, b }, { a, b } }, opt);
	return img;
}

} // namespace frappe
