// SPDX-License-Identifier: MIT
// The fixed-point perspective warp's quantisation and its defining sample
// (the contract is at the top of frappe/fixed_warp.h).
#include "frappe/fixed_warp.h"

#include <algorithm>
#include <cmath>

#include "frappe/candidate_warp.h"
#include "frappe/homography.h"
#include "sampling.h"

namespace frappe {

namespace {

std::optional<FixedWarp> refuse(const char **why, const char *reason)
{
	if (why)
		*why = reason;
	return std::nullopt;
}

/* A form in double, before quantisation. */
struct Form {
	double at00, di, dj;
	double at(int i, int j) const { return at00 + di * i + dj * j; }
};

} // namespace

std::optional<FixedWarp> quantiseWarp(const std::array<Point2f, 4> &corners, int side, const char **why)
{
	if (side < 1 || side > CandidateSamples::kMaxSide)
		return refuse(why, "grid side out of range");
	const auto H = Homography::fromUnitSquare(corners);
	if (!H)
		return refuse(why, "degenerate quad");
	const auto &h = H->h;
	/* With u = (2i + 1) / (2 side): numerators and denominator times
	 * 2 side, as forms in (i, j). */
	const double s2 = 2.0 * side;
	const Form den{ h[6] + h[7] + s2 * h[8], 2 * h[6], 2 * h[7] };
	const Form nx{ h[0] + h[1] + s2 * h[2], 2 * h[0], 2 * h[1] };
	const Form ny{ h[3] + h[4] + s2 * h[5], 2 * h[3], 2 * h[4] };
	/* The forms are linear: their extremes over the grid are at its corners. */
	const int last = side - 1;
	const int ci[4] = { 0, last, last, 0 }, cj[4] = { 0, 0, last, last };
	double dmin = 1e300, dmax = -1e300;
	for (int c = 0; c < 4; ++c) {
		dmin = std::min(dmin, den.at(ci[c], cj[c]));
		dmax = std::max(dmax, den.at(ci[c], cj[c]));
	}
	if (!(dmin * dmax > 0) || !std::isfinite(dmin) || !std::isfinite(dmax))
		return refuse(why, "the sample grid reaches the horizon");
	double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
	for (int c = 0; c < 4; ++c) {
		const double dc = den.at(ci[c], cj[c]);
		xmin = std::min(xmin, nx.at(ci[c], cj[c]) / dc);
		xmax = std::max(xmax, nx.at(ci[c], cj[c]) / dc);
		ymin = std::min(ymin, ny.at(ci[c], cj[c]) / dc);
		ymax = std::max(ymax, ny.at(ci[c], cj[c]) / dc);
	}
	if (!(std::abs(xmin) < 1e6 && std::abs(ymin) < 1e6))
		return refuse(why, "quad far outside any image");
	FixedWarp w;
	w.side = side;
	w.ox = static_cast<std::int32_t>(std::floor(xmin));
	w.oy = static_cast<std::int32_t>(std::floor(ymin));
	if (!(xmax - w.ox < (1 << kFixedWarpIntBits) - 2 && ymax - w.oy < (1 << kFixedWarpIntBits) - 2))
		return refuse(why, "quad wider than 2046 pixels");
	/* Scaled so that the largest denominator is 2^19: half the range, room
	 * for rounding; the smallest must keep 10 bits. */
	const double sign = dmax > 0 ? 1.0 : -1.0;
	const double k = sign * double(1 << 19) / std::max(std::abs(dmin), std::abs(dmax));
	if (std::min(std::abs(dmin), std::abs(dmax)) * std::abs(k) < 1024)
		return refuse(why, "quad too oblique (denominators differ by more than 512x)");
	constexpr double kLimit = 2147483648.0; /* 2^31 */
	bool inRange = true;
	auto quantise = [&](const Form &f) {
		const double v[3] = { std::round(k * f.at00), std::round(k * f.di), std::round(k * f.dj) };
		for (double x : v)
			inRange = inRange && std::abs(x) < kLimit;
		return inRange ? FixedWarpForm{ static_cast<std::int32_t>(v[0]), static_cast<std::int32_t>(v[1]),
						static_cast<std::int32_t>(v[2]) }
			       : FixedWarpForm{};
	};
	w.x = quantise({ nx.at00 - w.ox * den.at00, nx.di - w.ox * den.di, nx.dj - w.ox * den.dj });
	w.y = quantise({ ny.at00 - w.oy * den.at00, ny.di - w.oy * den.di, ny.dj - w.oy * den.dj });
	w.d = quantise(den);
	if (!inRange)
		return refuse(why, "fixed-point range exceeded");
	/* What the samples rely on, checked on the integers at the grid's
	 * corners (the extremes of linear forms). */
	for (int c = 0; c < 4; ++c) {
		const std::int64_t d = w.d.at(ci[c], cj[c]);
		if (d <= 0 || d >= kFixedWarpDenominatorLimit)
			return refuse(why, "denominator out of range");
		if (std::abs(w.x.at(ci[c], cj[c])) >= std::int64_t{ 1 } << 31 ||
		    std::abs(w.y.at(ci[c], cj[c])) >= std::int64_t{ 1 } << 31)
			return refuse(why, "numerator out of range");
	}
	return w;
}

std::uint8_t fixedWarpSample(const ImageView &image, const FixedWarp &w, int i, int j)
{
	return static_cast<std::uint8_t>((fixedWarpValue(image, w, i, j) + (1u << 19)) >> 20);
}

std::uint32_t fixedWarpValue(const ImageView &image, const FixedWarp &w, int i, int j)
{
	const std::int64_t d = w.d.at(i, j);
	auto quotient = [d](std::int64_t n) {
		return (std::clamp<std::int64_t>(n, 0, (d << kFixedWarpIntBits) - 1) << kFixedWarpFracBits) / d;
	};
	return detail::fixedBilinear(image, detail::fixedPosition(quotient(w.x.at(i, j)), w.ox, image.width),
				     detail::fixedPosition(quotient(w.y.at(i, j)), w.oy, image.height));
}

} // namespace frappe
