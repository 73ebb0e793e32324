/* SPDX-License-Identifier: MIT
 *
 * gstfrappedetect.cpp: the frappedetect element.
 *
 * \todo GstAnalyticsRelationMeta output behind a >= 1.24 meson feature.
 * \todo An overlay-composition path for GL/compositor consumers.
 */

/**
 * SECTION:element-frappedetect
 * @title: frappedetect
 *
 * Detects square fiducial markers (ArUco, ArUco MIP, AprilTag families) with
 * the Frappe detector. Only the luma plane is read; the frame is mapped
 * read-only unless #GstFrappeDetect:annotate is set, so zero-copy (dmabuf)
 * buffers from cameras are never copied.
 *
 * For every marker found, the buffer gets a #GstFrappeMarkerMeta (id,
 * dictionary, four sub-pixel corners, Hamming distance, pose when known; see
 * gstfrappemeta.h and the `gstfrappemeta` pkg-config package) and a
 * #GstVideoRegionOfInterestMeta of type "fiducial" whose parameter structure
 * `fiducial` holds `id` (int), `dictionary` (string), `hamming` (uint) and
 * `margin` (double).
 *
 * Corners are in OpenCV's order (top-left, top-right, bottom-right,
 * bottom-left of the marker's outer black border in its canonical
 * orientation, clockwise on screen), in pixels, (0, 0) being the centre of
 * the top-left pixel.
 *
 * When #GstFrappeDetect:post-messages is TRUE (the default) the element posts
 * one element message per frame, named `frappedetect`, with the fields:
 *
 * * `timestamp` (guint64): the buffer's presentation timestamp
 * * `stream-time` (guint64), `running-time` (guint64): from the segment
 * * `duration` (guint64): the buffer's duration
 * * `markers` (GstValueList of GstStructure `marker`): one per marker with
 *   `id` (int), `dictionary` (string), `corners` (GstValueArray of 8 doubles:
 *   x0, y0, ..., x3, y3), `hamming` (uint), `margin` (double: how clearly
 *   the code was read, in [0, 1], the weakest code cell's distance from
 *   the black-white threshold as a fraction of half the contrast; near 0
 *   some cell was nearly a coin toss) and, when the pose is known,
 *   `rvec` and `tvec` (GstValueArray of 3 doubles: Rodrigues rotation and
 *   translation in metres), `reprojection-error` (double, RMS pixels) and
 *   `alternative-reprojection-error` (double: the error of the other planar
 *   solution; close to `reprojection-error` when the pose is ambiguous).
 *
 * Pose: set #GstFrappeDetect:marker-size (metres, the side of the black
 * square) and #GstFrappeDetect:camera-matrix (and optionally
 * #GstFrappeDetect:distortion). The pose comes from OpenCV's IPPE square
 * solver on the refined corners. It is given in OpenCV's camera frame (x
 * right, y down, z forward) for the marker frame of OpenCV aruco: origin at
 * the marker centre, x right, y up, z out of the marker towards the camera.
 *
 * #GstFrappeDetect:backend chooses where the front end (Sobel, edges,
 * corners, empty tiles) runs: `cpu`; `vc4`, the QPUs of a Raspberry Pi Zero,
 * 1, 2 or 3 (it fails to start when they cannot be used, e.g. while the vc4
 * KMS driver owns the GPU); `vc4-emu`, the same QPU programs on an emulator,
 * bit-exact and slow, for testing anywhere; `auto` (the default), the QPUs
 * when the probe succeeds, else the CPU with one warning on a Pi.
 *
 * With #GstFrappeDetect:pipelined, the front end of frame N+1 runs while the
 * back end of frame N runs on a worker thread. The element then holds one
 * buffer, answers the LATENCY query with one extra frame, asks upstream
 * pools for one more buffer, pushes the held buffer on EOS, caps, segment,
 * gap, stream-start and DRAIN queries, and drops it on flush.
 * Every buffer comes out once, in order, with its own metas.
 *
 * ## Example launch lines
 * |[
 * gst-launch-1.0 -m videotestsrc num-buffers=10 ! video/x-raw,format=GRAY8 ! frappedetect ! fakesink
 * ]| Prints one frappedetect message per frame (no markers in a test pattern).
 * |[
 * gst-launch-1.0 filesrc location=markers.webm ! decodebin ! videoconvert ! \
 *     video/x-raw,format=I420 ! frappedetect annotate=true ! videoconvert ! \
 *     vp8enc ! webmmux ! filesink location=annotated.webm
 * ]| Draws the markers into the video and writes it to a file.
 * |[
 * gst-launch-1.0 -m libcamerasrc ! video/x-raw,format=NV12,width=640,height=480 ! \
 *     frappedetect dictionary=apriltag-36h11 marker-size=0.1 \
 *     camera-matrix="<600.0,0.0,320.0,0.0,600.0,240.0,0.0,0.0,1.0>" ! fakesink
 * ]| Poses of AprilTag markers of 10 cm seen by a camera, on the bus.
 */

#include "gstfrappedetect.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gst/allocators/gstdmabuf.h>
#include <gst/video/video.h>

#include <frappe/frappe.h>
#ifdef FRAPPE_HAVE_VC4
#include "frontend/backend.hpp"
#endif

#include "annotate.h"
#include "gstfrappemeta.h"
#include "pose.h"

GST_DEBUG_CATEGORY_STATIC(gst_frappe_detect_debug);
#define GST_CAT_DEFAULT gst_frappe_detect_debug

/* -------------------------------------------------------------------------
 * Properties
 */

