// SPDX-License-Identifier: MIT
// The CPU front end: nearest-neighbour scaling, Sobel, non-maximum
// suppression, the edge threshold, Shi-Tomasi corners and the empty-tile
// mask, streamed over rows so the working set stays in cache.
//
// All arithmetic is integer and exactly specified, so that other front ends
// (the QPU kernels) can reproduce the EdgeMap byte for byte:
//   p  = the image smoothed by the binomial [1 2 1]x[1 2 1] / 16, rounded,
//        edges replicated. Blurred edges have a broad, flat gradient
//        profile; without smoothing, noise splits its crest into broken
//        zig-zag edges and the marker outline no longer closes.
//   gx = (p[y-1][x+1] + 2 p[y][x+1] + p[y+1][x+1]) - (same at x-1)
//   gy = (p[y+1][x-1] + 2 p[y+1][x] + p[y+1][x+1]) - (same at y-1)
//   m  = gx^2 + gy^2, zero on the outermost row and column
//   direction: horizontal when 256|gy| <= 106|gx|, vertical when
//   256|gx| <= 106|gy| (106/256 ~ tan 22.5 deg), else the diagonal with the
//   sign of gx*gy
//   edge: m > edge_threshold_sq and m > m(previous neighbour) and
//   m >= m(next neighbour) along the direction (previous = left/up)
//   corner: edge and the minimum eigenvalue of the 3x3 sum of
//   [gx^2 gxgy; gxgy gy^2] > corner_threshold T, decided without a root
//   and in 32-bit integers (the QPU multiplies 24 x 24 bits):
//   c = (Sxx + Syy - 2T) >> 9, a = |Sxx - Syy| >> 9, b = |Sxy| >> 8
//   (arithmetic shifts), corner when c > 0 and c*c > a*a + b*b.
//   Both thresholds follow the light below mid-grey: at a pixel whose
//   smoothed value is p, with q = min(p + light_floor, 128),
//     edge_threshold_sq becomes E(q) = (((E' q) >> 7) q) >> 7, E' =
//     min(edge_threshold_sq, 2^22) (no magnitude reaches 2^21), and
//     corner_threshold T(q) = (((T q) >> 7) q) >> 7,
//   so a marker whose black and white are a fifth of full light's keeps
//   a fifth of its gradient and is held to a fifth of the threshold: a
//   dim room, a shadow. light_floor keeps the thresholds of the darkest
//   pixels above sensor noise; 128 or more gives the paper's absolute ones.
// The region map (EdgeMap::regions, region_map.cpp), from the same frame s
// (scaled when the edge map is), W x H, at w = W/2, h = H/2 (rounded down;
// none when either is below 3 or region_contrast is 0):
//   r  = (s[2y][2x] + s[2y][2x+1] + s[2y+1][2x] + s[2y+1][2x+1] + 2) >> 2
//   tiles of 4 x 4 r pixels (the last row and column of tiles may be
//   partial): lo and hi, the least and greatest r over the 3 x 3 tiles
//   around a pixel's tile (those that exist)
//   dark: hi - lo >= C(lo, hi) and r < (lo + hi + 1) >> 1, never on the
//   outermost row and column of the map, where the contrast follows the
//   light as the thresholds do: C = (region_contrast *
//   min(lo + hi + 2 light_floor, 256) + 255) >> 8.
// The shade map (EdgeMap::shades), when light_floor < 128: the same map
// but for the midpoint, dark where hi - lo >= C(lo, hi) and
// (r + 4)^2 < (lo + 4)(hi + 4).
#include <algorithm>
#include <cstdlib>
#include <thread>
#include <vector>

#include "frappe/edge_map.h"
#include "front_end_rows.h"
#include "region_map.h"
#include "worker.h"

namespace frappe {

int scaledLength(int full, float scale)
{
	if (scale >= 1.0f)
		return full;
	return std::max(1, static_cast<int>(static_cast<float>(full) * scale + 0.5f));
}

void TraceMap::resize(int w, int h)
{
	width = w;
	height = h;
	pixels.resize(static_cast<std::size_t>(w) * h);
	tiles_x = (w + kTile - 1) / kTile;
	tiles_y = (h + kTile - 1) / kTile;
	tiles.resize(static_cast<std::size_t>(tiles_x) * tiles_y);
}

namespace {

class CpuFrontEnd final : public FrontEnd
{
public:
	CpuFrontEnd(int threads, const detail::BandKernels &kernels)
		: threads_(threads), kernels_(kernels)
	{
	}
	const char *name() const override { return "cpu"; }
	void run(const ImageView &image, float scale, const FrontEndParams &params,
		 EdgeMap &out) override;
	bool makesRegionMap() const override { return true; }
	bool makesShadeMap() const override { return true; }

private:
	void runBand(const detail::BandJob &job);

