// SPDX-License-Identifier: MIT
// PERSPECTIVE_WARP (the fixed-point warp, its float fallback and the warps
// built on them) and BINARISE_DECODE.
#include "decode.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include "frappe/homography.h"
#include "corner_refine.h"
#include "warp_kernels.h"

namespace frappe::detail {

float Tone::apply(float v) const
{
	if (linear())
		return v;
	if (expScale > 0.0f)
		return 255.0f * std::expm1(std::clamp(v, 0.0f, 255.0f) / expScale) / std::expm1(255.0f / expScale);
	return 255.0f * std::log1p(std::max(v, 0.0f) / logFloor) / std::log1p(255.0f / logFloor);
}

float Tone::invert(float v) const
{
	if (linear())
		return v;
	if (expScale > 0.0f)
		return expScale * std::log1p(std::max(v, 0.0f) / 255.0f * std::expm1(255.0f / expScale));
	return logFloor * std::expm1(v / 255.0f * std::log1p(255.0f / logFloor));
}

/* The log scale's samples as they have always been computed (a factor,
 * not a division: a read's floats do not move). */
namespace {
float logSample(float v, float k, float norm)
{
	return norm * std::log1p(std::max(v, 0.0f) * k);
}
} // namespace

void Tone::apply(WarpedMarker &w) const
{
	if (linear())
		return;
	const float k = 1.0f / logFloor, norm = 255.0f / std::log1p(255.0f * k);
	for (int i = 0; i < w.side * w.side; ++i) {
		float &v = w.samples[static_cast<std::size_t>(i)];
		if (table) {
			/* Between whole levels, along the chord: within 0.05 of a
			 * grey level of the curve, at a fraction of a log's cost
			 * (soft-float on ARMv6). */
			const float c = std::clamp(v, 0.0f, 255.0f);
			const int g = std::min(static_cast<int>(c), 254);
			v = table[g] + (c - static_cast<float>(g)) * (table[g + 1] - table[g]);
		} else {
			v = expScale > 0.0f ? apply(v) : logSample(v, k, norm);
		}
	}
}

void Tone::fillTable(float *out256) const
{
	const float k = 1.0f / logFloor, norm = 255.0f / std::log1p(255.0f * k);
	for (int g = 0; g < 256; ++g)
		out256[g] = expScale > 0.0f ? apply(static_cast<float>(g)) : logSample(static_cast<float>(g), k, norm);
}

bool WarpMemo::warp(const ImageView &image, const std::array<Point2f, 4> &corners, int side, bool fine,
		    WarpedMarker &out)
{
	for (int i = 0; i < used_; ++i) {
		const Entry &e = entries_[static_cast<std::size_t>(i)];
		/* Corners compared as bits: the same floats, the same warp. */
		if (e.side == side && e.fine == fine && e.image.data == image.data && e.image.width == image.width &&
		    e.image.height == image.height && e.image.stride == image.stride &&
		    std::memcmp(e.corners.data(), corners.data(), sizeof corners) == 0) {
			if (e.ok) {
				out.side = e.samples.side;
				std::copy_n(e.samples.samples.begin(), side * side, out.samples.begin());
			}
			return e.ok;
		}
	}
	Entry &e = entries_[static_cast<std::size_t>(next_)];
	next_ = (next_ + 1) % kEntries;
	used_ = std::min(used_ + 1, kEntries);
	e.image = image;
	e.corners = corners;
	e.side = side;
	e.fine = fine;
	e.ok = warpToGrid(image, corners, side, e.samples, fine);
	if (e.ok) {
		out.side = e.samples.side;
		std::copy_n(e.samples.samples.begin(), side * side, out.samples.begin());
	}
	return e.ok;
}

bool warpMarker(const ImageView &image, const std::array<Point2f, 4> &corners, int bits, WarpedMarker &out, Tone tone,
		WarpMemo *memo)
{
	const int side = (bits + 2) * kSamplesPerCell;
	if (!(memo ? memo->warp(image, corners, side, false, out) : warpToGrid(image, corners, side, out)))
		return false;
	tone.apply(out);
	return true;
}

namespace {

using FloatSampler = void (*)(const ImageView &, const Homography &, int, bool, float *);
using FixedSampler = void (*)(const ImageView &, const FixedWarp &, bool, float *);

/* The warp: the fixed point's (frappe/fixed_warp.h) where it holds the quad,
 * else the float one, the single fallback every backend shares. */
bool warpWith(FixedSampler fixed, FloatSampler sample, const ImageView &image,
	      const std::array<Point2f, 4> &corners, int side, bool fine, WarpedMarker &out)
{
	if (image.width >= 2 && image.height >= 2) {
		if (const auto w = quantiseWarp(corners, side)) {
			out.side = side;
			fixed(image, *w, fine, out.samples.data());
			return true;
		}
	}
	const auto H = Homography::fromUnitSquare(corners);
	if (!H)
		return false;
	out.side = side;
	/* The samples lie inside the quad when the homography's denominator
	 * is positive over the unit square (it is linear there, so at its
	 * corners; a convex quad's is): then, when the quad's corners are at
	 * least a pixel inside the image, no sample needs clamping. */
	const auto &h = H->h;
	bool inside = image.width >= 2 && image.height >= 2 && h[8] + h[6] > 0.0 && h[8] + h[7] > 0.0 &&
		      h[8] + h[6] + h[7] > 0.0;
	for (const Point2f &c : corners)
		inside = inside && c.x >= 0.0f && c.y >= 0.0f && c.x <= static_cast<float>(image.width - 2) &&
			 c.y <= static_cast<float>(image.height - 2);
	sample(image, *H, side, inside, out.samples.data());
	return true;
}

} // namespace

bool warpToGrid(const ImageView &image, const std::array<Point2f, 4> &corners, int side, WarpedMarker &out,
		bool fine)
{
	return warpWith(warpFixedSamples, warpSamples, image, corners, side, fine, out);
}

bool warpToGridScalar(const ImageView &image, const std::array<Point2f, 4> &corners, int side, WarpedMarker &out,
		      bool fine)
{
	return warpWith(warpFixedSamplesScalar, warpSamplesScalar, image, corners, side, fine, out);
}

bool warpCellCentres(const ImageView &image, const std::array<Point2f, 4> &corners, int bits, float sharpening,
		     WarpedMarker &out, float *reference, Tone tone, WarpMemo *memo, float *lightest)
{
	const auto H = Homography::fromUnitSquare(corners);
	if (!H)
		return false;
	const int cells = bits + 2, side = cells + 2;
	/* The quad grown by a cell on every side: its grid of side x side
	 * samples puts one at the centre of every cell, ring included. */
	const double m = 1.0 / cells;
	const std::array<Point2f, 4> grown = { H->map(-m, -m), H->map(1 + m, -m), H->map(1 + m, 1 + m),
					       H->map(-m, 1 + m) };
	WarpedMarker grid;
	if (!(memo ? memo->warp(image, grown, side, true, grid) : warpToGrid(image, grown, side, grid, true)))
		return false;
	tone.apply(grid);
	out.side = cells;
	/* The grey level between the black border and the ring around it. */
	float border = 0.0f, ring = 0.0f;
	for (int c = 0; c < side; ++c) {
		ring += grid.at(c, 0) + grid.at(c, side - 1);
		if (c > 0 && c < side - 1)
			ring += grid.at(0, c) + grid.at(side - 1, c);
	}
	for (int c = 1; c < side - 1; ++c) {
		border += grid.at(c, 1) + grid.at(c, side - 2);
		if (c > 1 && c < side - 2)
			border += grid.at(1, c) + grid.at(side - 2, c);
	}
	const float ringMean = ring / static_cast<float>(4 * (side - 1));
	const float borderMean = border / static_cast<float>(4 * (cells - 1));
	if (reference)
		*reference = 0.5f * (ringMean + borderMean);
	if (lightest) {
		*lightest = grid.at(2, 2);
		for (int y = 2; y <= bits + 1; ++y)
			for (int x = 2; x <= bits + 1; ++x)
				*lightest = std::max(*lightest, grid.at(x, y));
	}
	for (int y = 0; y < cells; ++y) {
		for (int x = 0; x < cells; ++x) {
			const float c = grid.at(x + 1, y + 1);
			const float around =
				grid.at(x, y + 1) + grid.at(x + 2, y + 1) + grid.at(x + 1, y) + grid.at(x + 1, y + 2);
			out.samples[static_cast<std::size_t>(y) * cells + x] = c + sharpening * (4.0f * c - around);
		}
	}
	return true;
}

bool insetCorners(const ImageView &image, std::array<Point2f, 4> &corners, int bits)
{
	const auto H = Homography::fromUnitSquare(corners);
	if (!H)
		return false;
	const double m = 1.0 / (bits + 4);
	std::array<Point2f, 4> inner = { H->map(m, m), H->map(1 - m, m), H->map(1 - m, 1 - m), H->map(m, 1 - m) };
	float cell = 1e9f;
	for (int i = 0; i < 4; ++i) {
		const float dx = inner[i].x - inner[(i + 1) & 3].x, dy = inner[i].y - inner[(i + 1) & 3].y;
		cell = std::min(cell, std::sqrt(dx * dx + dy * dy) / static_cast<float>(bits + 2));
	}
	if (!refineCorners(image, inner, std::max(1.5f, 1.2f * cell)))
		return false;
	corners = inner;
	return true;
}

bool insetQuad(const ImageView &image, std::array<Point2f, 4> &corners, int bits,
	       WarpedMarker &out, Tone tone)
{
	std::array<Point2f, 4> inner = corners;
	if (!insetCorners(image, inner, bits) || !warpMarker(image, inner, bits, out, tone))
		return false;
	corners = inner;
	return true;
}

namespace {

/* binarise() with k samples a cell side; a constant K (the grids of
 * warpMarker, 2, and of cell centres, 1) lets the cell means unroll: the
 * same sums in the same order, so the same floats. */
template<int K>
Binarised binariseWith(const WarpedMarker &w, int bits, int kAny)
{
	const int cells = bits + 2;
	const int k = K > 0 ? K : kAny;
	float lo = 1e9f, hi = -1e9f;
	for (int y = k; y < (bits + 1) * k; ++y) {
		for (int x = k; x < (bits + 1) * k; ++x) {
			lo = std::min(lo, w.at(x, y));
			hi = std::max(hi, w.at(x, y));
		}
	}
	const float thr = lo + 0.5f * (hi - lo);
	auto mean = [&](int cx, int cy) { return cellMean(w, k, cx, cy); };
	Binarised out;
	out.contrast = hi - lo;
	out.threshold = thr;
	for (int cy = 1; cy <= bits; ++cy) {
		for (int cx = 1; cx <= bits; ++cx)
			out.code = (out.code << 1) | (mean(cx, cy) > thr ? 1u : 0u);
	}
	for (int c = 0; c < cells; ++c) {
		out.border_errors += mean(c, 0) > thr;
		out.border_errors += mean(c, cells - 1) > thr;
	}
	for (int c = 1; c < cells - 1; ++c) {
		out.border_errors += mean(0, c) > thr;
		out.border_errors += mean(cells - 1, c) > thr;
	}
	return out;
}

} // namespace

Binarised binarise(const WarpedMarker &w, int bits)
{
	const int k = std::max(1, w.side / (bits + 2)); /* samples per cell side */
	if (k == kSamplesPerCell)
		return binariseWith<kSamplesPerCell>(w, bits, k);
	if (k == 1)
		return binariseWith<1>(w, bits, k);
	return binariseWith<0>(w, bits, k);
}

namespace {

/* Set bits of a word. ARMv6 has no population count: GCC would call
 * libgcc's __popcountdi2 for every codeword and rotation, so there the
 * bits are summed in place; elsewhere the instruction (or libgcc's best). */
#if defined(__arm__) && !defined(__ARM_NEON)
inline int bitCount32(std::uint32_t x)
{
	x = x - ((x >> 1) & 0x55555555u);
	x = (x & 0x33333333u) + ((x >> 2) & 0x33333333u);
	x = (x + (x >> 4)) & 0x0F0F0F0Fu;
	return static_cast<int>((x * 0x01010101u) >> 24);
}
#else
inline int bitCount(std::uint64_t v)
{
	return std::popcount(v);
}
#endif

/* rotations[r]: the code as read with quad corner r as the top-left. Reading
 * from corner 1 sees the grid turned a quarter anticlockwise, i.e. three
 * quarter turns clockwise; from corner 3, one. */
std::array<std::uint64_t, 4> rotationsOf(std::uint64_t code, const Dictionary &dict)
{
	const std::uint64_t one = dict.rotate(code), two = dict.rotate(one);
	return { code, dict.rotate(two), two, one };
}

} // namespace

namespace {

/* The nearest codeword is a popcount per codeword and rotation; without
 * -mpopcnt GCC calls a library routine for each, so on x86 a second copy
 * with the POPCNT instruction is chosen at load time. (In an anonymous
 * namespace: GCC exports the ifunc of target_clones whatever its
 * visibility, and the library exports no internals.) Not under
 * ThreadSanitizer, which instruments the ifunc's resolver: it runs while
 * the program is loaded, before the sanitizer's runtime, and crashes. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_THREAD__)
__attribute__((target_clones("popcnt", "default")))
#endif
Decoded nearestCode(const Dictionary &dict, std::uint64_t code, int maxHamming)
{
	const std::array<std::uint64_t, 4> rotations = rotationsOf(code, dict);
	/* The nearest id and the nearest other id: an id's distance is its
	 * nearest rotation's. Ids further than the runner-up cannot matter. */
	const int words = dict.codeBits();
	Decoded best;
	best.hamming = words + 1;
	best.runnerUp = words + 1;
	const int n = dict.size();
	for (int id = 0; id < n; ++id) {
		const std::uint64_t word = dict.codes[id];
		int nearest = words + 1, rotation = 0;
		for (int r = 0; r < 4; ++r) {
#if defined(__arm__) && !defined(__ARM_NEON)
			/* Without a popcount instruction, count the low 32 bits first:
			 * most words already differ there in more bits than the
			 * runner-up. */
			const std::uint64_t x = word ^ rotations[r];
			const int low = bitCount32(static_cast<std::uint32_t>(x));
			if (low >= best.runnerUp)
				continue;
			const int d = low + bitCount32(static_cast<std::uint32_t>(x >> 32));
#else
			const int d = bitCount(word ^ rotations[r]);
#endif
			if (d < nearest) {
				nearest = d;
				rotation = r;
			}
		}
		if (nearest < best.hamming) {
			best.runnerUp = best.hamming;
			best.id = id;
			best.hamming = nearest;
			best.rotation = rotation;
		} else if (nearest < best.runnerUp) {
			best.runnerUp = nearest;
		}
	}
	if (best.id < 0 || best.hamming > maxHamming || best.runnerUp == best.hamming)
		return { -1, 0, 0, best.runnerUp };
	return best;
}

} // namespace

