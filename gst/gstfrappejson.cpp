/* SPDX-License-Identifier: MIT
 *
 * gstfrappejson.cpp: the frappejson element.
 */

/**
 * SECTION:element-frappejson
 * @title: frappejson
 *
 * Turns each video buffer coming out of frappedetect into lines of JSON
 * describing its markers, read from the #GstFrappeMarkerMeta on the buffer;
 * the pixels are never mapped or read. For files, sockets and applications
 * that want the markers without linking to GStreamer.
 *
 * Sink caps: `video/x-raw` in any format frappedetect outputs (GRAY8, I420,
 * YV12, NV12, NV21), any size and frame rate. Src caps: `application/x-json`
 * (the lines as they are), or `meta/x-klv, parsed=true` (each line as one
 * KLV packet, for mpegtsmux: below).
 *
 * ## The marker line
 *
 * Each output buffer is one line ending in "\n", one JSON object whose
 * keys come in this order (here on several lines):
 *
 * |[
 * {"frame": 41, "part": 1, "parts": 1, "pts": 1366666666,
 *  "running_time": 1366666666, "width": 640, "height": 480,
 *  "frame_id": "camera", "capture_time": 1780393200123456789,
 *  "capture_clock": "pipeline",
 *  "bundle": {"name": "grid", "rvec": [rx, ry, rz], "tvec": [tx, ty, tz],
 *   "reprojection_error": 0.12, "used": [0, 1, 2, 4], "rejected": [3]},
 *  "markers": [{"id": 7, "dictionary": "aruco_mip_36h12",
 *   "corners": [[x0, y0], [x1, y1], [x2, y2], [x3, y3]], "hamming": 0,
 *   "margin": 0.93, "rvec": [rx, ry, rz], "tvec": [tx, ty, tz],
 *   "reprojection_error": 0.05, "alternative_reprojection_error": 2.1}]}
 * ]|
 *
 * * `frame`: the frame's number since the stream started: the buffer's
 *   offset, which frappedetect sets to its count of buffers since it
 *   started (0 first, every buffer it outputs), or frappejson's own count
 *   for a buffer without an offset. Numbers missing on the host are frames
 *   lost between frappedetect and the host (a leaky queue, the network).
 * * `part`, `parts`: this line is part k of n of the frame (1 of 1 when the
 *   frame fits in #GstFrappeJson:max-bytes). Every part repeats the frame's
 *   fields; the markers are split between the parts in order, each marker
 *   whole in exactly one part. A frame without markers is one part with
 *   `"markers": []`.
 * * `pts`: the buffer's presentation time in nanoseconds; `running_time`:
 *   the same on the pipeline's running time (its segment); `null` when the
 *   buffer has none.
 * * `width`, `height`: the frame's size in pixels (the caps'), which the
 *   corners are in.
 * * `frame_id`: #GstFrappeJson:frame-id, the camera's name (ROS's
 *   `header.frame_id`), which the poses are in.
 * * `capture_time`, `capture_clock`: when the frame was taken, in
 *   nanoseconds since the Unix epoch (UTC). `"reference"`: from the
 *   buffer's #GstReferenceTimestampMeta of caps `timestamp/x-unix` (or
 *   `timestamp/x-ntp`, converted from the NTP epoch), a wall-clock time the
 *   source gave. Otherwise `"pipeline"`: the pipeline clock's time of the
 *   buffer's running time (base time + running time) mapped to the system's
 *   real-time clock by reading both now; for a live source that is when
 *   the frame was captured, as the source timestamped it. `null` for both
 *   when neither is known (no reference meta and no clock or no running
 *   time).
 * * `bundle`: only when the buffer has a #GstFrappeBundleMeta
 *   (frappedetect's bundle-file, the bundle seen): its `name`, `rvec`,
 *   `tvec` (bundle frame to camera frame), `reprojection_error` (RMS
 *   pixels), the ids `used` and `rejected` (outliers). A frame field: every
 *   part repeats it, so any part that arrives gives the pose.
 * * `markers`: in the order of their metas, with the fields of
 *   #GstFrappeMarkerMeta (frappe/marker_record.h's list); `rvec`, `tvec`
 *   and the two reprojection errors only when the pose is known, `tracked`
 *   only when frappedetect ran with mode=track (as frappe-detect writes
 *   it). Numbers are written with the
 *   digits that give back the meta's value exactly (float corners, double
 *   poses) unless #GstFrappeJson:precision says fewer; a value that is not
 *   finite (an alternative error of infinity: there was no other solution)
 *   is written `null`. #GstFrappeJson:fields leaves fields out.
 *
 * The frame's fields are frappejson's, written from what the buffer
 * carries (its offset, timestamps, reference metas and the segment, all of
 * which travel with it through queues and tees): two frappejson after one
 * frappedetect write the same frame numbers, whatever each branch drops.
 *
 * ## Parts and max-bytes
 *
 * With udpsink each line is one datagram. #GstFrappeJson:max-bytes (1400
 * by default: an Ethernet frame's 1472-byte UDP payload less room for a
 * VPN or tunnel header) bounds every line: a frame whose markers do not
 * fit is split into parts, so a datagram never needs IP fragmentation and
 * a lost one loses only its own markers. A marker that does not fit even
 * alone is sent alone in its part, longer than max-bytes, with one warning
 * per stream. 0: one line per frame, whatever its length (files, TCP).
 * A host reassembles a frame from its `parts` lines of one `frame`.
 *
 * Every input buffer gives one or more output buffers (its parts, in
 * order), each with the input's PTS, DTS, duration and offsets; the first
 * carries the input's DISCONT flag. Events (stream-start, segment, EOS,
 * ...) pass through; the caps event carries the src caps.
 *
 * ## Video and markers in one stream
 *
 * With src caps `meta/x-klv, parsed=true` each line becomes one KLV
 * packet: the 16-byte key `frappe/markers/1` (ASCII), the line's length
 * (BER), the line. mpegtsmux carries such a stream beside the video in one
 * MPEG transport stream, and on the host tsdemux gives both with the same
 * PTS: each decoded video frame is paired with its markers by PTS, whatever
 * the encoder, the RTP payloader or the network did to the timestamps
 * (`docs/streaming.md`, `python/frappe/video.py`, `examples/stream-markers.sh`).
 *
 * ## Example launch lines
 * |[
 * gst-launch-1.0 filesrc location=markers.webm ! decodebin ! videoconvert ! \
 *     frappedetect marker-size=0.05 calibration-file=camera-700.yaml ! \
 *     frappejson max-bytes=0 ! filesink location=markers.jsonl
 * ]| One line per frame, with the poses of 5 cm markers.
 * |[
 * gst-launch-1.0 libcamerasrc ! video/x-raw,format=NV12,width=640,height=480 ! \
 *     frappedetect ! frappejson frame-id=front ! udpsink host=192.168.1.10 port=5001
 * ]| Datagrams of at most 1400 bytes to a host (the host library reads them: docs/streaming.md).
 * |[
 * gst-launch-1.0 videotestsrc ! video/x-raw,format=I420 ! frappedetect annotate=true ! tee name=t \
 *     t. ! queue ! x264enc tune=zerolatency ! h264parse ! mpegtsmux name=mux alignment=7 ! \
 *         udpsink host=192.168.1.10 port=5000 \
 *     t. ! queue ! frappejson ! meta/x-klv,parsed=true ! mux.
 * ]| The annotated video and its markers in one MPEG-TS over UDP.
 */