	int threads_;
	const detail::BandKernels &kernels_;
	std::vector<std::uint8_t> scaled_;
	std::vector<detail::RowScratch> scratch_;
	detail::RegionScratch regionScratch_;
	detail::WorkerPool pool_;
};

void CpuFrontEnd::run(const ImageView &image, float scale, const FrontEndParams &params,
		      EdgeMap &out)
{
	ImageView src = image;
	if (scale < 1.0f) {
		const int w = scaledLength(image.width, scale);
		const int h = scaledLength(image.height, scale);
		scaled_.resize(static_cast<std::size_t>(w) * h);
		detail::scaleNearest(image, w, h, scaled_.data());
		src = ImageView(scaled_.data(), w, h, w);
	}
	out.resize(src.width, src.height);
	out.scale = scale < 1.0f ? scale : 1.0f;
	std::fill(out.tiles.begin(), out.tiles.end(), 0);

	const int w = src.width, h = src.height;
	/* Frame rows are never edges: Suzuki's tracer relies on a zero frame. */
	if (h > 0) {
		std::fill_n(out.pixels.data(), w, 0);
		std::fill_n(out.pixels.data() + static_cast<std::size_t>(h - 1) * w, w, 0);
	}
	if (w < 3 || h < 3) {
		std::fill(out.pixels.begin(), out.pixels.end(), 0);
		out.regions.resize(0, 0);
		out.shades.resize(0, 0);
		return;
	}

	int bands = threads_ <= 0 ? static_cast<int>(std::max(1u, std::thread::hardware_concurrency()))
				  : threads_;
	/* Bands are whole tile rows so that no two threads touch one tile. */
	const int tileRows = (h + EdgeMap::kTile - 1) / EdgeMap::kTile;
	bands = std::clamp(bands, 1, std::min(detail::WorkerPool::kMaxTasks, std::max(1, tileRows)));
	if (scratch_.size() < static_cast<std::size_t>(bands))
		scratch_.resize(bands);

	auto bandRows = [&](int b, int &y0, int &y1) {
		const int t0 = tileRows * b / bands, t1 = tileRows * (b + 1) / bands;
		y0 = std::max(1, t0 * EdgeMap::kTile);
		y1 = std::min(h - 1, t1 * EdgeMap::kTile);
	};
	/* The region map's 2x2 means are made by the bands, which read the
	 * frame's rows anyway: its rows of tile row t0 .. t1-1 are means rows
	 * 8 t0 .. 8 t1-1. */
	const bool regions = detail::makesRegionMap(w, h, params.region_contrast);
	if (regions)
		regionScratch_.decimated.resize(static_cast<std::size_t>(w / 2) * (h / 2));
	auto band = [&](int b) {
		int y0, y1;
		bandRows(b, y0, y1);
		detail::BandJob job{ src, &params, &out, y0, y1, &scratch_[b] };
		if (regions) {
			job.half = regionScratch_.decimated.data();
			job.hy0 = tileRows * b / bands * (EdgeMap::kTile / 2);
			job.hy1 = b + 1 == bands ? h / 2 : tileRows * (b + 1) / bands * (EdgeMap::kTile / 2);
		}
		runBand(job);
	};
	if (bands == 1)
		band(0);
	else
		pool_.run(bands, band);
	detail::regionMapFromMeans(w, h, out.scale, params, out.regions, out.shades, regionScratch_);
}

/* Edge rows y0 .. y1-1 (1 <= y0, y1 <= h-1), and the means rows of the job. */
void CpuFrontEnd::runBand(const detail::BandJob &job)
{
	kernels_.band(job);
}

} // namespace

std::unique_ptr<FrontEnd> makeCpuFrontEnd(int threads)
{
	return std::make_unique<CpuFrontEnd>(threads, detail::bestBandKernels());
}

std::unique_ptr<FrontEnd> detail::makeCpuFrontEnd(int threads, const BandKernels &kernels)
{
	return std::make_unique<CpuFrontEnd>(threads, kernels);
}

} // namespace frappe
