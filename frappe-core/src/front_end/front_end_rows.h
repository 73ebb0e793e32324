// SPDX-License-Identifier: MIT
// Row kernels of the CPU front end (see front_end_cpu.cpp for the exact
// arithmetic they implement).
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include "frappe/edge_map.h"
#include "frappe/image.h"
#include "region_map.h"

namespace frappe::detail {

/// Three consecutive rows (y-1, y, y+1) of gradients and squared magnitudes.
struct GradRows {
	const std::int16_t *gx[3];
	const std::int16_t *gy[3];
	const std::int32_t *mag[3];
	/// The middle row smoothed (smoothRow's), whose brightness scales the
	/// thresholds; in the ARMv6 kernels' lane-split layout there.
	const std::uint8_t *smooth = nullptr;
};

/// Per-thread scratch: rings of smoothed rows and of gradient rows.
struct RowScratch {
	std::vector<std::uint8_t> smooth[4];   ///< 2w + 8 bytes: the ARMv6 layout needs 2w
	std::vector<std::uint16_t> columns;    ///< smoothRow's vertical pass
	std::vector<std::int16_t> separable;   ///< gradientRow's two column passes (2w + 16)
	/// gx holds 2w values: the ARMv6 kernels store (gx, gy) pairs in it.
	std::vector<std::int16_t> gx[3], gy[3];
	std::vector<std::int32_t> mag[3];
	std::vector<std::uint8_t> tileAcc;     ///< the OR of a tile row's edge rows (orRow)
	void resize(int w)
	{
		tileAcc.resize(w);
		for (int i = 0; i < 4; ++i)
			smooth[i].resize(2 * static_cast<std::size_t>(w) + 8);
		columns.resize(w);
		separable.resize(2 * static_cast<std::size_t>(w) + 16);
		for (int i = 0; i < 3; ++i) {
			gx[i].resize(2 * static_cast<std::size_t>(w));
			gy[i].resize(w);
			mag[i].resize(w);
		}
	}
};

/// Nearest-neighbour scaling: destination pixel x samples source column
/// ((2x + 1) * round(65536 * srcW / dstW)) >> 17, clamped; rows likewise.
void scaleNearest(const ImageView &src, int dstW, int dstH, std::uint8_t *dst);

/// The middle of three image rows a, b, c smoothed by the 3x3 binomial
/// kernel [1 2 1]^T [1 2 1] / 16, rounded, edge pixels replicated beyond the
/// first and last column. `tmp` holds w values.
void smoothRow(const std::uint8_t *a, const std::uint8_t *b, const std::uint8_t *c, int w,
	       std::uint8_t *out, std::uint16_t *tmp);

/// Sobel gradients of the middle of three smoothed rows a, b, c; zero in
/// the first and last column. `tmp` holds 2w values.
void gradientRow(const std::uint8_t *a, const std::uint8_t *b, const std::uint8_t *c, int w,
		 std::int16_t *gx, std::int16_t *gy, std::int32_t *mag, std::int16_t *tmp);

/// The gradient row of the outermost image rows: all zero (2w values of gx).
void zeroGradientRow(int w, std::int16_t *gx, std::int16_t *gy, std::int32_t *mag);

/// The edge threshold the contract compares with: edge_threshold_sq capped
/// where no magnitude reaches (2^22), so that relativeThreshold() stays in
/// 32 bits.
inline std::int32_t edgeThreshold(const FrontEndParams &params)
{
	return static_cast<std::int32_t>(std::clamp<std::int64_t>(params.edge_threshold_sq, -1, std::int64_t{ 1 } << 22));
}
/// corner_threshold as the contract uses it (validate() keeps it below 2^23).
inline std::int32_t cornerThreshold(const FrontEndParams &params)
{
	return static_cast<std::int32_t>(std::clamp<std::int64_t>(params.corner_threshold, 0, (std::int64_t{ 1 } << 23) - 1));
}
/// The least edge threshold of any pixel (that of a black one): magnitudes
/// at or below it are never edges.
inline std::int32_t leastEdgeThreshold(const FrontEndParams &params)
{
	return params.relativeThreshold(edgeThreshold(params), 0);
}

/// Non-maximum suppression, edge threshold and corner test of the middle
/// row. Writes w bytes; returns whether any pixel is an edge.
bool edgeRow(const GradRows &rows, int w, const FrontEndParams &params, std::uint8_t *out);

/// edgeRow's rule for columns x0 .. x1-1 only (1 <= x0, x1 <= w-1).
bool edgeSpan(const GradRows &rows, int x0, int x1, const FrontEndParams &params, std::uint8_t *out);

/// ORs each 16-pixel run of an edge row into its tile's occupancy byte.
void markTiles(const std::uint8_t *edgeRow, int w, std::uint8_t *tileRow);
/// markTiles' portable form, the reference of the ARMv6 one.
void markTilesScalar(const std::uint8_t *edgeRow, int w, std::uint8_t *tileRow);

/// One band of the front end: edge rows y0 .. y1-1 (1 <= y0, y1 <= h-1).
/// With `half`, also rows hy0 .. hy1-1 of the frame's 2x2 means (the region
/// map's first step, decimateRow), w / 2 a row, made as the band reads the
/// frame's rows anyway.
struct BandJob {
	ImageView src;
	const FrontEndParams *params;
	EdgeMap *out;
	int y0, y1;
	RowScratch *scratch;
	std::uint8_t *half = nullptr;
	int hy0 = 0, hy1 = 0;
};

/// A set of row kernels: the portable scalar ones above (the reference), or
/// their ARMv6 SIMD32 twins; runBandRows runs them over a band.
struct RowKernels {
	const char *name;
	void (*smooth)(const std::uint8_t *a, const std::uint8_t *b, const std::uint8_t *c, int w,
		       std::uint8_t *out, std::uint16_t *tmp);
	void (*gradient)(const std::uint8_t *a, const std::uint8_t *b, const std::uint8_t *c, int w,
			 std::int16_t *gx, std::int16_t *gy, std::int32_t *mag, std::int16_t *tmp);
	bool (*edge)(const GradRows &rows, int w, const FrontEndParams &params, std::uint8_t *out);
};

/// What a CPU front end runs: one band of rows at a time. For the scalar and
/// ARMv6 sets, runBandRows over their RowKernels; for Highway, a band loop
/// of vectorised twins whose kernels are called directly, dispatched once
/// per band rather than three or four times a row. Every set produces the
/// scalar set's bytes.
struct BandKernels {
	const char *name;
	void (*band)(const BandJob &job);
};

/// The scalar row kernels: the reference.
const RowKernels &scalarRowKernels();
/// runBandRows over scalarRowKernels().
const BandKernels &scalarBandKernels();
/// The fastest for this CPU: Highway's runtime dispatch, or the ARMv6
/// SIMD32 kernels, or the scalar ones.
const BandKernels &bestBandKernels();
/// What bestBandKernels() runs on this CPU (frappe::simdTarget()).
const char *simdTargetName();

#if defined(__ARM_FEATURE_SIMD32) && defined(__ARM_FEATURE_DSP) && defined(__ARMEL__)
#define FRAPPE_HAVE_ARMV6_KERNELS 1
/// ARMv6 SIMD32 kernels (front_end_armv6.cpp): the scalar kernels' EdgeMap,
/// but their own row layouts: the smoothed rows lane-split (below), and the
/// gradient row's (gx, gy) as int16 pairs in `gx` (`gy` unused).
const RowKernels &armv6RowKernels();
/// runBandRows over armv6RowKernels().
const BandKernels &armv6BandKernels();
/// markTiles by LDM where the row is word aligned (front_end_armv6.cpp).
void markTilesV6(const std::uint8_t *edgeRow, int w, std::uint8_t *tileRow);
/// Where the ARMv6 smoothing stores pixel x of a row: as a uint16, per four
/// pixels 4k .. 4k+3 the words (p0, p2), (p1, p3).
inline std::size_t armv6SmoothedOffset(int x)
{
	return 8 * static_cast<std::size_t>(x >> 2) + 4 * (x & 1) + 2 * ((x >> 1) & 1);
}
#endif

/// A CPU front end with the given kernels (tests compare them).
std::unique_ptr<FrontEnd> makeCpuFrontEnd(int threads, const BandKernels &kernels);

/// The streamed row loop of one band: smoothed and gradient rows in rings,
/// an edge row per image row, the tile mask. Kernels has RowKernels'
/// smooth, gradient and edge, as pointers or as static functions, and may
/// have a static orRow(row, w, acc) (acc[x] |= row[x]): where a vector OR
/// makes marking the tiles once per tile row cheaper than once per edge row.
template <class Kernels>
void runBandRows(const Kernels &k, const BandJob &job)
{
	constexpr bool kOrRows = requires { Kernels::orRow; };
	const ImageView &src = job.src;
	const FrontEndParams &params = *job.params;
	EdgeMap &out = *job.out;
	RowScratch &s = *job.scratch;
	const int w = src.width, h = src.height;
	const int y0 = job.y0, y1 = job.y1;
	s.resize(w);
	/* Gradient row r needs smoothed rows r-1..r+1; both live in rings. */
	auto smoothed = [&](int r) { return s.smooth[r & 3].data(); };
	auto gradient = [&](int r) {
		const int i = r % 3;
		if (r <= 0 || r >= h - 1)
			zeroGradientRow(w, s.gx[i].data(), s.gy[i].data(), s.mag[i].data());
		else
			k.gradient(smoothed(r - 1), smoothed(r), smoothed(r + 1), w, s.gx[i].data(),
				   s.gy[i].data(), s.mag[i].data(), s.separable.data());
	};
	/* Rows beyond the frame replicate its first and last row. The 2x2
	 * means of rows r-1 and r while they are in cache. */
	auto smoothRow = [&](int r) {
		k.smooth(src.row(std::max(r - 1, 0)), src.row(r), src.row(std::min(r + 1, h - 1)), w,
			 smoothed(r), s.columns.data());
		const int hy = (r - 1) >> 1;
		if (job.half && (r & 1) && hy >= job.hy0 && hy < job.hy1)
			decimateRow(src.row(r - 1), src.row(r), w / 2, job.half + static_cast<std::size_t>(hy) * (w / 2));
	};
	for (int r = std::max(0, y0 - 2); r <= std::min(h - 1, y0 + 1); ++r)
		smoothRow(r);
	gradient(y0 - 1);
	gradient(y0);

	/* With orRow: the OR of the tile row's edge rows so far. */
	[[maybe_unused]] std::uint8_t *acc = s.tileAcc.data();
	[[maybe_unused]] bool accAny = false;
	if constexpr (kOrRows)
		std::fill_n(acc, w, 0);
	for (int y = y0; y < y1; ++y) {
		const int next = y + 1;
		if (next + 1 <= h - 1)
			smoothRow(next + 1);
		gradient(next);
		const GradRows rows{
			{ s.gx[(y - 1) % 3].data(), s.gx[y % 3].data(), s.gx[next % 3].data() },
			{ s.gy[(y - 1) % 3].data(), s.gy[y % 3].data(), s.gy[next % 3].data() },
			{ s.mag[(y - 1) % 3].data(), s.mag[y % 3].data(), s.mag[next % 3].data() },
			smoothed(y),
		};
		std::uint8_t *edgeRow = out.pixels.data() + static_cast<std::size_t>(y) * w;
		const bool any = k.edge(rows, w, params, edgeRow);
		std::uint8_t *tileRow = out.tiles.data() +
					static_cast<std::size_t>(y / EdgeMap::kTile) * out.tiles_x;
		if constexpr (!kOrRows) {
			if (any)
				markTiles(edgeRow, w, tileRow);
		} else {
			/* A vector OR per edge row, the tile test once per tile row. */
			if (any) {
				Kernels::orRow(edgeRow, w, acc);
				accAny = true;
			}
			if (accAny && ((y + 1) % EdgeMap::kTile == 0 || y + 1 == y1)) {
				markTiles(acc, w, tileRow);
				std::fill_n(acc, w, 0);
				accAny = false;
			}
		}
	}
}

/// The corner decision for one pixel from its 3x3 gradient neighbourhood.
bool isCorner(const GradRows &rows, int x, std::int64_t cornerThreshold);

} // namespace frappe::detail
