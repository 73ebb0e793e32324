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
//   {"source":"meta","pts":33333333,"markers":[{"id":7,"dictionary":"aruco_mip_36h12",
//    "corners":[[x0,y0],[x1,y1],[x2,y2],[x3,y3]],"hamming":0}]}
// with "rvec", "tvec" (metres) and "reprojection_error" added when the
// element knows the marker size and the camera matrix.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include <gst/app/gstappsink.h>
#include <gst/gst.h>

#include <gstfrappemeta.h>

namespace {

std::string number(double v)
{
	if (!std::isfinite(v))
		return "null";
	char buf[32];
	std::snprintf(buf, sizeof(buf), "%.4f", v);
	return buf;
}

std::string vec3(const double *v)
{
	std::string out = "[";
	for (int i = 0; i < 3; ++i) {
		if (i)
			out += ',';
		out += number(v[i]);
	}
	out += ']';
	return out;
}

std::string fromMeta(GstBuffer *buf)
{
	std::string out = "{\"source\":\"meta\",\"pts\":" +
			  (GST_BUFFER_PTS_IS_VALID(buf) ? std::to_string(GST_BUFFER_PTS(buf)) : "null") +
			  ",\"markers\":[";
	gpointer state = nullptr;
	GstMeta *meta;
	bool first = true;
	while ((meta = gst_buffer_iterate_meta_filtered(buf, &state, GST_FRAPPE_MARKER_META_API_TYPE))) {
		const auto *m = reinterpret_cast<const GstFrappeMarkerMeta *>(meta);
		out += first ? "" : ",";
		first = false;
		out += "{\"id\":" + std::to_string(m->id) + ",\"dictionary\":\"" +
		       (m->dictionary ? m->dictionary : "") + "\",\"corners\":[";
		for (int k = 0; k < 4; ++k)
		{
			out += k ? ",[" : "[";
			out += number(m->corners[2 * k]);
			out += ',';
			out += number(m->corners[2 * k + 1]);
			out += ']';
		}
		out += "],\"hamming\":" + std::to_string(m->hamming);
		if (m->has_pose)
			out += ",\"rvec\":" + vec3(m->rvec) + ",\"tvec\":" + vec3(m->tvec) +
			       ",\"reprojection_error\":" + number(m->reprojection_error) +
			       ",\"alternative_reprojection_error\":" + number(m->alternative_reprojection_error);
		out += "}";
	}
	return out + "]}";
}

std::string doubles(const GValue *array, int group)
{
	std::string out = "[";
	const guint n = gst_value_array_get_size(array);
	for (guint i = 0; i < n; ++i) {
		if (group > 1 && i % static_cast<guint>(group) == 0)
			out += i ? ",[" : "[";
		else if (i)
			out += ",";
		out += number(g_value_get_double(gst_value_array_get_value(array, i)));
		if (group > 1 && i % static_cast<guint>(group) == static_cast<guint>(group - 1))
			out += "]";
	}
	return out + "]";
}

std::string fromMessage(const GstStructure *s)
{
	guint64 ts = GST_CLOCK_TIME_NONE, rt = GST_CLOCK_TIME_NONE;
	gst_structure_get_uint64(s, "timestamp", &ts);
	gst_structure_get_uint64(s, "running-time", &rt);
	std::string out = "{\"source\":\"message\",\"timestamp\":" +
			  (GST_CLOCK_TIME_IS_VALID(ts) ? std::to_string(ts) : "null") + ",\"running_time\":" +
			  (GST_CLOCK_TIME_IS_VALID(rt) ? std::to_string(rt) : "null") + ",\"markers\":[";
	const GValue *markers = gst_structure_get_value(s, "markers");
	const guint n = markers ? gst_value_list_get_size(markers) : 0;
	for (guint i = 0; i < n; ++i) {
		const GstStructure *m = gst_value_get_structure(gst_value_list_get_value(markers, i));
		int id = -1;
		guint hamming = 0;
		gst_structure_get_int(m, "id", &id);
		gst_structure_get_uint(m, "hamming", &hamming);
		const char *dict = gst_structure_get_string(m, "dictionary");
		out += i ? ",{" : "{";
		out += "\"id\":" + std::to_string(id) + ",\"dictionary\":\"" +
		       (dict ? dict : "") + "\",\"corners\":" + doubles(gst_structure_get_value(m, "corners"), 2) +
		       ",\"hamming\":" + std::to_string(hamming);
		if (gst_structure_has_field(m, "tvec")) {
			double err = 0, alt = 0;
			gst_structure_get_double(m, "reprojection-error", &err);
			gst_structure_get_double(m, "alternative-reprojection-error", &alt);
			out += ",\"rvec\":" + doubles(gst_structure_get_value(m, "rvec"), 1) +
			       ",\"tvec\":" + doubles(gst_structure_get_value(m, "tvec"), 1) +
			       ",\"reprojection_error\":" + number(err) + ",\"alternative_reprojection_error\":" + number(alt);
		}
		out += "}";
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