Decoded decode(const Dictionary &dict, std::uint64_t code, int maxHamming)
{
	return nearestCode(dict, code, maxHamming);
}

bool plainCode(std::uint64_t code, int n)
{
	/* Cell (r, c) of the code with its border: 0 (black) outside the code. */
	auto cell = [&](int r, int c) {
		if (r < 0 || c < 0 || r >= n || c >= n)
			return 0;
		return static_cast<int>((code >> (n * n - 1 - (r * n + c))) & 1u);
	};
	int changes = 0;
	for (int r = -1; r < n; ++r)
		for (int c = -1; c < n; ++c) {
			changes += r >= 0 && cell(r, c) != cell(r, c + 1); /* rows: code cells and the border's */
			changes += c >= 0 && cell(r, c) != cell(r + 1, c); /* columns */
		}
	return 5 * changes <= 3 * n * (n + 1);
}

CodeBook::CodeBook(const Dictionary &dict) : dict_(&dict)
{
	sorted_.reserve(dict.codes.size());
	plain_.reserve(dict.codes.size());
	for (int id = 0; id < dict.size(); ++id) {
		sorted_.emplace_back(dict.codes[id], id);
		plain_.push_back(plainCode(dict.codes[id], dict.bits) ? 1 : 0);
	}
	std::sort(sorted_.begin(), sorted_.end());
}

