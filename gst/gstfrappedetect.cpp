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
 * one element message per frame it detects on, named `frappedetect`, with the
 * fields:
 *
 * * `timestamp` (guint64): the buffer's presentation timestamp
 * * `stream-time` (guint64), `running-time` (guint64): from the segment
 * * `duration` (guint64): the buffer's duration
 * * `markers` (GstValueList of GstStructure `marker`): one per marker with
 *   `id` (int), `dictionary` (string), `corners` (GstValueArray of 8 doubles:
 *   x0, y0, ..., x3, y3), `hamming` (uint), `margin` (double: how clearly
 *   the code was read, in [0, 1], the weakest code cell's distance from
 *   the black-white threshold as a fraction of half the contrast; near 0
 *   some cell was nearly a coin toss), `tracked` (boolean: mode track found
 *   it where the last frames predicted it) and, when the pose is known,
 *   `rvec` and `tvec` (GstValueArray of 3 doubles: Rodrigues rotation and
 *   translation in metres), `reprojection-error` (double, RMS pixels) and
 *   `alternative-reprojection-error` (double: the error of the other planar
 *   solution; close to `reprojection-error` when the pose is ambiguous).
 * * `bundle` (GstStructure `bundle`), only with #GstFrappeDetect:bundle-file
 *   when the bundle gave a pose: `name` (string), `rvec`, `tvec`
 *   (GstValueArray of 3 doubles: bundle frame to camera frame, metres),
 *   `reprojection-error` (double, RMS pixels over the corners used), `used`
 *   and `rejected` (GstValueArray of ints: the ids that made the pose and
 *   those seen but left out as outliers), the #GstFrappeBundleMeta's values.
 *
 * The detector's properties are the library's settings table
 * (frappe/settings.h, docs/settings.md): one per frappe::Config field, named
 * in kebab-case, with its default and range. #GstFrappeDetect:dictionary
 * takes every spelling the library does: its names (`apriltag_36h11`), the
 * same with dashes (`apriltag-36h11`), OpenCV's (`DICT_APRILTAG_36h11`) and
 * AprilTag's (`tag36h11`), and reads back as the library's; an unknown name
 * is a warning listing the known ones. #GstFrappeDetect:dictionary-file
 * a dictionary of one's own (frappe::loadDictionary), used instead; metas
 * and messages carry the dictionary's name.
 *
 * Pose: set #GstFrappeDetect:marker-size (metres, the side of the black
 * square; #GstFrappeDetect:marker-sizes, e.g. "0:0.05,7:0.10", for ids of
 * other sizes) and a camera: #GstFrappeDetect:calibration-file (ROS
 * camera_info YAML, OpenCV FileStorage YAML or XML), or
 * #GstFrappeDetect:camera-matrix and #GstFrappeDetect:distortion; the file
 * wins when both are set. A calibration made at another frame size of the
 * same aspect ratio is scaled to the caps; another aspect ratio posts a
 * warning and gives no pose. A file that cannot be used is an error at
 * start; set while playing, it is a warning and the previous file is kept
 * (a refused marker-sizes, camera-matrix or distortion: a warning too).
 * The pose (frappe::estimatePose: IPPE, refined by Levenberg-Marquardt) is in
 * OpenCV's camera frame (x right, y down, z forward) for the marker frame
 * of OpenCV aruco: origin at the marker centre, x right, y up, z out of the
 * marker towards the camera.
 *
 * Bundles: #GstFrappeDetect:bundle-file names a rigid set of markers with
 * known 3D corners (a grid board, apriltag_ros's tags.yaml bundle;
 * frappe/bundle.h). Each frame where markers of it are seen gets one pose
 * from all of them (frappe::estimateBundlePose: every agreeing corner
 * through the lens model, a marker whose corners disagree rejected) as a
 * #GstFrappeBundleMeta (gstfrappebundlemeta.h; at most one a buffer, none
 * when the bundle is not seen; bindings copy it out with
 * gst_frappe_buffer_get_bundle_pose()), the message's `bundle` structure
 * and frappejson's `"bundle"` object. The bundle gives its markers' sizes
 * (marker-size is for the single poses); the camera is the pose's
 * (calibration-file or camera-matrix, fitted to the caps): a bundle-file
 * without one fails the start, as a file that cannot be read does.
 *
 * A value the element refuses (an unknown dictionary or mode, a malformed
 * marker-sizes, a camera-matrix of other than 9 numbers, a distortion of
 * another count, a file it cannot read, a bundle-file without a camera) set while the element is stopped,
 * as on a gst-launch-1.0 line, makes its next state change fail with an
 * element error (GST_RESOURCE_ERROR_SETTINGS) naming the property, the
 * value, why and what the property takes: gst-launch-1.0 prints it and
 * exits. Set while playing, the previous value is kept and the same text is
 * a warning on the bus.
 *
 * Every buffer the element detects on is numbered: its offset (and offset
 * end, one more) is its count since the element started, 0 first, as
 * GstBuffer's offset is a video frame's number; frappejson writes it as
 * the line's `frame`. A buffer passed through unread keeps its own.
 *
 * #GstFrappeDetect:backend chooses where the front end (Sobel, edges,
 * corners, empty tiles) runs: `cpu`; `vc4`, the QPUs of a Raspberry Pi Zero,
 * 1, 2 or 3 (it fails to start when they cannot be used, e.g. while the vc4
 * KMS driver owns the GPU); `vc4-emu`, the same QPU programs on an emulator,
 * bit-exact and slow, for testing anywhere; `auto` (the default), the QPUs
 * when the probe succeeds, else the CPU with one warning on a Pi. With the
 * QPUs the element offers upstream a pool of GPU-visible dma-buf buffers
 * (rows 64-byte aligned when a GstVideoMeta can say so) and the QPUs read a
 * luma plane that lies in one dma-buf in place; other input is copied (the
 * stats' `copied-bytes`, and one debug line saying why).
 *
 * With #GstFrappeDetect:pipelined, two frames are detected at once (a
 * frappe::Pipeline), in the way #GstFrappeDetect:overlap says. `frames`:
 * each whole frame on a detector of its own on one of two threads, about
 * 1.5 times the frame rate a core allows where there are two cores.
 * `stages`: one detector whose worker thread runs the next frame's front
 * end (on the QPUs: their passes, while that thread sleeps in the GPU
 * call) while the streaming thread traces this frame's contours and then
 * finishes it: the paper's overlap for a Pi Zero's one core beside its 12
 * QPUs, with one QPU context and one set of GPU buffers. `auto` (the
 * default) stages when the front end runs on the QPUs (backend vc4, vc4-emu,
 * or auto that found them) and takes whole frames on CPUs; the `stats`
 * field `overlap` says which ran (`none` when not pipelined) and
 * `qpu-contexts` how many QPU contexts the element opened since it started.
 * Either way, one frame of latency: the element then holds one buffer,
 * answers the LATENCY query with one extra frame, asks upstream pools for
 * one more buffer, pushes the held buffer on EOS, caps, segment, gap,
 * stream-start and DRAIN queries, and drops it on flush. Every buffer the
 * element receives comes out once, in order, with its own metas (QoS may
 * drop buffers before that: below). In AScale mode a frame scales from
 * the last frame finished before its front end started (with `frames`,
 * the last its own detector ran), so it may differ from the unpipelined
 * element's; in NORMAL mode the markers are the same.
 *
 * A buffer that does not hold the frame it describes is neither mapped nor
 * read: no memory at all; a #GstVideoMeta whose format, size or planes
 * differ from the caps; a stride negative or shorter than a row; the luma
 * plane (and, with #GstFrappeDetect:annotate, any plane) ending past the
 * buffer or, with a meta, past the memory its offset is in; a chroma
 * plane starting past the buffer whatever #GstFrappeDetect:annotate is;
 * any buffer that cannot be mapped all the same. It comes out
 * untouched, in its place (pipelined, after the held buffer), with no
 * metas, no drawing and no message. The first buffer of each kind of fault
 * posts a warning (GST_STREAM_ERROR_FORMAT), later ones only a debug line.
 * Caps of more than frappe::Config's max_pixels (2^26) are refused.
 *
 * QoS (#GstBaseTransform:qos) is on by default, as for every GstVideoFilter:
 * with a synchronising sink downstream, a buffer that is already late when
 * it arrives is dropped before detection and neither comes out nor gets a
 * message. With qos=false every buffer comes out.
 *
 * When detection fails on a frame the element posts an error and returns
 * a flow error, pipelined or not (pipelined, when that frame is finished:
 * at the next buffer or a drain); that buffer does not come out, the ones
 * before and after it do.
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
 *     frappedetect dictionary=apriltag_36h11 marker-size=0.1 \
 *     calibration-file=camera.yaml ! frappejson ! fdsink
 * ]| Poses of AprilTag markers of 10 cm seen by a camera, as JSON lines.
 * |[
 * gst-launch-1.0 -m libcamerasrc ! video/x-raw,format=NV12,width=640,height=480 ! \
 *     frappedetect dictionary=6x6_250 calibration-file=camera.yaml \
 *     bundle-file=board.yaml ! fakesink
 * ]| One pose of a board of markers (board.yaml: `board: grid`, `rows: 3`,
 * `cols: 4`, `size: 0.05`, `gap: 0.01`) a frame, in the messages' `bundle`.
 */

#include "gstfrappedetect.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <exception>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <gst/video/video.h>

#include <frappe/frappe.h>

#include "annotate.h"
#include "frappe_backend.h"
#include "gstfrappebuffer.h"
#include "gstfrappecamera.h"
#include "gstfrappeenums.h"
#include "gstfrappeoutput.h"
#include "gstfrappepool.h"
#include "gstfrappesettings.h"
#include "gstfrappeframe.h"

/* Not static: the settings log through it too. */
GST_DEBUG_CATEGORY(gst_frappe_detect_debug);
#define GST_CAT_DEFAULT gst_frappe_detect_debug

using frappe::gst::Lie;
using frappe::gst::MappedFrame;
using frappe::gst::Settings;

/* -------------------------------------------------------------------------
 * Instance
 */

/* What the pipeline overlaps: nothing (not pipelined), whole frames, or
 * one detector's stages. */
enum class Overlap { None, Frames, Stages };

struct FrappeDetectPrivate {
	/* Under the object lock. */
	Settings props;
	GstStructure *stats = nullptr;
	bool running = false;          /* started: files are read when set */
	frappe::gst::Refusals refused; /* values refused while stopped */

	/* Streaming thread only. */
	Settings active;
	frappe::gst::PoseCamera camera; /* active's, fitted to the caps */
	frappe::gst::Poses poses;       /* the frame's, reused */
	std::vector<std::optional<frappe::Pose>> bestPoses;
	frappe::BundlePose bundlePose; /* the frame's, with bundle-file, when hasBundlePose */
	bool hasBundlePose = false;
	frappe::BundleScratch bundleScratch; /* estimateBundlePose()'s memory, reused */
	bool warnedBundleCamera = false;     /* a bundle without a camera, since the settings changed */
	std::string dictionary;         /* the pipeline's dictionary name */
	std::unique_ptr<frappe::Pipeline> pipeline;
	Overlap overlap = Overlap::None; /* the pipeline's */
	guint qpuContexts = 0;           /* opened since start */
	std::vector<MappedFrame> held;   /* in the pipeline, oldest first */
	std::vector<GstBuffer *> output; /* finished, waiting for generate_output */
	frappe::gst::BufferLog bufferLog;
	bool warnedFallback = false, warnedDropped = false;
	bool poolOffered = false; /* a GstFrappePool went upstream */
	guint64 frames = 0;
	guint64 numbered = 0; /* buffers numbered (offset) since start */
	frappe::gst::StatsWindow window;
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

static const char *overlap_name(Overlap o)
{
	return o == Overlap::Stages ? "stages" : o == Overlap::Frames ? "frames" : "none";
}

/* A pipeline of the active settings with its front end, or nullptr after
 * an element error. Not pipelined: frames one at a time on one thread.
 * Pipelined, one frame held either way: whole frames on two detectors and
 * threads (frappe::Pipeline::Overlap::Frames, latency 1), or one detector's
 * stages (Overlap::Stages, latency 1: the next frame's front end beside this
 * frame's trace). */
static std::unique_ptr<frappe::Pipeline> make_pipeline(GstFrappeDetect *self, Overlap overlap,
						       GstFrappeBackend backend)
{
	FrappeDetectPrivate *priv = self->priv;
	const bool staged = overlap == Overlap::Stages;
	std::unique_ptr<frappe::Pipeline> pipeline;
	try {
		pipeline = std::make_unique<frappe::Pipeline>(priv->active.config(staged),
							      staged ? frappe::Pipeline::Overlap::Stages
								     : frappe::Pipeline::Overlap::Frames,
							      overlap == Overlap::None ? 0 : 1);
	} catch (const std::exception &e) {
		GST_ELEMENT_ERROR(self, LIBRARY, SETTINGS, ("Invalid detector settings"), ("%s", e.what()));
		return nullptr;
	}
	if (!frappe::gst::selectFrontEnd(GST_ELEMENT(self), *pipeline, backend, priv->warnedFallback))
		return nullptr;
	return pipeline;
}

/* The pipeline of the active settings. overlap=auto stages the frames when
 * the front end runs on the QPUs: backend=auto only knows after its probe,
 * so it is first built staged (only that shape may hold the QPUs' one
 * context) and rebuilt over whole frames when the front end came out on the
 * CPU (no QPU context was opened then). */
static bool ensure_pipeline(GstFrappeDetect *self)
{
	FrappeDetectPrivate *priv = self->priv;
	if (priv->pipeline)
		return true;
	const Settings &s = priv->active;
	Overlap overlap = Overlap::None;
	if (s.pipelined) {
		if (s.overlap == GST_FRAPPE_OVERLAP_FRAMES)
			overlap = Overlap::Frames;
		else if (s.overlap == GST_FRAPPE_OVERLAP_STAGES)
			overlap = Overlap::Stages;
		else
			overlap = s.backend == GST_FRAPPE_BACKEND_CPU ? Overlap::Frames : Overlap::Stages;
	}
	priv->pipeline = make_pipeline(self, overlap, s.backend);
	if (priv->pipeline && s.pipelined && s.overlap == GST_FRAPPE_OVERLAP_AUTO && overlap == Overlap::Stages &&
	    !frappe::gst::frontEndOnQpus(*priv->pipeline)) {
		GST_DEBUG_OBJECT(self, "overlap=auto: the front end is on the CPU, whole frames then");
		overlap = Overlap::Frames;
		priv->pipeline = make_pipeline(self, overlap, GST_FRAPPE_BACKEND_CPU);
	}
	if (!priv->pipeline)
		return false;
	priv->overlap = overlap;
	priv->qpuContexts += static_cast<guint>(frappe::qpuContexts(*priv->pipeline));
	priv->held.reserve(static_cast<std::size_t>(priv->pipeline->latency()) + 1);
	priv->dictionary = priv->pipeline->detector().dictionary().name;
	GST_DEBUG_OBJECT(self,
			 "pipeline for %s, mode %s, max-hamming %d, front end %s, overlap %s, %d thread(s), "
			 "%u QPU context(s) opened",
			 priv->dictionary.c_str(), std::string(frappe::modeName(s.library.mode)).c_str(),
			 priv->pipeline->detector().maxHamming(), priv->pipeline->detector().frontEnd().name(),
			 overlap_name(overlap), priv->pipeline->threads(), priv->qpuContexts);
	return true;
}

static void update_stats(GstFrappeDetect *self, const frappe::Result &result, double poseMs)
{
	FrappeDetectPrivate *priv = self->priv;
	GstStructure *s = frappe::gst::statsStructure(priv->frames, result, poseMs,
						      priv->pipeline->detector().frontEnd().name(),
						      priv->active.pipelined, overlap_name(priv->overlap),
						      priv->qpuContexts);

	GST_LOG_OBJECT(self, "stats %" GST_PTR_FORMAT, static_cast<void *>(s));
	frappe::gst::reportDroppedCandidates(GST_ELEMENT(self), priv->frames, result, priv->warnedDropped);

	if (const auto line = priv->window.add(priv->frames, result, poseMs))
		GST_INFO_OBJECT(self, "last 100 frames, ms per frame: %s%s", line->c_str(),
				priv->overlap == Overlap::Frames   ? " (two frames at once)"
				: priv->overlap == Overlap::Stages ? " (the next frame's front end beside this trace)"
								   : "");
	GST_OBJECT_LOCK(self);
	if (priv->stats)
		gst_structure_free(priv->stats);
	priv->stats = s;
	GST_OBJECT_UNLOCK(self);
}

/* A frame whose detection failed: an element error, pipelined or not, and
 * the buffer is dropped. */
static GstFlowReturn fail(GstFrappeDetect *self, MappedFrame &f, const char *why)
{
	GST_ELEMENT_ERROR(self, STREAM, FAILED, ("Marker detection failed"), ("%s", why));
	f.discard();
	return GST_FLOW_ERROR;
}

/* The bundle's pose from the frame's markers into priv->bundlePose (no
 * allocation once its vectors and the scratch have grown), none without
 * bundle-file; a bundle without a camera (camera-matrix cleared while
 * playing) is one warning until the settings change. */
static void estimate_bundle_pose(GstFrappeDetect *self, const frappe::Result &result)
{
	FrappeDetectPrivate *priv = self->priv;
	const Settings &s = priv->active;
	priv->hasBundlePose = false;
	if (!s.bundle)
		return;
	const frappe::Camera *camera = priv->camera.camera();
	if (!camera) {
		/* A calibration of another aspect ratio has warned already. */
		if (!s.poseCamera() && !std::exchange(priv->warnedBundleCamera, true))
			GST_ELEMENT_WARNING(self, RESOURCE, SETTINGS,
					    ("bundle-file is set but there is no camera: no bundle pose"),
					    ("set calibration-file or camera-matrix"));
		return;
	}
	try {
		priv->hasBundlePose = frappe::estimateBundlePose(*s.bundle, result.markers, *camera, priv->bundlePose,
								 priv->bundleScratch);
	} catch (const std::exception &e) {
		/* Not reached: the camera was checked when set. */
		GST_WARNING_OBJECT(self, "bundle %s: %s", s.bundle->name.c_str(), e.what());
	}
}

/* Attaches metas, draws, posts the message and releases the frame; the
 * buffer goes to the output list. */
static void finish(GstFrappeDetect *self, MappedFrame &f, const frappe::Result &result)
{
	FrappeDetectPrivate *priv = self->priv;
	const Settings &s = priv->active;
	const char *dictName = priv->dictionary.c_str();
	const frappe::gst::Poses &poses = priv->poses;

	const gint64 t0 = g_get_monotonic_time();
	frappe::gst::estimatePoses(result.markers, s.sizes, priv->camera.camera(), priv->poses);
	estimate_bundle_pose(self, result);
	const double poseMs = static_cast<double>(g_get_monotonic_time() - t0) / 1000.0;
	const frappe::gst::BundleOutput bundle{ s.bundle.get(), priv->hasBundlePose ? &priv->bundlePose : nullptr };

	frappe::gst::attachMarkerMetas(f.buffer, GST_VIDEO_FRAME_WIDTH(&f.frame), GST_VIDEO_FRAME_HEIGHT(&f.frame),
				       result, poses, dictName, s.library.mode == frappe::Mode::Track);
	frappe::gst::attachBundleMeta(f.buffer, bundle);
	if (f.writable && s.annotate && !result.markers.empty()) {
		frappe::gst::bestPoses(poses, priv->bestPoses);
		/* The bundle's axes as long as its largest marker's side. */
		frappe::gst::BundleAxes axes;
		if (bundle.pose) {
			axes.pose = &bundle.pose->pose;
			for (const frappe::BundleMarker &m : bundle.bundle->markers)
				axes.axis = std::max(axes.axis, m.size);
		}
		frappe::gst::annotateMarkers(&f.frame, result, priv->bestPoses, s.sizes, priv->camera.fitted(), axes);
	}

	priv->bufferLog.copied(GST_ELEMENT(self), f.image, f.dmabufInput, result.copy_bytes, priv->poolOffered);
	GstBuffer *buffer = f.release();

	if (s.postMessages) {
		GstStructure *msg = frappe::gst::frameMessage(buffer, GST_BASE_TRANSFORM(self)->segment, result, poses,
							      dictName, bundle);
		gst_element_post_message(GST_ELEMENT(self), gst_message_new_element(GST_OBJECT(self), msg));
	}

	++priv->frames;
	GST_LOG_OBJECT(self, "frame %" G_GUINT64_FORMAT " pts %" GST_TIME_FORMAT ": %zu markers in %.3f ms",
		       priv->frames, GST_TIME_ARGS(GST_BUFFER_PTS(buffer)), result.markers.size(),
		       result.times.total_ms + poseMs);
	update_stats(self, result, poseMs);

	priv->output.push_back(buffer);
}

/* Finishes the oldest held frame with what the pipeline returned for it
 * (push() or flush()), or fails it when that threw. */
static GstFlowReturn finish_oldest(GstFrappeDetect *self, const frappe::Result *result, const std::string &error)
{
	FrappeDetectPrivate *priv = self->priv;
	MappedFrame f = priv->held.front();
	priv->held.erase(priv->held.begin());
	if (!error.empty())
		return fail(self, f, error.c_str());
	finish(self, f, *result);
	return GST_FLOW_OK;
}

/* Finishes every held frame, in order; an error is returned once all are
 * out of the pipeline. */
static GstFlowReturn finish_held(GstFrappeDetect *self)
{
	FrappeDetectPrivate *priv = self->priv;
	GstFlowReturn ret = GST_FLOW_OK;
	while (!priv->held.empty()) {
		const frappe::Result *result = nullptr;
		std::string error;
		try {
			result = priv->pipeline->flush();
			if (!result)
				error = "the pipeline lost a frame"; /* not reached */
		} catch (const std::exception &e) {
			error = e.what();
		}
		const GstFlowReturn r = finish_oldest(self, result, error);
		if (ret == GST_FLOW_OK)
			ret = r;
	}
	return ret;
}

/* Throws the held frames away (flush, stop). */
static void drop_held(GstFrappeDetect *self)
{
	FrappeDetectPrivate *priv = self->priv;
	if (priv->held.empty())
		return;
	priv->pipeline->drop(); /* waits for the frames running */
	for (MappedFrame &f : priv->held) {
		GST_DEBUG_OBJECT(self, "dropping held %" GST_PTR_FORMAT, static_cast<void *>(f.buffer));
		f.discard();
	}
	priv->held.clear();
}

static void clear_output(GstFrappeDetect *self)
{
	for (GstBuffer *b : self->priv->output)
		gst_buffer_unref(b);
	self->priv->output.clear();
}

/* Pushes the held frames and anything waiting (serialized events). */
static GstFlowReturn drain(GstFrappeDetect *self)
{
	FrappeDetectPrivate *priv = self->priv;
	const GstFlowReturn held = finish_held(self);
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
	return ret != GST_FLOW_OK ? ret : held;
}

/* Picks up property changes; a new pipeline finishes the held frames of
 * the old one first, a new camera is fitted to the frames. */
static GstFlowReturn apply_settings(GstFrappeDetect *self)
{
	FrappeDetectPrivate *priv = self->priv;
	GST_OBJECT_LOCK(self);
	if (priv->props.generation == priv->active.generation) {
		GST_OBJECT_UNLOCK(self);
		return GST_FLOW_OK;
	}
	Settings next = priv->props;
	GST_OBJECT_UNLOCK(self);

	const bool pipelineChange = next.pipelined != priv->active.pipelined;
	const bool rebuild = !next.samePipeline(priv->active);
	GstFlowReturn ret = GST_FLOW_OK;
	if (rebuild)
		ret = finish_held(self);
	const bool newCamera = next.cameraGeneration != priv->active.cameraGeneration;
	priv->active = next;
	priv->warnedBundleCamera = false;
	if (newCamera) {
		const GstVideoInfo *info = &GST_VIDEO_FILTER(self)->in_info;
		priv->camera.fit(GST_ELEMENT(self), priv->active.poseCamera(), GST_VIDEO_INFO_WIDTH(info),
				 GST_VIDEO_INFO_HEIGHT(info));
	}
	if (rebuild && priv->pipeline) {
		GST_DEBUG_OBJECT(self, "settings changed, rebuilding the pipeline");
		priv->pipeline.reset();
	}
	if (pipelineChange) {
		GST_DEBUG_OBJECT(self, "pipelined now %d", next.pipelined);
		gst_element_post_message(GST_ELEMENT(self), gst_message_new_latency(GST_OBJECT(self)));
	}
	return ret;
}

/* A buffer that does not hold its frame comes out untouched (no metas,
 * no drawing, no message), after the held frames: it must not overtake
 * them, so pipelined it costs one frame of overlap. */
static GstFlowReturn pass_through(GstFrappeDetect *self, GstBuffer *buffer)
{
	const GstFlowReturn ret = finish_held(self);
	if (ret != GST_FLOW_OK) {
		gst_buffer_unref(buffer);
		return ret;
	}
	self->priv->output.push_back(buffer);
	return GST_FLOW_OK;
}

/* Pushes the buffer into the pipeline and finishes the one it returns
 * (itself when not pipelined, the held one when pipelined). */
static GstFlowReturn process(GstFrappeDetect *self, GstBuffer *input)
{
	FrappeDetectPrivate *priv = self->priv;

	GstFlowReturn ret = apply_settings(self);
	if (ret != GST_FLOW_OK) {
		gst_buffer_unref(input);
		return ret;
	}
	if (!ensure_pipeline(self)) {
		gst_buffer_unref(input);
		return GST_FLOW_NOT_NEGOTIATED;
	}

	/* Every buffer has a number since start, its offset as GstBuffer's is
	 * for video (frappejson's `frame`, the same in every branch after); a
	 * buffer passed through untouched keeps its own. */
	const guint64 number = priv->numbered++;

	/* Before anything maps or reads it: the luma plane the detector
	 * reads and, to annotate, the chroma planes it writes. */
	const GstVideoInfo *info = &GST_VIDEO_FILTER(self)->in_info;
	std::array<char, frappe::gst::kLieText> why;
	const Lie lie = frappe::gst::checkBuffer(input, info, priv->active.annotate, why);
	if (lie != Lie::None) {
		priv->bufferLog.lie(GST_ELEMENT(self), lie, why.data(), input);
		return pass_through(self, input);
	}

	/* Metas and the number need a writable buffer: a shallow copy when
	 * shared, which keeps the memory (and zero-copy) as long as we map
	 * read-only. */
	GstBuffer *buffer = gst_buffer_make_writable(input);
	GST_BUFFER_OFFSET(buffer) = number;
	GST_BUFFER_OFFSET_END(buffer) = number + 1;

	priv->bufferLog.memory(GST_ELEMENT(self), buffer, info, priv->active.annotate);

	MappedFrame f;
	if (!f.map(buffer, info, priv->active.annotate)) {
		/* What checkBuffer() does not foresee: passed through all the
		 * same, never a reason to stop the stream. */
		priv->bufferLog.lie(GST_ELEMENT(self), Lie::Map, "the buffer could not be mapped", buffer);
		return pass_through(self, buffer);
	}
	try {
		priv->pipeline->detector().checkImage(f.image);
	} catch (const std::exception &e) {
		return fail(self, f, e.what());
	}

	/* In the pipeline now: any exception of push() is the oldest frame's
	 * (in AScale mode a frame scales from the last one its detector ran). */
	priv->held.push_back(f);
	const frappe::Result *result = nullptr;
	std::string error;
	try {
		result = priv->pipeline->push(f.image);
	} catch (const std::exception &e) {
		error = e.what();
	}
	if (!result && error.empty())
		return GST_FLOW_OK; /* held */
	return finish_oldest(self, result, error);
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
		if (!self->priv->held.empty() || !self->priv->output.empty()) {
			GST_DEBUG_OBJECT(self, "draining before %s", GST_EVENT_TYPE_NAME(event));
			drain(self);
		}
		break;
	case GST_EVENT_FLUSH_STOP:
		drop_held(self);
		clear_output(self);
		if (self->priv->pipeline)
			self->priv->pipeline->reset();
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
	    (!self->priv->held.empty() || !self->priv->output.empty())) {
		GST_DEBUG_OBJECT(self, "draining for a DRAIN query");
		drain(self);
	}

	gboolean ret = GST_BASE_TRANSFORM_CLASS(parent_class)->query(trans, direction, query);

	if (ret && direction == GST_PAD_SRC && GST_QUERY_TYPE(query) == GST_QUERY_LATENCY) {
		GST_OBJECT_LOCK(self);
		const gboolean pipelined = self->priv->props.pipelined;
		GST_OBJECT_UNLOCK(self);
		if (pipelined)
			frappe::gst::addHeldFrameLatency(GST_ELEMENT(self), query, &GST_VIDEO_FILTER(self)->in_info);
	}
	return ret;
}

/* The QPUs' frame memory for upstream to write into; holding a buffer in
 * pipelined mode takes one more from upstream's pool (or ours). */
static gboolean gst_frappe_detect_propose_allocation(GstBaseTransform *trans, GstQuery *decide_query,
						     GstQuery *query)
{
	GstFrappeDetect *self = GST_FRAPPE_DETECT(trans);
	FrappeDetectPrivate *priv = self->priv;
	gboolean ret = GST_BASE_TRANSFORM_CLASS(parent_class)->propose_allocation(trans, decide_query, query);
	GST_OBJECT_LOCK(self);
	const GstFrappeBackend backend = priv->props.backend;
	const gboolean pipelined = priv->props.pipelined;
	GST_OBJECT_UNLOCK(self);
	/* auto probes the QPUs here, once. */
	const bool probed = backend == GST_FRAPPE_BACKEND_AUTO && ensure_pipeline(self);
	const char *memory = frappe::gst::frameMemoryBackend(backend, probed ? priv->pipeline.get() : nullptr);
	priv->poolOffered = memory && frappe::gst::offerFramePool(GST_ELEMENT(self), query, memory);
	ret = ret || priv->poolOffered;
	if (ret && pipelined)
		frappe::gst::askOneMoreBuffer(GST_ELEMENT(self), query);
	return ret;
}

static gboolean gst_frappe_detect_start(GstBaseTransform *trans)
{
	GstFrappeDetect *self = GST_FRAPPE_DETECT(trans);
	if (!frappe::gst::startSettings(GST_ELEMENT(self), self->priv->props, self->priv->running))
		return FALSE;
	GST_OBJECT_LOCK(self);
	self->priv->active = self->priv->props;
	GST_OBJECT_UNLOCK(self);
	self->priv->camera.reset();
	self->priv->frames = 0;
	self->priv->numbered = 0;
	self->priv->window.reset();
	self->priv->bufferLog.reset();
	self->priv->warnedDropped = false;
	self->priv->poolOffered = false;
	self->priv->qpuContexts = 0;
	return TRUE;
}

static gboolean gst_frappe_detect_stop(GstBaseTransform *trans)
{
	GstFrappeDetect *self = GST_FRAPPE_DETECT(trans);
	drop_held(self);
	clear_output(self);
	self->priv->pipeline.reset();
	GST_OBJECT_LOCK(self);
	self->priv->running = false;
	GST_OBJECT_UNLOCK(self);
	return TRUE;
}

/* Too large frames are refused here, once; a buffer's meta must then match
 * these caps (checkBuffer). */
static gboolean gst_frappe_detect_set_info(GstVideoFilter *filter, GstCaps *, GstVideoInfo *in_info,
					   GstCaps *, GstVideoInfo *)
{
	if (!frappe::gst::acceptFrameSize(GST_ELEMENT(filter), in_info))
		return FALSE;
	GstFrappeDetect *self = GST_FRAPPE_DETECT(filter);
	self->priv->camera.fit(GST_ELEMENT(self), self->priv->active.poseCamera(), GST_VIDEO_INFO_WIDTH(in_info),
			       GST_VIDEO_INFO_HEIGHT(in_info));
	return TRUE;
}

/* A value refused while stopped fails the next state change up: on a
 * gst-launch-1.0 line its warning had no bus to go to. */
static GstStateChangeReturn gst_frappe_detect_change_state(GstElement *element, GstStateChange transition)
{
	if ((transition == GST_STATE_CHANGE_NULL_TO_READY || transition == GST_STATE_CHANGE_READY_TO_PAUSED) &&
	    !frappe::gst::failRefused(element, GST_FRAPPE_DETECT(element)->priv->refused))
		return GST_STATE_CHANGE_FAILURE;
	return GST_ELEMENT_CLASS(parent_class)->change_state(element, transition);
}

/* -------------------------------------------------------------------------
 * GObject
 */

static void gst_frappe_detect_set_property(GObject *object, guint prop_id, const GValue *value, GParamSpec *pspec)
{
	GstFrappeDetect *self = GST_FRAPPE_DETECT(object);
	if (!frappe::gst::setProperty(GST_ELEMENT(self), self->priv->props, self->priv->running, self->priv->refused,
				      prop_id, value))
		G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
}

static void gst_frappe_detect_get_property(GObject *object, guint prop_id, GValue *value, GParamSpec *pspec)
{
	GstFrappeDetect *self = GST_FRAPPE_DETECT(object);

	GST_OBJECT_LOCK(self);
	if (prop_id == frappe::gst::PROP_STATS) {
		if (self->priv->stats)
			g_value_set_boxed(value, self->priv->stats);
		else
			g_value_take_boxed(value, gst_structure_new_empty("frappe-stats"));
	} else if (!frappe::gst::getProperty(self->priv->props, prop_id, value)) {
		G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec);
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

	frappe::gst::installProperties(gobject_class);

	gst_element_class_set_static_metadata(element_class, "Frappe fiducial marker detector",
					      "Filter/Analyzer/Video",
					      "Detects square fiducial markers (ArUco, AprilTag) and their pose",
					      "The Frappe authors");
	gst_element_class_add_static_pad_template(element_class, &sink_template);
	gst_element_class_add_static_pad_template(element_class, &src_template);
	element_class->change_state = GST_DEBUG_FUNCPTR(gst_frappe_detect_change_state);

	trans_class->passthrough_on_same_caps = FALSE;
	trans_class->generate_output = GST_DEBUG_FUNCPTR(gst_frappe_detect_generate_output);
	trans_class->sink_event = GST_DEBUG_FUNCPTR(gst_frappe_detect_sink_event);
	trans_class->query = GST_DEBUG_FUNCPTR(gst_frappe_detect_query);
	trans_class->propose_allocation = GST_DEBUG_FUNCPTR(gst_frappe_detect_propose_allocation);
	trans_class->start = GST_DEBUG_FUNCPTR(gst_frappe_detect_start);
	trans_class->stop = GST_DEBUG_FUNCPTR(gst_frappe_detect_stop);
	filter_class->set_info = GST_DEBUG_FUNCPTR(gst_frappe_detect_set_info);

	gst_type_mark_as_plugin_api(GST_TYPE_FRAPPE_BACKEND, static_cast<GstPluginAPIFlags>(0));
}
