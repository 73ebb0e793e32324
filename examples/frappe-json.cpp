// SPDX-License-Identifier: MIT
//
// frappe-json: runs a pipeline ending in frappedetect ! appsink and prints
// every frame's markers as JSON lines, twice: once from the
// GstFrappeMarkerMeta on the buffers ("source": "meta") and once from the
// frappedetect bus messages ("source": "message").
//
//   frappe-json                      the shipped sample video
//   frappe-json VIDEO-FILE           any file decodebin can read
//   frappe-json -p 'PIPELINE'        a pipeline with an appsink named "sink"
//
// Lines look like
//   {"source": "meta", "pts": 33333333, "markers": [{"id": 7, "dictionary": "aruco_mip_36h12",
//    "corners": [[x0, y0], [x1, y1], [x2, y2], [x3, y3]], "hamming": 0, "margin": 0.93}]}
// with "rvec", "tvec" (metres) and the reprojection errors added when the
// element knows the marker size and the camera matrix: each marker as the
// library's one writer makes it (frappe/marker_record.h), as frappejson and
// frappe-detect write theirs.
#include <cstdio>
#include <cstring>
#include <string>

#include <gst/app/gstappsink.h>
#include <gst/gst.h>

#include <gstfrappemeta.h>
#include <gstfrappemeta-record.h>

namespace {

/* The meta's marker in the library's record (gstfrappemeta-record.h),
 * written by the one JSON writer frappejson and frappe-detect use too. */
void appendMeta(std::string &out, const GstFrappeMarkerMeta &m)
{
	frappe::appendMarkerJson(out, frappe::gst::MetaRecord(m).record(), frappe::JsonNumbers::Exact);
}

std::string timeOrNull(guint64 t)
{
	return GST_CLOCK_TIME_IS_VALID(t) ? std::to_string(t) : "null";
}

std::string fromMeta(GstBuffer *buf)
{
	std::string out = "{\"source\": \"meta\", \"pts\": " + timeOrNull(GST_BUFFER_PTS(buf)) + ", \"markers\": [";
	gpointer state = nullptr;
	bool first = true;
	while (GstMeta *meta = gst_buffer_iterate_meta_filtered(buf, &state, GST_FRAPPE_MARKER_META_API_TYPE)) {
		out += first ? "" : ", ";
		first = false;
		appendMeta(out, *reinterpret_cast<const GstFrappeMarkerMeta *>(meta));
	}
	return out + "]}";
}

double arrayValue(const GstStructure *s, const char *field, guint i)
{
	const GValue *array = gst_structure_get_value(s, field);
	return array && i < gst_value_array_get_size(array) ? g_value_get_double(gst_value_array_get_value(array, i))
							    : 0.0;
}

/* The message's marker: the same record, from the structure's fields
 * (the list's names in kebab-case). */
void appendMessageMarker(std::string &out, const GstStructure *m)
{
	frappe::Marker marker;
	guint hamming = 0;
	gdouble margin = 0.0;
	gst_structure_get_int(m, "id", &marker.id);
	gst_structure_get_uint(m, "hamming", &hamming);
	gst_structure_get_double(m, "margin", &margin);
	marker.hamming = static_cast<int>(hamming);
	marker.margin = static_cast<float>(margin);
	for (guint k = 0; k < 4; ++k)
		marker.corners[k] = { static_cast<float>(arrayValue(m, "corners", 2 * k)),
				      static_cast<float>(arrayValue(m, "corners", 2 * k + 1)) };
	frappe::MarkerPose pose;
	const bool hasPose = gst_structure_has_field(m, "tvec");
	for (guint k = 0; k < 3; ++k) {
		pose.pose.rvec[k] = arrayValue(m, "rvec", k);
		pose.pose.tvec[k] = arrayValue(m, "tvec", k);
	}
	gst_structure_get_double(m, "reprojection-error", &pose.pose.error);
	gst_structure_get_double(m, "alternative-reprojection-error", &pose.alternative.error);
	const char *dict = gst_structure_get_string(m, "dictionary");
	frappe::appendMarkerJson(out, { &marker, dict ? dict : "", hasPose ? &pose : nullptr },
				 frappe::JsonNumbers::Exact);
}

std::string fromMessage(const GstStructure *s)
{
	guint64 ts = GST_CLOCK_TIME_NONE, rt = GST_CLOCK_TIME_NONE;
	gst_structure_get_uint64(s, "timestamp", &ts);
	gst_structure_get_uint64(s, "running-time", &rt);
	std::string out = "{\"source\": \"message\", \"timestamp\": " + timeOrNull(ts) +
			  ", \"running_time\": " + timeOrNull(rt) + ", \"markers\": [";
	const GValue *markers = gst_structure_get_value(s, "markers");
	const guint n = markers ? gst_value_list_get_size(markers) : 0;
	for (guint i = 0; i < n; ++i) {
		out += i ? ", " : "";
		appendMessageMarker(out, gst_value_get_structure(gst_value_list_get_value(markers, i)));
	}
	return out + "]}";
}

/* Prints pending frappedetect messages; false on EOS or error. */
bool drainBus(GstBus *bus, int &rc)
{
	GstMessage *msg;
	bool running = true;
	while ((msg = gst_bus_pop(bus))) {
		switch (GST_MESSAGE_TYPE(msg)) {
		case GST_MESSAGE_ELEMENT: {
			const GstStructure *s = gst_message_get_structure(msg);
			if (s && gst_structure_has_name(s, "frappedetect"))
				std::printf("%s\n", fromMessage(s).c_str());
			break;
		}
		case GST_MESSAGE_ERROR: {
			GError *e = nullptr;
			gchar *dbg = nullptr;
			gst_message_parse_error(msg, &e, &dbg);
			std::fprintf(stderr, "frappe-json: %s\n%s\n", e->message, dbg ? dbg : "");
			g_error_free(e);
			g_free(dbg);
			rc = 1;
			running = false;
			break;
		}
		case GST_MESSAGE_EOS:
			running = false;
			break;
		default:
			break;
		}
		gst_message_unref(msg);
	}
	return running;
}

} // namespace

