/* SPDX-License-Identifier: MIT
 *
 * gstfrappejson.h: the frappejson element, a frame's markers as a line of
 * JSON.
 */
#pragma once

#include <gst/base/gstbasetransform.h>
#include <gst/gst.h>

G_BEGIN_DECLS

#define GST_TYPE_FRAPPE_JSON (gst_frappe_json_get_type())
G_DECLARE_FINAL_TYPE(GstFrappeJson, gst_frappe_json, GST, FRAPPE_JSON, GstBaseTransform)

GST_ELEMENT_REGISTER_DECLARE(frappejson);

G_END_DECLS