#include "gstfrappejson.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include <gst/video/video.h>

#include <frappe/marker_record.h>

#include "gstfrappeenums.h"
#include "gstfrappemeta-record.h"
#include "gstfrappemeta.h"

GST_DEBUG_CATEGORY_STATIC(gst_frappe_json_debug);
#define GST_CAT_DEFAULT gst_frappe_json_debug

namespace {

/* The properties' defaults. */
constexpr guint kDefaultMaxBytes = 1400;
constexpr gint kMaxPrecision = 17; /* a double's digits */
const char *const kDefaultFrameId = "camera";

/* Every field of a marker but the id, which is always written. */
guint allFields()
{
	return ((1u << frappe::markerFieldNames().size()) - 1u) & ~1u;
}

/* The KLV key of a marker line (src caps meta/x-klv). */
constexpr char kKlvKey[16] = { 'f', 'r', 'a', 'p', 'p', 'e', '/', 'm', 'a', 'r', 'k', 'e', 'r', 's', '/', '1' };

} /* namespace */

enum { PROP_0, PROP_FRAME_ID, PROP_MAX_BYTES, PROP_PRECISION, PROP_FIELDS };

struct FrappeJsonPrivate {
	/* Under the object lock. */
	std::string frameId = kDefaultFrameId;
	guint maxBytes = kDefaultMaxBytes;
	gint precision = 0;
	guint fields = allFields();

