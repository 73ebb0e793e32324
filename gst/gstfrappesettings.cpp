/* SPDX-License-Identifier: MIT
 *
 * gstfrappesettings.cpp: frappedetect's properties.
 */
#include "gstfrappesettings.h"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <variant>
#include <cstddef>
#include <exception>
#include <limits>
#include <string>
#include <vector>

#include <frappe/dictionary.h>

#include "frappe_backend.h"

GST_DEBUG_CATEGORY_EXTERN(gst_frappe_detect_debug);
#define GST_CAT_DEFAULT gst_frappe_detect_debug

namespace frappe::gst {

namespace {

/* The least float above an open minimum. Not a subnormal: in a process
 * where any library built with -ffast-math set flush-to-zero (GStreamer
 * scanning its plugins in-process loads some), a subnormal minimum reads
 * as the refused minimum itself. */
float aboveOpenMinimum(float lo, float hi)
{
	const float v = std::nextafter(lo, hi);
	return std::fpclassify(v) == FP_SUBNORMAL ? std::numeric_limits<float>::min() : v;
}

/* The element's own: the pose's marker side in metres. */
constexpr gdouble kMarkerSizeMax = 1000.0;

/* The detector's settings the element offers, in the table's order: the
 * property id of settingsOnElement()[i] is PROP_SETTING_0 + i. */
const std::vector<const frappe::Setting *> &settingsOnElement()
{
	static const std::vector<const frappe::Setting *> list = [] {
		std::vector<const frappe::Setting *> out;
		for (const frappe::Setting &s : frappe::settings())
			if (s.surfaces & frappe::kOnElement)
				out.push_back(&s);
		return out;
	}();
	return list;
}

const frappe::Setting *settingOf(guint propId)
{
	const auto &list = settingsOnElement();
	if (propId < PROP_SETTING_0 || propId - PROP_SETTING_0 >= list.size())
		return nullptr;
	return list[propId - PROP_SETTING_0];
}

/* A property's spec from its entry: a choice (dictionary, mode) is a
 * string that takes every spelling the library does; a number has the
 * table's range (a GParamSpec range is closed: an open end starts at the
 * next float). */
GParamSpec *settingSpec(const frappe::Setting &s, GParamFlags flags)
{
	const char *name = g_intern_string(s.kebabName().c_str());
	std::string blurb(s.doc);
	if (s.isChoice())
		blurb += " (" + s.rangeText() + ")";
	const char *nick = g_intern_string(std::string(s.name).c_str());
	const char *text = g_intern_string(blurb.c_str());
	const frappe::Config defaults;
	return std::visit(
		[&](auto m) -> GParamSpec * {
			using T = std::remove_cvref_t<decltype(defaults.*m)>;
			if constexpr (std::is_same_v<T, float>) {
				const float lo = static_cast<float>(s.min), hi = static_cast<float>(s.max);
				return g_param_spec_float(name, nick, text, s.min_open ? aboveOpenMinimum(lo, hi) : lo,
							  std::isinf(s.max) ? G_MAXFLOAT : hi, defaults.*m, flags);
			} else if constexpr (std::is_same_v<T, int>) {
				return g_param_spec_int(name, nick, text, static_cast<gint>(s.min) + s.min_open,
							static_cast<gint>(s.max), defaults.*m, flags);
			} else if constexpr (std::is_same_v<T, long long>) {
				return g_param_spec_int64(name, nick, text, static_cast<gint64>(s.min) + s.min_open,
							  static_cast<gint64>(s.max), defaults.*m, flags);
			} else {
				return g_param_spec_string(name, nick, text, s.text(defaults).c_str(), flags);
			}
		},
		s.member);
}

void setDoubleArray(const GValue *value, std::vector<double> &out)
{
	out.clear();
	const guint n = gst_value_array_get_size(value);
	for (guint i = 0; i < n; ++i) {
		const GValue *v = gst_value_array_get_value(value, i);
		if (G_VALUE_HOLDS_DOUBLE(v))
			out.push_back(g_value_get_double(v));
		else if (G_VALUE_HOLDS_FLOAT(v))
			out.push_back(g_value_get_float(v));
		else if (G_VALUE_HOLDS_INT(v))
			out.push_back(g_value_get_int(v));
	}
}

void getDoubleArray(GValue *value, const double *v, std::size_t n)
{
	for (std::size_t i = 0; i < n; ++i) {
		GValue item = G_VALUE_INIT;
		g_value_init(&item, G_TYPE_DOUBLE);
		g_value_set_double(&item, v[i]);
		gst_value_array_append_and_take_value(value, &item);
	}
}

/* The files of calibration-file and dictionary-file: std::nullopt or
 * nullptr, and `error` set, when they cannot be used. */
std::optional<frappe::Camera> readCalibrationFile(const std::string &path, std::string &error)
{
	try {
		return frappe::readCalibration(path);
	} catch (const std::exception &e) {
		error = e.what();
		return std::nullopt;
	}
}

std::shared_ptr<const frappe::Dictionary> readDictionaryFile(const std::string &path, std::string &error)
{
	try {
		return frappe::loadDictionary(path);
	} catch (const std::exception &e) {
		error = e.what();
		return nullptr;
	}
}

std::shared_ptr<const frappe::Bundle> readBundleFile(const std::string &path, std::string &error)
{
	try {
		return std::make_shared<const frappe::Bundle>(frappe::loadBundle(path));
	} catch (const std::exception &e) {
		error = e.what();
		return nullptr;
	}
}

/* What a bundle-file without a camera is refused with. */
constexpr const char *kBundleNeedsCamera = "a bundle's pose needs the camera: set calibration-file or camera-matrix";

/* A file property's value, read when the element is running. */
struct FileValue {
	std::string path;
	std::optional<frappe::Camera> calibration;
	std::shared_ptr<const frappe::Dictionary> dictionary;
	std::shared_ptr<const frappe::Bundle> bundle;
};

/* Outside the object lock (a dictionary may take a while to check):
 * false, and `why` set, when the file cannot be used. */
bool readFileProperty(guint propId, const GValue *value, bool running, FileValue &out, std::string &why)
{
	const gchar *path = g_value_get_string(value);
	out.path = path ? path : "";
	if (!running || out.path.empty())
		return true;
	std::string error;
	if (propId == PROP_CALIBRATION_FILE)
		out.calibration = readCalibrationFile(out.path, error);
	else if (propId == PROP_BUNDLE_FILE)
		out.bundle = readBundleFile(out.path, error);
	else
		out.dictionary = readDictionaryFile(out.path, error);
	if (error.empty())
		return true;
	why = error;
	return false;
}

} /* namespace */

bool Settings::samePipeline(const Settings &o) const
{
	for (const frappe::Setting &s : frappe::settings())
		if (!s.same(library, o.library))
			return false;
	return backend == o.backend && pipelined == o.pipelined &&
	       (overlap == o.overlap || !pipelined) && /* overlap means nothing unpipelined */
	       customDictionary == o.customDictionary;
}

frappe::Config Settings::config(bool staged) const
{
	frappe::Config config = library;
	const auto &dict = customDictionary ? *customDictionary : *frappe::findDictionary(library.dictionary);
	config.custom_dictionary = customDictionary;
	config.max_hamming = std::min(library.max_hamming, dict.codeBits() / 2);
	/* Whole frames on two threads; track follows the video on one. */
	config.threads = pipelined && !staged && config.mode != frappe::Mode::Track ? 2 : 1;
	return config;
}

const frappe::Camera *Settings::poseCamera() const
{
	if (!calibrationFile.empty())
		return calibration ? &*calibration : nullptr;
	return camera.valid() ? &camera : nullptr;
}

void installProperties(GObjectClass *gobject_class)
{
	const Settings defaults;
	const auto rw = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS);
	const auto live = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
						   GST_PARAM_MUTABLE_PLAYING);

	/* The detector's: one per entry of the library's table. */
	const auto &list = settingsOnElement();
	for (std::size_t i = 0; i < list.size(); ++i)
		g_object_class_install_property(gobject_class, static_cast<guint>(PROP_SETTING_0 + i),
						settingSpec(*list[i], live));
	g_object_class_install_property(
		gobject_class, PROP_ANNOTATE,
		g_param_spec_boolean("annotate", "Annotate",
				     "Draw outlines, first corners, ids and pose axes into the frame "
				     "(maps the frame writable)",
				     defaults.annotate, live));
	g_object_class_install_property(
		gobject_class, PROP_POST_MESSAGES,
		g_param_spec_boolean("post-messages", "Post messages",
				     "Post a frappedetect element message per frame", defaults.postMessages, live));
	g_object_class_install_property(
		gobject_class, PROP_PIPELINED,
		g_param_spec_boolean("pipelined", "Pipelined",
				     "Detect two frames at once, as overlap says "
				     "(holds one buffer: one frame of extra latency)",
				     defaults.pipelined, live));
	/**
	 * GstFrappeDetect:overlap:
	 *
	 * What #GstFrappeDetect:pipelined overlaps; no effect without it.
	 * `auto` (the default): `stages` when the front end runs on the QPUs
	 * (backend vc4, vc4-emu, or auto that found them), `frames` on CPUs.
	 * `frames`: two whole frames at once, each on a detector and a thread of
	 * its own (for several cores). `stages`: one detector, the next frame's
	 * front end (the QPU passes) while this frame's contours are traced,
	 * then this frame finished (for a Pi Zero's one core beside its QPUs: one
	 * QPU context). Either holds one buffer. The `stats` field `overlap`
	 * says which ran.
	 */
	g_object_class_install_property(
		gobject_class, PROP_OVERLAP,
		g_param_spec_enum("overlap", "Overlap",
				  "What pipelined=true overlaps: auto (stages with the QPUs, else frames), frames "
				  "(two whole frames on two threads), stages (the next frame's QPU front end beside "
				  "this frame's trace, one detector)",
				  GST_TYPE_FRAPPE_OVERLAP, defaults.overlap, live));
	g_object_class_install_property(
		gobject_class, PROP_BACKEND,
		g_param_spec_enum("backend", "Backend", "Where the front end runs", GST_TYPE_FRAPPE_BACKEND,
				  defaults.backend, live));
	g_object_class_install_property(
		gobject_class, PROP_MARKER_SIZE,
		g_param_spec_double("marker-size", "Marker size",
				    "Side of the markers' black square in metres, for the pose (0 = no pose)",
				    0.0, kMarkerSizeMax, defaults.markerSize, live));
	g_object_class_install_property(
		gobject_class, PROP_CAMERA_MATRIX,
		gst_param_spec_array("camera-matrix", "Camera matrix",
				     "Camera intrinsics for the pose, 9 numbers row-major: "
				     "<fx, 0, cx, 0, fy, cy, 0, 0, 1> (empty = no pose; calibration-file wins)",
				     g_param_spec_double("element", "Element", "A matrix element", -G_MAXDOUBLE,
							 G_MAXDOUBLE, 0.0, rw),
				     live));
	g_object_class_install_property(
		gobject_class, PROP_DISTORTION,
		gst_param_spec_array("distortion", "Distortion",
				     "Lens distortion in OpenCV's order <k1, k2, p1, p2[, k3[, k4, k5, k6]]> "
				     "(empty = none)",
				     g_param_spec_double("coefficient", "Coefficient", "A distortion coefficient",
							 -G_MAXDOUBLE, G_MAXDOUBLE, 0.0, rw),
				     live));
	g_object_class_install_property(
		gobject_class, PROP_CALIBRATION_FILE,
		g_param_spec_string("calibration-file", "Calibration file",
				    "Camera calibration for the pose: ROS camera_info YAML or OpenCV FileStorage "
				    "YAML/XML, scaled to the frame size; wins over camera-matrix and distortion",
				    nullptr, live));
	g_object_class_install_property(
		gobject_class, PROP_MARKER_SIZES,
		g_param_spec_string("marker-sizes", "Marker sizes",
				    "Sides in metres of some ids, \"id:size,...\" (e.g. \"0:0.05,7:0.10\"); "
				    "other ids have marker-size",
				    "", live));
	g_object_class_install_property(
		gobject_class, PROP_DICTIONARY_FILE,
		g_param_spec_string("dictionary-file", "Dictionary file",
				    "A dictionary of your own (frappe's text format or OpenCV aruco YAML); when set, "
				    "used instead of dictionary",
				    nullptr, live));
	/**
	 * GstFrappeDetect:bundle-file:
	 *
	 * A bundle (a board, a rigid set of markers with known 3D corners,
	 * frappe/bundle.h): apriltag_ros's tags.yaml (its first tag_bundles
	 * entry) or a grid board (`board: grid`, `rows`, `cols`, `size`, `gap`
	 * in metres, optional `first_id`, `name`). Each frame where markers of
	 * the bundle are seen gets one pose from all of them
	 * (frappe::estimateBundlePose) as a #GstFrappeBundleMeta, a `bundle`
	 * structure in the element message and a `"bundle"` object in
	 * frappejson's line. The bundle gives its markers' sizes: marker-size is
	 * not needed for it. Needs the camera (calibration-file or
	 * camera-matrix): without one the element does not start. Read at
	 * start; set while playing it is read at once, and a file that cannot be
	 * used is a warning and the previous bundle is kept, as for
	 * calibration-file. NULL or "" for none.
	 *
	 * Since: 0.3
	 */
	g_object_class_install_property(
		gobject_class, PROP_BUNDLE_FILE,
		g_param_spec_string("bundle-file", "Bundle file",
				    "A bundle of markers for one pose from all of them: apriltag_ros tags.yaml "
				    "(tag_bundles) or a grid board (board: grid, rows, cols, size, gap in metres); "
				    "needs calibration-file or camera-matrix",
				    nullptr, live));
	g_object_class_install_property(
		gobject_class, PROP_STATS,
		g_param_spec_boxed("stats", "Statistics",
				   "Per-stage timings (ms) and counts of the last frame (candidates read, "
				   "candidates-dropped over the cap, copied-bytes the backend copied before "
				   "reading it), the overlap that ran (none, frames, stages) and the QPU "
				   "contexts opened since start", GST_TYPE_STRUCTURE,
				   static_cast<GParamFlags>(G_PARAM_READABLE | G_PARAM_STATIC_STRINGS)));
}

