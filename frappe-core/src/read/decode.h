// SPDX-License-Identifier: MIT
// PERSPECTIVE_WARP and BINARISE_DECODE.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "frappe/candidate_warp.h"
#include "frappe/dictionary.h"
#include "frappe/image.h"

namespace frappe::detail {

/// Samples per cell side: each bit is the mean of 2x2 samples.
constexpr int kSamplesPerCell = 2;


/// The warped samples of one candidate: (bits + 2) cells a side, 2x2 samples
/// a cell (16x16 for 6x6 codes).
using WarpedMarker = CandidateSamples;

/// The scale a candidate's samples are read on. Grey levels first; then,
/// where the light is dim or changes across the marker (a blind's stripes,
/// a cast shadow's edge), a log scale: light that multiplies every grey
/// level (a shadow, a dim room) only shifts it there, so one threshold
/// between black and white holds across a shadow's edge. Where the whites
/// clip, an exponential scale: the true white lies somewhere above 255, so
/// the midpoint between black and the clipped white is too dark a
/// threshold (a blurred black cell among white ones reads white); on this
/// scale the threshold rises towards the ceiling.
/// A grey level at or above which a sample is taken as clipped.
constexpr float kClippedGrey = 250.0f;

struct Tone {
	/// 0: not the log scale. Otherwise the grey level added before the
	/// log, which keeps the darkest levels' noise from being magnified
	/// without bound: v -> 255 ln(1 + v / floor) / ln(1 + 255 / floor).
	float logFloor = 0.0f;
	/// 0: not the exponential scale. Otherwise its grey levels per e-fold:
	/// v -> 255 (e^(v / s) - 1) / (e^(255 / s) - 1); the midpoint of a
	/// black at 60 and the ceiling is about 255 - 0.7 s in grey levels.
	float expScale = 0.0f;
	/// Optional: apply()'s value of each grey level 0 .. 255 (fillTable()):
	/// apply(WarpedMarker) then takes whole grey levels (the fixed-point
	/// warp's samples) from it and interpolates between them.
	const float *table = nullptr;
	bool linear() const { return logFloor <= 0.0f && expScale <= 0.0f; }
	void fillTable(float *out256) const;
	float apply(float v) const;
	/// apply()'s inverse: the grey level of a value on this scale.
	float invert(float v) const;
	/// Every sample of `w` through apply(), in place.
	void apply(WarpedMarker &w) const;
};

/// Warps the quad into `side` x `side` samples (CandidateSamples' grid):
/// the fixed-point warp of frappe/fixed_warp.h (integer grey levels) where
/// quantiseWarp() holds the quad, else a float warp (double homography,
/// float bilinear). `fine`: the fixed point's fine samples, for the warps
/// only the CPU runs. False when the quad is degenerate.
bool warpToGrid(const ImageView &image, const std::array<Point2f, 4> &corners, int side, WarpedMarker &out,
		bool fine = false);
/// warpToGrid without SIMD, the reference its vectorised sampling is tested
/// against.
bool warpToGridScalar(const ImageView &image, const std::array<Point2f, 4> &corners, int side, WarpedMarker &out,
		      bool fine = false);

/// The grey-level grids one candidate's reads have warped: a read on another
/// Tone (the log scale, the exponential one) warps the same corners again,
/// and a tone applies to the samples after the warp, so it takes a copy
/// instead of sampling the frame again (the same samples to the bit).
/// Holds the last kEntries warps; clear() before each candidate (the frame
/// under the same pointer changes between frames).
class WarpMemo {
public:
	void clear() { used_ = 0; }
	/// warpToGrid(image, corners, side, out, fine), from the memo when it
	/// made these very arguments' samples before.
	bool warp(const ImageView &image, const std::array<Point2f, 4> &corners, int side, bool fine,
		  WarpedMarker &out);

private:
	static constexpr int kEntries = 6;
	struct Entry {
		ImageView image;
		std::array<Point2f, 4> corners;
		int side = 0;
		bool fine = false, ok = false;
		WarpedMarker samples;
	};
	std::array<Entry, kEntries> entries_;
	int used_ = 0, next_ = 0;
};

/// Warps the quad (clockwise, corners[0] mapped to the grid's top-left) into
/// the sample grid of a marker with `bits` bits a side. False when the quad
/// is degenerate. With a memo, a warp it holds is copied from it.
bool warpMarker(const ImageView &image, const std::array<Point2f, 4> &corners, int bits, WarpedMarker &out,
		Tone tone = {}, WarpMemo *memo = nullptr);

/// Treats `corners` as the outline of a one-cell quiet zone: moves them one
/// cell inwards and re-measures the sides there. False when the inner
/// outline cannot be measured. Grey levels only: a second read on another
/// Tone reuses it.
bool insetCorners(const ImageView &image, std::array<Point2f, 4> &corners, int bits);

/// insetCorners(), then warpMarker() at the result.
bool insetQuad(const ImageView &image, std::array<Point2f, 4> &corners, int bits,
	       WarpedMarker &out, Tone tone = {});

/// Reads a marker's cells at their centres, one sample each, from a grid
/// that also covers the ring of cells around the marker, and sharpens each
/// centre against its four neighbours: c + sharpening (4 c - sum of the
/// four). Where blur reaches a quarter of a cell (small cells, or blurred
/// ones) warpMarker's samples a quarter cell from the cell's edges take in
/// the neighbours; the centres less so, and the sharpening takes back what
/// blur spread over the neighbouring cells. `out` holds one value per cell
/// (side bits + 2), for binarise and readMarker; `reference`, when given,
/// the grey level halfway between the mean of the border cells and that of
/// the ring outside them; `lightest`, when given, the lightest code cell's
/// centre before sharpening (sharpening overshoots it). False when the quad
/// is degenerate.
bool warpCellCentres(const ImageView &image, const std::array<Point2f, 4> &corners, int bits, float sharpening,
		     WarpedMarker &out, float *reference = nullptr, Tone tone = {}, WarpMemo *memo = nullptr,
		     float *lightest = nullptr);

/// The bits of a warped marker, read as in the dictionary files with the
/// grid's top-left cell first.
struct Binarised {
	std::uint64_t code = 0;
	int border_errors = 0; ///< border cells that read white
	float contrast = 0.0f; ///< max - min sample over the payload
	float threshold = 0.0f; ///< the grey level between black and white
	/// The code's lightest level where the samples overshoot it (sharpened
	/// cell centres); below 0: threshold + contrast / 2.
	float lightest = -1.0f;
};

/// The mean of cell (cx, cy)'s k x k samples.
inline float cellMean(const WarpedMarker &w, int k, int cx, int cy)
{
	float s = 0.0f;
	for (int y = 0; y < k; ++y)
		for (int x = 0; x < k; ++x)
			s += w.at(cx * k + x, cy * k + y);
	return s / static_cast<float>(k * k);
}

/// Thresholds the payload at the mid-point of its darkest and brightest
/// samples, averages the k x k samples of each cell (k = side / (bits + 2):
/// 2 for warpMarker's grid, 1 for a grid of cell centres), and checks the
/// border cells.
Binarised binarise(const WarpedMarker &warped, int bits);

struct Decoded {
	int id = -1;
	int hamming = 0;
	int rotation = 0; ///< the quad's corner that is the marker's top-left
	/// Distance to the nearest codeword of any other id, in any rotation
	/// (at least this much: an exact read reports the dictionary's minimum
	/// distance, a lower bound).
	int runnerUp = 0;
};

/// Hamming-nearest codeword over the four rotations; id = -1 when none is
/// within maxHamming or another id is as near.
Decoded decode(const Dictionary &dict, std::uint64_t code, int maxHamming);

/// A dictionary's codes sorted for exact lookup. Most markers read without a
/// wrong bit, and finding their code by binary search skips decode()'s scan
/// of every code in four rotations; the answer is always decode()'s.
class CodeBook
{
public:
	explicit CodeBook(const Dictionary &dict);
	const Dictionary &dictionary() const { return *dict_; }
	Decoded decode(std::uint64_t code, int maxHamming) const;
	/// Whether codeword `id` is a plain shape (plainCode()).
	bool plain(int id) const { return plain_[static_cast<std::size_t>(id)] != 0; }

private:
	const Dictionary *dict_;
	std::vector<std::pair<std::uint64_t, int>> sorted_; ///< (code, id), by code
	std::vector<std::uint8_t> plain_;
};

/// The last decodes of one stage of the detector: CodeBook::decode() is a
/// function of the code and maxHamming alone, and a frame reads the same
/// codes many times over (a candidate's reads on each Tone and at its cell
/// centres; the probe's reads of a marker's nested outlines): two thirds of
/// the scans of every codeword on synth/images repeat one of the last 64.
/// Direct-mapped; one per stage (stages of different frames run at once).
class DecodeCache {
public:
	/// codes.decode(code, maxHamming), from the cache when it holds it.
	Decoded decode(const CodeBook &codes, std::uint64_t code, int maxHamming);

private:
	static constexpr int kEntries = 256;
	struct Entry {
		const CodeBook *codes = nullptr;
		std::uint64_t code = 0;
		int maxHamming = 0;
		Decoded decoded;
	};
	std::array<Entry, kEntries> entries_{};
};

/// Whether an n x n code inside its black border is a plain shape: at most
/// 0.6 of the black-white changes between neighbouring cells that random
/// bits make on average (n (n + 1), the border's neighbours counted). A
/// hollow square, a bar, an L: letters and their strokes read as these far
/// more often than chance says (ArUco's original dictionary has 12, 4x4_1000
/// 29; AprilTag's families none).
bool plainCode(std::uint64_t code, int n);

} // namespace frappe::detail
