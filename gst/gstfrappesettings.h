/* SPDX-License-Identifier: MIT
 *
 * gstfrappesettings.h: frappedetect's properties. The detector's take their
 * defaults from frappe::Config{} and their ranges from the library's
 * validation; the element's own (annotate, pose, ...) are defined here.
 */
#pragma once

#include <gst/gst.h>

#include <frappe/config.h>

#include "gstfrappeenums.h"
#include "pose.h"

namespace frappe::gst {

enum Property {
	PROP_0,
	PROP_DICTIONARY,
	PROP_MODE,
	PROP_EDGE_THRESHOLD,
	PROP_CORNER_THRESHOLD,
	PROP_REGION_CONTRAST,
	PROP_MAX_HAMMING,
	PROP_SCALED_SIZE,
	PROP_MAX_SCALED_FRAMES,
	PROP_ANNOTATE,
	PROP_POST_MESSAGES,
	PROP_PIPELINED,
	PROP_BACKEND,
	PROP_MARKER_SIZE,
	PROP_CAMERA_MATRIX,
	PROP_DISTORTION,
	PROP_STATS,
};

/* The library's defaults: the detector's properties start from these. */
inline const frappe::Config kLibraryDefaults{};

/* Everything the properties set. The element copies it under the object
 * lock at the start of each frame. */
struct Settings {
	gint dictionary = gst_frappe_dictionary_index(kLibraryDefaults.dictionary.c_str());
	GstFrappeMode mode = gst_frappe_mode_from_library(kLibraryDefaults.mode);
	gfloat edgeThreshold = kLibraryDefaults.edge_threshold;
	gfloat cornerThreshold = kLibraryDefaults.corner_threshold;
	gfloat regionContrast = kLibraryDefaults.region_contrast;
	gint maxHamming = kLibraryDefaults.max_hamming;
	gfloat scaledSize = kLibraryDefaults.scaled_size;
	gint maxScaledFrames = kLibraryDefaults.max_scaled_frames;
	gboolean annotate = FALSE;
	gboolean postMessages = TRUE;
	gboolean pipelined = FALSE;
	GstFrappeBackend backend = GST_FRAPPE_BACKEND_AUTO;
	gdouble markerSize = 0.0; /* no pose */
	Camera camera;

	/* Whether a change between two settings needs a new Pipeline. */
	bool samePipeline(const Settings &o) const;

	/* The pipeline's configuration: one thread, or two when pipelined;
	 * max-hamming clamped to what the dictionary allows. */
	frappe::Config config() const;
};

/* Installs every property; PROP_STATS is the element's to answer. */
void installProperties(GObjectClass *klass);

/* Sets or gets a property of `s` (not PROP_STATS); false for an id that
 * is not a setting. `self` is for the warnings about ignored values. */
bool setProperty(GObject *self, Settings &s, guint propId, const GValue *value);
bool getProperty(const Settings &s, guint propId, GValue *value);

} /* namespace frappe::gst */
