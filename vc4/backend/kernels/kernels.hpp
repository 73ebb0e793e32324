// SPDX-License-Identifier: MIT
// The QPU kernels of Frappe's front end (issue 6), reproducing frappe-core's CPU front end
// (frappe-core/src/front_end/front_end_cpu.cpp) byte for byte.
//
// Two passes over the scaled frame, one launch of 12 programs each. A program invocation
// takes a list of work units: its uniform stream is a header (the first struct below) then
// one block per unit, each followed by a `more` word, non-zero when another block follows.
//
//  pass 1, gradientPass(): units are strips of 16 lanes (pixels x + 4i of a 64-pixel
//    group) over a band of rows. Nearest-neighbour scaled fetch (per-lane TMU gathers
//    whose addresses implement scaleNearest's fixed-point mapping and the edge
//    replication), binomial smoothing, separable Sobel, squared magnitude, the four-way
//    direction, and the structure tensor's products summed over the rows y-1 .. y+1.
//  pass 2, edgePass(): units are 64x16 half tiles. Non-maximum suppression and the edge
//    threshold, the Shi-Tomasi minimum-eigenvalue test and corner threshold, and the
//    16x16 empty-tile mask.
//
// Gradient buffer (pass 1 -> pass 2): four 32-bit planes per pixel of the scaled frame.
// A row of a plane is paddedWidth words (width rounded up to 64), interleaved within each
// 64-pixel group so that the 16 pixels x0 + 4i + j (i = 0..15) are one 16-word run: word
// gradWord(x) = (x & ~63) + 16 (x & 3) + (x & 63) / 4. Rows interleave the planes, so one
// 4-row VDW stores one image row of a pass-1 strip:
//   byte offset of plane k at (x, y) = y * gradPitch + k * gradPitch / 4 + 4 gradWord(x)
//   gradPitch = 16 * paddedWidth; rows 0 .. height-1 are written.
//   plane 0: B = q << 24 | m << 2 | dir   m = gx^2 + gy^2 < 2^21, q = min(p + light_floor,
//            128) at the pixel's smoothed value p: its thresholds follow the light
//   plane 1..3: Vxx, Vyy, Vxy = sum over rows y-1 .. y+1 of gx^2, gy^2, gx*gy (signed)
//   dir: 0 horizontal (compare left/right), 1 vertical (up/down),
//        2 diagonal with gx*gy > 0 (up-left/down-right), 3 the other diagonal.
// gx = gy = 0 on the outermost rows and columns, as in the CPU's gradient rows. B keeps the
// direction beside m, and q where pass 2 unpacks it for free (byte 3, regfile-A unpack
// .8d); m's comparisons need the low 24 bits only (differences shifted left by 8, or
// mul24, which reads 24 bits). Products go through mul24 on |gx|, |gy| (24-bit unsigned
// operands) with the sign put back, so every value is exact. Pass 2 reads a row above and below every row and a word left and right
// of every group: the buffer needs a margin (gradMargin()) on both sides.
//
// Edge output: one byte per pixel (EdgeMap::kEdge | kCorner), rows of paddedWidth bytes.
// Pass 2 lanes hold pixels 4i + j (j = 0..3), so four bytes pack into the lane's word and
// a 16-word VPM row is a 64-pixel image row.
// Mask output: per tile two rows of 16 words (rows 0-15 and 16-31 of the tile); word 4t+3
// of a row is non-zero when the 16x16 block t of those rows holds an edge pixel (it is
// the OR of the block's edge bytes; the other words are partial ORs, ignored).
//
// TMU: at most kTmuDepth (tmu_depth.hpp, meson option vc4_tmu_depth) requests in flight
// per QPU, both TMUs together; the lint and the emulator's strict mode hold both passes to it.
// VPM: each QPU uses the 8 rows starting at 8 * qpu_num (96 of the 192 rows), so twelve
// invocations run at once with no locking of VPM space; VDW setup and start are done under
// the hardware mutex, as GPU_FFT does, because the guide does not say that the VCD's setup
// registers are per QPU. Limits: width <= 2048 (the VDW stride field holds 13 bits).
#pragma once

#include <cstdint>

#include "asm/program.hpp"

