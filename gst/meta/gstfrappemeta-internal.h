/* SPDX-License-Identifier: MIT
 *
 * gstfrappemeta-internal.h: what the marker and bundle metas share inside
 * libgstfrappemeta (not installed): their API type's registration and the
 * factors of a scale transform.
 */
#pragma once

#include <gst/video/video.h>

namespace frappe::gstmeta {

/* A meta API registered once under `name`, with the tags of a meta tied to
 * the video's geometry: elements that change it other than by scaling
 * drop it. */
inline GType registerApi(GType &type, const char *name)
{
	static const gchar *tags[] = { GST_META_TAG_VIDEO_STR, GST_META_TAG_VIDEO_SIZE_STR,
				       GST_META_TAG_VIDEO_ORIENTATION_STR, nullptr };
	if (g_once_init_enter(&type)) {
		GType t = gst_meta_api_type_register(name, tags);
		g_once_init_leave(&type, t);
	}
	return type;
}

/* The x and y factors of a GstVideoMetaTransform's scaling; false for an
 * input of no size. */
inline bool scaleFactors(gpointer data, gdouble &sx, gdouble &sy)
{
	const auto *trans = static_cast<const GstVideoMetaTransform *>(data);
	const gint inW = GST_VIDEO_INFO_WIDTH(trans->in_info);
	const gint inH = GST_VIDEO_INFO_HEIGHT(trans->in_info);
	if (inW <= 0 || inH <= 0)
		return false;
	sx = static_cast<gdouble>(GST_VIDEO_INFO_WIDTH(trans->out_info)) / inW;
	sy = static_cast<gdouble>(GST_VIDEO_INFO_HEIGHT(trans->out_info)) / inH;
	return true;
}

} // namespace frappe::gstmeta
