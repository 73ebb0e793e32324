/* SPDX-License-Identifier: MIT
 *
 * gstfrappeenums.h: the enum types of frappedetect's own properties (the
 * detector's choices, dictionary and mode, are strings: frappe/settings.h)
 * and the flags of frappejson's fields.
 */
#pragma once

#include <glib-object.h>

G_BEGIN_DECLS

/* The indices of frappe::backendNames(). */
typedef enum {
	GST_FRAPPE_BACKEND_AUTO,
	GST_FRAPPE_BACKEND_CPU,
	GST_FRAPPE_BACKEND_VC4,
	GST_FRAPPE_BACKEND_VC4_EMU,
} GstFrappeBackend;

/* What pipelined=true overlaps (pipelined=false overlaps nothing). */
typedef enum {
	GST_FRAPPE_OVERLAP_AUTO,
	GST_FRAPPE_OVERLAP_FRAMES,
	GST_FRAPPE_OVERLAP_STAGES,
} GstFrappeOverlap;

#define GST_TYPE_FRAPPE_BACKEND (gst_frappe_backend_get_type())
GType gst_frappe_backend_get_type(void);

#define GST_TYPE_FRAPPE_OVERLAP (gst_frappe_overlap_get_type())
GType gst_frappe_overlap_get_type(void);

/* frappejson's fields: bit i is frappe::markerFieldNames()[i] (the id, bit
 * 0, is always written and not a flag). */
#define GST_TYPE_FRAPPE_JSON_FIELDS (gst_frappe_json_fields_get_type())
GType gst_frappe_json_fields_get_type(void);

G_END_DECLS

/* The nick ("auto", "cpu", "vc4", "vc4-emu"): the name frappe::selectBackend() takes. */
const char *gst_frappe_backend_nick(GstFrappeBackend backend);