	/* Streaming thread only. */
	gint width = 0, height = 0; /* the caps' */
	bool klv = false;           /* src caps meta/x-klv */
	guint64 count = 0;          /* input buffers since start */
	bool warnedTooSmall = false;
	std::string markers;             /* the frame's markers, one after another */
	std::vector<std::size_t> ends;   /* where each ends in `markers` */
	std::vector<std::size_t> parts;  /* the first marker of each part, then the count */
	std::string bundle;              /* the frame's bundle object, "" for none */
	std::string line;                /* a part's line */
	std::vector<GstBuffer *> output; /* the parts waiting for generate_output */
};

struct _GstFrappeJson {
	GstBaseTransform parent;
	FrappeJsonPrivate *priv;
};

#define gst_frappe_json_parent_class parent_class
G_DEFINE_TYPE(GstFrappeJson, gst_frappe_json, GST_TYPE_BASE_TRANSFORM);
GST_ELEMENT_REGISTER_DEFINE(frappejson, "frappejson", GST_RANK_NONE, GST_TYPE_FRAPPE_JSON);

#define FRAPPE_JSON_CAPS "application/x-json; meta/x-klv, parsed = (boolean) true"

/* What frappedetect's src pad gives. */
#define FRAPPE_VIDEO_CAPS GST_VIDEO_CAPS_MAKE("{ GRAY8, I420, YV12, NV12, NV21 }")

