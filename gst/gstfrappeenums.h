/* SPDX-License-Identifier: MIT
 *
 * gstfrappeenums.h: the enum types of frappedetect's properties.
 */
#pragma once

#include <glib-object.h>

#include <frappe/config.h>

G_BEGIN_DECLS

typedef enum {
	GST_FRAPPE_MODE_NORMAL,
	GST_FRAPPE_MODE_ASCALE,
	GST_FRAPPE_MODE_TRACK,
} GstFrappeMode;

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

#define GST_TYPE_FRAPPE_MODE (gst_frappe_mode_get_type())
GType gst_frappe_mode_get_type(void);

#define GST_TYPE_FRAPPE_BACKEND (gst_frappe_backend_get_type())
GType gst_frappe_backend_get_type(void);

#define GST_TYPE_FRAPPE_OVERLAP (gst_frappe_overlap_get_type())
GType gst_frappe_overlap_get_type(void);

/* One value per built-in dictionary, in the library's stable order; value
 * names are the library's names ("6x6_250"), nicks the same with dashes
 * ("6x6-250"). */
#define GST_TYPE_FRAPPE_DICTIONARY (gst_frappe_dictionary_get_type())
GType gst_frappe_dictionary_get_type(void);

G_END_DECLS

/* The value of a dictionary name, 0 when the library has no such name. */
gint gst_frappe_dictionary_index(const char *name);

GstFrappeMode gst_frappe_mode_from_library(frappe::Mode mode);
frappe::Mode gst_frappe_mode_to_library(GstFrappeMode mode);

/* The nick ("auto", "cpu", "vc4", "vc4-emu"): the name frappe::selectBackend() takes. */
const char *gst_frappe_backend_nick(GstFrappeBackend backend);
