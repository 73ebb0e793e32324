/* SPDX-License-Identifier: MIT
 *
 * gstfrappebundlemeta.h: the pose of a bundle (a board, a rigid set of
 * markers: frappe/bundle.h) that frappedetect attaches to a buffer when
 * its bundle-file is set and the bundle is seen. Included by
 * gstfrappemeta.h.
 */
#pragma once

#include <gst/gst.h>

#include "gstfrappemeta-export.h"

G_BEGIN_DECLS

#define GST_FRAPPE_BUNDLE_META_API_TYPE (gst_frappe_bundle_meta_api_get_type())
#define GST_FRAPPE_BUNDLE_META_INFO (gst_frappe_bundle_meta_get_info())

/**
 * GstFrappeBundleMeta:
 * @meta: parent #GstMeta
 * @name: the bundle's name (its file's `name`; "grid" for a grid board
 *   without one), an interned string
 * @rvec: rotation (Rodrigues vector) from the bundle frame to the camera
 *   frame
 * @tvec: the bundle frame's origin in the camera frame, in metres
 * @reprojection_error: RMS distance in pixels between the corners of the
 *   markers in @used and the posed bundle's projected corners
 * @n_used: how many ids are in @used (at least 1)
 * @used: (array length=n_used): the ids whose corners made the pose, in
 *   the order of the frame's markers
 * @n_rejected: how many ids are in @rejected
 * @rejected: (array length=n_rejected): ids of the bundle seen in the
 *   frame but left out: corners that disagree with the others (a marker
 *   moved, a wrong read), an id seen twice
 *
 * One pose from every marker of the bundle seen in the frame
 * (frappe::estimateBundlePose: each marker's two planar poses as starting
 * points, Levenberg-Marquardt over every agreeing corner through the lens
 * model, outliers rejected). A buffer carries at most one; none when no
 * marker of the bundle was seen, none gave a pose, or the element has no
 * camera. @used and @rejected are owned by the meta (one block).
 *
 * Camera frame: OpenCV's (x right, y down, z forward, metres). Bundle
 * frame: the bundle file's; a grid board's is OpenCV's GridBoard's (origin
 * at the board's bottom-left corner, x right, y up, z out of the board).
 *
 * The meta is copied with the buffer; a scaling element (videoscale)
 * keeps the pose (the camera frame is the same) and scales
 * @reprojection_error, which is in pixels; elements that crop, rotate or
 * otherwise change the geometry drop it, as they drop the marker metas.
 *
 * Bindings, which cannot cast a #GstMeta, read a copy of it as a boxed
 * #GstFrappeBundlePose: gst_frappe_buffer_get_bundle_pose().
 *
 * Since: 0.3
 */
typedef struct {
	GstMeta meta;

	const gchar *name;
	gdouble rvec[3];
	gdouble tvec[3];
	gdouble reprojection_error;
	guint n_used;
	gint *used;
	guint n_rejected;
	gint *rejected;
} GstFrappeBundleMeta;

/**
 * gst_frappe_bundle_meta_api_get_type:
 *
 * Returns: the API type of #GstFrappeBundleMeta
 *
 * Since: 0.3
 */
GST_FRAPPE_META_API GType gst_frappe_bundle_meta_api_get_type(void);

/**
 * gst_frappe_bundle_meta_get_info:
 *
 * Returns: (transfer none): the registration of #GstFrappeBundleMeta
 *
 * Since: 0.3
 */
GST_FRAPPE_META_API const GstMetaInfo *gst_frappe_bundle_meta_get_info(void);

/**
 * gst_buffer_add_frappe_bundle_meta:
 * @buffer: a writable #GstBuffer
 * @name: (nullable): the bundle's name (interned internally)
 * @rvec: (array fixed-size=3): Rodrigues rotation, bundle to camera
 * @tvec: (array fixed-size=3): translation, metres
 * @reprojection_error: RMS reprojection error, pixels
 * @used: (array length=n_used) (nullable): the ids that made the pose
 * @n_used: their count
 * @rejected: (array length=n_rejected) (nullable): the ids rejected
 * @n_rejected: their count
 *
 * Adds a bundle meta to @buffer (what frappedetect does), copying the ids.
 *
 * Returns: (transfer none) (nullable): the new meta, %NULL (and a
 * critical) when @buffer is not a buffer, @rvec or @tvec is %NULL, or an
 * id list is %NULL with a count
 *
 * Since: 0.3
 */
GST_FRAPPE_META_API GstFrappeBundleMeta *gst_buffer_add_frappe_bundle_meta(GstBuffer *buffer, const gchar *name,
									   const gdouble rvec[3], const gdouble tvec[3],
									   gdouble reprojection_error, const gint *used,
									   guint n_used, const gint *rejected,
									   guint n_rejected);

/**
 * gst_buffer_get_frappe_bundle_meta:
 * @b: a #GstBuffer
 *
 * Returns: (transfer none) (nullable): the bundle meta of @buffer.
 *
 * Since: 0.3
 */
#define gst_buffer_get_frappe_bundle_meta(b)                                                                           \
	((GstFrappeBundleMeta *)gst_buffer_get_meta((b), GST_FRAPPE_BUNDLE_META_API_TYPE))