namespace {

/* A value that needs no file; `why` set when it is refused (and the
 * previous one kept). */
bool setValue(Settings &p, guint propId, const GValue *value, std::string &why)
{
	if (const frappe::Setting *s = settingOf(propId)) {
		if (s->isChoice()) {
			const gchar *text = g_value_get_string(value);
			try {
				s->parse(p.library, text ? text : "");
			} catch (const std::exception &) {
				why = "not one of its values"; /* which the property's text lists */
			}
		} else if (G_VALUE_HOLDS_FLOAT(value)) {
			s->setNumber(p.library, g_value_get_float(value));
		} else if (G_VALUE_HOLDS_INT(value)) {
			s->setNumber(p.library, g_value_get_int(value));
		} else {
			s->setNumber(p.library, static_cast<double>(g_value_get_int64(value)));
		}
		return true;
	}
	switch (propId) {
	case PROP_ANNOTATE:
		p.annotate = g_value_get_boolean(value);
		break;
	case PROP_POST_MESSAGES:
		p.postMessages = g_value_get_boolean(value);
		break;
	case PROP_PIPELINED:
		p.pipelined = g_value_get_boolean(value);
		break;
	case PROP_OVERLAP:
		p.overlap = static_cast<GstFrappeOverlap>(g_value_get_enum(value));
		break;
	case PROP_BACKEND:
		p.backend = static_cast<GstFrappeBackend>(g_value_get_enum(value));
		break;
	case PROP_CAMERA_MATRIX: {
		std::vector<double> m;
		setDoubleArray(value, m);
		frappe::Camera c = p.camera;
		if (m.empty()) {
			p.camera.matrix = {};
			break;
		}
		if (m.size() != 9) {
			why = "needs 9 numbers (row-major 3x3), got " + std::to_string(m.size());
			return true;
		}
		std::copy(m.begin(), m.end(), c.matrix.begin());
		try {
			c.validate();
		} catch (const std::exception &e) {
			why = e.what();
			return true;
		}
		p.camera = c;
		break;
	}
	case PROP_DISTORTION: {
		/* Checked as the library would with any valid matrix. */
		frappe::Camera c = frappe::Camera::pinhole(1.0, 1.0, 0.0, 0.0);
		setDoubleArray(value, c.distortion);
		try {
			c.validate();
		} catch (const std::exception &e) {
			why = e.what();
			return true;
		}
		p.camera.distortion = c.distortion;
		break;
	}
	default:
		return false;
	}
	return true;
}

/* marker-size and marker-sizes make one MarkerSizes: parsed outside the
 * object lock, which the streaming thread takes for every buffer, and
 * parsed again if either changed meanwhile. `why` set when refused. */
void setMarkerSizes(GstElement *element, Settings &p, guint propId, const GValue *value, std::string &why)
{
	const gchar *given = propId == PROP_MARKER_SIZES ? g_value_get_string(value) : nullptr;
	for (;;) {
		GST_OBJECT_LOCK(element);
		const guint generation = p.generation;
		const double size = propId == PROP_MARKER_SIZE ? g_value_get_double(value) : p.markerSize;
		const std::string text = propId == PROP_MARKER_SIZES ? (given ? given : "") : p.markerSizesSpec;
		GST_OBJECT_UNLOCK(element);
		frappe::MarkerSizes sizes;
		try {
			sizes = frappe::MarkerSizes::parse(text, size);
		} catch (const std::exception &e) {
			why = e.what();
			return;
		}
		GST_OBJECT_LOCK(element);
		if (p.generation == generation) {
			p.sizes = std::move(sizes);
			p.markerSize = size;
			if (propId == PROP_MARKER_SIZES)
				p.markerSizesSpec = text;
			++p.generation;
			GST_OBJECT_UNLOCK(element);
			return;
		}
		GST_OBJECT_UNLOCK(element);
	}
}

/* The start of a value for a message: a value may be up to
 * MarkerSizes::kMaxSpecBytes long. */
std::string shortened(const std::string &text)
{
	constexpr std::size_t kShown = 60;
	return text.size() <= kShown ? text : text.substr(0, kShown) + "...";
}

/* What a refused value's warning and error say: the property, the value
 * as it would be written on a gst-launch-1.0 line, why, and the property's
 * own text (its blurb: what it takes, a choice's valid values). */
std::string refusal(GstElement *element, guint propId, const std::string &valueText, const std::string &why)
{
	GParamSpec *spec = nullptr;
	guint n = 0;
	GParamSpec **specs = g_object_class_list_properties(G_OBJECT_GET_CLASS(element), &n);
	for (guint i = 0; i < n && !spec; ++i)
		if (specs[i]->param_id == propId && specs[i]->owner_type == G_OBJECT_TYPE(element))
			spec = specs[i];
	g_free(specs);
	const char *name = spec ? g_param_spec_get_name(spec) : "?";
	std::string text = std::string(name) + "=\"" + shortened(valueText) + "\" refused: " + why;
	if (spec)
		text += ". " + std::string(name) + ": " + g_param_spec_get_blurb(spec);
	return text;
}

std::string refusal(GstElement *element, guint propId, const GValue *value, const std::string &why)
{
	std::string valueText;
	if (G_VALUE_HOLDS_STRING(value)) {
		const gchar *v = g_value_get_string(value);
		valueText = v ? v : "";
	} else if (GST_VALUE_HOLDS_ARRAY(value)) {
		/* As a gst-launch line writes it: <1.0, 2.5>. */
		std::vector<double> numbers;
		setDoubleArray(value, numbers);
		for (double x : numbers) {
			char text[32];
			g_ascii_dtostr(text, sizeof(text), x);
			valueText += (valueText.empty() ? "<" : ", ") + std::string(text);
		}
		valueText += valueText.empty() ? "<>" : ">";
	} else if (gchar *v = gst_value_serialize(value)) {
		valueText = v;
		g_free(v);
	}
	return refusal(element, propId, valueText, why);
}

} /* namespace */

