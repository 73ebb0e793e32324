/* SPDX-License-Identifier: MIT
 *
 * gstfrappemeta.cpp: registration and transforms of GstFrappeMarkerMeta.
 */
#include "gstfrappemeta.h"

#include <cstring>

#include <gst/video/video.h>

#include "gstfrappemeta-internal.h"

GType gst_frappe_marker_meta_api_get_type(void)
{
	static GType type = 0;
	return frappe::gstmeta::registerApi(type, "GstFrappeMarkerMetaAPI");
}

static gboolean frappe_marker_meta_init(GstMeta *meta, gpointer, GstBuffer *)
{
	auto *m = reinterpret_cast<GstFrappeMarkerMeta *>(meta);
	m->id = -1;
	m->dictionary = nullptr;
	std::memset(m->corners, 0, sizeof(m->corners));
	m->hamming = 0;
	m->has_pose = FALSE;
	std::memset(m->rvec, 0, sizeof(m->rvec));
	std::memset(m->tvec, 0, sizeof(m->tvec));
	m->reprojection_error = 0.0;
	m->alternative_reprojection_error = 0.0;
	m->margin = 0.0f;
	m->tracking = FALSE;
	m->tracked = FALSE;
	return TRUE;
}

/* Every field of src after the GstMeta header: a new field is copied with
 * the others, never listed here. */
static void copyFields(GstFrappeMarkerMeta *m, const GstFrappeMarkerMeta *src)
{
	const GstMeta head = m->meta;
	*m = *src;
	m->meta = head;
}

static gboolean frappe_marker_meta_transform(GstBuffer *dest, GstMeta *meta, GstBuffer *,
					     GQuark type, gpointer data)
{
	const auto *src = reinterpret_cast<const GstFrappeMarkerMeta *>(meta);

	if (GST_META_TRANSFORM_IS_COPY(type)) {
		GstFrappeMarkerMeta *m = gst_buffer_add_frappe_marker_meta(
			dest, src->id, src->dictionary, src->corners, src->hamming);
		if (!m)
			return FALSE;
		copyFields(m, src);
		return TRUE;
	}

	if (GST_VIDEO_META_TRANSFORM_IS_SCALE(type)) {
		gdouble sx = 1.0, sy = 1.0;
		if (!frappe::gstmeta::scaleFactors(data, sx, sy))
			return FALSE;
		gfloat corners[8];
		/* Pixel centres sit at integers: scale about the image's corner. */
		for (int i = 0; i < 4; ++i) {
			corners[2 * i] = static_cast<gfloat>((src->corners[2 * i] + 0.5) * sx - 0.5);
			corners[2 * i + 1] = static_cast<gfloat>((src->corners[2 * i + 1] + 0.5) * sy - 0.5);
		}
		GstFrappeMarkerMeta *m = gst_buffer_add_frappe_marker_meta(dest, src->id, src->dictionary,
									   corners, src->hamming);
		if (!m)
			return FALSE;
		/* The pose is in metres in the camera frame: scaling the image does
		 * not move the marker. The corners and the reprojection errors are
		 * in pixels. */
		copyFields(m, src);
		std::memcpy(m->corners, corners, sizeof(m->corners));
		m->reprojection_error = src->reprojection_error * (sx + sy) / 2.0;
		m->alternative_reprojection_error = src->alternative_reprojection_error * (sx + sy) / 2.0;
		return TRUE;
	}

	/* Anything else (crops, rotations, ...) would invalidate the corners. */
	return FALSE;
}

const GstMetaInfo *gst_frappe_marker_meta_get_info(void)
{
	static const GstMetaInfo *info = nullptr;

	if (g_once_init_enter(&info)) {
		const GstMetaInfo *i = gst_meta_register(
			GST_FRAPPE_MARKER_META_API_TYPE, "GstFrappeMarkerMeta",
			sizeof(GstFrappeMarkerMeta), frappe_marker_meta_init, nullptr,
			frappe_marker_meta_transform);
		g_once_init_leave(&info, i);
	}
	return info;
}

GstFrappeMarkerMeta *gst_buffer_add_frappe_marker_meta(GstBuffer *buffer, gint id,
						       const gchar *dictionary,
						       const gfloat corners[8], guint hamming)
{
	g_return_val_if_fail(GST_IS_BUFFER(buffer), nullptr);
	g_return_val_if_fail(corners != nullptr, nullptr);

	auto *m = reinterpret_cast<GstFrappeMarkerMeta *>(
		gst_buffer_add_meta(buffer, GST_FRAPPE_MARKER_META_INFO, nullptr));
	if (!m)
		return nullptr;
	m->id = id;
	m->dictionary = dictionary ? g_intern_string(dictionary) : nullptr;
	std::memcpy(m->corners, corners, sizeof(m->corners));
	m->hamming = hamming;
	return m;
}

guint gst_buffer_get_n_frappe_marker_metas(GstBuffer *buffer)
{
	g_return_val_if_fail(GST_IS_BUFFER(buffer), 0);

	guint n = 0;
	gpointer state = nullptr;
	while (gst_buffer_iterate_meta_filtered(buffer, &state, GST_FRAPPE_MARKER_META_API_TYPE))
		++n;
	return n;
}
