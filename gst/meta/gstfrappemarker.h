/* SPDX-License-Identifier: MIT
 *
 * gstfrappemarker.h: GstFrappeMarker, a boxed copy of one marker meta, and
 * gst_frappe_buffer_get_markers(), the way bindings (Python through
 * GObject introspection, namespace GstFrappe) read a buffer's markers.
 */
#pragma once

#include <gst/gst.h>

#include "gstfrappemeta-export.h"

G_BEGIN_DECLS

#define GST_FRAPPE_TYPE_MARKER (gst_frappe_marker_get_type())

/**
 * GstFrappeMarker:
 * @id: the marker id in @dictionary
 * @dictionary: the dictionary name ("aruco_mip_36h12", ...), an interned
 *   string
 * @corners: (array fixed-size=8): the four corners as x0, y0, ..., x3, y3,
 *   as in #GstFrappeMarkerMeta; from bindings use
 *   gst_frappe_marker_get_corners() or gst_frappe_marker_get_corner()
 * @hamming: bits corrected to decode the marker
 * @margin: how clearly the code was read, in [0, 1]
 * @has_pose: whether @rvec, @tvec and the reprojection errors are valid
 * @rvec: (array fixed-size=3): rotation (Rodrigues vector) from the marker
 *   frame to the camera frame; from bindings use gst_frappe_marker_get_rvec()
 * @tvec: (array fixed-size=3): the marker centre in the camera frame, in
 *   metres; from bindings use gst_frappe_marker_get_tvec()
 * @reprojection_error: RMS reprojection error of the pose, in pixels
 * @alternative_reprojection_error: the same for the planar pose's other
 *   solution (infinity when there was one)
 * @tracking: whether frappedetect ran with mode=track on its frame. Since: 0.3
 * @tracked: with @tracking, whether the marker continued a track of the
 *   last frames. Since: 0.3
 *
 * One marker of a buffer, copied out of its #GstFrappeMarkerMeta (see
 * there for the frames and conventions): a boxed type, so that bindings
 * can hold it after the buffer is gone.
 *
 * Since: 0.2
 */
typedef struct {
	gint id;
	const gchar *dictionary;
	gfloat corners[8];
	guint hamming;
	gfloat margin;

	gboolean has_pose;
	gdouble rvec[3];
	gdouble tvec[3];
	gdouble reprojection_error;
	gdouble alternative_reprojection_error;

	/* Since 0.3; appended: the library allocates every GstFrappeMarker. */
	gboolean tracking;
	gboolean tracked;
} GstFrappeMarker;

GST_FRAPPE_META_API GType gst_frappe_marker_get_type(void);

/**
 * gst_frappe_marker_copy:
 * @marker: a #GstFrappeMarker
 *
 * Returns: (transfer full): a copy of @marker, freed with
 * gst_frappe_marker_free()
 *
 * Since: 0.2
 */
GST_FRAPPE_META_API GstFrappeMarker *gst_frappe_marker_copy(const GstFrappeMarker *marker);

/**
 * gst_frappe_marker_free: (skip)
 * @marker: (transfer full): a #GstFrappeMarker
 *
 * Bindings free their markers themselves.
 *
 * Since: 0.2
 */
GST_FRAPPE_META_API void gst_frappe_marker_free(GstFrappeMarker *marker);

/**
 * gst_frappe_marker_get_corners:
 * @marker: a #GstFrappeMarker
 *
 * Returns: (transfer none) (array fixed-size=8): the corners as x0, y0,
 * x1, y1, x2, y2, x3, y3 (a list of 8 floats in Python)
 *
 * Since: 0.2
 */
GST_FRAPPE_META_API const gfloat *gst_frappe_marker_get_corners(const GstFrappeMarker *marker);

/**
 * gst_frappe_marker_get_corner:
 * @marker: a #GstFrappeMarker
 * @index: which corner, 0 to 3 (top-left, top-right, bottom-right,
 *   bottom-left of the marker)
 * @x: (out): its x in pixels
 * @y: (out): its y in pixels
 *
 * One corner (an (x, y) tuple in Python). An @index beyond 3 is a
 * programming error: a critical, and @x, @y untouched.
 *
 * Since: 0.2
 */
GST_FRAPPE_META_API void gst_frappe_marker_get_corner(const GstFrappeMarker *marker, guint index, gfloat *x, gfloat *y);

/**
 * gst_frappe_marker_get_rvec:
 * @marker: a #GstFrappeMarker
 *
 * Returns: (transfer none) (array fixed-size=3): the rotation vector (all
 * zero unless has_pose)
 *
 * Since: 0.2
 */
GST_FRAPPE_META_API const gdouble *gst_frappe_marker_get_rvec(const GstFrappeMarker *marker);

/**
 * gst_frappe_marker_get_tvec:
 * @marker: a #GstFrappeMarker
 *
 * Returns: (transfer none) (array fixed-size=3): the translation in metres
 * (all zero unless has_pose)
 *
 * Since: 0.2
 */
GST_FRAPPE_META_API const gdouble *gst_frappe_marker_get_tvec(const GstFrappeMarker *marker);

/**
 * gst_frappe_buffer_get_markers:
 * @buffer: a #GstBuffer
 *
 * Copies out the markers frappedetect attached to @buffer, in the order
 * of their metas. Allocates: meant for applications and bindings; C code
 * on a per-frame path iterates the metas instead.
 *
 * Returns: (transfer full) (element-type GstFrappeMarker): the markers,
 * %NULL (an empty list) when there are none; free with
 * g_list_free_full (list, (GDestroyNotify) gst_frappe_marker_free)
 *
 * Since: 0.2
 */
GST_FRAPPE_META_API GList *gst_frappe_buffer_get_markers(GstBuffer *buffer);

G_END_DECLS