bool setProperty(GstElement *element, Settings &props, const bool &running, Refusals &refused, guint propId,
		 const GValue *value)
{
	std::string why;
	if (propId == PROP_CALIBRATION_FILE || propId == PROP_DICTIONARY_FILE || propId == PROP_BUNDLE_FILE) {
		GST_OBJECT_LOCK(element);
		const bool read = running;
		GST_OBJECT_UNLOCK(element);
		FileValue file;
		if (readFileProperty(propId, value, read, file, why)) {
			GST_OBJECT_LOCK(element);
			if (propId == PROP_CALIBRATION_FILE) {
				props.calibrationFile = file.path;
				props.calibration = file.calibration;
				++props.cameraGeneration;
			} else if (propId == PROP_BUNDLE_FILE) {
				props.bundleFile = file.path;
				props.bundle = file.bundle;
			} else {
				props.dictionaryFile = file.path;
				props.customDictionary = file.dictionary;
			}
			++props.generation;
			GST_OBJECT_UNLOCK(element);
		}
	} else if (propId == PROP_MARKER_SIZE || propId == PROP_MARKER_SIZES) {
		setMarkerSizes(element, props, propId, value, why);
	} else {
		GST_OBJECT_LOCK(element);
		const guint cameraGeneration = props.cameraGeneration;
		if (!setValue(props, propId, value, why)) {
			GST_OBJECT_UNLOCK(element);
			return false;
		}
		if (why.empty()) {
			++props.generation;
			if (propId == PROP_CAMERA_MATRIX || propId == PROP_DISTORTION)
				props.cameraGeneration = cameraGeneration + 1;
		}
		GST_OBJECT_UNLOCK(element);
	}

	const std::string text = why.empty() ? std::string() : refusal(element, propId, value, why);
	GST_OBJECT_LOCK(element);
	if (why.empty())
		refused.erase(propId);
	else if (!running)
		refused[propId] = text;
	GST_OBJECT_UNLOCK(element);
	if (!why.empty())
		GST_ELEMENT_WARNING(element, RESOURCE, SETTINGS, ("%s; keeping the previous value", text.c_str()),
				    (nullptr));
	return true;
}

