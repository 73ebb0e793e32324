// SPDX-License-Identifier: MIT
#include "front_end_rows.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>

namespace frappe::detail {

void scaleNearest(const ImageView &src, int dstW, int dstH, std::uint8_t *dst)
{
	const std::uint64_t stepX = (static_cast<std::uint64_t>(src.width) * 65536u + dstW / 2) / dstW;
	const std::uint64_t stepY = (static_cast<std::uint64_t>(src.height) * 65536u + dstH / 2) / dstH;
	for (int y = 0; y < dstH; ++y) {
		const int sy = std::min<int>(src.height - 1, static_cast<int>(((2u * y + 1) * stepY) >> 17));
		const std::uint8_t *row = src.row(sy);
		std::uint8_t *out = dst + static_cast<std::size_t>(y) * dstW;
		for (int x = 0; x < dstW; ++x) {
			const int sx = std::min<int>(src.width - 1, static_cast<int>(((2u * x + 1) * stepX) >> 17));
			out[x] = row[sx];
		}
	}
}

void smoothRow(const std::uint8_t *a, const std::uint8_t *b, const std::uint8_t *c, int w,
	       std::uint8_t *out, std::uint16_t *tmp)
{
	/* Separable: the vertical [1 2 1] first, into 16 bits, then across. */
	for (int x = 0; x < w; ++x)
		tmp[x] = static_cast<std::uint16_t>(a[x] + 2 * b[x] + c[x]);
	if (w == 1) {
		out[0] = static_cast<std::uint8_t>((4 * tmp[0] + 8) >> 4);
		return;
	}
	out[0] = static_cast<std::uint8_t>((3 * tmp[0] + tmp[1] + 8) >> 4);
	for (int x = 1; x < w - 1; ++x)
		out[x] = static_cast<std::uint8_t>((tmp[x - 1] + 2 * tmp[x] + tmp[x + 1] + 8) >> 4);
	out[w - 1] = static_cast<std::uint8_t>((tmp[w - 2] + 3 * tmp[w - 1] + 8) >> 4);
}

void gradientRow(const std::uint8_t *a, const std::uint8_t *b, const std::uint8_t *c, int w,
		 std::int16_t *gx, std::int16_t *gy, std::int32_t *mag, std::int16_t *tmp)
{
	/* Separable Sobel: vertical smoothing and vertical difference per
	 * column, then the horizontal difference and smoothing. */
	std::int16_t *vs = tmp, *vd = tmp + w;
	for (int x = 0; x < w; ++x) {
		vs[x] = static_cast<std::int16_t>(a[x] + 2 * b[x] + c[x]);
		vd[x] = static_cast<std::int16_t>(c[x] - a[x]);
	}
	gx[0] = gy[0] = 0;
	mag[0] = 0;
	gx[w - 1] = gy[w - 1] = 0;
	mag[w - 1] = 0;
	for (int x = 1; x < w - 1; ++x) {
		const std::int32_t sx = vs[x + 1] - vs[x - 1];
		const std::int32_t sy = vd[x - 1] + 2 * vd[x] + vd[x + 1];
		gx[x] = static_cast<std::int16_t>(sx);
		gy[x] = static_cast<std::int16_t>(sy);
		mag[x] = sx * sx + sy * sy;
	}
}

void zeroGradientRow(int w, std::int16_t *gx, std::int16_t *gy, std::int32_t *mag)
{
	std::memset(gx, 0, sizeof(*gx) * 2 * w);
	std::memset(gy, 0, sizeof(*gy) * w);
	std::memset(mag, 0, sizeof(*mag) * w);
}

bool isCorner(const GradRows &rows, int x, std::int64_t cornerThreshold)
{
	std::int32_t sxx = 0, syy = 0, sxy = 0;
	for (int r = 0; r < 3; ++r) {
		for (int dx = -1; dx <= 1; ++dx) {
			const std::int32_t gx = rows.gx[r][x + dx];
			const std::int32_t gy = rows.gy[r][x + dx];
			sxx += gx * gx;
			syy += gy * gy;
			sxy += gx * gy;
		}
	}
	/* In 32 bits (the QPU has no wider multiply): the sums are below 2^24.2
	 * and D <= S^2, so after >> 9 every square below fits in an int32. */
	const std::int32_t c = (sxx + syy - 2 * static_cast<std::int32_t>(cornerThreshold)) >> 9;
	if (c <= 0)
		return false;
	const std::int32_t a = std::abs(sxx - syy) >> 9;
	const std::int32_t b = std::abs(sxy) >> 8;
	return c * c > a * a + b * b;
}

bool edgeRow(const GradRows &rows, int w, const FrontEndParams &params, std::uint8_t *out)
{
	out[0] = 0;
	out[w - 1] = 0;
	return edgeSpan(rows, 1, w - 1, params, out);
}

bool edgeSpan(const GradRows &rows, int x0, int x1, const FrontEndParams &params, std::uint8_t *out)
{
	const std::int32_t *up = rows.mag[0];
	const std::int32_t *mid = rows.mag[1];
	const std::int32_t *down = rows.mag[2];
	const std::int16_t *gxr = rows.gx[1];
	const std::int16_t *gyr = rows.gy[1];
	const std::int32_t edgeT = edgeThreshold(params), cornerT = cornerThreshold(params);
	const std::int32_t least = leastEdgeThreshold(params);
	bool any = false;
	for (int x = x0; x < x1; ++x) {
		const std::int32_t m = mid[x];
		std::uint8_t v = 0;
		if (m > least && m > params.relativeThreshold(edgeT, rows.smooth[x])) {
			const int gx = gxr[x], gy = gyr[x];
			const int ax = std::abs(gx), ay = std::abs(gy);
			std::int32_t prev, next;
			if (256 * ay <= 106 * ax) {
				prev = mid[x - 1];
				next = mid[x + 1];
			} else if (256 * ax <= 106 * ay) {
				prev = up[x];
				next = down[x];
			} else if ((gx > 0) == (gy > 0)) {
				prev = up[x - 1];
				next = down[x + 1];
			} else {
				prev = up[x + 1];
				next = down[x - 1];
			}
			if (m > prev && m >= next) {
				v = EdgeMap::kEdge;
				if (isCorner(rows, x, params.relativeThreshold(cornerT, rows.smooth[x])))
					v |= EdgeMap::kCorner;
				any = true;
			}
		}
		out[x] = v;
	}
	return any;
}

void markTiles(const std::uint8_t *edgeRow, int w, std::uint8_t *tileRow)
{
#ifdef FRAPPE_HAVE_ARMV6_KERNELS
	markTilesV6(edgeRow, w, tileRow);
#else
	markTilesScalar(edgeRow, w, tileRow);
#endif
}

void markTilesScalar(const std::uint8_t *edgeRow, int w, std::uint8_t *tileRow)
{
	int x0 = 0, t = 0;
	for (; x0 + EdgeMap::kTile <= w; x0 += EdgeMap::kTile, ++t) {
		std::uint64_t a, b;
		std::memcpy(&a, edgeRow + x0, 8);
		std::memcpy(&b, edgeRow + x0 + 8, 8);
		/* Branchless: whether a tile holds an edge is not predictable. */
		tileRow[t] |= static_cast<std::uint8_t>((a | b) != 0);
	}
	if (x0 < w) {
		std::uint8_t acc = 0;
		for (int x = x0; x < w; ++x)
			acc |= edgeRow[x];
		if (acc)
			tileRow[t] = 1;
	}
}

const RowKernels &scalarRowKernels()
{
	static constexpr RowKernels kScalar{ "scalar", smoothRow, gradientRow, edgeRow };
	return kScalar;
}

const BandKernels &scalarBandKernels()
{
	static constexpr BandKernels kScalar{ "scalar", [](const BandJob &job) {
		runBandRows(scalarRowKernels(), job);
	} };
	return kScalar;
}

#ifndef FRAPPE_HAVE_HWY
const BandKernels &bestBandKernels()
{
#ifdef FRAPPE_HAVE_ARMV6_KERNELS
	return armv6BandKernels();
#else
	return scalarBandKernels();
#endif
}

const char *simdTargetName()
{
#ifdef FRAPPE_HAVE_ARMV6_KERNELS
	return "ARMv6 SIMD32";
#else
	return "scalar";
#endif
}
#endif

} // namespace frappe::detail
