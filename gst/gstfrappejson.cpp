/* SPDX-License-Identifier: MIT
 *
 * gstfrappejson.cpp: the frappejson element.
 */

/**
 * SECTION:element-frappejson
 * @title: frappejson
 *
 * Turns each video buffer coming out of frappedetect into one line of JSON
 * describing its markers, read from the #GstFrappeMarkerMeta on the buffer;
 * the pixels are never mapped or read. For files, sockets and applications
 * that want the markers without linking to GStreamer.
 *
 * Sink caps: `video/x-raw` in any format frappedetect outputs (GRAY8, I420,
 * YV12, NV12, NV21), any size and frame rate. Src caps: `application/x-json`,
 * no fields. Each output buffer is one line ending in "\n":
 *
 * |[
 * {"pts": 33333333, "markers": [{"id": 7, "dictionary": "aruco_mip_36h12",
 *  "corners": [[x0, y0], [x1, y1], [x2, y2], [x3, y3]], "hamming": 0,
 *  "margin": 0.93, "rvec": [rx, ry, rz], "tvec": [tx, ty, tz],
 *  "reprojection_error": 0.05, "alternative_reprojection_error": 2.1}]}
 * ]|
 *
 * (on a single line). `pts` is the buffer's presentation time in
 * nanoseconds, `null` when it has none. Markers are in the order of their
 * metas, with the fields of #GstFrappeMarkerMeta; `rvec`, `tvec` and the
 * two reprojection errors only when the pose is known. Numbers are written
 * with the digits that give back the meta's value exactly (float corners,
 * double poses); a value that is not finite (an alternative error of
 * infinity: there was no other solution) is written `null`. A buffer
 * without marker metas gives `"markers": []`.
 *
 * Every input buffer gives exactly one output buffer, in order, with the
 * input's PTS, DTS, duration, offsets and DISCONT flag. Events (stream-start,
 * segment, EOS, ...) pass through; the caps event carries
 * `application/x-json`. With udpsink each line is one datagram; with
 * filesink, fdsink or tcpserversink the lines follow each other.
 *
 * ## Example launch lines
 * |[
 * gst-launch-1.0 filesrc location=markers.webm ! decodebin ! videoconvert ! \
 *     frappedetect marker-size=0.05 calibration-file=camera-700.yaml ! \
 *     frappejson ! filesink location=markers.jsonl
 * ]| One line per frame, with the poses of 5 cm markers.
 * |[
 * gst-launch-1.0 libcamerasrc ! video/x-raw,format=NV12,width=640,height=480 ! \
 *     frappedetect ! frappejson ! udpsink host=192.168.1.10 port=5001
 * ]| One datagram per frame to a host (examples/receive-markers.py reads them).
 */

#include "gstfrappejson.h"

#include <charconv>
#include <string>

#include <gst/video/video.h>

#include "gstfrappemeta-record.h"
#include "gstfrappemeta.h"

GST_DEBUG_CATEGORY_STATIC(gst_frappe_json_debug);
#define GST_CAT_DEFAULT gst_frappe_json_debug

struct FrappeJsonPrivate {
	std::string line; /* the frame's line, its capacity reused */
};

struct _GstFrappeJson {
	GstBaseTransform parent;
	FrappeJsonPrivate *priv;
};

#define gst_frappe_json_parent_class parent_class
G_DEFINE_TYPE(GstFrappeJson, gst_frappe_json, GST_TYPE_BASE_TRANSFORM);
GST_ELEMENT_REGISTER_DEFINE(frappejson, "frappejson", GST_RANK_NONE, GST_TYPE_FRAPPE_JSON);

#define FRAPPE_JSON_CAPS "application/x-json"

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

/* A meta as the library's marker record, written by its one JSON writer
 * (frappe/marker_record.h): the fields every output has, in one order. */
void appendMarker(std::string &out, const GstFrappeMarkerMeta &m)
{
	frappe::appendMarkerJson(out, frappe::gst::MetaRecord(m).record(), frappe::JsonNumbers::Exact);
}