bool failRefused(GstElement *element, const Refusals &refused)
{
	GST_OBJECT_LOCK(element);
	std::string text;
	for (const auto &[id, why] : refused)
		text += (text.empty() ? "" : "\n") + why;
	GST_OBJECT_UNLOCK(element);
	if (text.empty())
		return true;
	GST_ELEMENT_ERROR(element, RESOURCE, SETTINGS, ("%s", text.c_str()),
			  ("refused while the element was stopped; set a valid value before starting"));
	return false;
}

bool startSettings(GstElement *element, Settings &props, bool &running)
{
	/* Running first: a file set from now on is read when set. */
	GST_OBJECT_LOCK(element);
	running = true;
	const std::string calibrationFile = props.calibrationFile, dictionaryFile = props.dictionaryFile,
			  bundleFile = props.bundleFile;
	const bool cameraMatrix = props.camera.valid();
	GST_OBJECT_UNLOCK(element);

	std::string error;
	std::optional<frappe::Camera> calibration;
	std::shared_ptr<const frappe::Dictionary> dictionary;
	std::shared_ptr<const frappe::Bundle> bundle;
	const auto refuse = [&](guint propId, const std::string &file) {
		GST_ELEMENT_ERROR(element, RESOURCE, SETTINGS, ("%s", refusal(element, propId, file, error).c_str()),
				  (nullptr));
	};
	if (!calibrationFile.empty() && !(calibration = readCalibrationFile(calibrationFile, error))) {
		refuse(PROP_CALIBRATION_FILE, calibrationFile);
	} else if (!dictionaryFile.empty() && !(dictionary = readDictionaryFile(dictionaryFile, error))) {
		refuse(PROP_DICTIONARY_FILE, dictionaryFile);
	} else if (!bundleFile.empty() && !(bundle = readBundleFile(bundleFile, error))) {
		refuse(PROP_BUNDLE_FILE, bundleFile);
	} else if (bundle && !calibration && !cameraMatrix) {
		error = kBundleNeedsCamera;
		refuse(PROP_BUNDLE_FILE, bundleFile);
	}

	GST_OBJECT_LOCK(element);
	if (!error.empty()) {
		running = false;
	} else {
		/* Unless set again meanwhile (then read when set). */
		if (calibration && props.calibrationFile == calibrationFile) {
			props.calibration = calibration;
			++props.cameraGeneration;
		}
		if (dictionary && props.dictionaryFile == dictionaryFile)
			props.customDictionary = dictionary;
		if (bundle && props.bundleFile == bundleFile)
			props.bundle = bundle;
		++props.generation;
	}
	GST_OBJECT_UNLOCK(element);
	return error.empty();
}