#define GST_FRAPPE_TYPE_BUNDLE_POSE (gst_frappe_bundle_pose_get_type())

/**
 * GstFrappeBundlePose:
 * @name: the bundle's name, as in #GstFrappeBundleMeta, an interned string
 * @rvec: (array fixed-size=3): rotation (Rodrigues vector) from the bundle
 *   frame to the camera frame; from bindings use
 *   gst_frappe_bundle_pose_get_rvec()
 * @tvec: (array fixed-size=3): the bundle frame's origin in the camera
 *   frame, in metres; from bindings use gst_frappe_bundle_pose_get_tvec()
 * @reprojection_error: RMS reprojection error of the pose, in pixels
 * @n_used: how many ids are in @used
 * @used: (array length=n_used): the ids whose corners made the pose; from
 *   bindings use gst_frappe_bundle_pose_get_used()
 * @n_rejected: how many ids are in @rejected
 * @rejected: (array length=n_rejected): the ids of the bundle seen but left
 *   out; from bindings use gst_frappe_bundle_pose_get_rejected()
 *
 * A buffer's #GstFrappeBundleMeta copied out (see there for the frames and
 * conventions): a boxed type, so that bindings can hold it after the
 * buffer is gone. The struct and its ids are one allocation.
 *
 * Since: 0.3
 */
typedef struct {
	const gchar *name;
	gdouble rvec[3];
	gdouble tvec[3];
	gdouble reprojection_error;
	guint n_used;
	gint *used;
	guint n_rejected;
	gint *rejected;
} GstFrappeBundlePose;

/**
 * gst_frappe_bundle_pose_get_type:
 *
 * Returns: the boxed type of #GstFrappeBundlePose
 *
 * Since: 0.3
 */
GST_FRAPPE_META_API GType gst_frappe_bundle_pose_get_type(void);

/**
 * gst_frappe_bundle_pose_copy:
 * @pose: a #GstFrappeBundlePose
 *
 * Returns: (transfer full): a copy of @pose and its ids, freed with
 * gst_frappe_bundle_pose_free()
 *
 * Since: 0.3
 */
GST_FRAPPE_META_API GstFrappeBundlePose *gst_frappe_bundle_pose_copy(const GstFrappeBundlePose *pose);

/**
 * gst_frappe_bundle_pose_free: (skip)
 * @pose: (transfer full): a #GstFrappeBundlePose
 *
 * Bindings free their poses themselves.
 *
 * Since: 0.3
 */
GST_FRAPPE_META_API void gst_frappe_bundle_pose_free(GstFrappeBundlePose *pose);

/**
 * gst_frappe_bundle_pose_get_rvec:
 * @pose: a #GstFrappeBundlePose
 *
 * Returns: (transfer none) (array fixed-size=3): the rotation vector,
 * bundle to camera
 *
 * Since: 0.3
 */
GST_FRAPPE_META_API const gdouble *gst_frappe_bundle_pose_get_rvec(const GstFrappeBundlePose *pose);

/**
 * gst_frappe_bundle_pose_get_tvec:
 * @pose: a #GstFrappeBundlePose
 *
 * Returns: (transfer none) (array fixed-size=3): the bundle frame's origin
 * in the camera frame, in metres
 *
 * Since: 0.3
 */
GST_FRAPPE_META_API const gdouble *gst_frappe_bundle_pose_get_tvec(const GstFrappeBundlePose *pose);

/**
 * gst_frappe_bundle_pose_get_used:
 * @pose: a #GstFrappeBundlePose
 * @n_used: (out): how many ids
 *
 * Returns: (transfer none) (array length=n_used): the ids that made the
 * pose (a list of ints in Python)
 *
 * Since: 0.3
 */
GST_FRAPPE_META_API const gint *gst_frappe_bundle_pose_get_used(const GstFrappeBundlePose *pose, guint *n_used);

/**
 * gst_frappe_bundle_pose_get_rejected:
 * @pose: a #GstFrappeBundlePose
 * @n_rejected: (out): how many ids
 *
 * Returns: (transfer none) (array length=n_rejected): the ids of the
 * bundle seen but left out (a list of ints in Python, often empty)
 *
 * Since: 0.3
 */
GST_FRAPPE_META_API const gint *gst_frappe_bundle_pose_get_rejected(const GstFrappeBundlePose *pose, guint *n_rejected);

/**
 * gst_frappe_buffer_get_bundle_pose:
 * @buffer: a #GstBuffer
 *
 * Copies out the bundle pose frappedetect attached to @buffer. Allocates:
 * meant for applications and bindings; C code on a per-frame path reads
 * the meta (gst_buffer_get_frappe_bundle_meta()) instead.
 *
 * Returns: (transfer full) (nullable): the pose, %NULL when @buffer has no
 * #GstFrappeBundleMeta; free with gst_frappe_bundle_pose_free()
 *
 * Since: 0.3
 */
GST_FRAPPE_META_API GstFrappeBundlePose *gst_frappe_buffer_get_bundle_pose(GstBuffer *buffer);

G_END_DECLS
