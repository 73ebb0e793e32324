/* SPDX-License-Identifier: MIT
 *
 * gstfrappemeta-record.h: for C++ applications that link frappe-core too: a
 * GstFrappeMarkerMeta as the library's marker record (frappe/marker_record.h),
 * so that it is written by the library's one JSON writer as frappejson and
 * frappe-detect write theirs. Header-only: libgstfrappemeta itself does not
 * depend on frappe-core.
 *
 * Since: 0.3
 */
#pragma once

#include <cstddef>

#include <frappe/marker_record.h>

#include "gstfrappemeta.h"

namespace frappe::gst {

/* The meta's fields in the library's types; record() points into it. */
struct MetaRecord {
	Marker marker;
	MarkerPose pose;
	bool hasPose = false;
	bool tracking = false;
	const char *dictionary = "";

	explicit MetaRecord(const GstFrappeMarkerMeta &m)
	{
		marker.id = m.id;
		for (std::size_t k = 0; k < 4; ++k)
			marker.corners[k] = { m.corners[2 * k], m.corners[2 * k + 1] };
		marker.hamming = static_cast<int>(m.hamming);
		marker.margin = m.margin;
		marker.tracked = m.tracked;
		tracking = m.tracking;
		hasPose = m.has_pose;
		for (std::size_t k = 0; k < 3; ++k) {
			pose.pose.rvec[k] = m.rvec[k];
			pose.pose.tvec[k] = m.tvec[k];
		}
		pose.pose.error = m.reprojection_error;
		pose.alternative.error = m.alternative_reprojection_error;
		dictionary = m.dictionary ? m.dictionary : "";
	}

	MarkerRecord record() const { return { &marker, dictionary, hasPose ? &pose : nullptr, tracking }; }
};

} // namespace frappe::gst