bool selectFrontEnd(GstElement *element, frappe::Pipeline &pipeline, GstFrappeBackend backend,
		    bool &warnedFallback)
{
	const char *name = gst_frappe_backend_nick(backend);
	try {
		const std::string fallback = frappe::selectBackend(pipeline, name);
		if (!fallback.empty() && !warnedFallback) {
			warnedFallback = true;
			GST_ELEMENT_WARNING(element, RESOURCE, NOT_FOUND,
					    ("The GPU cannot be used; detecting on the CPU"),
					    ("backend=auto: %s", fallback.c_str()));
		}
	} catch (const frappe::BackendNotBuilt &) {
		GST_ELEMENT_ERROR(element, LIBRARY, SETTINGS, ("Backend %s is not in this build", name),
				  ("the plugin was built without vc4/"));
		return false;
	} catch (const std::exception &e) {
		GST_ELEMENT_ERROR(element, RESOURCE, OPEN_READ, ("Backend %s cannot be used", name),
				  ("%s", e.what()));
		return false;
	}
	return true;
}

bool frontEndOnQpus(frappe::Pipeline &pipeline)
{
	return g_str_has_prefix(pipeline.detector().frontEnd().name(), "vc4");
}

const char *frameMemoryBackend(GstFrappeBackend backend, frappe::Pipeline *pipeline)
{
	if (backend == GST_FRAPPE_BACKEND_VC4 || backend == GST_FRAPPE_BACKEND_VC4_EMU)
		return gst_frappe_backend_nick(backend);
	if (backend == GST_FRAPPE_BACKEND_AUTO && pipeline &&
	    g_str_equal(pipeline->detector().frontEnd().name(), "vc4"))
		return "vc4";
	return nullptr;
}