namespace frappe::vc4::kernels {

inline constexpr int kTileW = 64;
inline constexpr int kTileH = 32;
inline constexpr int kMaxWidth = 2048;
/// Rows of a pass-2 unit (half a tile: one mask row).
inline constexpr int kEdgeRows = 16;

/// The word of pixel x in a gradient-buffer row (the interleaved 64-pixel groups).
inline constexpr uint32_t gradWord(uint32_t x) { return (x & ~63u) + 16 * (x & 3u) + ((x & 63u) >> 2); }
/// Bytes before and after the gradient rows that pass 2 may read: a row above the first,
/// two below the last (a unit's last row gathers the next row's first columns), and a
/// group's worth of words beside them.
inline constexpr uint32_t gradMargin(uint32_t grad_pitch) { return 2 * grad_pitch + 256; }

/// Pass 1 uniforms: the header, once per program.
struct GradientUniforms {
	uint32_t src_wmax;   ///< full width - 1
	uint32_t step_x;     ///< round(65536 * full width / scaled width), as scaleNearest
	uint32_t wmax;       ///< scaled width - 1
	uint32_t dst_pitch;  ///< gradPitch
	uint32_t vdw_stride; ///< VdwStride word: gradPitch / 4 - 64
	uint32_t light_floor;///< clamp(FrontEndParams::light_floor, 0, 128)
};
inline constexpr unsigned kGradientUniforms = sizeof(GradientUniforms) / 4;
/// Pass 1 unit: a strip over a band of rows; then gradientRowUniforms(rows) words, `more`.
struct GradientUnit {
	uint32_t x;    ///< lane i holds pixel x + 4i (x = x0 + strip, x0 a multiple of 64)
	uint32_t dst;  ///< bus address of plane 0 at (x, y0): the strip's 16-word run
	uint32_t rows; ///< rows of the band, y0 .. y0 + rows - 1
};
inline constexpr unsigned kGradientUnitUniforms = sizeof(GradientUnit) / 4;
/// Row words of a band of `rows` rows.
inline constexpr unsigned gradientRowUniformCount(int rows) { return 1 + 2 * (static_cast<unsigned>(rows) + 6); }

/// Writes a band's row words: the source-row address of input row y0-3, then for
/// i = 0 .. rows+5 the address of input row y0-2+i and the interior mask of gradient row
/// y0-5+i (-1 for rows 1 .. h-2, else 0). A row address is
/// src + stride * min(H-1, ((2 clamp(r, 0, h-1) + 1) step_y) >> 17) (scaleNearest's row,
/// edge replicated); src and stride must be multiples of 4.
inline uint32_t *gradientRowUniforms(uint32_t *out, uint32_t src, uint32_t stride, int src_h, uint32_t step_y,
                                     int h, int y0, int rows)
{
	auto row = [&](int r) {
		const int y = r < 0 ? 0 : r > h - 1 ? h - 1 : r;
		const uint64_t sy = ((2 * static_cast<uint64_t>(y) + 1) * step_y) >> 17;
		return src + stride * static_cast<uint32_t>(sy < static_cast<uint64_t>(src_h - 1) ? sy : src_h - 1);
	};
	*out++ = row(y0 - 3);
	for (int i = 0; i < rows + 6; ++i) {
		const int g = y0 - 5 + i;
		*out++ = row(y0 - 2 + i);
		*out++ = g >= 1 && g <= h - 2 ? 0xffffffffu : 0u;
	}
	return out;
}

/// Pass 2 uniforms: the header, once per program.
struct EdgeUniforms {
	uint32_t grad_pitch; ///< gradPitch
	uint32_t edge_thr;   ///< E' = clamp(edge_threshold_sq, 0, 2^22) (-1 acts as 0: m > 0 anyway)
	uint32_t corner_t;   ///< T = clamp(corner_threshold, 0, 2^23 - 1)
	uint32_t vdw_stride; ///< VdwStride word: edge pitch - 64
	uint32_t edge_pitch4;///< 4 * edge pitch: one block of four rows
};
inline constexpr unsigned kEdgeUniforms = sizeof(EdgeUniforms) / 4;
/// Pass 2 unit: 64 x kEdgeRows pixels at (x0, y0); then the kEdgeRows rows' interior
/// masks (-1 for rows 1 .. h-2, else 0), then `more`.
struct EdgeUnit {
	uint32_t x0;         ///< a multiple of 64
	uint32_t wm2;        ///< scaled width - 2
	uint32_t grad;       ///< bus address of plane 0 at (x0, y0 - 1) in the gradient buffer
	uint32_t plane;      ///< gradPitch / 4
	uint32_t edge_dst;   ///< bus address of byte (x0, y0) of the edge buffer
	uint32_t mask_dst;   ///< bus address of the unit's 16 mask words
};
inline constexpr unsigned kEdgeUnitUniforms = sizeof(EdgeUnit) / 4;

struct Built {
	qasm::Program program;
	unsigned nops = 0; ///< slots the builder filled with nops (hazards it could not fill)
};

Built gradientPass();
Built edgePass();

// The region map (EdgeMap::regions; kernels/pass_region.cpp): two launches over blocks of
// 64 x 16 pixels of the map (w = W / 2 by h = H / 2 for a W x H scaled frame), block b on
// program b % 12. Lane i holds pixels x0 + 4i .. x0 + 4i + 3, one byte each in its word.
// Region buffer (means -> dark), pitch P = w rounded up to 64, for tile row t (map rows
// 4t .. 4t+3) five rows at buffer + 5 t P: the four rows of r = (2x2 sum + 2) >> 2, then
// the tile words, lo | (255 - hi) << 8 at byte 4c for tile c (bytes 2, 3 undefined).
// Rows and columns past the map repeat its last (their tiles are never read).
// Output: dark bytes (kEdge or 0), rows of P bytes; per block a row of 16 mask words
// (non-zero in one of words 4t .. 4t+3 when 16 x 16 block t holds a dark pixel).
inline constexpr int kRegionBlockW = 64;
inline constexpr int kRegionBlockH = 16;

/// Means pass uniforms of one block; then regionSourceRows()'s kRegionSourceRows words,
/// then `more`.
struct RegionMeansUniforms {
	uint32_t src_wmax;   ///< full width - 1
	uint32_t step_x;     ///< as GradientUniforms::step_x
	uint32_t rwmax;      ///< w - 1
	uint32_t x0;         ///< block origin in the map
	uint32_t dst;        ///< bus address of the block's first row: buffer + 5 (y0 / 4) P + x0
	uint32_t vdw_stride; ///< VdwStride word: P - 64
	uint32_t dst_step;   ///< 5 P: one tile row
};
inline constexpr unsigned kRegionMeansUniforms = sizeof(RegionMeansUniforms) / 4;
/// For map rows y0 .. y0 + 16 (clamped to h - 1; the last is read ahead), the source-row
/// addresses of scaled rows 2y and 2y + 1 (scaleNearest's rows; src, stride multiples of 4).
inline constexpr unsigned kRegionSourceRows = 2 * (kRegionBlockH + 1);
uint32_t *regionSourceRows(uint32_t *out, uint32_t src, uint32_t stride, int src_h, uint32_t step_y, int h, int y0);

/// Dark pass uniforms of one block; then regionTileRows()'s kRegionTileRows words, then
/// `more`.
struct RegionDarkUniforms {
	uint32_t contrast;   ///< min(FrontEndParams::region_contrast, 65536) (> 0)
	uint32_t floor2;     ///< 2 clamp(FrontEndParams::light_floor, 0, 128)
	uint32_t x0;
	uint32_t txm1;       ///< tiles across - 1: (w + 3) / 4 - 1
	uint32_t rwm2;       ///< w - 2
	uint32_t out_dst;    ///< bus address of output byte (x0, y0)
	uint32_t vdw_stride; ///< VdwStride word: P - 64
	uint32_t out_pitch4; ///< 4 P
	uint32_t mask_dst;   ///< bus address of this block's 16 mask words
};
inline constexpr unsigned kRegionDarkUniforms = sizeof(RegionDarkUniforms) / 4;
/// Per tile row of the block: the tile-word rows of tile rows t - 1, t, t + 1 (clamped to
/// those that exist), the addresses of its four rows of r, and their masks (-1 for map
/// rows 1 .. h-2, else 0).
inline constexpr unsigned kRegionTileRows = 4 * 11;
uint32_t *regionTileRows(uint32_t *out, uint32_t buffer, uint32_t pitch, int h, int y0);

Built regionMeansPass();
Built regionDarkPass();

} // namespace frappe::vc4::kernels