enum {
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

typedef enum {
	GST_FRAPPE_MODE_NORMAL,
	GST_FRAPPE_MODE_ASCALE,
} GstFrappeMode;

typedef enum {
	GST_FRAPPE_BACKEND_AUTO,
	GST_FRAPPE_BACKEND_CPU,
	GST_FRAPPE_BACKEND_VC4,
	GST_FRAPPE_BACKEND_VC4_EMU,
} GstFrappeBackend;

#define DEFAULT_DICTIONARY_NAME "aruco_mip_36h12"
#define DEFAULT_MODE GST_FRAPPE_MODE_NORMAL
#define DEFAULT_EDGE_THRESHOLD 0.27f
#define DEFAULT_CORNER_THRESHOLD 0.19f
#define DEFAULT_REGION_CONTRAST (frappe::Config{}.region_contrast)
#define DEFAULT_MAX_HAMMING -1
#define DEFAULT_SCALED_SIZE 28.0f
#define DEFAULT_MAX_SCALED_FRAMES 5
#define DEFAULT_ANNOTATE FALSE
#define DEFAULT_POST_MESSAGES TRUE
#define DEFAULT_PIPELINED FALSE
#define DEFAULT_BACKEND GST_FRAPPE_BACKEND_AUTO
#define DEFAULT_MARKER_SIZE 0.0
/* The largest max-hamming any built-in dictionary accepts (7x7: 49 / 2). */
#define MAX_MAX_HAMMING 24

#define GST_TYPE_FRAPPE_MODE (gst_frappe_mode_get_type())
static GType gst_frappe_mode_get_type(void)
{
	static GType type = 0;
	static const GEnumValue values[] = {
		{ GST_FRAPPE_MODE_NORMAL, "Every frame at full resolution", "normal" },
		{ GST_FRAPPE_MODE_ASCALE,
		  "Scale frames down from the size of the markers of the previous frame", "ascale" },
		{ 0, nullptr, nullptr },
	};
	if (g_once_init_enter(&type)) {
		GType t = g_enum_register_static("GstFrappeMode", values);
		g_once_init_leave(&type, t);
	}
	return type;
}

#define GST_TYPE_FRAPPE_BACKEND (gst_frappe_backend_get_type())
static GType gst_frappe_backend_get_type(void)
{
	static GType type = 0;
	static const GEnumValue values[] = {
		{ GST_FRAPPE_BACKEND_AUTO,
		  "The Raspberry Pi's QPUs when they can be used, else the CPU (with one warning on a Pi)", "auto" },
		{ GST_FRAPPE_BACKEND_CPU, "The reference CPU front end", "cpu" },
		{ GST_FRAPPE_BACKEND_VC4, "The QPU kernels on the VideoCore IV GPU (Pi Zero, 1, 2, 3)", "vc4" },
		{ GST_FRAPPE_BACKEND_VC4_EMU,
		  "The QPU kernels on an emulator: bit-exact with vc4, slow; for testing", "vc4-emu" },
		{ 0, nullptr, nullptr },
	};
	if (g_once_init_enter(&type)) {
		GType t = g_enum_register_static("GstFrappeBackend", values);
		g_once_init_leave(&type, t);
	}
	return type;
}

/* The dictionary enum: one value per built-in dictionary, in the library's
 * stable order; nicks are the dictionary names with dashes ("6x6-250"). */
#define GST_TYPE_FRAPPE_DICTIONARY (gst_frappe_dictionary_get_type())
static GType gst_frappe_dictionary_get_type(void)
{
	static GType type = 0;
	if (g_once_init_enter(&type)) {
		const auto dicts = frappe::dictionaries();
		GEnumValue *values = g_new0(GEnumValue, dicts.size() + 1);
		for (std::size_t i = 0; i < dicts.size(); ++i) {
			std::string nick(dicts[i].name);
			std::replace(nick.begin(), nick.end(), '_', '-');
			const std::string desc = std::string(dicts[i].name) + " (" +
						 std::to_string(dicts[i].size()) + " markers, " +
						 std::to_string(dicts[i].bits) + "x" +
						 std::to_string(dicts[i].bits) + " bits)";
			values[i].value = static_cast<gint>(i);
			values[i].value_name = g_intern_string(desc.c_str());
			values[i].value_nick = g_intern_string(nick.c_str());
		}
		GType t = g_enum_register_static("GstFrappeDictionary", values);
		g_once_init_leave(&type, t);
	}
	return type;
}

static gint default_dictionary_index()
{
	const auto dicts = frappe::dictionaries();
	for (std::size_t i = 0; i < dicts.size(); ++i)
		if (dicts[i].name == DEFAULT_DICTIONARY_NAME)
			return static_cast<gint>(i);
	return 0;
}

/* -------------------------------------------------------------------------
 * Instance
 */

namespace {

/* Everything the properties set. Copied under the object lock by the
 * streaming thread at the start of each frame. */
struct Settings {
	gint dictionary = 0;
	GstFrappeMode mode = DEFAULT_MODE;
	gfloat edgeThreshold = DEFAULT_EDGE_THRESHOLD;
	gfloat cornerThreshold = DEFAULT_CORNER_THRESHOLD;
	gfloat regionContrast = DEFAULT_REGION_CONTRAST;
	gint maxHamming = DEFAULT_MAX_HAMMING;
	gfloat scaledSize = DEFAULT_SCALED_SIZE;
	gint maxScaledFrames = DEFAULT_MAX_SCALED_FRAMES;
	gboolean annotate = DEFAULT_ANNOTATE;
	gboolean postMessages = DEFAULT_POST_MESSAGES;
	gboolean pipelined = DEFAULT_PIPELINED;
	GstFrappeBackend backend = DEFAULT_BACKEND;
	gdouble markerSize = DEFAULT_MARKER_SIZE;
	frappe::gst::Camera camera;

	/* Whether a change between two settings needs a new Detector. */
	bool sameDetector(const Settings &o) const
	{
		return dictionary == o.dictionary && mode == o.mode && edgeThreshold == o.edgeThreshold &&
		       cornerThreshold == o.cornerThreshold && regionContrast == o.regionContrast &&
		       maxHamming == o.maxHamming &&
		       scaledSize == o.scaledSize && maxScaledFrames == o.maxScaledFrames &&
		       backend == o.backend;
	}
};

/* One job at a time on a second thread: the back end of the held frame. */
class Worker {
public:
	~Worker() { stop(); }

	void submit(std::function<void()> job)
	{
		std::unique_lock lock(mutex_);
		if (!thread_.joinable())
			thread_ = std::thread([this] { loop(); });
		job_ = std::move(job);
		busy_ = true;
		cv_.notify_all();
	}

	void wait()
	{
		std::unique_lock lock(mutex_);
		cv_.wait(lock, [this] { return !busy_; });
	}

	void stop()
	{
		{
			std::unique_lock lock(mutex_);
			if (!thread_.joinable())
				return;
			cv_.wait(lock, [this] { return !busy_; });
			quit_ = true;
			cv_.notify_all();
		}
		thread_.join();
		quit_ = false;
	}

private:
	void loop()
	{
		std::unique_lock lock(mutex_);
		for (;;) {
			cv_.wait(lock, [this] { return quit_ || busy_; });
			if (busy_) {
				auto job = std::move(job_);
				lock.unlock();
				job();
				lock.lock();
				busy_ = false;
				cv_.notify_all();
				continue;
			}
			if (quit_)
				return;
		}
	}

	std::mutex mutex_;
	std::condition_variable cv_;
	std::thread thread_;
	std::function<void()> job_;
	bool busy_ = false;
	bool quit_ = false;
};

/* A buffer between its front end and its output. */
struct InFlight {
	GstBuffer *buffer = nullptr;  /* writable, owned */
	GstVideoFrame frame{};        /* mapped until finished */
	bool writable = false;        /* mapped for annotation */
	int slot = 0;
	frappe::ImageView image;
	const frappe::Result *result = nullptr; /* set by the back end */
	std::string error;                      /* set when the back end threw */
};

} // namespace

struct FrappeDetectPrivate {
	/* Under the object lock. */
	Settings props;
	GstStructure *stats = nullptr;

