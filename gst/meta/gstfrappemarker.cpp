/* SPDX-License-Identifier: MIT
 *
 * gstfrappemarker.cpp: the boxed GstFrappeMarker and the copy of a buffer's
 * marker metas into a list of them.
 */
#include "gstfrappemarker.h"

#include <cstring>

#include "gstfrappemeta.h"

G_DEFINE_BOXED_TYPE(GstFrappeMarker, gst_frappe_marker, gst_frappe_marker_copy, gst_frappe_marker_free)

GstFrappeMarker *gst_frappe_marker_copy(const GstFrappeMarker *marker)
{
	g_return_val_if_fail(marker != nullptr, nullptr);

	return static_cast<GstFrappeMarker *>(g_memdup2(marker, sizeof(*marker)));
}

void gst_frappe_marker_free(GstFrappeMarker *marker)
{
	g_free(marker);
}

const gfloat *gst_frappe_marker_get_corners(const GstFrappeMarker *marker)
{
	g_return_val_if_fail(marker != nullptr, nullptr);

	return marker->corners;
}

void gst_frappe_marker_get_corner(const GstFrappeMarker *marker, guint index, gfloat *x, gfloat *y)
{
	g_return_if_fail(marker != nullptr);
	g_return_if_fail(index < 4);

	if (x)
		*x = marker->corners[2 * index];
	if (y)
		*y = marker->corners[2 * index + 1];
}

const gdouble *gst_frappe_marker_get_rvec(const GstFrappeMarker *marker)
{
	g_return_val_if_fail(marker != nullptr, nullptr);

	return marker->rvec;
}

const gdouble *gst_frappe_marker_get_tvec(const GstFrappeMarker *marker)
{
	g_return_val_if_fail(marker != nullptr, nullptr);

	return marker->tvec;
}

GList *gst_frappe_buffer_get_markers(GstBuffer *buffer)
{
	g_return_val_if_fail(GST_IS_BUFFER(buffer), nullptr);

	GList *markers = nullptr;
	gpointer state = nullptr;
	GstMeta *meta;
	while ((meta = gst_buffer_iterate_meta_filtered(buffer, &state, GST_FRAPPE_MARKER_META_API_TYPE))) {
		const auto *m = reinterpret_cast<const GstFrappeMarkerMeta *>(meta);
		auto *marker = g_new(GstFrappeMarker, 1);
		marker->id = m->id;
		marker->dictionary = m->dictionary;
		std::memcpy(marker->corners, m->corners, sizeof(marker->corners));
		marker->hamming = m->hamming;
		marker->margin = m->margin;
		marker->has_pose = m->has_pose;
		std::memcpy(marker->rvec, m->rvec, sizeof(marker->rvec));
		std::memcpy(marker->tvec, m->tvec, sizeof(marker->tvec));
		marker->reprojection_error = m->reprojection_error;
		marker->alternative_reprojection_error = m->alternative_reprojection_error;
		marker->tracking = m->tracking;
		marker->tracked = m->tracked;
		/* Prepend then reverse: the list in meta order, in linear time. */
		markers = g_list_prepend(markers, marker);
	}
	return g_list_reverse(markers);
}
