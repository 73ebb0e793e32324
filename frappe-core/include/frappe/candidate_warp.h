// SPDX-License-Identifier: MIT
// frappe/candidate_warp.h: PERSPECTIVE_WARP as an interface, so that a backend
// can take the warp of a frame's candidates off the CPU in one batch (the VC4's
// QPUs warp up to 32 candidates a launch).
#pragma once

#include "frappe/export.h"

#include <array>
#include <cstdint>
#include <memory>
#include <span>

#include "frappe/image.h"

namespace frappe {

/// The samples of one warped candidate: side x side, row-major; sample (i, j)
/// lies at ((i + 0.5) / side, (j + 0.5) / side) of the unit square that the
/// quad's homography maps corner 0 to (0, 0), corner 1 to (1, 0), corner 2 to
/// (1, 1). side = (bits + 2) * 2: two samples a cell, border included.
struct CandidateSamples {
	static constexpr int kMaxSide = 20;
	int side = 0;
	std::array<float, kMaxSide * kMaxSide> samples{};
	float at(int x, int y) const { return samples[static_cast<std::size_t>(y) * side + x]; }
};

class FRAPPE_EXPORT CandidateWarper {
public:
	virtual ~CandidateWarper() = default;
	virtual const char *name() const = 0;
	/// Warps every quad (clockwise corners, pixel centres at integers) of
	/// `image` into out[k] with `side` samples a side (<= kMaxSide), and sets
	/// ok[k] to 0 where a quad is degenerate. The spans have equal sizes.
	virtual void warp(const ImageView &image, std::span<const std::array<Point2f, 4>> quads, int side,
			  std::span<CandidateSamples> out, std::span<std::uint8_t> ok) = 0;
};

/// The CPU's warp: frappe/fixed_warp.h's samples where quantiseWarp() holds
/// the quad, else the float fallback (double-precision homography, bilinear
/// samples in float). Every warper must give its samples bit for bit: a
/// backend's own warp implements fixed_warp.h exactly and sends the quads
/// it cannot take here.
FRAPPE_EXPORT std::unique_ptr<CandidateWarper> makeCpuWarper();

} // namespace frappe
