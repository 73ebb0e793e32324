// SPDX-License-Identifier: MIT
// The markers of one frame as a set: each marker once, however many of the
// frame's candidates read as it.
#pragma once

#include <span>
#include <vector>

#include "frappe/marker.h"
#include "quad_geometry.h"

namespace frappe::detail {

/// Whether a candidate (corners `q`, area `area`) is the outline of the
/// quiet zone of a marker already in `found`: about its size (within 3x of
/// its area) and centred on it. Such an outline would decode to the same
/// marker again. Not when the probe's read of the traced frame
/// (`probeRead`, -1 when there was none) found it dark: that is a marker's
/// own border, around what decoded inside it.
bool surroundsMarker(const QuadCorners &q, float area, int probeRead, int bits, std::span<const Marker> found);

/// Adds `m` to `markers` unless it is one of them read again (same id,
/// first corner within half a side of it: through two nested borders, say);
/// then the read of the lower Hamming distance stays, in the earlier place.
///
/// Unlike surroundsMarker() and this, dropNestedMarkers() (verify.h) is not
/// a repeat: it drops whatever lies in another marker's code area, which is
/// known only once every candidate is read.
void keepMarker(std::vector<Marker> &markers, const Marker &m);

} // namespace frappe::detail