bool getProperty(const Settings &p, guint propId, GValue *value)
{
	if (const frappe::Setting *s = settingOf(propId)) {
		if (s->isChoice())
			g_value_set_string(value, s->text(p.library).c_str());
		else if (G_VALUE_HOLDS_FLOAT(value))
			g_value_set_float(value, static_cast<gfloat>(s->number(p.library)));
		else if (G_VALUE_HOLDS_INT(value))
			g_value_set_int(value, static_cast<gint>(s->number(p.library)));
		else
			g_value_set_int64(value, static_cast<gint64>(s->number(p.library)));
		return true;
	}
	switch (propId) {
	case PROP_ANNOTATE:
		g_value_set_boolean(value, p.annotate);
		break;
	case PROP_POST_MESSAGES:
		g_value_set_boolean(value, p.postMessages);
		break;
	case PROP_PIPELINED:
		g_value_set_boolean(value, p.pipelined);
		break;
	case PROP_OVERLAP:
		g_value_set_enum(value, p.overlap);
		break;
	case PROP_BACKEND:
		g_value_set_enum(value, p.backend);
		break;
	case PROP_MARKER_SIZE:
		g_value_set_double(value, p.markerSize);
		break;
	case PROP_MARKER_SIZES:
		g_value_set_string(value, p.markerSizesSpec.c_str());
		break;
	case PROP_CALIBRATION_FILE:
		g_value_set_string(value, p.calibrationFile.empty() ? nullptr : p.calibrationFile.c_str());
		break;
	case PROP_DICTIONARY_FILE:
		g_value_set_string(value, p.dictionaryFile.empty() ? nullptr : p.dictionaryFile.c_str());
		break;
	case PROP_BUNDLE_FILE: g_value_set_string(value, p.bundleFile.empty() ? nullptr : p.bundleFile.c_str()); break;
	case PROP_CAMERA_MATRIX:
		if (p.camera.valid())
			getDoubleArray(value, p.camera.matrix.data(), 9);
		break;
	case PROP_DISTORTION:
		getDoubleArray(value, p.camera.distortion.data(), p.camera.distortion.size());
		break;
	default:
		return false;
	}
	return true;
}

} /* namespace frappe::gst */
