/* SPDX-License-Identifier: MIT
 *
 * gstfrappemeta.h: the per-marker metadata that frappedetect attaches to
 * the buffers it detects on, for applications (link with pkg-config
 * gstfrappemeta); a bundle's pose is in gstfrappebundlemeta.h, included
 * here. Bindings read the markers through gstfrappemarker.h (GObject
 * introspection namespace GstFrappe, typelib GstFrappe-1.0).
 */
#pragma once

#include <gst/gst.h>

#include "gstfrappemeta-export.h"

#include "gstfrappebundlemeta.h"
#include "gstfrappemarker.h"

G_BEGIN_DECLS

#define GST_FRAPPE_MARKER_META_API_TYPE (gst_frappe_marker_meta_api_get_type())
#define GST_FRAPPE_MARKER_META_INFO (gst_frappe_marker_meta_get_info())

/**
 * GstFrappeMarkerMeta:
 * @meta: parent #GstMeta
 * @id: the marker id in @dictionary
 * @dictionary: the dictionary name ("aruco_mip_36h12", "6x6_250", ...), an
 *   interned string
 * @corners: outer corners of the black border as x0, y0, x1, y1, ... in
 *   pixels of the luma plane, sub-pixel, (0, 0) being the centre of the
 *   top-left pixel. Order as OpenCV aruco: top-left, top-right,
 *   bottom-right, bottom-left of the marker in its canonical orientation
 *   (clockwise on screen).
 * @hamming: bits corrected to decode the marker
 * @has_pose: whether @rvec, @tvec and @reprojection_error are valid (the
 *   element's marker-size and camera-matrix were set)
 * @rvec: rotation (Rodrigues vector) from the marker frame to the camera
 *   frame
 * @tvec: position of the marker centre in the camera frame, in metres
 * @reprojection_error: RMS distance in pixels between the corners and the
 *   projected corners of the posed marker
 * @alternative_reprojection_error: the same for the other solution of the
 *   planar pose problem (IPPE's second pose, the marker "flipped"). When it
 *   is close to @reprojection_error the pose is ambiguous (typical of small
 *   or distant markers seen face on); infinity when there was one solution.
 * @margin: how clearly the code was read, in [0, 1]: over the code cells,
 *   the smallest distance of a cell's mean grey level from the threshold
 *   between black and white, as a fraction of half the black-white
 *   contrast (frappe::Marker::margin). Near 0, some cell was nearly a coin
 *   toss; filter on it to trade misses for certainty.
 * @tracking: whether frappedetect ran with mode=track on this frame (then
 *   @tracked says how this marker was found). Since: 0.3
 * @tracked: with @tracking, %TRUE when the marker continued a track of
 *   the last frames (read where they predicted it), %FALSE when it was
 *   found afresh; %FALSE without @tracking. Since: 0.3
 *
 * One marker found by frappedetect. A buffer carries one meta per marker;
 * iterate them with gst_buffer_iterate_meta_filtered() and
 * %GST_FRAPPE_MARKER_META_API_TYPE (bindings, which cannot cast a #GstMeta,
 * call gst_frappe_buffer_get_markers() instead).
 *
 * Camera frame: OpenCV's (x right, y down, z forward, in metres). Marker
 * frame: OpenCV aruco's (origin at the marker centre, x right, y up, z out
 * of the marker towards the camera); corner 0 is at (-s/2, s/2, 0) for a
 * marker of side s.
 *
 * The meta is copied with the buffer and rescaled by scaling elements
 * (videoscale); elements that crop or otherwise change the geometry drop it.
 *
 * Since: 0.1
 */
typedef struct {
	GstMeta meta;

	gint id;
	const gchar *dictionary;
	gfloat corners[8];
	guint hamming;

	gboolean has_pose;
	gdouble rvec[3];
	gdouble tvec[3];
	gdouble reprojection_error;
	gdouble alternative_reprojection_error;

	gfloat margin;
	/* Since 0.3; appended, so that 0.2's fields keep their offsets. */
	gboolean tracking;
	gboolean tracked;
} GstFrappeMarkerMeta;

/**
 * gst_frappe_marker_meta_api_get_type:
 *
 * Returns: the API type of #GstFrappeMarkerMeta, to find the metas of a
 * buffer with
 *
 * Since: 0.1
 */
GST_FRAPPE_META_API GType gst_frappe_marker_meta_api_get_type(void);

/**
 * gst_frappe_marker_meta_get_info:
 *
 * Returns: (transfer none): the registration of #GstFrappeMarkerMeta
 *
 * Since: 0.1
 */
GST_FRAPPE_META_API const GstMetaInfo *gst_frappe_marker_meta_get_info(void);

/**
 * gst_buffer_add_frappe_marker_meta:
 * @buffer: a writable #GstBuffer
 * @id: marker id
 * @dictionary: (nullable): dictionary name (interned internally)
 * @corners: (array fixed-size=8): 8 floats, x0, y0, ..., x3, y3
 * @hamming: corrected bits
 *
 * Adds a marker meta to @buffer (what frappedetect does), without pose
 * (set has_pose, rvec, tvec and the reprojection errors afterwards when
 * known) and with a margin of 0 (set margin afterwards).
 *
 * Returns: (transfer none) (nullable): the new meta, %NULL (and a
 * critical) when @buffer is not a buffer or @corners is %NULL
 *
 * Since: 0.1
 */
GST_FRAPPE_META_API GstFrappeMarkerMeta *gst_buffer_add_frappe_marker_meta(GstBuffer *buffer, gint id,
									   const gchar *dictionary,
									   const gfloat corners[8], guint hamming);

/**
 * gst_buffer_get_frappe_marker_meta:
 * @b: a #GstBuffer
 *
 * Returns: (transfer none) (nullable): the first marker meta of @buffer.
 *
 * Since: 0.1
 */
#define gst_buffer_get_frappe_marker_meta(b) \
	((GstFrappeMarkerMeta *)gst_buffer_get_meta((b), GST_FRAPPE_MARKER_META_API_TYPE))

/**
 * gst_buffer_get_n_frappe_marker_metas:
 * @buffer: a #GstBuffer
 *
 * Returns: how many marker metas @buffer carries.
 *
 * Since: 0.1
 */
GST_FRAPPE_META_API guint gst_buffer_get_n_frappe_marker_metas(GstBuffer *buffer);

/**
 * GST_FRAPPE_ROI_TYPE:
 *
 * The roi_type of the GstVideoRegionOfInterestMeta frappedetect adds per
 * marker.
 *
 * Since: 0.1
 */
#define GST_FRAPPE_ROI_TYPE "fiducial"

G_END_DECLS
