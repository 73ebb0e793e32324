/* SPDX-License-Identifier: MIT
 *
 * plugin.cpp: the frappe GStreamer plugin.
 */
#include <gst/gst.h>

#include "gstfrappedetect.h"
#include "gstfrappejson.h"

static gboolean plugin_init(GstPlugin *plugin)
{
	gboolean ok = GST_ELEMENT_REGISTER(frappedetect, plugin);
	ok &= GST_ELEMENT_REGISTER(frappejson, plugin);
	return ok;
}

/* "MIT/X11" is how GStreamer names the MIT licence: with any string outside
 * its list, every registry scan logs an "unknown license" warning. */
GST_PLUGIN_DEFINE(GST_VERSION_MAJOR, GST_VERSION_MINOR, frappe,
		  "Frappe square fiducial marker (ArUco, AprilTag) detection",
		  plugin_init, FRAPPE_VERSION, "MIT/X11", "frappe", "https://github.com/frappe-markers/frappe")
