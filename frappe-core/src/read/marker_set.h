// SPDX-License-Identifier: MIT
// The markers of one frame as a set: each marker once, however many of the
// frame's candidates read as it.
#pragma once

#include <span>
#include <vector>

#include "frappe/marker.h"
#include "point_grid.h"
#include "quad_geometry.h"

namespace frappe::detail {

/// Whether a candidate (corners `q`, area `area`) is the outline of the
/// quiet zone of a marker already in `found`: about its size (within 3x of
/// its area) and centred on it. Such an outline would decode to the same
/// marker again. Not when the probe's read of the traced frame
/// (`probeRead`, -1 when there was none) found it dark: that is a marker's
/// own border, around what decoded inside it. `centres` holds the centres
/// of `found` (as finish() files them after keepMarker()): only the markers
/// whose centre lies near q's are tested.
bool surroundsMarker(const QuadCorners &q, float area, int probeRead, int bits, std::span<const Marker> found,
		     const PointGrid &centres);

/// Adds `m` to `markers` unless it is one of them read again (same id,
/// first corner within half a side of it: through two nested borders, say);
/// then the read of the lower Hamming distance stays, in the earlier place.
/// Returns where m was stored, -1 when it was not.
///
/// Unlike surroundsMarker() and this, dropNestedMarkers() (verify.h) is not
/// a repeat: it drops whatever lies in another marker's code area, which is
/// known only once every candidate is read.
int keepMarker(std::vector<Marker> &markers, const Marker &m);

} // namespace frappe::detail
