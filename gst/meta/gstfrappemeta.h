/* SPDX-License-Identifier: MIT
 *
 * gstfrappemeta.h: the per-marker metadata that frappedetect attaches to
 * the buffers it detects on, for applications (link with pkg-config
 * gstfrappemeta).
 */
#pragma once

#include <gst/gst.h>

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
 *
 * One marker found by frappedetect. A buffer carries one meta per marker;
 * iterate them with gst_buffer_iterate_meta_filtered() and
 * %GST_FRAPPE_MARKER_META_API_TYPE.
 *
 * Camera frame: OpenCV's (x right, y down, z forward, in metres). Marker
 * frame: OpenCV aruco's (origin at the marker centre, x right, y up, z out
 * of the marker towards the camera); corner 0 is at (-s/2, s/2, 0) for a
 * marker of side s.
 *
 * The meta is copied with the buffer and rescaled by scaling elements
 * (videoscale); elements that crop or otherwise change the geometry drop it.
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
} GstFrappeMarkerMeta;

GType gst_frappe_marker_meta_api_get_type(void);
const GstMetaInfo *gst_frappe_marker_meta_get_info(void);

/**
 * gst_buffer_add_frappe_marker_meta:
 * @buffer: a writable #GstBuffer
 * @id: marker id
 * @dictionary: dictionary name (interned internally)
 * @corners: 8 floats, x0, y0, ..., x3, y3
 * @hamming: corrected bits
 *
 * Returns: (transfer none): the new meta, without pose (set has_pose, rvec,
 * tvec and reprojection_error afterwards when known) and with a margin of 0
 * (set margin afterwards).
 */
GstFrappeMarkerMeta *gst_buffer_add_frappe_marker_meta(GstBuffer *buffer, gint id,
						       const gchar *dictionary,
						       const gfloat corners[8], guint hamming);

/**
 * gst_buffer_get_frappe_marker_meta:
 * Returns: (transfer none) (nullable): the first marker meta of @buffer.
 */
#define gst_buffer_get_frappe_marker_meta(b) \
	((GstFrappeMarkerMeta *)gst_buffer_get_meta((b), GST_FRAPPE_MARKER_META_API_TYPE))

/**
 * gst_buffer_get_n_frappe_marker_metas:
 * Returns: how many marker metas @buffer carries.
 */
guint gst_buffer_get_n_frappe_marker_metas(GstBuffer *buffer);

/** The roi_type of the GstVideoRegionOfInterestMeta frappedetect adds per marker. */
#define GST_FRAPPE_ROI_TYPE "fiducial"

G_END_DECLS
