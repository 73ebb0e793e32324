// SPDX-License-Identifier: MIT
// frappe/edge_map.h: what the front end hands the back end, and the
// interface every front-end implementation (CPU, VC4) provides.
#pragma once

#include "frappe/export.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "frappe/image.h"

namespace frappe {

/// Integer parameters of the front end, derived from Config so that every
/// implementation compares exactly the same integers.
struct FrontEndParams {
	/// An edge pixel's squared Sobel magnitude (8-bit intensities, kernel
	/// weights 1-2-1) must be greater than this.
	std::int64_t edge_threshold_sq = 0;
	/// An edge pixel is a corner when the minimum eigenvalue of its 3x3
	/// summed structure tensor (8-bit intensity units squared) exceeds this.
	std::int64_t corner_threshold = 0;
	/// A region-map pixel is dark when the brightest and darkest pixels
	/// around it differ by at least this much (8-bit grey levels) and it
	/// lies below their midpoint; 0: no region map.
	int region_contrast = 0;
	/// Below mid-grey the three thresholds above scale with the local
	/// brightness (relativeThreshold(), the contract at the top of
	/// front_end_cpu.cpp): the grey level added to a brightness before it
	/// is compared with kLightReference. kLightReference or more: the
	/// thresholds are absolute, as in the paper.
	int light_floor = kLightReference;

	/// The brightness (8-bit grey level) at and above which the
	/// thresholds are the absolute ones.
	static constexpr int kLightReference = 128;
	/// A squared-gradient threshold `t` (edge or corner, 0 <= t < 2^23) at
	/// a pixel of smoothed brightness `p`: t ((p + light_floor) / 128)^2,
	/// capped at t, in two exact 32-bit steps (the QPU multiplies 24 x 24
	/// bits).
	std::int32_t relativeThreshold(std::int32_t t, int p) const
	{
		const std::int32_t q = std::min(p + light_floor, kLightReference);
		return (((t * q) >> 7) * q) >> 7;
	}
	/// The region map's contrast for tile extremes lo and hi: region_contrast
	/// scaled by (lo + hi + 2 light_floor) / 256, capped at it, rounded up.
	int relativeRegionContrast(int lo, int hi) const
	{
		const int sum = std::min(lo + hi + 2 * light_floor, 2 * kLightReference);
		return (region_contrast * sum + 255) >> 8;
	}
	/// Whether the map of shaded regions (EdgeMap::shades) is made: with
	/// the region map, when the thresholds follow the light.
	bool makesShades() const { return region_contrast > 0 && light_floor < kLightReference; }
	/// The grey level added before the shade map's product (kept small: a
	/// shadowed white must stay above the geometric mean of a shadowed
	/// black and a lit white).
	static constexpr int kShadeFloor = 4;
	/// The shade map's threshold for tile extremes lo and hi that pass the
	/// contrast test: the least r with (r + 4)^2 >= (lo + 4)(hi + 4), so
	/// that r is dark exactly when (r + 4)^2 < (lo + 4)(hi + 4).
	/// (p >= 16, so r = ceil(sqrt(p)) - 4 >= 0.)
	static int shadeThreshold(int lo, int hi)
	{
		const int p = (lo + kShadeFloor) * (hi + kShadeFloor);
		/* A float square root of p (exact below 2^24) is within one of
		 * floor(sqrt(p)); the integer tests make it exact. */
		int s = static_cast<int>(std::sqrt(static_cast<float>(p)));
		s -= s * s > p;
		s += (s + 1) * (s + 1) <= p;
		return (s * s < p ? s + 1 : s) - kShadeFloor;
	}
};

/// A byte map the contour tracer follows: foreground pixels have bit 0
/// (kEdge) set, and a 16x16 tile mask says where any are.
struct FRAPPE_EXPORT TraceMap {
	static constexpr std::uint8_t kEdge = 1;
	static constexpr std::uint8_t kCorner = 2;
	static constexpr int kTile = 16; ///< side of an empty-tile mask block

	int width = 0;
	int height = 0;
	/// This map's resolution / full resolution; 1 when the frame was not scaled.
	float scale = 1.0f;
	/// width * height bytes, row-major. The outermost row and column on
	/// every side are always zero.
	std::vector<std::uint8_t> pixels;
	int tiles_x = 0;
	int tiles_y = 0;
	/// tiles_x * tiles_y bytes: 1 when the 16x16 block holds a foreground pixel.
	std::vector<std::uint8_t> tiles;

	/// Sizes the buffers; reuses their storage when the size is unchanged.
	void resize(int w, int h);
	std::uint8_t at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x]; }
	bool tileEmpty(int tx, int ty) const { return tiles[static_cast<std::size_t>(ty) * tiles_x + tx] == 0; }
};

/// The output of the front end for one frame, at the traced resolution:
/// kEdge | kCorner bits.
struct EdgeMap : TraceMap {
	/// The frame's dark regions at half the traced resolution (kEdge marks
	/// a dark pixel; the exact rule is at the top of front_end_cpu.cpp),
	/// the second source of candidates: blur spreads a marker's outline
	/// over several pixels and the one-pixel edge ring opens, but the dark
	/// region inside the outline stays whole. Empty (width 0) when region
	/// candidates are off or the frame is too small for them.
	TraceMap regions;
	/// The same dark regions judged on a log scale (the rule at the top of
	/// front_end_cpu.cpp: a pixel is dark below the geometric mean of the
	/// extremes around it, not their midpoint): across a blind's stripes a
	/// white in shadow stays light beside a black in the light, so the
	/// marker's black border is one region. Made with the region map when
	/// FrontEndParams::makesShades(); empty (width 0) otherwise.
	TraceMap shades;
};

/// Scaled frame size for a scale factor: the same rounding everywhere.
FRAPPE_EXPORT int scaledLength(int full, float scale);

/// A front-end implementation: nearest-neighbour scaling, Sobel gradients,
/// four-direction non-maximum suppression, the edge threshold, Shi-Tomasi
/// corners on edge pixels, the empty-tile mask and the region map, all in
/// one call. Implementations must produce byte-identical EdgeMaps; one that
/// does not make the region map (makesRegionMap()) gets the CPU's from the
/// Detector.
class FRAPPE_EXPORT FrontEnd {
public:
	virtual ~FrontEnd() = default;
	virtual const char *name() const = 0;
	/// Fills `out` (resizing it) for `image` sampled at `scale` (<= 1).
	virtual void run(const ImageView &image, float scale, const FrontEndParams &params,
			 EdgeMap &out) = 0;
	/// Whether run() fills out.regions and out.shades too; otherwise the
	/// Detector adds the CPU's.
	virtual bool makesRegionMap() const { return false; }
	/// Whether run() fills out.shades when it fills out.regions; otherwise
	/// the Detector adds the CPU's shade map (FrontEndParams::makesShades()).
	virtual bool makesShadeMap() const { return false; }
	/// Bytes of the last frame the front end copied into memory of its
	/// own before reading them (0 when it read the frame in place, as the
	/// CPU does), so that a zero-copy path can be checked and logged.
	virtual std::size_t lastCopyBytes() const { return 0; }
};

/// The reference CPU front end. `threads` > 1 splits the frame into row
/// bands processed in parallel; the output does not depend on it.
FRAPPE_EXPORT std::unique_ptr<FrontEnd> makeCpuFrontEnd(int threads = 1);

} // namespace frappe
