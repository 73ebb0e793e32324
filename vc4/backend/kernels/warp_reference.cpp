// SPDX-License-Identifier: MIT
#include "kernels/warp_reference.hpp"

#include <algorithm>
#include <cmath>

#include "frappe/homography.h"

namespace frappe::vc4::kernels {

namespace {

constexpr int64_t kOne = int64_t{1} << kWarpFracBits;

bool fail(std::string *why, const char *reason)
{
	if (why)
		*why = reason;
	return false;
}

// Fixed-point position along one axis (see the header's formula).
int32_t position(int64_t n, int64_t d, int32_t origin, int extent)
{
	const int64_t nc = std::clamp<int64_t>(n, 0, (d << kWarpIntBits) - 1);
	const int64_t q = (nc << kWarpFracBits) / d;
	const int64_t p = int64_t{origin} * kOne + q;
	return static_cast<int32_t>(std::clamp<int64_t>(p, 0, (extent - 1) * kOne));
}

} // namespace

std::optional<WarpParams> warpParams(const std::array<Point2f, 4> &corners, int side, std::string *why)
{
	if (side < 2 || side > kWarpSide) {
		fail(why, "the kernel samples at most 16 x 16");
		return std::nullopt;
	}
	const auto H = Homography::fromUnitSquare(corners);
	if (!H) {
		fail(why, "degenerate quad");
		return std::nullopt;
	}
	const auto &h = H->h;
	// With u = (2i + 1) / (2 side): numerators and denominator times 2 side, as forms in (i, j).
	const double s2 = 2.0 * side;
	struct Form {
		double at00, di, dj;
		double at(int i, int j) const { return at00 + di * i + dj * j; }
	};
	const Form den{h[6] + h[7] + s2 * h[8], 2 * h[6], 2 * h[7]};
	const Form nx{h[0] + h[1] + s2 * h[2], 2 * h[0], 2 * h[1]};
	const Form ny{h[3] + h[4] + s2 * h[5], 2 * h[3], 2 * h[4]};
	const int last = kWarpSide - 1;
	const int ci[4] = {0, last, last, 0}, cj[4] = {0, 0, last, last};
	double dmin = 1e300, dmax = -1e300, xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
	for (int k = 0; k < 4; ++k) {
		const double dk = den.at(ci[k], cj[k]);
		dmin = std::min(dmin, dk);
		dmax = std::max(dmax, dk);
	}
	const double sign = dmax > 0 ? 1.0 : -1.0;
	if (dmin * dmax <= 0 || !std::isfinite(dmin) || !std::isfinite(dmax)) {
		fail(why, "the sample grid reaches the horizon");
		return std::nullopt;
	}
	for (int k = 0; k < 4; ++k) {
		const double dk = den.at(ci[k], cj[k]);
		xmin = std::min(xmin, nx.at(ci[k], cj[k]) / dk);
		xmax = std::max(xmax, nx.at(ci[k], cj[k]) / dk);
		ymin = std::min(ymin, ny.at(ci[k], cj[k]) / dk);
		ymax = std::max(ymax, ny.at(ci[k], cj[k]) / dk);
	}
	if (!(std::abs(xmin) < 1e6 && std::abs(ymin) < 1e6)) {
		fail(why, "quad far outside any image");
		return std::nullopt;
	}
	WarpParams p;
	p.ox = static_cast<int32_t>(std::floor(xmin));
	p.oy = static_cast<int32_t>(std::floor(ymin));
	if (xmax - p.ox >= (1 << kWarpIntBits) - 2 || ymax - p.oy >= (1 << kWarpIntBits) - 2) {
		fail(why, "quad wider than 2046 pixels");
		return std::nullopt;
	}
	// Scale so that the largest denominator is 2^19 (half the range, room for rounding).
	const double k = sign * double(1 << 19) / std::max(std::abs(dmin), std::abs(dmax));
	if (std::min(std::abs(dmin), std::abs(dmax)) * std::abs(k) < 1024) {
		fail(why, "quad too oblique (denominators differ by more than 512x)");
		return std::nullopt;
	}
	constexpr double kLimit = 2147483648.0; // 2^31
	bool in_range = true;
	auto quantise = [&](const Form &f) {
		const double v[3] = {std::round(k * f.at00), std::round(k * f.di), std::round(k * f.dj)};
		for (double x : v)
			in_range = in_range && std::abs(x) < kLimit;
		return WarpForm{static_cast<int32_t>(v[0]), static_cast<int32_t>(v[1]), static_cast<int32_t>(v[2])};
	};
	const Form rx{nx.at00 - p.ox * den.at00, nx.di - p.ox * den.di, nx.dj - p.ox * den.dj};
	const Form ry{ny.at00 - p.oy * den.at00, ny.di - p.oy * den.di, ny.dj - p.oy * den.dj};
	p.x = quantise(rx);
	p.y = quantise(ry);
	p.d = quantise(den);
	if (!in_range) {
		fail(why, "fixed-point range exceeded");
		return std::nullopt;
	}
	// What the kernel relies on, checked on the integers: the forms are linear, so their
	// extremes over the grid are at its corners. (Intermediate lane and step sums may wrap;
	// the QPU's 32-bit arithmetic is modular, so only the values on the grid matter.)
	for (int c = 0; c < 4; ++c) {
		const int64_t d = p.d.at(ci[c], cj[c]);
		if (d <= 0 || d >= kWarpDenominatorLimit) {
			fail(why, "denominator out of range");
			return std::nullopt;
		}
		if (std::abs(static_cast<double>(p.x.at(ci[c], cj[c]))) >= kLimit ||
		    std::abs(static_cast<double>(p.y.at(ci[c], cj[c]))) >= kLimit) {
			fail(why, "numerator out of range");
			return std::nullopt;
		}
	}
	return p;
}

void warpReferenceFixed(const ImageView &image, const WarpParams &p, std::span<uint32_t, kWarpSamples> out)
{
	for (int j = 0; j < kWarpSide; ++j) {
		for (int i = 0; i < kWarpSide; ++i) {
			const int64_t d = p.d.at(i, j);
			const int32_t X = position(p.x.at(i, j), d, p.ox, image.width);
			const int32_t Y = position(p.y.at(i, j), d, p.oy, image.height);
			const int x0 = std::min(X >> kWarpFracBits, image.width - 2);
			const int y0 = std::min(Y >> kWarpFracBits, image.height - 2);
			const uint32_t fx = static_cast<uint32_t>(X - (x0 << kWarpFracBits));
			const uint32_t fy = static_cast<uint32_t>(Y - (y0 << kWarpFracBits));
			const uint8_t *r0 = image.row(y0) + x0;
			const uint8_t *r1 = image.row(y0 + 1) + x0;
			const uint32_t top = r0[0] * (1024 - fx) + r0[1] * fx;
			const uint32_t bot = r1[0] * (1024 - fx) + r1[1] * fx;
			out[static_cast<size_t>(j * kWarpSide + i)] = top * (1024 - fy) + bot * fy;
		}
	}
}

void warpReference(const ImageView &image, const WarpParams &p, std::span<uint8_t, kWarpSamples> out)
{
	std::array<uint32_t, kWarpSamples> v;
	warpReferenceFixed(image, p, v);
	for (int k = 0; k < kWarpSamples; ++k)
		out[static_cast<size_t>(k)] = static_cast<uint8_t>((v[static_cast<size_t>(k)] + (1u << 19)) >> 20);
}

} // namespace frappe::vc4::kernels
