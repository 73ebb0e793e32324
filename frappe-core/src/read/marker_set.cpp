// SPDX-License-Identifier: MIT
// The markers of one frame as a set.
#include "marker_set.h"

#include <cmath>

#include "suppression.h"
#include "verify.h"

namespace frappe::detail {

bool surroundsMarker(const QuadCorners &q, float area, int probeRead, int bits, std::span<const Marker> found,
		     const PointGrid &centres)
{
	if (probeRead >= 0 && probeRead <= allowedBorderErrors(bits))
		return false;
	const Point2f c = quadCentre(q);
	auto surrounds = [&](const Marker &m, const QuadCorners &) {
		const float am = quadArea(m.corners);
		if (area > 3.0f * am || 3.0f * area < am)
			return false;
		const Point2f cm = quadCentre(m.corners);
		const float dx = c.x - cm.x, dy = c.y - cm.y;
		return dx * dx + dy * dy < 0.12f * am;
	};
	/* A marker it surrounds has an area of at most 3 * area, so its centre
	 * lies within sqrt(0.12 * 3 * area) of q's (padded: the test rounds). */
	const float r = 1.0f + 1.01f * std::sqrt(0.36f * area);
	if (!(r < 1e9f) || !std::isfinite(c.x) || !std::isfinite(c.y))
		return firstRepeated(found, q, surrounds) != nullptr;
	return centres.anyIn(c.x - r, c.y - r, c.x + r, c.y + r, [&](int i, int) {
		return surrounds(found[static_cast<std::size_t>(i)], q);
	});
}

int keepMarker(std::vector<Marker> &markers, const Marker &m)
{
	/* The first corner of the same id within half of m's first side. */
	auto sameMarker = [](const Marker &other, const Marker &m) {
		if (other.id != m.id)
			return false;
		const float dx = other.corners[0].x - m.corners[0].x;
		const float dy = other.corners[0].y - m.corners[0].y;
		const float sx = m.corners[1].x - m.corners[0].x, sy = m.corners[1].y - m.corners[0].y;
		return dx * dx + dy * dy < 0.25f * (sx * sx + sy * sy);
	};
	Marker *other = firstRepeated(std::span(markers), m, sameMarker);
	if (!other) {
		markers.push_back(m);
		return static_cast<int>(markers.size() - 1);
	}
	if (m.hamming < other->hamming) {
		*other = m;
		return static_cast<int>(other - markers.data());
	}
	return -1;
}

} // namespace frappe::detail
