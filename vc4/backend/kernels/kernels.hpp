// SPDX-License-Identifier: MIT
// The QPU kernels of Frappe's front end (issue 6), reproducing frappe-core's CPU front end
// (frappe-core/src/front_end_cpu.cpp) byte for byte.
//
// Two passes over 64x32-pixel tiles of the scaled frame. A program invocation takes a list
// of tiles: its uniform stream is one block per tile (the structs below, in order), each
// followed by a `more` word, non-zero when another block follows. One launch of 12 programs
// covers a frame (tile t goes to program t % 12).
//
//  pass 1, gradientPass(): nearest-neighbour scaled fetch (per-lane TMU gathers whose
//    addresses implement scaleNearest's fixed-point mapping and the edge replication),
//    binomial smoothing, separable Sobel, squared magnitude, the four-way direction, and
//    the structure tensor's products summed over the three rows y-1 .. y+1.
//  pass 2, edgePass(): non-maximum suppression and the edge threshold, the Shi-Tomasi
//    minimum-eigenvalue test and corner threshold, and the 16x16 empty-tile mask.
//
// Gradient buffer (pass 1 -> pass 2): four 32-bit planes per pixel of the scaled frame,
// rows interleaved so that one 4-row VDW stores one image row of a 16-pixel strip:
//   byte offset of plane k at (x, y) = y * gradPitch + k * gradPitch / 4 + 4 x
//   gradPitch = 16 * paddedWidth (paddedWidth = width rounded up to 64), rows up to the
//   height rounded up to 32.
//   plane 0: B = m << 2 | dir      m = gx^2 + gy^2 < 2^21
//   plane 1..3: Vxx, Vyy, Vxy = sum over rows y-1 .. y+1 of gx^2, gy^2, gx*gy (signed)
//   dir: 0 horizontal (compare left/right), 1 vertical (up/down),
//        2 diagonal with gx*gy > 0 (up-left/down-right), 3 the other diagonal.
// gx = gy = 0 on the outermost rows and columns, as in the CPU's gradient rows. B keeps the
// direction beside m: B > thr << 2 | 3 decides m > thr without unpacking. Products go
// through mul24 on |gx|, |gy| (24-bit unsigned operands) with the sign put back, so every
// value is exact.
//
// Edge output: one byte per pixel (EdgeMap::kEdge | kCorner), rows of paddedWidth bytes.
// Pass 2 lanes hold pixels 4i + j (j = 0..3 in four sub-passes), so four bytes pack into the
// lane's word and a 16-word VPM row is a 64-pixel image row.
// Mask output: per tile two rows of 16 words (rows 0-15 and 16-31 of the tile); word 4t+3
// of a row is non-zero when the 16x16 block t of those rows holds an edge pixel (it is
// the OR of the block's edge bytes; the other words are partial ORs, ignored).
//
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

/// Pass 1 uniforms of one tile, in stream order; then for each of the four 16-pixel
/// strips the kGradientRowUniforms words of gradientRowUniforms(); then `more`.
struct GradientUniforms {
	uint32_t src_wmax;   ///< full width - 1
	uint32_t step_x;     ///< round(65536 * full width / scaled width), as scaleNearest
	uint32_t wmax;       ///< scaled width - 1
	uint32_t x0;         ///< tile origin in the scaled frame
	uint32_t dst;        ///< bus address of plane 0 at (x0, y0) in the gradient buffer
	uint32_t dst_pitch;  ///< gradPitch
	uint32_t vdw_stride; ///< VdwStride word: gradPitch / 4 - 64
};
inline constexpr unsigned kGradientUniforms = sizeof(GradientUniforms) / 4;
/// Per strip: the source-row address of input row y0-3, then for i = 0 .. 37 the address
/// of input row y0-2+i and the interior mask of gradient row y0-5+i (-1 for rows 1 .. h-2,
/// else 0). A row address is src + stride * min(H-1, ((2 clamp(r, 0, h-1) + 1) step_y) >> 17)
/// (scaleNearest's row, edge replicated); src and stride must be multiples of 4.
inline constexpr unsigned kGradientRowUniforms = 1 + 2 * 38;

/// Writes one strip's kGradientRowUniforms words for the tile at y0.
inline uint32_t *gradientRowUniforms(uint32_t *out, uint32_t src, uint32_t stride, int src_h, uint32_t step_y,
                                     int h, int y0)
{
	auto row = [&](int r) {
		const int y = r < 0 ? 0 : r > h - 1 ? h - 1 : r;
		const uint64_t sy = ((2 * static_cast<uint64_t>(y) + 1) * step_y) >> 17;
		return src + stride * static_cast<uint32_t>(sy < static_cast<uint64_t>(src_h - 1) ? sy : src_h - 1);
	};
	*out++ = row(y0 - 3);
	for (int i = 0; i < 38; ++i) {
		const int g = y0 - 5 + i;
		*out++ = row(y0 - 2 + i);
		*out++ = g >= 1 && g <= h - 2 ? 0xffffffffu : 0u;
	}
	return out;
}

/// Pass 2 uniforms of one tile, in stream order (then `more`).
struct EdgeUniforms {
	uint32_t grad;       ///< bus address of the gradient buffer (plane 0 at (0, 0))
	uint32_t grad_pitch; ///< gradPitch
	uint32_t plane;      ///< gradPitch / 4
	uint32_t wm2;        ///< scaled width - 2
	uint32_t hm2;        ///< scaled height - 2
	uint32_t x0;
	uint32_t y0;
	uint32_t edge_thr;   ///< clamp(edge_threshold_sq, -1, 2^22) << 2 | 3
	uint32_t corner_c;   ///< 2 * corner_threshold (int32 arithmetic, as the CPU)
	uint32_t edge_dst;   ///< bus address of byte (x0, y0) of the edge buffer
	uint32_t vdw_stride; ///< VdwStride word: edge pitch - 64
	uint32_t edge_pitch4;///< 4 * edge pitch: one block of four rows
	uint32_t mask_dst;   ///< bus address of this tile's 2 x 16 mask words
};
inline constexpr unsigned kEdgeUniforms = sizeof(EdgeUniforms) / 4;

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
	uint32_t contrast;   ///< FrontEndParams::region_contrast (> 0)
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
