/* SPDX-License-Identifier: MIT
 *
 * gstfrappebundlemeta.cpp: registration and transforms of
 * GstFrappeBundleMeta.
 */
#include "gstfrappebundlemeta.h"

#include <cstring>

#include <gst/video/video.h>

#include "gstfrappemeta-internal.h"

GType gst_frappe_bundle_meta_api_get_type(void)
{
	static GType type = 0;
	/* As the marker meta's: a geometry change other than scaling drops it. */
	return frappe::gstmeta::registerApi(type, "GstFrappeBundleMetaAPI");
}

static gboolean frappe_bundle_meta_init(GstMeta *meta, gpointer, GstBuffer *)
{
	auto *m = reinterpret_cast<GstFrappeBundleMeta *>(meta);
	m->name = nullptr;
	std::memset(m->rvec, 0, sizeof(m->rvec));
	std::memset(m->tvec, 0, sizeof(m->tvec));
	m->reprojection_error = 0.0;
	m->n_used = m->n_rejected = 0;
	m->used = m->rejected = nullptr;
	return TRUE;
}

/* used and rejected share one block, which used starts. */
static void frappe_bundle_meta_free(GstMeta *meta, GstBuffer *)
{
	g_free(reinterpret_cast<GstFrappeBundleMeta *>(meta)->used);
}

static gboolean frappe_bundle_meta_transform(GstBuffer *dest, GstMeta *meta, GstBuffer *, GQuark type, gpointer data)
{
	const auto *src = reinterpret_cast<const GstFrappeBundleMeta *>(meta);
	gdouble error = src->reprojection_error;
	if (GST_VIDEO_META_TRANSFORM_IS_SCALE(type)) {
		/* The pose is in metres in the camera frame: scaling the image
		 * does not move the bundle. The error is in pixels. */
		gdouble sx = 1.0, sy = 1.0;
		if (!frappe::gstmeta::scaleFactors(data, sx, sy))
			return FALSE;
		error *= (sx + sy) / 2.0;
	} else if (!GST_META_TRANSFORM_IS_COPY(type)) {
		return FALSE; /* crops, rotations, ...: the camera is another */
	}
	return gst_buffer_add_frappe_bundle_meta(dest, src->name, src->rvec, src->tvec, error, src->used, src->n_used,
						 src->rejected, src->n_rejected) != nullptr;
}

const GstMetaInfo *gst_frappe_bundle_meta_get_info(void)
{
	static const GstMetaInfo *info = nullptr;

	if (g_once_init_enter(&info)) {
		const GstMetaInfo *i = gst_meta_register(GST_FRAPPE_BUNDLE_META_API_TYPE, "GstFrappeBundleMeta",
							 sizeof(GstFrappeBundleMeta), frappe_bundle_meta_init,
							 frappe_bundle_meta_free, frappe_bundle_meta_transform);
		g_once_init_leave(&info, i);
	}
	return info;
}

GstFrappeBundleMeta *gst_buffer_add_frappe_bundle_meta(GstBuffer *buffer, const gchar *name, const gdouble rvec[3],
						       const gdouble tvec[3], gdouble reprojection_error,
						       const gint *used, guint n_used, const gint *rejected,
						       guint n_rejected)
{
	g_return_val_if_fail(GST_IS_BUFFER(buffer), nullptr);
	g_return_val_if_fail(rvec != nullptr && tvec != nullptr, nullptr);
	g_return_val_if_fail(used != nullptr || n_used == 0, nullptr);
	g_return_val_if_fail(rejected != nullptr || n_rejected == 0, nullptr);

	auto *m = reinterpret_cast<GstFrappeBundleMeta *>(
		gst_buffer_add_meta(buffer, GST_FRAPPE_BUNDLE_META_INFO, nullptr));
	if (!m)
		return nullptr;
	m->name = name ? g_intern_string(name) : nullptr;
	std::memcpy(m->rvec, rvec, sizeof(m->rvec));
	std::memcpy(m->tvec, tvec, sizeof(m->tvec));
	m->reprojection_error = reprojection_error;
	m->n_used = n_used;
	m->n_rejected = n_rejected;
	if (n_used + n_rejected > 0) {
		m->used = g_new(gint, n_used + n_rejected);
		m->rejected = m->used + n_used;
		if (n_used)
			std::memcpy(m->used, used, n_used * sizeof(gint));
		if (n_rejected)
			std::memcpy(m->rejected, rejected, n_rejected * sizeof(gint));
	}
	return m;
}