	/* Streaming thread only. */
	Settings active;
	std::unique_ptr<frappe::Detector> detector;
	std::optional<InFlight> held;
	std::vector<GstBuffer *> output; /* finished, waiting for generate_output */
	Worker worker;
	bool loggedMemory = false;
	bool warnedStride = false;
	bool warnedFallback = false;
	guint64 frames = 0;
	frappe::StageTimes windowTimes; /* sums over the current 100 frames */
	double windowPoseMs = 0.0;
};

struct _GstFrappeDetect {
	GstVideoFilter parent;
	FrappeDetectPrivate *priv;
};

#define gst_frappe_detect_parent_class parent_class
G_DEFINE_TYPE(GstFrappeDetect, gst_frappe_detect, GST_TYPE_VIDEO_FILTER);
GST_ELEMENT_REGISTER_DEFINE(frappedetect, "frappedetect", GST_RANK_NONE, GST_TYPE_FRAPPE_DETECT);

/* Every accepted format starts with a full-resolution 8-bit Y plane, the
 * only plane the detector reads. */
#define FRAPPE_CAPS GST_VIDEO_CAPS_MAKE("{ GRAY8, I420, YV12, NV12, NV21 }")

static GstStaticPadTemplate sink_template =
	GST_STATIC_PAD_TEMPLATE("sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS(FRAPPE_CAPS));
static GstStaticPadTemplate src_template =
	GST_STATIC_PAD_TEMPLATE("src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS(FRAPPE_CAPS));

/* -------------------------------------------------------------------------
 * Detection
 */

static frappe::Config make_config(const Settings &s)
{
	frappe::Config config;
	const auto dicts = frappe::dictionaries();
	const auto &dict = dicts[static_cast<std::size_t>(s.dictionary)];
	config.dictionary = std::string(dict.name);
	config.mode = s.mode == GST_FRAPPE_MODE_ASCALE ? frappe::Mode::AScale : frappe::Mode::Normal;
	config.edge_threshold = s.edgeThreshold;
	config.corner_threshold = s.cornerThreshold;
	config.region_contrast = s.regionContrast;
	config.max_hamming = std::min(s.maxHamming, dict.bits * dict.bits / 2);
	config.scaled_size = s.scaledSize;
	config.max_scaled_frames = s.maxScaledFrames;
	config.threads = 1;
	return config;
}

static const char *backend_name(GstFrappeBackend backend)
{
	GEnumClass *klass = G_ENUM_CLASS(g_type_class_ref(GST_TYPE_FRAPPE_BACKEND));
	const GEnumValue *v = g_enum_get_value(klass, backend);
	const char *name = v ? v->value_nick : "auto";
	g_type_class_unref(klass);
	return name;
}

/* Puts the front end the backend property asks for into the detector. The
 * element only names it; vc4/ decides what runs. */
static bool select_front_end(GstFrappeDetect *self, frappe::Detector &detector)
{
	FrappeDetectPrivate *priv = self->priv;
	const GstFrappeBackend backend = priv->active.backend;
	if (backend == GST_FRAPPE_BACKEND_CPU)
		return true;
	const char *name = backend_name(backend);
#ifdef FRAPPE_HAVE_VC4
	try {
		frappe::vc4::BackendChoice choice = frappe::vc4::selectFrontEnd(name, 1);
		if (!choice.fallback.empty() && !priv->warnedFallback) {
			priv->warnedFallback = true;
			GST_ELEMENT_WARNING(self, RESOURCE, NOT_FOUND, ("The GPU cannot be used; detecting on the CPU"),
					    ("backend=auto: %s", choice.fallback.c_str()));
		}
		detector.setFrontEnd(std::move(choice.frontEnd));
		detector.setWarper(std::move(choice.warper));
	} catch (const std::exception &e) {
		GST_ELEMENT_ERROR(self, RESOURCE, OPEN_READ, ("Backend %s cannot be used", name), ("%s", e.what()));
		return false;
	}
#else
	(void)detector;
	if (backend != GST_FRAPPE_BACKEND_AUTO) {
		GST_ELEMENT_ERROR(self, LIBRARY, SETTINGS, ("Backend %s is not in this build", name),
				  ("the plugin was built without vc4/"));
		return false;
	}
#endif
	return true;
}

static bool ensure_detector(GstFrappeDetect *self)
{
	FrappeDetectPrivate *priv = self->priv;
	if (priv->detector)
		return true;
	const frappe::Config config = make_config(priv->active);
	try {
		priv->detector = std::make_unique<frappe::Detector>(config);
	} catch (const std::exception &e) {
		GST_ELEMENT_ERROR(self, LIBRARY, SETTINGS, ("Invalid detector settings"), ("%s", e.what()));
		return false;
	}
	if (!select_front_end(self, *priv->detector)) {
		priv->detector.reset();
		return false;
	}
	GST_DEBUG_OBJECT(self, "detector for %s, mode %s, max-hamming %d, front end %s",
			 config.dictionary.c_str(),
			 config.mode == frappe::Mode::AScale ? "ascale" : "normal",
			 priv->detector->maxHamming(), priv->detector->frontEnd().name());
	return true;
}

static void add_double_array(GstStructure *s, const char *field, const double *v, int n)
{
	GValue array = G_VALUE_INIT;
	gst_value_array_init(&array, static_cast<guint>(n));
	for (int i = 0; i < n; ++i) {
		GValue item = G_VALUE_INIT;
		g_value_init(&item, G_TYPE_DOUBLE);
		g_value_set_double(&item, v[i]);
		gst_value_array_append_and_take_value(&array, &item);
	}
	gst_structure_take_value(s, field, &array);
}

static void update_stats(GstFrappeDetect *self, const frappe::Result &result, double poseMs)
{
	FrappeDetectPrivate *priv = self->priv;
	GstStructure *s = gst_structure_new("frappe-stats", "frames", G_TYPE_UINT64, priv->frames,
					    "markers", G_TYPE_UINT,
					    static_cast<guint>(result.markers.size()), "candidates",
					    G_TYPE_INT, result.candidates, "scale", G_TYPE_DOUBLE,
					    static_cast<double>(result.scale), nullptr);
	for (int i = 0; i < frappe::kStageCount; ++i) {
		std::string name(frappe::stageName(static_cast<frappe::Stage>(i)));
		std::replace(name.begin(), name.end(), '_', '-');
		name += "-ms";
		gst_structure_set(s, name.c_str(), G_TYPE_DOUBLE, result.times.ms[static_cast<std::size_t>(i)],
				  nullptr);
	}
	gst_structure_set(s, "pose-ms", G_TYPE_DOUBLE, poseMs, "total-ms", G_TYPE_DOUBLE,
			  result.times.total_ms + poseMs, "backend", G_TYPE_STRING,
			  priv->detector ? priv->detector->frontEnd().name() : "cpu", "pipelined",
			  G_TYPE_BOOLEAN, priv->active.pipelined, nullptr);

	GST_LOG_OBJECT(self, "stats %" GST_PTR_FORMAT, static_cast<void *>(s));

	/* Every 100 frames, the average cost per stage at INFO level, so
	 * GST_DEBUG=frappedetect:4 shows the speed without any tooling. */
	priv->windowTimes.total_ms += result.times.total_ms + poseMs;
	for (std::size_t i = 0; i < result.times.ms.size(); ++i)
		priv->windowTimes.ms[i] += result.times.ms[i];
	priv->windowPoseMs += poseMs;
	if (priv->frames % 100 == 0) {
		std::string line;
		for (int i = 0; i < frappe::kStageCount; ++i) {
			char part[64];
			std::snprintf(part, sizeof(part), "%s %.2f, ",
				      std::string(frappe::stageName(static_cast<frappe::Stage>(i))).c_str(),
				      priv->windowTimes.ms[static_cast<std::size_t>(i)] / 100.0);
			line += part;
		}
		GST_INFO_OBJECT(self, "last 100 frames, ms per frame: %spose %.2f, total %.2f%s", line.c_str(),
				priv->windowPoseMs / 100.0, priv->windowTimes.total_ms / 100.0,
				priv->active.pipelined ? " (front end overlapped with the back end)" : "");
		priv->windowTimes = {};
		priv->windowPoseMs = 0.0;
	}
	GST_OBJECT_LOCK(self);
	if (priv->stats)
		gst_structure_free(priv->stats);
	priv->stats = s;
	GST_OBJECT_UNLOCK(self);
}

static void annotate_frame(GstVideoFrame *frame, const frappe::Result &result,
			   const std::vector<std::optional<frappe::gst::Pose>> &poses, const Settings &s)
{
	frappe::gst::Canvas canvas(frame);
	for (std::size_t i = 0; i < result.markers.size(); ++i) {
		const frappe::Marker &m = result.markers[i];
		double side = 0.0;
		for (int k = 0; k < 4; ++k) {
			const auto a = m.corners[static_cast<std::size_t>(k)];
			const auto b = m.corners[static_cast<std::size_t>((k + 1) & 3)];
			side += std::hypot(a.x - b.x, a.y - b.y) / 4.0;
		}
		const int thickness = std::max(1, static_cast<int>(side / 32.0));
		for (int k = 0; k < 4; ++k) {
			const auto a = m.corners[static_cast<std::size_t>(k)];
			const auto b = m.corners[static_cast<std::size_t>((k + 1) & 3)];
			canvas.haloLine(a.x, a.y, b.x, b.y, thickness, frappe::gst::colours::outline);
		}
		/* The first corner (top-left in the marker's orientation). */
		const int r = std::max(2, static_cast<int>(side / 24.0));
		const int cx = static_cast<int>(std::lround(m.corners[0].x));
		const int cy = static_cast<int>(std::lround(m.corners[0].y));
		canvas.fillRect(cx - r - 1, cy - r - 1, cx + r + 1, cy + r + 1, frappe::gst::colours::black);
		canvas.fillRect(cx - r, cy - r, cx + r, cy + r, frappe::gst::colours::firstCorner);

		if (poses[i]) {
			const double h = s.markerSize / 2.0;
			const auto p = frappe::gst::projectPoints({ { 0, 0, 0 }, { h, 0, 0 }, { 0, h, 0 }, { 0, 0, h } },
								  *poses[i], s.camera);
			if (p.size() == 4) {
				canvas.haloLine(p[0].x, p[0].y, p[1].x, p[1].y, thickness, frappe::gst::colours::axisX);
				canvas.haloLine(p[0].x, p[0].y, p[2].x, p[2].y, thickness, frappe::gst::colours::axisY);
				canvas.haloLine(p[0].x, p[0].y, p[3].x, p[3].y, thickness, frappe::gst::colours::axisZ);
			}
		}

		/* The id between the centre and the first corner: the quadrant of
		 * the marker frame (-x, +y) that the axes leave free. */
		double mx = 0.0, my = 0.0;
		for (const auto &c : m.corners) {
			mx += c.x / 4.0;
			my += c.y / 4.0;
		}
		mx = (mx * 3.0 + m.corners[0].x * 2.0) / 5.0;
		my = (my * 3.0 + m.corners[0].y * 2.0) / 5.0;
		canvas.number(m.id, mx, my, std::max(1, static_cast<int>(side / 24.0)));
	}
}

/* Attaches metas, draws, posts the message and releases the frame; the
 * buffer goes to the output list. */
static void finish(GstFrappeDetect *self, InFlight &f)
{
	FrappeDetectPrivate *priv = self->priv;
	GstBaseTransform *trans = GST_BASE_TRANSFORM(self);
	const Settings &s = priv->active;
	const auto &dict = priv->detector->dictionary();
	const std::string dictName(dict.name);

	static const frappe::Result empty;
	const frappe::Result &result = f.result ? *f.result : empty;
	if (!f.error.empty())
		GST_WARNING_OBJECT(self, "detection failed on %" GST_PTR_FORMAT ": %s", static_cast<void *>(f.buffer),
				   f.error.c_str());

	/* Pose. */
	const bool wantPose = s.markerSize > 0.0 && s.camera.valid();
	std::vector<std::optional<frappe::gst::Pose>> poses(result.markers.size());
	const gint64 t0 = g_get_monotonic_time();
	if (wantPose) {
		for (std::size_t i = 0; i < result.markers.size(); ++i) {
			frappe::gst::Pose pose;
			if (frappe::gst::estimatePose(result.markers[i], s.markerSize, s.camera, pose))
				poses[i] = pose;
		}
	}
	const double poseMs = static_cast<double>(g_get_monotonic_time() - t0) / 1000.0;

	GstStructure *msg = nullptr;
	GValue list = G_VALUE_INIT;
	if (s.postMessages)
		g_value_init(&list, GST_TYPE_LIST);

	for (std::size_t i = 0; i < result.markers.size(); ++i) {
		const frappe::Marker &m = result.markers[i];
		gfloat corners[8];
		float minX = G_MAXFLOAT, minY = G_MAXFLOAT, maxX = -G_MAXFLOAT, maxY = -G_MAXFLOAT;
		for (int k = 0; k < 4; ++k) {
			const auto c = m.corners[static_cast<std::size_t>(k)];
			corners[2 * k] = c.x;
			corners[2 * k + 1] = c.y;
			minX = std::min(minX, c.x);
			minY = std::min(minY, c.y);
			maxX = std::max(maxX, c.x);
			maxY = std::max(maxY, c.y);
		}
		GstFrappeMarkerMeta *meta = gst_buffer_add_frappe_marker_meta(
			f.buffer, m.id, dictName.c_str(), corners, static_cast<guint>(m.hamming));
		if (meta)
			meta->margin = m.margin;
		if (meta && poses[i]) {
			meta->has_pose = TRUE;
			for (int k = 0; k < 3; ++k) {
				meta->rvec[k] = poses[i]->rvec[static_cast<std::size_t>(k)];
				meta->tvec[k] = poses[i]->tvec[static_cast<std::size_t>(k)];
			}
			meta->reprojection_error = poses[i]->reprojectionError;
			meta->alternative_reprojection_error = poses[i]->alternativeError;
		}

		/* The ROI covers the pixels the corners touch, clipped to the frame. */
		const gint width = GST_VIDEO_FRAME_WIDTH(&f.frame), height = GST_VIDEO_FRAME_HEIGHT(&f.frame);
		const gint x0 = std::clamp(static_cast<gint>(std::floor(minX + 0.5f)), 0, width - 1);
		const gint y0 = std::clamp(static_cast<gint>(std::floor(minY + 0.5f)), 0, height - 1);
		const gint x1 = std::clamp(static_cast<gint>(std::ceil(maxX + 0.5f)), x0 + 1, width);
		const gint y1 = std::clamp(static_cast<gint>(std::ceil(maxY + 0.5f)), y0 + 1, height);
		GstVideoRegionOfInterestMeta *roi = gst_buffer_add_video_region_of_interest_meta(
			f.buffer, GST_FRAPPE_ROI_TYPE, static_cast<guint>(x0), static_cast<guint>(y0),
			static_cast<guint>(x1 - x0), static_cast<guint>(y1 - y0));
		if (roi) {
			roi->id = static_cast<gint>(i);
			gst_video_region_of_interest_meta_add_param(
				roi, gst_structure_new(GST_FRAPPE_ROI_TYPE, "id", G_TYPE_INT, m.id,
						       "dictionary", G_TYPE_STRING, dictName.c_str(),
						       "hamming", G_TYPE_UINT,
						       static_cast<guint>(m.hamming), "margin", G_TYPE_DOUBLE,
						       static_cast<gdouble>(m.margin), nullptr));
		}

		if (s.postMessages) {
			GstStructure *ms = gst_structure_new("marker", "id", G_TYPE_INT, m.id, "dictionary",
							     G_TYPE_STRING, dictName.c_str(), nullptr);
			double dc[8];
			for (int k = 0; k < 8; ++k)
				dc[k] = corners[k];
			add_double_array(ms, "corners", dc, 8);
			gst_structure_set(ms, "hamming", G_TYPE_UINT, static_cast<guint>(m.hamming), "margin",
					  G_TYPE_DOUBLE, static_cast<gdouble>(m.margin), nullptr);
			if (poses[i]) {
				add_double_array(ms, "rvec", poses[i]->rvec.data(), 3);
				add_double_array(ms, "tvec", poses[i]->tvec.data(), 3);
				gst_structure_set(ms, "reprojection-error", G_TYPE_DOUBLE,
						  poses[i]->reprojectionError, "alternative-reprojection-error",
						  G_TYPE_DOUBLE, poses[i]->alternativeError, nullptr);
			}
			GValue item = G_VALUE_INIT;
			g_value_init(&item, GST_TYPE_STRUCTURE);
			g_value_take_boxed(&item, ms);
			gst_value_list_append_and_take_value(&list, &item);
		}
	}

	if (f.writable && s.annotate && !result.markers.empty())
		annotate_frame(&f.frame, result, poses, s);

	gst_video_frame_unmap(&f.frame);

	if (s.postMessages) {
		const GstClockTime pts = GST_BUFFER_PTS(f.buffer);
		GstClockTime running = GST_CLOCK_TIME_NONE, stream = GST_CLOCK_TIME_NONE;
		if (trans->segment.format == GST_FORMAT_TIME) {
			running = gst_segment_to_running_time(&trans->segment, GST_FORMAT_TIME, pts);
			stream = gst_segment_to_stream_time(&trans->segment, GST_FORMAT_TIME, pts);
		}
		msg = gst_structure_new("frappedetect", "timestamp", G_TYPE_UINT64, pts, "stream-time",
					G_TYPE_UINT64, stream, "running-time", G_TYPE_UINT64, running,
					"duration", G_TYPE_UINT64, GST_BUFFER_DURATION(f.buffer), nullptr);
		gst_structure_take_value(msg, "markers", &list);
		gst_element_post_message(GST_ELEMENT(self), gst_message_new_element(GST_OBJECT(self), msg));
	}

	++priv->frames;
	GST_LOG_OBJECT(self, "frame %" G_GUINT64_FORMAT " pts %" GST_TIME_FORMAT ": %zu markers in %.3f ms",
		       priv->frames, GST_TIME_ARGS(GST_BUFFER_PTS(f.buffer)), result.markers.size(),
		       result.times.total_ms + poseMs);
	update_stats(self, result, poseMs);

	priv->output.push_back(f.buffer);
	f.buffer = nullptr;
}

/* Waits for the held frame's back end and finishes it. */
static void finish_held(GstFrappeDetect *self)
{
	FrappeDetectPrivate *priv = self->priv;
	if (!priv->held)
		return;
	priv->worker.wait();
	finish(self, *priv->held);
	priv->held.reset();
}

/* Throws the held frame away (flush, stop). */
static void drop_held(GstFrappeDetect *self)
{
	FrappeDetectPrivate *priv = self->priv;
	if (!priv->held)
		return;
	priv->worker.wait();
	GST_DEBUG_OBJECT(self, "dropping held %" GST_PTR_FORMAT, static_cast<void *>(priv->held->buffer));
	gst_video_frame_unmap(&priv->held->frame);
	gst_buffer_unref(priv->held->buffer);
	priv->held.reset();
}

static void clear_output(GstFrappeDetect *self)
{
	for (GstBuffer *b : self->priv->output)
		gst_buffer_unref(b);
	self->priv->output.clear();
}

/* Pushes the held frame and anything waiting (serialized events). */
static GstFlowReturn drain(GstFrappeDetect *self)
{
	FrappeDetectPrivate *priv = self->priv;
	finish_held(self);
	GstFlowReturn ret = GST_FLOW_OK;
	std::vector<GstBuffer *> out;
	out.swap(priv->output);
	for (GstBuffer *b : out) {
		if (ret == GST_FLOW_OK) {
			GST_LOG_OBJECT(self, "draining %" GST_PTR_FORMAT, static_cast<void *>(b));
			ret = gst_pad_push(GST_BASE_TRANSFORM_SRC_PAD(self), b);
		} else {
			gst_buffer_unref(b);
		}
	}
	return ret;
}

/* Picks up property changes; may finish the held frame first. */
static void apply_settings(GstFrappeDetect *self)
{
	FrappeDetectPrivate *priv = self->priv;
	GST_OBJECT_LOCK(self);
	Settings next = priv->props;
	GST_OBJECT_UNLOCK(self);

	const bool rebuild = !next.sameDetector(priv->active);
	const bool pipelineChange = next.pipelined != priv->active.pipelined;
	if (rebuild || pipelineChange)
		finish_held(self);
	priv->active = next;
	if (rebuild && priv->detector) {
		GST_DEBUG_OBJECT(self, "settings changed, rebuilding the detector");
		priv->detector.reset();
	}
	if (pipelineChange) {
		GST_DEBUG_OBJECT(self, "pipelined now %d", next.pipelined);
		gst_element_post_message(GST_ELEMENT(self), gst_message_new_latency(GST_OBJECT(self)));
	}
}

static void log_memory(GstFrappeDetect *self, GstBuffer *buffer)
{
	FrappeDetectPrivate *priv = self->priv;
	GstMemory *mem = gst_buffer_peek_memory(buffer, 0);
	const bool dmabuf = mem && gst_is_dmabuf_memory(mem);
	if (!priv->loggedMemory) {
		priv->loggedMemory = true;
		if (dmabuf)
			GST_DEBUG_OBJECT(self, "input is dmabuf memory (fd %d): mapped %s, not copied",
					 gst_dmabuf_memory_get_fd(mem),
					 priv->active.annotate ? "read-write to annotate" : "read-only");
		else
			GST_DEBUG_OBJECT(self, "input is %s memory",
					 mem && mem->allocator ? mem->allocator->mem_type : "unknown");
	}
	GstVideoFilter *filter = GST_VIDEO_FILTER(self);
	if (dmabuf && !priv->warnedStride && !gst_buffer_get_video_meta(buffer) &&
	    GST_VIDEO_INFO_WIDTH(&filter->in_info) % 64 != 0) {
		priv->warnedStride = true;
		GST_WARNING_OBJECT(self, "dmabuf input %d pixels wide without GstVideoMeta: the "
				   "producer's stride may differ from the default one",
				   GST_VIDEO_INFO_WIDTH(&filter->in_info));
	}
}

static GstFlowReturn process(GstFrappeDetect *self, GstBuffer *input)
{
	FrappeDetectPrivate *priv = self->priv;
	GstVideoFilter *filter = GST_VIDEO_FILTER(self);

	apply_settings(self);
	if (!ensure_detector(self)) {
		gst_buffer_unref(input);
		return GST_FLOW_NOT_NEGOTIATED;
	}

	/* Metas need a writable buffer: a shallow copy when shared, which
	 * keeps the memory (and zero-copy) as long as we map read-only. */
	GstBuffer *buffer = gst_buffer_make_writable(input);
	log_memory(self, buffer);

	InFlight f;
	f.buffer = buffer;
	f.writable = priv->active.annotate;
	/* NO_REF: a mapped frame holding a second ref would make the buffer
	 * read-only for the metas; we own the buffer until it is pushed. */
	const auto flags = static_cast<GstMapFlags>(static_cast<int>(f.writable ? GST_MAP_READWRITE : GST_MAP_READ) |
						    static_cast<int>(GST_VIDEO_FRAME_MAP_FLAG_NO_REF));
	if (!gst_video_frame_map(&f.frame, &filter->in_info, buffer, flags)) {
		gst_buffer_unref(buffer);
		GST_ELEMENT_ERROR(self, STREAM, FAILED, ("Could not map the video frame"), (nullptr));
		return GST_FLOW_ERROR;
	}
	f.image = frappe::ImageView(static_cast<const std::uint8_t *>(GST_VIDEO_FRAME_COMP_DATA(&f.frame, 0)),
				    GST_VIDEO_FRAME_COMP_WIDTH(&f.frame, 0),
				    GST_VIDEO_FRAME_COMP_HEIGHT(&f.frame, 0),
				    GST_VIDEO_FRAME_COMP_STRIDE(&f.frame, 0));

	frappe::Detector &detector = *priv->detector;
	const bool pipelined = priv->active.pipelined;
	try {
		if (!pipelined) {
			detector.runFrontEnd(f.image, 0);
			f.result = &detector.runBackEnd(f.image, 0);
		} else {
			f.slot = priv->held ? 1 - priv->held->slot : 0;
			/* Overlaps the held back end. In AScale mode the scale comes
			 * from the last frame finished before this front end starts
			 * (frappe-core locks that hand-over), as on live video. */
			detector.runFrontEnd(f.image, f.slot);
		}
	} catch (const std::exception &e) {
		gst_video_frame_unmap(&f.frame);
		gst_buffer_unref(f.buffer);
		GST_ELEMENT_ERROR(self, STREAM, FAILED, ("Marker detection failed"), ("%s", e.what()));
		return GST_FLOW_ERROR;
	}
	if (!pipelined) {
		finish(self, f);
		return GST_FLOW_OK;
	}

	finish_held(self);
	priv->held = std::move(f);
	InFlight *h = &*priv->held;
	frappe::Detector *d = &detector;
	priv->worker.submit([h, d] {
		try {
			h->result = &d->runBackEnd(h->image, h->slot);
		} catch (const std::exception &e) {
			h->error = e.what();
			h->result = nullptr;
		}
	});
	return GST_FLOW_OK;
}

/* -------------------------------------------------------------------------
 * GstBaseTransform vfuncs
 */

static GstFlowReturn gst_frappe_detect_generate_output(GstBaseTransform *trans, GstBuffer **outbuf)
{
	GstFrappeDetect *self = GST_FRAPPE_DETECT(trans);
	FrappeDetectPrivate *priv = self->priv;
	*outbuf = nullptr;

	if (trans->queued_buf) {
		GstBuffer *input = trans->queued_buf;
		trans->queued_buf = nullptr;
		GstFlowReturn ret = process(self, input);
		if (ret != GST_FLOW_OK)
			return ret;
	}
	if (!priv->output.empty()) {
		*outbuf = priv->output.front();
		priv->output.erase(priv->output.begin());
	}
	return GST_FLOW_OK;
}

static gboolean gst_frappe_detect_sink_event(GstBaseTransform *trans, GstEvent *event)
{
	GstFrappeDetect *self = GST_FRAPPE_DETECT(trans);

	switch (GST_EVENT_TYPE(event)) {
	case GST_EVENT_EOS:
	case GST_EVENT_CAPS:
	case GST_EVENT_SEGMENT:
	case GST_EVENT_STREAM_START:
	case GST_EVENT_GAP:
		/* The held buffer belongs before this event. */
		if (self->priv->held || !self->priv->output.empty()) {
			GST_DEBUG_OBJECT(self, "draining before %s", GST_EVENT_TYPE_NAME(event));
			drain(self);
		}
		break;
	case GST_EVENT_FLUSH_STOP:
		drop_held(self);
		clear_output(self);
		if (self->priv->detector)
			self->priv->detector->reset();
		break;
	default:
		break;
	}
	return GST_BASE_TRANSFORM_CLASS(parent_class)->sink_event(trans, event);
}

static gboolean gst_frappe_detect_query(GstBaseTransform *trans, GstPadDirection direction, GstQuery *query)
{
	GstFrappeDetect *self = GST_FRAPPE_DETECT(trans);

	/* Upstream wants its buffers back (e.g. to change its pool): push the
	 * held one. DRAIN is serialized, so this is the streaming thread. */
	if (direction == GST_PAD_SINK && GST_QUERY_TYPE(query) == GST_QUERY_DRAIN &&
	    (self->priv->held || !self->priv->output.empty())) {
		GST_DEBUG_OBJECT(self, "draining for a DRAIN query");
		drain(self);
	}

	gboolean ret = GST_BASE_TRANSFORM_CLASS(parent_class)->query(trans, direction, query);

	if (ret && direction == GST_PAD_SRC && GST_QUERY_TYPE(query) == GST_QUERY_LATENCY) {
		GST_OBJECT_LOCK(self);
		const gboolean pipelined = self->priv->props.pipelined;
		GST_OBJECT_UNLOCK(self);
		if (pipelined) {
			GstVideoInfo *info = &GST_VIDEO_FILTER(self)->in_info;
			gint n = GST_VIDEO_INFO_FPS_N(info), d = GST_VIDEO_INFO_FPS_D(info);
			if (n <= 0 || d <= 0) {
				/* Unknown or variable frame rate: assume 25 fps. */
				n = 25;
				d = 1;
			}
			const GstClockTime frame = gst_util_uint64_scale_int(GST_SECOND, d, n);
			gboolean live;
			GstClockTime min, max;
			gst_query_parse_latency(query, &live, &min, &max);
			min += frame;
			if (GST_CLOCK_TIME_IS_VALID(max))
				max += frame;
			GST_DEBUG_OBJECT(self, "adding %" GST_TIME_FORMAT " of latency (one frame held)",
					 GST_TIME_ARGS(frame));
			gst_query_set_latency(query, live, min, max);
		}
	}
	return ret;
}

/* Holding a buffer in pipelined mode takes one more from upstream's pool. */
static gboolean gst_frappe_detect_propose_allocation(GstBaseTransform *trans, GstQuery *decide_query,
						     GstQuery *query)
{
	GstFrappeDetect *self = GST_FRAPPE_DETECT(trans);
	if (!GST_BASE_TRANSFORM_CLASS(parent_class)->propose_allocation(trans, decide_query, query))
		return FALSE;

	GST_OBJECT_LOCK(self);
	const gboolean pipelined = self->priv->props.pipelined;
	GST_OBJECT_UNLOCK(self);
	if (!pipelined)
		return TRUE;
	for (guint i = 0; i < gst_query_get_n_allocation_pools(query); ++i) {
		GstBufferPool *pool = nullptr;
		guint size, min, max;
		gst_query_parse_nth_allocation_pool(query, i, &pool, &size, &min, &max);
		if (max != 0 && max < min + 1)
			max = min + 1;
		gst_query_set_nth_allocation_pool(query, i, pool, size, min + 1, max);
		GST_DEBUG_OBJECT(self, "asking for %u buffers in pool %u (one held)", min + 1, i);
		if (pool)
			gst_object_unref(pool);
	}
	return TRUE;
}

static gboolean gst_frappe_detect_start(GstBaseTransform *trans)
{
	GstFrappeDetect *self = GST_FRAPPE_DETECT(trans);
	GST_OBJECT_LOCK(self);
	self->priv->active = self->priv->props;
	GST_OBJECT_UNLOCK(self);
	self->priv->frames = 0;
	self->priv->windowTimes = {};
	self->priv->windowPoseMs = 0.0;
	self->priv->loggedMemory = false;
	self->priv->warnedStride = false;
	return TRUE;
}

static gboolean gst_frappe_detect_stop(GstBaseTransform *trans)
{
	GstFrappeDetect *self = GST_FRAPPE_DETECT(trans);
	drop_held(self);
	clear_output(self);
	self->priv->worker.stop();
	self->priv->detector.reset();
	return TRUE;
}

static gboolean gst_frappe_detect_set_info(GstVideoFilter *filter, GstCaps *, GstVideoInfo *in_info,
					   GstCaps *, GstVideoInfo *)
{
	GST_DEBUG_OBJECT(filter, "%s %dx%d", GST_VIDEO_INFO_NAME(in_info), GST_VIDEO_INFO_WIDTH(in_info),
			 GST_VIDEO_INFO_HEIGHT(in_info));
	return TRUE;
}

/* -------------------------------------------------------------------------
 * GObject
 */

static void set_double_array(const GValue *value, std::vector<double> &out)
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

static void get_double_array(GValue *value, const double *v, std::size_t n)
{
	for (std::size_t i = 0; i < n; ++i) {
		GValue item = G_VALUE_INIT;
		g_value_init(&item, G_TYPE_DOUBLE);
		g_value_set_double(&item, v[i]);
		gst_value_array_append_and_take_value(value, &item);
	}
}

static void gst_frappe_detect_set_property(GObject *object, guint prop_id, const GValue *value, GParamSpec *pspec)
{
	GstFrappeDetect *self = GST_FRAPPE_DETECT(object);
	Settings &p = self->priv->props;

	GST_OBJECT_LOCK(self);
	switch (prop_id) {
	case PROP_DICTIONARY:
		p.dictionary = g_value_get_enum(value);
		break;
	case PROP_MODE:
		p.mode = static_cast<GstFrappeMode>(g_value_get_enum(value));
		break;
	case PROP_EDGE_THRESHOLD:
		p.edgeThreshold = g_value_get_float(value);
		break;
	case PROP_CORNER_THRESHOLD:
		p.cornerThreshold = g_value_get_float(value);
		break;
	case PROP_REGION_CONTRAST:
		p.regionContrast = g_value_get_float(value);
		break;
	case PROP_MAX_HAMMING:
		p.maxHamming = g_value_get_int(value);
		break;
	case PROP_SCALED_SIZE:
		p.scaledSize = g_value_get_float(value);
		break;
	case PROP_MAX_SCALED_FRAMES:
		p.maxScaledFrames = g_value_get_int(value);
		break;
	case PROP_ANNOTATE:
		p.annotate = g_value_get_boolean(value);
		break;
	case PROP_POST_MESSAGES:
		p.postMessages = g_value_get_boolean(value);
		break;
	case PROP_PIPELINED:
		p.pipelined = g_value_get_boolean(value);
		break;
	case PROP_BACKEND:
		p.backend = static_cast<GstFrappeBackend>(g_value_get_enum(value));
		break;
	case PROP_MARKER_SIZE:
		p.markerSize = g_value_get_double(value);
		break;
	case PROP_CAMERA_MATRIX: {
		std::vector<double> m;
		set_double_array(value, m);
		if (m.empty()) {
			p.camera.matrix = {};
		} else if (m.size() == 9) {
			std::copy(m.begin(), m.end(), p.camera.matrix.begin());
		} else {
			GST_WARNING_OBJECT(self, "camera-matrix needs 9 numbers (row-major 3x3), got %zu; ignored",
					   m.size());
		}
		break;
	}
	case PROP_DISTORTION: {
		std::vector<double> d;
		set_double_array(value, d);
		const std::size_t n = d.size();
		if (n == 0 || n == 4 || n == 5 || n == 8 || n == 12 || n == 14)
			p.camera.distortion = d;
		else
			GST_WARNING_OBJECT(self, "distortion needs 4, 5, 8, 12 or 14 coefficients, got %zu; ignored",
					   n);
		break;
	}
	default:
		G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
		break;
	}
	GST_OBJECT_UNLOCK(self);
}

static void gst_frappe_detect_get_property(GObject *object, guint prop_id, GValue *value, GParamSpec *pspec)
{
	GstFrappeDetect *self = GST_FRAPPE_DETECT(object);
	const Settings &p = self->priv->props;

	GST_OBJECT_LOCK(self);
	switch (prop_id) {
	case PROP_DICTIONARY:
		g_value_set_enum(value, p.dictionary);
		break;
	case PROP_MODE:
		g_value_set_enum(value, p.mode);
		break;
	case PROP_EDGE_THRESHOLD:
		g_value_set_float(value, p.edgeThreshold);
		break;
	case PROP_CORNER_THRESHOLD:
		g_value_set_float(value, p.cornerThreshold);
		break;
	case PROP_REGION_CONTRAST:
		g_value_set_float(value, p.regionContrast);
		break;
	case PROP_MAX_HAMMING:
		g_value_set_int(value, p.maxHamming);
		break;
	case PROP_SCALED_SIZE:
		g_value_set_float(value, p.scaledSize);
		break;
	case PROP_MAX_SCALED_FRAMES:
		g_value_set_int(value, p.maxScaledFrames);
		break;
	case PROP_ANNOTATE:
		g_value_set_boolean(value, p.annotate);
		break;
	case PROP_POST_MESSAGES:
		g_value_set_boolean(value, p.postMessages);
		break;
	case PROP_PIPELINED:
		g_value_set_boolean(value, p.pipelined);
		break;
	case PROP_BACKEND:
		g_value_set_enum(value, p.backend);
		break;
	case PROP_MARKER_SIZE:
		g_value_set_double(value, p.markerSize);
		break;
	case PROP_CAMERA_MATRIX:
		if (p.camera.valid())
			get_double_array(value, p.camera.matrix.data(), 9);
		break;
	case PROP_DISTORTION:
		get_double_array(value, p.camera.distortion.data(), p.camera.distortion.size());
		break;
	case PROP_STATS:
		if (self->priv->stats)
			g_value_set_boxed(value, self->priv->stats);
		else
			g_value_take_boxed(value, gst_structure_new_empty("frappe-stats"));
		break;
	default:
		G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
		break;
	}
	GST_OBJECT_UNLOCK(self);
}

static void gst_frappe_detect_finalize(GObject *object)
{
	GstFrappeDetect *self = GST_FRAPPE_DETECT(object);
	if (self->priv->stats)
		gst_structure_free(self->priv->stats);
	delete self->priv;
	G_OBJECT_CLASS(parent_class)->finalize(object);
}

static void gst_frappe_detect_init(GstFrappeDetect *self)
{
	self->priv = new FrappeDetectPrivate();
	self->priv->props.dictionary = default_dictionary_index();
	self->priv->active = self->priv->props;
	gst_base_transform_set_in_place(GST_BASE_TRANSFORM(self), TRUE);
	gst_base_transform_set_passthrough(GST_BASE_TRANSFORM(self), FALSE);
}

static void gst_frappe_detect_class_init(GstFrappeDetectClass *klass)
{
	GObjectClass *gobject_class = G_OBJECT_CLASS(klass);
	GstElementClass *element_class = GST_ELEMENT_CLASS(klass);
	GstBaseTransformClass *trans_class = GST_BASE_TRANSFORM_CLASS(klass);
	GstVideoFilterClass *filter_class = GST_VIDEO_FILTER_CLASS(klass);

	GST_DEBUG_CATEGORY_INIT(gst_frappe_detect_debug, "frappedetect", 0, "Frappe fiducial marker detector");

	gobject_class->set_property = gst_frappe_detect_set_property;
	gobject_class->get_property = gst_frappe_detect_get_property;
	gobject_class->finalize = gst_frappe_detect_finalize;

	const auto rw = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS);
	const auto live = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
						   GST_PARAM_MUTABLE_PLAYING);

	/**
	 * GstFrappeDetect:dictionary:
	 *
	 * The marker family to look for.
	 */
	g_object_class_install_property(
		gobject_class, PROP_DICTIONARY,
		g_param_spec_enum("dictionary", "Dictionary", "Marker family to detect", GST_TYPE_FRAPPE_DICTIONARY,
				  default_dictionary_index(), live));
	g_object_class_install_property(
		gobject_class, PROP_MODE,
		g_param_spec_enum("mode", "Mode",
				  "normal: every frame at full resolution; ascale: scale frames down from the "
				  "size of the smallest marker of the previous frame (faster on video)",
				  GST_TYPE_FRAPPE_MODE, DEFAULT_MODE, live));
	g_object_class_install_property(
		gobject_class, PROP_EDGE_THRESHOLD,
		g_param_spec_float("edge-threshold", "Edge threshold",
				   "Sobel gradient magnitude (intensities in [0, 1]) an edge pixel must exceed; "
				   "lower finds fainter markers but costs more contour tracing",
				   0.001f, 4.0f, DEFAULT_EDGE_THRESHOLD, live));
	g_object_class_install_property(
		gobject_class, PROP_CORNER_THRESHOLD,
		g_param_spec_float("corner-threshold", "Corner threshold",
				   "Shi-Tomasi minimum eigenvalue that marks an edge pixel as a corner; too high "
				   "loses low-contrast markers, too low splits corners",
				   0.0f, 100.0f, DEFAULT_CORNER_THRESHOLD, live));
	g_object_class_install_property(
		gobject_class, PROP_REGION_CONTRAST,
		g_param_spec_float("region-contrast", "Region contrast",
				   "Contrast (intensities in [0, 1]) around a pixel for the dark-region candidates "
				   "that find blurred markers; lower finds fainter blurred markers but traces more "
				   "clutter; 0 turns them off (edge candidates only, faster)",
				   0.0f, 1.0f, DEFAULT_REGION_CONTRAST, live));
	g_object_class_install_property(
		gobject_class, PROP_MAX_HAMMING,
		g_param_spec_int("max-hamming", "Max Hamming",
				 "Most bit errors corrected among cells read clearly (-1 = the dictionary's "
				 "careful default; clamped to half the bits of the dictionary)",
				 -1, MAX_MAX_HAMMING, DEFAULT_MAX_HAMMING, live));
	g_object_class_install_property(
		gobject_class, PROP_SCALED_SIZE,
		g_param_spec_float("scaled-size", "Scaled size",
				   "ascale: target side in pixels of the smallest marker after scaling",
				   8.0f, 1000.0f, DEFAULT_SCALED_SIZE, live));
	g_object_class_install_property(
		gobject_class, PROP_MAX_SCALED_FRAMES,
		g_param_spec_int("max-scaled-frames", "Max scaled frames",
				 "ascale: at most this many scaled frames in a row before one at full resolution",
				 0, 1000, DEFAULT_MAX_SCALED_FRAMES, live));
	g_object_class_install_property(
		gobject_class, PROP_ANNOTATE,
		g_param_spec_boolean("annotate", "Annotate",
				     "Draw outlines, first corners, ids and pose axes into the frame "
				     "(maps the frame writable)",
				     DEFAULT_ANNOTATE, live));
	g_object_class_install_property(
		gobject_class, PROP_POST_MESSAGES,
		g_param_spec_boolean("post-messages", "Post messages",
				     "Post a frappedetect element message per frame", DEFAULT_POST_MESSAGES, live));
	g_object_class_install_property(
		gobject_class, PROP_PIPELINED,
		g_param_spec_boolean("pipelined", "Pipelined",
				     "Overlap the front end of the next frame with the back end of this one "
				     "(holds one buffer: one frame of extra latency)",
				     DEFAULT_PIPELINED, live));
	g_object_class_install_property(
		gobject_class, PROP_BACKEND,
		g_param_spec_enum("backend", "Backend", "Where the front end runs", GST_TYPE_FRAPPE_BACKEND,
				  DEFAULT_BACKEND, live));
	g_object_class_install_property(
		gobject_class, PROP_MARKER_SIZE,
		g_param_spec_double("marker-size", "Marker size",
				    "Side of the markers' black square in metres, for the pose (0 = no pose)",
				    0.0, 1000.0, DEFAULT_MARKER_SIZE, live));
	g_object_class_install_property(
		gobject_class, PROP_CAMERA_MATRIX,
		gst_param_spec_array("camera-matrix", "Camera matrix",
				     "Camera intrinsics for the pose, 9 numbers row-major: "
				     "<fx, 0, cx, 0, fy, cy, 0, 0, 1> (empty = no pose)",
				     g_param_spec_double("element", "Element", "A matrix element", -G_MAXDOUBLE,
							 G_MAXDOUBLE, 0.0, rw),
				     live));
	g_object_class_install_property(
		gobject_class, PROP_DISTORTION,
		gst_param_spec_array("distortion", "Distortion",
				     "Lens distortion in OpenCV's order <k1, k2, p1, p2[, k3[, k4, k5, k6"
				     "[, s1, s2, s3, s4[, tx, ty]]]]> (empty = none)",
				     g_param_spec_double("coefficient", "Coefficient", "A distortion coefficient",
							 -G_MAXDOUBLE, G_MAXDOUBLE, 0.0, rw),
				     live));
	g_object_class_install_property(
		gobject_class, PROP_STATS,
		g_param_spec_boxed("stats", "Statistics",
				   "Per-stage timings (ms) and counts of the last frame", GST_TYPE_STRUCTURE,
				   static_cast<GParamFlags>(G_PARAM_READABLE | G_PARAM_STATIC_STRINGS)));

	gst_element_class_set_static_metadata(element_class, "Frappe fiducial marker detector",
					      "Filter/Analyzer/Video",
					      "Detects square fiducial markers (ArUco, AprilTag) and their pose",
					      "The Frappe authors");
	gst_element_class_add_static_pad_template(element_class, &sink_template);
	gst_element_class_add_static_pad_template(element_class, &src_template);

	trans_class->passthrough_on_same_caps = FALSE;
	trans_class->generate_output = GST_DEBUG_FUNCPTR(gst_frappe_detect_generate_output);
	trans_class->sink_event = GST_DEBUG_FUNCPTR(gst_frappe_detect_sink_event);
	trans_class->query = GST_DEBUG_FUNCPTR(gst_frappe_detect_query);
	trans_class->propose_allocation = GST_DEBUG_FUNCPTR(gst_frappe_detect_propose_allocation);
	trans_class->start = GST_DEBUG_FUNCPTR(gst_frappe_detect_start);
	trans_class->stop = GST_DEBUG_FUNCPTR(gst_frappe_detect_stop);
	filter_class->set_info = GST_DEBUG_FUNCPTR(gst_frappe_detect_set_info);

	gst_type_mark_as_plugin_api(GST_TYPE_FRAPPE_MODE, static_cast<GstPluginAPIFlags>(0));
	gst_type_mark_as_plugin_api(GST_TYPE_FRAPPE_BACKEND, static_cast<GstPluginAPIFlags>(0));
	gst_type_mark_as_plugin_api(GST_TYPE_FRAPPE_DICTIONARY, static_cast<GstPluginAPIFlags>(0));
}
