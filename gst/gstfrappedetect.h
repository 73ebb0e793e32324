/* SPDX-License-Identifier: MIT
 *
 * gstfrappedetect.h: the frappedetect element.
 */
#pragma once

#include <gst/gst.h>
#include <gst/video/gstvideofilter.h>

G_BEGIN_DECLS

#define GST_TYPE_FRAPPE_DETECT (gst_frappe_detect_get_type())
G_DECLARE_FINAL_TYPE(GstFrappeDetect, gst_frappe_detect, GST, FRAPPE_DETECT, GstVideoFilter)

GST_ELEMENT_REGISTER_DECLARE(frappedetect);

G_END_DECLS