Decoded CodeBook::decode(std::uint64_t code, int maxHamming) const
{
	if (maxHamming < 0)
		return {};
	/* decode() takes the lowest id at distance 0 and the lowest rotation
	 * for it, and calls two ids at distance 0 ambiguous. */
	const std::array<std::uint64_t, 4> rotations = rotationsOf(code, *dict_);
	Decoded exact;
	for (int r = 0; r < 4; ++r) {
		auto it = std::lower_bound(sorted_.begin(), sorted_.end(), std::make_pair(rotations[r], -1));
		for (; it != sorted_.end() && it->first == rotations[r]; ++it) {
			if (exact.id < 0)
				exact = { it->second, 0, r, std::max(1, dict_->min_hamming) };
			else if (it->second != exact.id)
				return {};
		}
	}
	if (exact.id >= 0)
		return exact;
	return maxHamming > 0 ? frappe::detail::decode(*dict_, code, maxHamming) : Decoded{};
}

Decoded DecodeCache::decode(const CodeBook &codes, std::uint64_t code, int maxHamming)
{
	/* Fibonacci hashing of the code, the distance mixed in. */
	const std::uint64_t key = code ^ static_cast<std::uint64_t>(static_cast<std::uint32_t>(maxHamming)) << 56;
	Entry &e = entries_[static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> 56)];
	static_assert(kEntries == 256);
	if (e.codes != &codes || e.code != code || e.maxHamming != maxHamming) {
		e.codes = &codes;
		e.code = code;
		e.maxHamming = maxHamming;
		e.decoded = codes.decode(code, maxHamming);
	}
	return e.decoded;
}

} // namespace frappe::detail

namespace frappe {

namespace {

class CpuWarper final : public CandidateWarper {
public:
	const char *name() const override { return "cpu"; }
	void warp(const ImageView &image, std::span<const std::array<Point2f, 4>> quads, int side,
		  std::span<CandidateSamples> out, std::span<std::uint8_t> ok) override
	{
		for (std::size_t k = 0; k < quads.size(); ++k)
			ok[k] = detail::warpToGrid(image, quads[k], side, out[k]) ? 1 : 0;
	}
};

} // namespace

std::unique_ptr<CandidateWarper> makeCpuWarper()
{
	return std::make_unique<CpuWarper>();
}

} // namespace frappe