static GstStaticPadTemplate sink_template =
	GST_STATIC_PAD_TEMPLATE("sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS(FRAPPE_VIDEO_CAPS));
static GstStaticPadTemplate src_template =
	GST_STATIC_PAD_TEMPLATE("src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS(FRAPPE_JSON_CAPS));

/* -------------------------------------------------------------------------
 * The line
 */

namespace {

/* A frame's fields, which every part repeats. */
struct FrameHeader {
	guint64 frame = 0;
	std::size_t part = 1, parts = 1;
	GstClockTime pts = GST_CLOCK_TIME_NONE, runningTime = GST_CLOCK_TIME_NONE;
	gint width = 0, height = 0;
	std::string_view frameId;
	std::optional<gint64> captureTime; /* ns since the Unix epoch */
	const char *captureClock = nullptr;
	std::string_view bundle; /* the bundle's JSON object, empty for none */
};

/* A value written as it is (a JSON object); the key is left out when
 * there is none. */
struct RawJson {
	std::string_view text;
};

/* The line's frame fields, in their order: the one list of the keys
 * (docs/streaming.md, "The marker line"). f(key, value) with value an
 * optional integer or an optional string, null when empty, or an optional
 * RawJson, left out when empty. */
template<typename F>
void forEachFrameField(const FrameHeader &h, F &&f)
{
	using Number = std::optional<gint64>;
	using Text = std::optional<std::string_view>;
	const auto time = [](GstClockTime t) { return GST_CLOCK_TIME_IS_VALID(t) ? Number(t) : Number(); };
	f("frame", Number(h.frame));
	f("part", Number(h.part));
	f("parts", Number(h.parts));
	f("pts", time(h.pts));
	f("running_time", time(h.runningTime));
	f("width", Number(h.width));
	f("height", Number(h.height));
	f("frame_id", Text(h.frameId));
	f("capture_time", h.captureTime);
	f("capture_clock", h.captureClock ? Text(h.captureClock) : Text());
	f("bundle", h.bundle.empty() ? std::optional<RawJson>() : std::optional<RawJson>(RawJson{ h.bundle }));
}

/* The frame's fields, then `"markers": [`, which the caller fills and
 * closes with kLineEnd. */
void appendHeader(std::string &out, const FrameHeader &h)
{
	out += '{';
	forEachFrameField(h, [&](std::string_view key, const auto &value) {
		using T = std::remove_cvref_t<decltype(*value)>;
		if constexpr (std::is_same_v<T, RawJson>) {
			if (!value)
				return;
		}
		out += '"';
		out += key;
		out += "\": ";
		if (!value) {
			out += "null";
		} else if constexpr (std::is_same_v<T, RawJson>) {
			out += value->text;
		} else if constexpr (std::is_same_v<T, std::string_view>) {
			frappe::appendJsonString(out, *value);
		} else {
			char text[24];
			const auto r = std::to_chars(text, text + sizeof(text), *value);
			out.append(text, r.ptr);
		}
		out += ", ";
	});
	out += "\"markers\": [";
}
constexpr std::string_view kLineEnd = "]}\n";

/* Nanoseconds from the NTP epoch (1900) to the Unix epoch (1970). */
constexpr guint64 kNtpToUnix = G_GUINT64_CONSTANT(2208988800) * GST_SECOND;

/* The capture time on the wall clock: a reference timestamp the source
 * gave, else the pipeline clock's time of the running time mapped to the
 * real-time clock. */
void captureTime(GstElement *element, GstBuffer *buffer, GstClockTime runningTime, FrameHeader &h)
{
	gpointer state = nullptr;
	while (GstMeta *meta =
		       gst_buffer_iterate_meta_filtered(buffer, &state, GST_REFERENCE_TIMESTAMP_META_API_TYPE)) {
		const auto *ref = reinterpret_cast<GstReferenceTimestampMeta *>(meta);
		const GstStructure *s = gst_caps_get_structure(ref->reference, 0);
		if (!s || !GST_CLOCK_TIME_IS_VALID(ref->timestamp))
			continue;
		if (gst_structure_has_name(s, "timestamp/x-unix")) {
			h.captureTime = static_cast<gint64>(ref->timestamp);
		} else if (gst_structure_has_name(s, "timestamp/x-ntp") && ref->timestamp >= kNtpToUnix) {
			h.captureTime = static_cast<gint64>(ref->timestamp - kNtpToUnix);
		} else {
			continue;
		}
		h.captureClock = "reference";
		return;
	}
	if (!GST_CLOCK_TIME_IS_VALID(runningTime))
		return;
	GstClock *clock = gst_element_get_clock(element);
	if (!clock)
		return;
	const GstClockTime base = gst_element_get_base_time(element);
	const GstClockTime now = gst_clock_get_time(clock);
	const gint64 real = g_get_real_time() * 1000;
	gst_object_unref(clock);
	if (!GST_CLOCK_TIME_IS_VALID(base) || !GST_CLOCK_TIME_IS_VALID(now))
		return;
	h.captureTime = real - (static_cast<gint64>(now) - static_cast<gint64>(base + runningTime));
	h.captureClock = "pipeline";
}

/* A double as the markers' numbers are written (frappe/marker_record.h):
 * the shortest exact text, or `digits` significant digits; null when not
 * finite. */
void appendNumber(std::string &out, double v, int digits)
{
	if (!std::isfinite(v)) {
		out += "null";
		return;
	}
	char text[48];
	const auto r = digits > 0 ? std::to_chars(text, text + sizeof(text), v, std::chars_format::general, digits)
				  : std::to_chars(text, text + sizeof(text), v);
	out.append(text, r.ptr);
}

template<typename T>
void appendArray(std::string &out, const T *v, guint n, int digits)
{
	out += '[';
	for (guint i = 0; i < n; ++i) {
		if (i)
			out += ", ";
		if constexpr (std::is_floating_point_v<T>) {
			appendNumber(out, v[i], digits);
		} else {
			char text[16];
			out.append(text, std::to_chars(text, text + sizeof(text), v[i]).ptr);
		}
	}
	out += ']';
}

/* The buffer's GstFrappeBundleMeta as the line's "bundle" object into
 * `out`, empty when the buffer has none: the meta's fields, in its order. */
void formatBundle(std::string &out, GstBuffer *buffer, int digits)
{
	out.clear();
	const GstFrappeBundleMeta *b = gst_buffer_get_frappe_bundle_meta(buffer);
	if (!b)
		return;
	out += "{\"name\": ";
	frappe::appendJsonString(out, b->name ? b->name : "");
	out += ", \"rvec\": ";
	appendArray(out, b->rvec, 3, digits);
	out += ", \"tvec\": ";
	appendArray(out, b->tvec, 3, digits);
	out += ", \"reprojection_error\": ";
	appendNumber(out, b->reprojection_error, digits);
	out += ", \"used\": ";
	appendArray(out, b->used, b->n_used, digits);
	out += ", \"rejected\": ";
	appendArray(out, b->rejected, b->n_rejected, digits);
	out += '}';
}

/* The buffer's markers into priv->markers, where each ends into
 * priv->ends. */
void formatMarkers(FrappeJsonPrivate &priv, GstBuffer *buffer, const frappe::JsonStyle &style)
{
	priv.markers.clear();
	priv.ends.clear();
	gpointer state = nullptr;
	while (GstMeta *meta = gst_buffer_iterate_meta_filtered(buffer, &state, GST_FRAPPE_MARKER_META_API_TYPE)) {
		const frappe::gst::MetaRecord record(*reinterpret_cast<GstFrappeMarkerMeta *>(meta));
		frappe::appendMarkerJson(priv.markers, record.record(), style);
		priv.ends.push_back(priv.markers.size());
	}
}

/* Splits the markers into parts of lines of at most `maxBytes` (0: no
 * limit): priv->parts gets each part's first marker, then the count.
 * `header` is the longest header of the frame. Returns the length of the
 * longest marker that did not fit alone, 0 when all did. */
std::size_t splitParts(FrappeJsonPrivate &priv, std::size_t header, guint maxBytes)
{
	priv.parts.assign(1, 0);
	const std::size_t n = priv.ends.size();
	const std::size_t fixed = header + kLineEnd.size();
	const std::size_t budget = maxBytes == 0 ? SIZE_MAX : maxBytes > fixed ? maxBytes - fixed : 0;
	std::size_t used = 0, tooLong = 0;
	for (std::size_t i = 0; i < n; ++i) {
		const std::size_t length = priv.ends[i] - (i ? priv.ends[i - 1] : 0);
		const bool first = priv.parts.back() == i;
		if (!first && used + 2 + length > budget) {
			priv.parts.push_back(i);
			used = 0;
		}
		used += (priv.parts.back() == i ? 0 : 2) + length;
		if (length > budget)
			tooLong = std::max(tooLong, fixed + length);
	}
	priv.parts.push_back(n);
	return tooLong;
}

/* Part k's line (0-based) into priv->line: the header, its markers, the end;
 * as a KLV packet when priv->klv. */
void formatPart(FrappeJsonPrivate &priv, FrameHeader &h, std::size_t k)
{
	std::string &out = priv.line;
	out.clear();
	h.part = k + 1;
	h.parts = priv.parts.size() - 1;
	appendHeader(out, h);
	const std::size_t from = priv.parts[k], to = priv.parts[k + 1];
	for (std::size_t i = from; i < to; ++i) {
		const std::size_t a = i ? priv.ends[i - 1] : 0;
		if (i > from)
			out += ", ";
		out.append(priv.markers, a, priv.ends[i] - a);
	}
	out += kLineEnd;
	if (!priv.klv)
		return;
	/* Key, BER length (short form below 128, else 0x80 + its bytes), value. */
	std::string packet(kKlvKey, sizeof(kKlvKey));
	const std::size_t length = out.size();
	if (length < 128) {
		packet += static_cast<char>(length);
	} else {
		int bytes = 0;
		for (std::size_t l = length; l; l >>= 8)
			++bytes;
		packet += static_cast<char>(0x80 | bytes);
		for (int b = bytes - 1; b >= 0; --b)
			packet += static_cast<char>((length >> (8 * b)) & 0xff);
	}
	out.insert(0, packet);
}

} /* namespace */

/* -------------------------------------------------------------------------
 * GstBaseTransform vfuncs
 */

/* Video in, application/x-json or meta/x-klv out, whatever the video's
 * fields. */
static GstCaps *gst_frappe_json_transform_caps(GstBaseTransform *trans, GstPadDirection direction, GstCaps *caps,
					       GstCaps *filter)
{
	GstCaps *json = gst_static_pad_template_get_caps(&src_template);
	GstCaps *out;
	if (direction == GST_PAD_SINK) {
		out = json;
	} else {
		out = gst_caps_can_intersect(caps, json) ? gst_static_pad_template_get_caps(&sink_template)
							 : gst_caps_new_empty();
		gst_caps_unref(json);
	}
	if (filter) {
		GstCaps *both = gst_caps_intersect_full(filter, out, GST_CAPS_INTERSECT_FIRST);
		gst_caps_unref(out);
		out = both;
	}
	GST_DEBUG_OBJECT(trans, "%s %" GST_PTR_FORMAT " -> %" GST_PTR_FORMAT,
			 direction == GST_PAD_SINK ? "sink" : "src", static_cast<void *>(caps),
			 static_cast<void *>(out));
	return out;
}

/* The frame size for the lines, and which of the two src formats. */
static gboolean gst_frappe_json_set_caps(GstBaseTransform *trans, GstCaps *incaps, GstCaps *outcaps)
{
	FrappeJsonPrivate *priv = GST_FRAPPE_JSON(trans)->priv;
	GstVideoInfo info;
	if (!gst_video_info_from_caps(&info, incaps))
		return FALSE;
	priv->width = GST_VIDEO_INFO_WIDTH(&info);
	priv->height = GST_VIDEO_INFO_HEIGHT(&info);
	priv->klv = gst_structure_has_name(gst_caps_get_structure(outcaps, 0), "meta/x-klv");
	return TRUE;
}

static void clear_output(FrappeJsonPrivate *priv)
{
	for (GstBuffer *b : priv->output)
		gst_buffer_unref(b);
	priv->output.clear();
}

/* The buffer's parts into priv->output, as buffers with its timestamps;
 * parts of an earlier frame whose push failed are dropped first. */
static GstFlowReturn format_buffer(GstFrappeJson *self, GstBuffer *input)
{
	FrappeJsonPrivate *priv = self->priv;
	GstBaseTransform *trans = GST_BASE_TRANSFORM(self);
	clear_output(priv);

	GST_OBJECT_LOCK(self);
	const std::string frameId = priv->frameId;
	const guint maxBytes = priv->maxBytes;
	const frappe::JsonStyle style{ frappe::JsonNumbers::Exact, priv->precision, ~priv->fields };
	GST_OBJECT_UNLOCK(self);

	FrameHeader h;
	h.frame = GST_BUFFER_OFFSET_IS_VALID(input) ? GST_BUFFER_OFFSET(input) : priv->count;
	++priv->count;
	h.pts = GST_BUFFER_PTS(input);
	if (GST_CLOCK_TIME_IS_VALID(h.pts) && trans->segment.format == GST_FORMAT_TIME)
		h.runningTime = gst_segment_to_running_time(&trans->segment, GST_FORMAT_TIME, h.pts);
	h.width = priv->width;
	h.height = priv->height;
	h.frameId = frameId;
	captureTime(GST_ELEMENT(self), input, h.runningTime, h);
	formatBundle(priv->bundle, input, style.digits);
	h.bundle = priv->bundle;

	formatMarkers(*priv, input, style);
	/* The longest header: part and parts at most the marker count. */
	h.part = h.parts = std::max<std::size_t>(1, priv->ends.size());
	priv->line.clear();
	appendHeader(priv->line, h);
	const std::size_t tooLong = splitParts(*priv, priv->line.size(), maxBytes);
	if (tooLong && !priv->warnedTooSmall) {
		priv->warnedTooSmall = true;
		GST_ELEMENT_WARNING(self, RESOURCE, SETTINGS,
				    ("max-bytes=%u is less than a line of one marker needs (%zu bytes): such a marker "
				     "is sent alone in its part, longer than max-bytes",
				     maxBytes, tooLong),
				    ("frame %" G_GUINT64_FORMAT "; said once per stream", h.frame));
	}

	for (std::size_t k = 0; k + 1 < priv->parts.size(); ++k) {
		formatPart(*priv, h, k);
		GstBuffer *out = gst_buffer_new_memdup(priv->line.data(), priv->line.size());
		GST_BUFFER_PTS(out) = GST_BUFFER_PTS(input);
		GST_BUFFER_DTS(out) = GST_BUFFER_DTS(input);
		GST_BUFFER_DURATION(out) = GST_BUFFER_DURATION(input);
		GST_BUFFER_OFFSET(out) = GST_BUFFER_OFFSET(input);
		GST_BUFFER_OFFSET_END(out) = GST_BUFFER_OFFSET_END(input);
		if (k == 0 && GST_BUFFER_FLAG_IS_SET(input, GST_BUFFER_FLAG_DISCONT))
			GST_BUFFER_FLAG_SET(out, GST_BUFFER_FLAG_DISCONT);
		GST_LOG_OBJECT(self, "part %zu of %zu: %zu bytes", k + 1, priv->parts.size() - 1, priv->line.size());
		priv->output.push_back(out);
	}
	return GST_FLOW_OK;
}

/* One input buffer, several output buffers: its parts, one per call. */
static GstFlowReturn gst_frappe_json_generate_output(GstBaseTransform *trans, GstBuffer **outbuf)
{
	GstFrappeJson *self = GST_FRAPPE_JSON(trans);
	FrappeJsonPrivate *priv = self->priv;
	*outbuf = nullptr;
	if (trans->queued_buf) {
		GstBuffer *input = trans->queued_buf;
		trans->queued_buf = nullptr;
		const GstFlowReturn ret = format_buffer(self, input);
		gst_buffer_unref(input);
		if (ret != GST_FLOW_OK)
			return ret;
	}
	if (!priv->output.empty()) {
		*outbuf = priv->output.front();
		priv->output.erase(priv->output.begin());
	}
	return GST_FLOW_OK;
}

/* The pixels are never read: any stride will do, so upstream need not copy
 * its frames into GStreamer's default layout. */
static gboolean gst_frappe_json_propose_allocation(GstBaseTransform *, GstQuery *, GstQuery *query)
{
	gst_query_add_allocation_meta(query, GST_VIDEO_META_API_TYPE, nullptr);
	return TRUE;
}

static gboolean gst_frappe_json_start(GstBaseTransform *trans)
{
	FrappeJsonPrivate *priv = GST_FRAPPE_JSON(trans)->priv;
	priv->count = 0;
	priv->warnedTooSmall = false;
	return TRUE;
}

static gboolean gst_frappe_json_stop(GstBaseTransform *trans)
{
	clear_output(GST_FRAPPE_JSON(trans)->priv);
	return TRUE;
}

/* -------------------------------------------------------------------------
 * GObject
 */

static void gst_frappe_json_set_property(GObject *object, guint prop_id, const GValue *value, GParamSpec *pspec)
{
	FrappeJsonPrivate *priv = GST_FRAPPE_JSON(object)->priv;
	GST_OBJECT_LOCK(object);
	switch (prop_id) {
	case PROP_FRAME_ID: {
		const gchar *id = g_value_get_string(value);
		priv->frameId = id ? id : "";
		break;
	}
	case PROP_MAX_BYTES: priv->maxBytes = g_value_get_uint(value); break;
	case PROP_PRECISION: priv->precision = g_value_get_int(value); break;
	case PROP_FIELDS: priv->fields = g_value_get_flags(value); break;
	default: G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec); break;
	}
	GST_OBJECT_UNLOCK(object);
}

static void gst_frappe_json_get_property(GObject *object, guint prop_id, GValue *value, GParamSpec *pspec)
{
	FrappeJsonPrivate *priv = GST_FRAPPE_JSON(object)->priv;
	GST_OBJECT_LOCK(object);
	switch (prop_id) {
	case PROP_FRAME_ID: g_value_set_string(value, priv->frameId.c_str()); break;
	case PROP_MAX_BYTES: g_value_set_uint(value, priv->maxBytes); break;
	case PROP_PRECISION: g_value_set_int(value, priv->precision); break;
	case PROP_FIELDS: g_value_set_flags(value, priv->fields); break;
	default: G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec); break;
	}
	GST_OBJECT_UNLOCK(object);
}

