/* SPDX-License-Identifier: MIT
 *
 * gstfrappesettings.h: frappedetect's properties. The detector's are made
 * from the library's settings table (frappe/settings.h): name, type,
 * default, range and text; the element's own (annotate, pose, files, ...)
 * are defined here, with what setting them checks and reads.
 */
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>

#include <gst/gst.h>

#include <frappe/bundle.h>
#include <frappe/camera.h>
#include <frappe/config.h>
#include <frappe/pipeline.h>
#include <frappe/pose.h>
#include <frappe/settings.h>

#include "gstfrappeenums.h"

namespace frappe::gst {

/* The element's own properties; the detector's (frappe::settings() with
 * kOnElement) follow from PROP_SETTING_0, one per entry of the table. */
enum Property {
	PROP_0,
	PROP_ANNOTATE,
	PROP_POST_MESSAGES,
	PROP_PIPELINED,
	PROP_BACKEND,
	PROP_MARKER_SIZE,
	PROP_CAMERA_MATRIX,
	PROP_DISTORTION,
	PROP_CALIBRATION_FILE,
	PROP_MARKER_SIZES,
	PROP_DICTIONARY_FILE,
	PROP_STATS,
	PROP_OVERLAP,
	PROP_BUNDLE_FILE,
	PROP_SETTING_0,
};

/* Everything the properties set. The element copies it under the object
 * lock at the start of a frame when its generation changed. */
struct Settings {
	/* The detector's properties: frappe::Config{}'s defaults, set through
	 * the table (frappe/settings.h). */
	frappe::Config library;
	gboolean annotate = FALSE;
	gboolean postMessages = TRUE;
	gboolean pipelined = FALSE;
	GstFrappeOverlap overlap = GST_FRAPPE_OVERLAP_AUTO;
	GstFrappeBackend backend = GST_FRAPPE_BACKEND_AUTO;
	gdouble markerSize = 0.0; /* no pose */
	std::string markerSizesSpec;   /* marker-sizes, as set */
	frappe::MarkerSizes sizes;     /* marker-sizes over the default marker-size */
	frappe::Camera camera;         /* camera-matrix and distortion */
	std::string calibrationFile;   /* calibration-file, "" for none */
	std::optional<frappe::Camera> calibration; /* read from it: at start, or when set while running */
	std::string dictionaryFile;    /* dictionary-file, "" for none */
	std::shared_ptr<const frappe::Dictionary> customDictionary; /* read from it, as the calibration */
	std::string bundleFile;                                     /* bundle-file, "" for none */
	std::shared_ptr<const frappe::Bundle> bundle;               /* read from it, as the calibration */

	/* Bumped by every property set: the element copies the settings only
	 * when it changed (no copy, no allocation per frame). */
	guint generation = 0;
	/* Bumped when the camera of the pose changes (camera-matrix,
	 * distortion, calibration-file): the element fits it to the frame
	 * size again. */
	guint cameraGeneration = 0;

	/* Whether a change between two settings needs a new Pipeline. */
	bool samePipeline(const Settings &o) const;

	/* The pipeline's configuration: one thread, or two when pipelined
	 * over whole frames (`staged`: one detector, whose second thread is
	 * the pipeline's); max-hamming clamped to what the dictionary allows;
	 * the custom dictionary when dictionary-file is set. */
	frappe::Config config(bool staged = false) const;

	/* The camera of the pose, at the calibration's size: the calibration
	 * file's when one is set (it wins over camera-matrix and distortion),
	 * else camera-matrix's when set; nullptr for none. */
	const frappe::Camera *poseCamera() const;
};

/* Installs every property; PROP_STATS is the element's to answer. */
void installProperties(GObjectClass *klass);

/* The values refused while the element was stopped, by property id: each
 * text names the property, the value, why and what the property takes.
 * The next state change fails on them (failRefused()): a gst-launch-1.0
 * line sets the properties before the pipeline has a bus, so a warning
 * then reaches nobody. Setting a property again clears its entry. */
using Refusals = std::map<guint, std::string>;

/* Sets a property of `props` (not PROP_STATS), taking `element`'s object
 * lock around it; false for an id that is not a setting. A value that
 * cannot be used is refused with a GST_ELEMENT_WARNING and the previous
 * one kept; when not `running` it also goes into `refused` (under the
 * lock). The files of calibration-file, dictionary-file and bundle-file
 * are read (outside the lock) when `running` (read under the lock) is set,
 * else at start by startSettings(). */
bool setProperty(GstElement *element, Settings &props, const bool &running, Refusals &refused, guint propId,
		 const GValue *value);

/* Before a state change from NULL or READY: a GST_ELEMENT_ERROR
 * (GST_RESOURCE_ERROR_SETTINGS) listing the refused values and false, or
 * true when there are none. Takes the object lock. */
bool failRefused(GstElement *element, const Refusals &refused);
/* Gets a property of `s` (not PROP_STATS); false for an unknown id. */
bool getProperty(const Settings &s, guint propId, GValue *value);

/* At start: reads the files that calibration-file, dictionary-file and
 * bundle-file name into `props` and sets `running`. A file that cannot be
 * used, or a bundle-file without a camera (calibration-file or
 * camera-matrix) for its pose, is a GST_ELEMENT_ERROR naming the
 * property, the file and why, and false. */
bool startSettings(GstElement *element, Settings &props, bool &running);

/* Puts the front end `backend` names into the pipeline's detectors: an
 * element error and false when it cannot be used, one warning (the first
 * time: `warnedFallback`) when auto falls back to the CPU. */
bool selectFrontEnd(GstElement *element, frappe::Pipeline &pipeline, GstFrappeBackend backend,
		    bool &warnedFallback);

/* Whether the pipeline's front end runs on the QPUs (vc4 or vc4-emu). */
bool frontEndOnQpus(frappe::Pipeline &pipeline);

/* The backend whose QPUs read frames in place, for the pool offered
 * upstream: vc4 or vc4-emu, or auto when `pipeline` (the one auto made, or
 * nullptr) runs the QPUs; nullptr for the CPU. */
const char *frameMemoryBackend(GstFrappeBackend backend, frappe::Pipeline *pipeline);

} /* namespace frappe::gst */
