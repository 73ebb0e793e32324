// SPDX-License-Identifier: MIT
// The warp kernel's view of frappe-core's fixed-point warp (see warp_reference.hpp).
#include "kernels/warp_reference.hpp"

#include <cstdlib>

namespace frappe::vc4::kernels {

std::optional<WarpParams> warpParams(const std::array<Point2f, 4> &corners, int side, std::string *why)
{
	auto fail = [why](const char *reason) {
		if (why)
			*why = reason;
		return std::nullopt;
	};
	if (side > kWarpSide)
		return fail("the kernel samples at most 16 x 16");
	const char *reason = nullptr;
	const auto p = quantiseWarp(corners, side, &reason);
	if (!p)
		return fail(reason);
	// The kernel's extra samples (side < 16) are discarded, but its per-lane sums and
	// divisions are only defined for forms in range; linear forms peak at the corners.
	const int last = kWarpSide - 1;
	const int ci[4] = {0, last, last, 0}, cj[4] = {0, 0, last, last};
	for (int c = 0; c < 4; ++c) {
		const int64_t d = p->d.at(ci[c], cj[c]);
		if (d <= 0 || d >= kFixedWarpDenominatorLimit)
			return fail("denominator out of range on the kernel's 16 x 16 grid");
		if (std::llabs(p->x.at(ci[c], cj[c])) >= int64_t{1} << 31 ||
		    std::llabs(p->y.at(ci[c], cj[c])) >= int64_t{1} << 31)
			return fail("numerator out of range on the kernel's 16 x 16 grid");
	}
	return p;
}

void warpReference(const ImageView &image, const WarpParams &p, std::span<uint8_t, kWarpSamples> out)
{
	for (int j = 0; j < kWarpSide; ++j)
		for (int i = 0; i < kWarpSide; ++i)
			out[static_cast<size_t>(j * kWarpSide + i)] = fixedWarpSample(image, p, i, j);
}

} // namespace frappe::vc4::kernels