static void gst_frappe_json_finalize(GObject *object)
{
	FrappeJsonPrivate *priv = GST_FRAPPE_JSON(object)->priv;
	clear_output(priv);
	delete priv;
	G_OBJECT_CLASS(parent_class)->finalize(object);
}

static void gst_frappe_json_init(GstFrappeJson *self)
{
	self->priv = new FrappeJsonPrivate();
	gst_base_transform_set_in_place(GST_BASE_TRANSFORM(self), FALSE);
	gst_base_transform_set_passthrough(GST_BASE_TRANSFORM(self), FALSE);
}

static void gst_frappe_json_class_init(GstFrappeJsonClass *klass)
{
	GObjectClass *gobject_class = G_OBJECT_CLASS(klass);
	GstElementClass *element_class = GST_ELEMENT_CLASS(klass);
	GstBaseTransformClass *trans_class = GST_BASE_TRANSFORM_CLASS(klass);

	GST_DEBUG_CATEGORY_INIT(gst_frappe_json_debug, "frappejson", 0, "Frappe markers as JSON lines");

	gobject_class->set_property = gst_frappe_json_set_property;
	gobject_class->get_property = gst_frappe_json_get_property;
	gobject_class->finalize = gst_frappe_json_finalize;

	const auto flags =
		static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS | GST_PARAM_MUTABLE_PLAYING);
	/**
	 * GstFrappeJson:frame-id:
	 *
	 * The camera's name in every line's `frame_id`, the frame the poses are
	 * in (ROS's `header.frame_id`).
	 *
	 * Since: 0.3
	 */
	g_object_class_install_property(
		gobject_class, PROP_FRAME_ID,
		g_param_spec_string("frame-id", "Frame id",
				    "The camera's name in each line's frame_id (the frame the poses are in)",
				    kDefaultFrameId, flags));
	/**
	 * GstFrappeJson:max-bytes:
	 *
	 * The longest line: a frame whose markers do not fit is split into
	 * parts ("part", "parts"), each marker whole in one. 1400 fits an
	 * Ethernet frame's UDP payload (1472) with room for a tunnel's header;
	 * 0 is no limit (one line per frame). A marker too long for a line of
	 * its own is sent alone, longer (one warning per stream).
	 *
	 * Since: 0.3
	 */
	g_object_class_install_property(
		gobject_class, PROP_MAX_BYTES,
		g_param_spec_uint("max-bytes", "Max bytes",
				  "The longest line in bytes: a frame's markers are split into parts of at most "
				  "this (0 = one line per frame, whatever its length)",
				  0, G_MAXINT, kDefaultMaxBytes, flags));
	/**
	 * GstFrappeJson:precision:
	 *
	 * Significant digits of the corners, margin, poses and errors: 0 (the
	 * default) writes the digits that read back the exact value.
	 *
	 * Since: 0.3
	 */
	g_object_class_install_property(
		gobject_class, PROP_PRECISION,
		g_param_spec_int("precision", "Precision",
				 "Significant digits of the numbers (corners, margin, poses, errors); 0 = the "
				 "digits that read back the exact value",
				 0, kMaxPrecision, 0, flags));
	/**
	 * GstFrappeJson:fields:
	 *
	 * The marker fields written, from frappe/marker_record.h's list (the id
	 * always is): e.g. `fields=corners+rvec+tvec`. A field a marker does not
	 * have (the pose's without a pose) is not written either way.
	 *
	 * Since: 0.3
	 */
	g_object_class_install_property(
		gobject_class, PROP_FIELDS,
		g_param_spec_flags("fields", "Fields",
				   "The marker fields written besides the id (e.g. corners+rvec+tvec)",
				   GST_TYPE_FRAPPE_JSON_FIELDS, allFields(), flags));

	gst_element_class_set_static_metadata(element_class, "Frappe markers as JSON", "Formatter/Metadata",
					      "Lines of JSON per frame: the markers frappedetect found, their poses "
					      "and the frame's number and times",
					      "The Frappe authors");
	gst_element_class_add_static_pad_template(element_class, &sink_template);
	gst_element_class_add_static_pad_template(element_class, &src_template);

	trans_class->passthrough_on_same_caps = FALSE;
	trans_class->transform_caps = GST_DEBUG_FUNCPTR(gst_frappe_json_transform_caps);
	trans_class->set_caps = GST_DEBUG_FUNCPTR(gst_frappe_json_set_caps);
	trans_class->generate_output = GST_DEBUG_FUNCPTR(gst_frappe_json_generate_output);
	trans_class->propose_allocation = GST_DEBUG_FUNCPTR(gst_frappe_json_propose_allocation);
	trans_class->start = GST_DEBUG_FUNCPTR(gst_frappe_json_start);
	trans_class->stop = GST_DEBUG_FUNCPTR(gst_frappe_json_stop);

	gst_type_mark_as_plugin_api(GST_TYPE_FRAPPE_JSON_FIELDS, static_cast<GstPluginAPIFlags>(0));
}
