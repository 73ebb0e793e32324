/* SPDX-License-Identifier: MIT
 *
 * gstfrappebundlemeta.cpp: registration and transforms of
 * GstFrappeBundleMeta, and its boxed copy for bindings, GstFrappeBundlePose.
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

/* The meta and its boxed copy have the same fields: one writer of both.
 * `ids` holds n_used + n_rejected ids, used first. */
template<typename Pose>
static void setPose(Pose &p, const gchar *name, const gdouble rvec[3], const gdouble tvec[3],
		    gdouble reprojection_error, const gint *used, guint n_used, const gint *rejected, guint n_rejected,
		    gint *ids)
{
	p.name = name;
	std::memcpy(p.rvec, rvec, sizeof(p.rvec));
	std::memcpy(p.tvec, tvec, sizeof(p.tvec));
	p.reprojection_error = reprojection_error;
	p.n_used = n_used;
	p.n_rejected = n_rejected;
	p.used = ids;
	p.rejected = ids ? ids + n_used : nullptr;
	if (n_used)
		std::memcpy(p.used, used, n_used * sizeof(gint));
	if (n_rejected)
		std::memcpy(p.rejected, rejected, n_rejected * sizeof(gint));
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
	setPose(*m, name ? g_intern_string(name) : nullptr, rvec, tvec, reprojection_error, used, n_used, rejected,
		n_rejected, n_used + n_rejected > 0 ? g_new(gint, n_used + n_rejected) : nullptr);
	return m;
}

/* A copy of the meta or of a pose, its ids in the same block: copying and
 * freeing stay one call, as GstFrappeMarker's. */
template<typename Pose>
static GstFrappeBundlePose *newBundlePose(const Pose &from)
{
	static_assert(sizeof(GstFrappeBundlePose) % alignof(gint) == 0);
	auto *p = static_cast<GstFrappeBundlePose *>(
		g_malloc(sizeof(GstFrappeBundlePose) + (from.n_used + from.n_rejected) * sizeof(gint)));
	setPose(*p, from.name, from.rvec, from.tvec, from.reprojection_error, from.used, from.n_used, from.rejected,
		from.n_rejected, reinterpret_cast<gint *>(p + 1));
	return p;
}

G_DEFINE_BOXED_TYPE(GstFrappeBundlePose, gst_frappe_bundle_pose, gst_frappe_bundle_pose_copy,
		    gst_frappe_bundle_pose_free)

GstFrappeBundlePose *gst_frappe_bundle_pose_copy(const GstFrappeBundlePose *pose)
{
	g_return_val_if_fail(pose != nullptr, nullptr);

	return newBundlePose(*pose);
}

void gst_frappe_bundle_pose_free(GstFrappeBundlePose *pose)
{
	g_free(pose);
}

const gdouble *gst_frappe_bundle_pose_get_rvec(const GstFrappeBundlePose *pose)
{
	g_return_val_if_fail(pose != nullptr, nullptr);

	return pose->rvec;
}

const gdouble *gst_frappe_bundle_pose_get_tvec(const GstFrappeBundlePose *pose)
{
	g_return_val_if_fail(pose != nullptr, nullptr);

	return pose->tvec;
}

const gint *gst_frappe_bundle_pose_get_used(const GstFrappeBundlePose *pose, guint *n_used)
{
	g_return_val_if_fail(pose != nullptr, nullptr);

	if (n_used)
		*n_used = pose->n_used;
	return pose->used;
}

const gint *gst_frappe_bundle_pose_get_rejected(const GstFrappeBundlePose *pose, guint *n_rejected)
{
	g_return_val_if_fail(pose != nullptr, nullptr);

	if (n_rejected)
		*n_rejected = pose->n_rejected;
	return pose->rejected;
}

GstFrappeBundlePose *gst_frappe_buffer_get_bundle_pose(GstBuffer *buffer)
{
	g_return_val_if_fail(GST_IS_BUFFER(buffer), nullptr);

	const GstFrappeBundleMeta *m = gst_buffer_get_frappe_bundle_meta(buffer);
	return m ? newBundlePose(*m) : nullptr;
}