int main(int argc, char **argv)
{
	gst_init(&argc, &argv);

	std::string launch;
	if (argc > 2 && std::strcmp(argv[1], "-p") == 0) {
		launch = argv[2];
	} else {
		const std::string file = argc > 1 ? argv[1] : FRAPPE_SAMPLE_VIDEO;
		launch = "filesrc location=\"" + file +
			 "\" ! decodebin ! videoconvert ! video/x-raw,format=I420 ! frappedetect ! "
			 "appsink name=sink sync=false";
	}

	GError *err = nullptr;
	GstElement *pipeline = gst_parse_launch(launch.c_str(), &err);
	if (!pipeline || err) {
		std::fprintf(stderr, "frappe-json: %s\n", err ? err->message : "bad pipeline");
		return 1;
	}
	GstElement *sink = gst_bin_get_by_name(GST_BIN(pipeline), "sink");
	if (!sink || !GST_IS_APP_SINK(sink)) {
		std::fprintf(stderr, "frappe-json: the pipeline needs an appsink named \"sink\"\n");
		return 1;
	}
	GstBus *bus = gst_element_get_bus(pipeline);
	gst_element_set_state(pipeline, GST_STATE_PLAYING);

	int rc = 0;
	bool running = true;
	while (running) {
		GstSample *sample = gst_app_sink_try_pull_sample(GST_APP_SINK(sink), 100 * GST_MSECOND);
		if (sample) {
			std::printf("%s\n", fromMeta(gst_sample_get_buffer(sample)).c_str());
			gst_sample_unref(sample);
		}
		running = drainBus(bus, rc);
		if (!sample && gst_app_sink_is_eos(GST_APP_SINK(sink))) {
			/* The EOS message follows the last element messages. */
			GstMessage *msg = gst_bus_timed_pop_filtered(bus, 5 * GST_SECOND,
								     static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
			if (msg) {
				gst_bus_post(bus, msg); /* drainBus sees it after the rest */
			}
			drainBus(bus, rc);
			running = false;
		}
		std::fflush(stdout);
	}

	gst_element_set_state(pipeline, GST_STATE_NULL);
	gst_object_unref(bus);
	gst_object_unref(sink);
	gst_object_unref(pipeline);
	return rc;
}