/* The buffer's line, into `out`. */
void formatLine(std::string &out, GstBuffer *buffer)
{
	out.clear();
	out += "{\"pts\": ";
	if (GST_BUFFER_PTS_IS_VALID(buffer)) {
		char text[24];
		const auto r = std::to_chars(text, text + sizeof(text), static_cast<guint64>(GST_BUFFER_PTS(buffer)));
		out.append(text, r.ptr);
	} else
		out += "null";
	out += ", \"markers\": [";
	gpointer state = nullptr;
	bool first = true;
	while (GstMeta *meta = gst_buffer_iterate_meta_filtered(buffer, &state, GST_FRAPPE_MARKER_META_API_TYPE)) {
		if (!first)
			out += ", ";
		first = false;
		appendMarker(out, *reinterpret_cast<GstFrappeMarkerMeta *>(meta));
	}
	out += "]}\n";
}

} /* namespace */

/* -------------------------------------------------------------------------
 * GstBaseTransform vfuncs
 */

/* Video in, application/x-json out, whatever the video's fields. */
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

/* The output buffer is sized to the line, so it is made here rather than
 * from a pool of fixed-size buffers. */
static GstFlowReturn gst_frappe_json_prepare_output_buffer(GstBaseTransform *trans, GstBuffer *input,
							   GstBuffer **output)
{
	GstFrappeJson *self = GST_FRAPPE_JSON(trans);
	std::string &line = self->priv->line;
	formatLine(line, input);

	*output = gst_buffer_new_allocate(nullptr, line.size(), nullptr);
	if (!*output) {
		GST_ELEMENT_ERROR(self, RESOURCE, FAILED, ("Could not allocate %zu bytes", line.size()), (nullptr));
		return GST_FLOW_ERROR;
	}
	GST_BUFFER_PTS(*output) = GST_BUFFER_PTS(input);
	GST_BUFFER_DTS(*output) = GST_BUFFER_DTS(input);
	GST_BUFFER_DURATION(*output) = GST_BUFFER_DURATION(input);
	GST_BUFFER_OFFSET(*output) = GST_BUFFER_OFFSET(input);
	GST_BUFFER_OFFSET_END(*output) = GST_BUFFER_OFFSET_END(input);
	if (GST_BUFFER_FLAG_IS_SET(input, GST_BUFFER_FLAG_DISCONT))
		GST_BUFFER_FLAG_SET(*output, GST_BUFFER_FLAG_DISCONT);
	return GST_FLOW_OK;
}

static GstFlowReturn gst_frappe_json_transform(GstBaseTransform *trans, GstBuffer *, GstBuffer *output)
{
	const std::string &line = GST_FRAPPE_JSON(trans)->priv->line;
	gst_buffer_fill(output, 0, line.data(), line.size());
	GST_LOG_OBJECT(trans, "%.*s", static_cast<int>(line.size()) - 1, line.c_str());
	return GST_FLOW_OK;
}

/* The pixels are never read: any stride will do, so upstream need not copy
 * its frames into GStreamer's default layout. */
static gboolean gst_frappe_json_propose_allocation(GstBaseTransform *, GstQuery *, GstQuery *query)
{
	gst_query_add_allocation_meta(query, GST_VIDEO_META_API_TYPE, nullptr);
	return TRUE;
}

/* -------------------------------------------------------------------------
 * GObject
 */

static void gst_frappe_json_finalize(GObject *object)
{
	delete GST_FRAPPE_JSON(object)->priv;
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

	gobject_class->finalize = gst_frappe_json_finalize;

	gst_element_class_set_static_metadata(element_class, "Frappe markers as JSON", "Formatter/Metadata",
					      "One line of JSON per frame: the markers frappedetect found and "
					      "their poses",
					      "The Frappe authors");
	gst_element_class_add_static_pad_template(element_class, &sink_template);
	gst_element_class_add_static_pad_template(element_class, &src_template);

	trans_class->passthrough_on_same_caps = FALSE;
	trans_class->transform_caps = GST_DEBUG_FUNCPTR(gst_frappe_json_transform_caps);
	trans_class->prepare_output_buffer = GST_DEBUG_FUNCPTR(gst_frappe_json_prepare_output_buffer);
	trans_class->transform = GST_DEBUG_FUNCPTR(gst_frappe_json_transform);
	trans_class->propose_allocation = GST_DEBUG_FUNCPTR(gst_frappe_json_propose_allocation);
}
