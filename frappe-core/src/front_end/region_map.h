// SPDX-License-Identifier: MIT
// The region map: the frame's dark regions at half resolution, where the
// second source of candidates is traced (see EdgeMap::regions). The exact
// integer rule is at the top of front_end_cpu.cpp; the row kernels are
// vectorised where Highway is built in, beside their scalar references.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "frappe/edge_map.h"
#include "frappe/image.h"

namespace frappe::detail {

/// Side of a threshold tile, in region-map pixels (8 pixels of the frame).
constexpr int kRegionTile = 4;

/// Working rows of regionMap(), kept between frames.
struct RegionScratch {
	std::vector<std::uint8_t> decimated; ///< the half-resolution image
	std::vector<std::uint8_t> tileMin, tileMax, lo, mid, level, spread;
	std::vector<std::uint8_t> shadeMid, shadeAcc; ///< the shade map's thresholds and row ORs
};

/// Fills `out` with the dark pixels of `src` at half its resolution, and
/// `shades` with those of the shade map (EdgeMap::shades);
/// out.scale = shades.scale = srcScale / 2. Leaves `out` empty (0 x 0) when
/// region_contrast is 0 or `src` is too small for a 3 x 3 map, `shades`
/// also when params.makesShades() is false or `withShades` is (the region
/// map is the same either way).
void regionMap(const ImageView &src, float srcScale, const FrontEndParams &params, TraceMap &out, TraceMap &shades,
	       RegionScratch &scratch, bool withShades = true);

/// Whether regionMap() makes a map of a src.width x src.height frame.
inline bool makesRegionMap(int width, int height, int minContrast)
{
	return minContrast > 0 && width / 2 >= 3 && height / 2 >= 3;
}

/// regionMap() from the frame's 2x2 means already made (scratch.decimated,
/// width / 2 x height / 2, as decimateRow makes them): the CPU front end
/// makes them as it reads the frame's rows.
void regionMapFromMeans(int width, int height, float srcScale, const FrontEndParams &params, TraceMap &out,
			TraceMap &shades, RegionScratch &scratch, bool withShades = true);

/// out, (src.width / 2) x (src.height / 2) = decimateRow() of each pair of
/// src's rows: the image at half resolution, as the region map makes it.
void halveImage(const ImageView &src, std::uint8_t *out);

/// out[x] = the rounded mean of r0[2x], r0[2x + 1], r1[2x], r1[2x + 1] for
/// x in [0, w).
void decimateRow(const std::uint8_t *r0, const std::uint8_t *r1, int w, std::uint8_t *out);
/// out[x] = the least (or greatest) of a0[2x], a0[2x + 1], a1[2x],
/// a1[2x + 1] for x in [0, w).
void extremePairs(const std::uint8_t *a0, const std::uint8_t *a1, int w, std::uint8_t *out, bool least);
/// out[x] = kEdge if d[x] < mid[x], else 0, for x in [0, w); whether any is.
bool darkRow(const std::uint8_t *d, const std::uint8_t *mid, int w, std::uint8_t *out);

/// The thresholds of a row of tx tiles from their (spread) extremes, one
/// byte per column of the tile (kRegionTile bytes a tile): mid, the
/// midpoint (lo + hi + 1) >> 1 where hi - lo >= relativeRegionContrast(lo,
/// hi), else 0; when shaded, shadeMid: shadeThreshold(lo, hi) where mid is
/// not 0, else 0.
void tileThresholds(const std::uint8_t *tmin, const std::uint8_t *tmax, int tx, const FrontEndParams &params,
		    bool shaded, std::uint8_t *mid, std::uint8_t *shadeMid);
/// The same without SIMD, the references the vector forms are tested against.
void decimateRowScalar(const std::uint8_t *r0, const std::uint8_t *r1, int w, std::uint8_t *out);
void extremePairsScalar(const std::uint8_t *a0, const std::uint8_t *a1, int w, std::uint8_t *out, bool least);
bool darkRowScalar(const std::uint8_t *d, const std::uint8_t *mid, int w, std::uint8_t *out);
void tileThresholdsScalar(const std::uint8_t *tmin, const std::uint8_t *tmax, int tx, const FrontEndParams &params,
			  bool shaded, std::uint8_t *mid, std::uint8_t *shadeMid);

/// One row of tiles in one pass, the form the ARMv6 kernels take: tmin[i]
/// and tmax[i] = the least and greatest of columns [4i, min(4i + 4, w)) of
/// the n rows (1 <= n <= 4) at `rows`, `stride` bytes apart.
void tileExtremesScalar(const std::uint8_t *rows, std::ptrdiff_t stride, int n, int w, std::uint8_t *tmin,
			std::uint8_t *tmax);
/// Each of the tx x ty tiles' extremes becomes the least (greatest) over
/// the 3 x 3 tiles around it that exist, in place. work: 4 tx + 4 bytes.
void spreadTilesScalar(std::uint8_t *tileMin, std::uint8_t *tileMax, int tx, int ty, std::uint8_t *work);
/// The frame every form of spreadTiles shares: across each row through a
/// copy with its end tiles repeated (work: a, b), then down, keeping each
/// row's values before the pass for the next (work: upMin, upMax).
/// across(a, b, tmin, tmax, tx) and down(upMin, upMax, dnMin, dnMax, tmin,
/// tmax, tx) do the tiles they can in whole vectors and return how many;
/// the rest are done here, one by one.
template <class Across, class Down>
void spreadTilesWith(std::uint8_t *tileMin, std::uint8_t *tileMax, int tx, int ty, std::uint8_t *work,
		     Across across, Down down)
{
	std::uint8_t *a = work, *b = work + tx + 2;
	for (int j = 0; j < ty; ++j) {
		std::uint8_t *tmin = tileMin + static_cast<std::size_t>(j) * tx;
		std::uint8_t *tmax = tileMax + static_cast<std::size_t>(j) * tx;
		std::memcpy(a + 1, tmin, tx);
		std::memcpy(b + 1, tmax, tx);
		a[0] = a[1];
		a[tx + 1] = a[tx];
		b[0] = b[1];
		b[tx + 1] = b[tx];
		for (int i = across(a, b, tmin, tmax, tx); i < tx; ++i) {
			tmin[i] = std::min(std::min(a[i], a[i + 1]), a[i + 2]);
			tmax[i] = std::max(std::max(b[i], b[i + 1]), b[i + 2]);
		}
	}
	std::uint8_t *upMin = b + tx + 2, *upMax = upMin + tx;
	for (int j = 0; j < ty; ++j) {
		std::uint8_t *tmin = tileMin + static_cast<std::size_t>(j) * tx;
		std::uint8_t *tmax = tileMax + static_cast<std::size_t>(j) * tx;
		const std::uint8_t *dnMin = j + 1 < ty ? tmin + tx : tmin;
		const std::uint8_t *dnMax = j + 1 < ty ? tmax + tx : tmax;
		if (j == 0) {
			std::memcpy(upMin, tmin, tx);
			std::memcpy(upMax, tmax, tx);
		}
		for (int i = down(upMin, upMax, dnMin, dnMax, tmin, tmax, tx); i < tx; ++i) {
			const std::uint8_t m = tmin[i], n = tmax[i];
			tmin[i] = std::min(std::min(upMin[i], m), dnMin[i]);
			tmax[i] = std::max(std::max(upMax[i], n), dnMax[i]);
			upMin[i] = m;
			upMax[i] = n;
		}
	}
}

#ifdef FRAPPE_HAVE_HWY
/// spreadTilesScalar, vectorised (Highway's best target).
void spreadTiles(std::uint8_t *tileMin, std::uint8_t *tileMax, int tx, int ty, std::uint8_t *work);
#endif
/// darkRowScalar, and tiles[x / 16] = kEdge for every x where out[x] is
/// (other tile bytes left as they are).
bool darkRowTilesScalar(const std::uint8_t *d, const std::uint8_t *mid, int w, std::uint8_t *out,
			std::uint8_t *tiles);

#if defined(__ARM_FEATURE_SIMD32) && defined(__ARMEL__) && !defined(FRAPPE_HAVE_HWY)
#define FRAPPE_HAVE_ARMV6_REGION 1
/// ARMv6 SIMD32 forms of decimateRowScalar, tileExtremesScalar,
/// spreadTilesScalar and darkRowTilesScalar (region_map_armv6.cpp), byte
/// for byte the same.
void decimateRowV6(const std::uint8_t *r0, const std::uint8_t *r1, int w, std::uint8_t *out);
void tileExtremesV6(const std::uint8_t *rows, std::ptrdiff_t stride, int n, int w, std::uint8_t *tmin,
		    std::uint8_t *tmax);
/// darkRowV6 returns nothing: the tiles say whether any pixel is dark.
void spreadTilesV6(std::uint8_t *tileMin, std::uint8_t *tileMax, int tx, int ty, std::uint8_t *work);
void darkRowV6(const std::uint8_t *d, const std::uint8_t *mid, int w, std::uint8_t *out, std::uint8_t *tiles);
#endif

} // namespace frappe::detail
