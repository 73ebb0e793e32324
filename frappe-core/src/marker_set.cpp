// SPDX-License-Identifier: MIT
// The markers of one frame as a set.
#include "marker_set.h"

#include "suppression.h"
#include "verify.h"

namespace frappe::detail {

bool surroundsMarker(const QuadCorners &q, float area, int probeRead, int bits, std::span<const Marker> found)
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
	return firstRepeated(found, q, surrounds) != nullptr;
}

void keepMarker(std::vector<Marker> &markers, const Marker &m)
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
	if (!other)
		markers.push_back(m);
	else if (m.hamming < other->hamming)
		*other = m;
}

} // namespace frappe::detail
