// SPDX-License-Identifier: MIT
// Built against an installed gstfrappemeta (tests/install): attaches a
// marker meta to a buffer and reads it back, as an application reading
// frappedetect's output would.
#include <cstdio>

#include <gstfrappemeta.h>

int main(int argc, char **argv)
{
	gst_init(&argc, &argv);

	GstBuffer *buffer = gst_buffer_new();
	const gfloat corners[8] = { 10, 10, 50, 10, 50, 50, 10, 50 };
	gst_buffer_add_frappe_marker_meta(buffer, 7, "apriltag_36h11", corners, 1);

	const GstFrappeMarkerMeta *meta = gst_buffer_get_frappe_marker_meta(buffer);
	std::printf("%s id %d dictionary %s count %u\n", g_type_name(GST_FRAPPE_MARKER_META_API_TYPE),
		    meta ? meta->id : -1, meta ? meta->dictionary : "none",
		    gst_buffer_get_n_frappe_marker_metas(buffer));

	gst_buffer_unref(buffer);
	gst_deinit();
	return 0;
}
