/* SPDX-License-Identifier: MIT
 *
 * gstfrappeoutput.cpp: frappedetect's metas, message and statistics.
 */
#include "gstfrappeoutput.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>
#include <type_traits>
#include <utility>

#include <gst/video/video.h>

#include <frappe/marker_record.h>

#include "gstfrappemeta.h"

GST_DEBUG_CATEGORY_EXTERN(gst_frappe_detect_debug);
#define GST_CAT_DEFAULT gst_frappe_detect_debug

namespace frappe::gst {

namespace {

void addDoubleArray(GstStructure *s, const char *field, const double *v, int n)
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

/* A field name of the library's list in GStreamer's kebab-case. */
const char *kebab(std::string_view name)
{
	std::string k(name);
	std::replace(k.begin(), k.end(), '_', '-');
	return g_intern_string(k.c_str());
}

/* Adds the fields of frappe::forEachMarkerField() to `s`, the arrays only
 * when `arrays` (an ROI's parameters are the scalars). */
void addMarkerFields(GstStructure *s, const frappe::MarkerRecord &r, bool arrays)
{
	frappe::forEachMarkerField(r, [&](std::string_view name, const auto &value) {
		using T = std::remove_cvref_t<decltype(value)>;
		const char *field = kebab(name);
		if constexpr (std::is_same_v<T, std::string_view>) {
			const std::string text(value);
			gst_structure_set(s, field, G_TYPE_STRING, text.c_str(), nullptr);
		} else if constexpr (std::is_same_v<T, frappe::Count>) {
			gst_structure_set(s, field, G_TYPE_UINT, static_cast<guint>(value.value), nullptr);
		} else if constexpr (std::is_same_v<T, bool>) {
			gst_structure_set(s, field, G_TYPE_BOOLEAN, value ? TRUE : FALSE, nullptr);
		} else if constexpr (std::is_same_v<T, int>) {
			gst_structure_set(s, field, G_TYPE_INT, value, nullptr);
		} else if constexpr (std::is_floating_point_v<T>) {
			gst_structure_set(s, field, G_TYPE_DOUBLE, static_cast<gdouble>(value), nullptr);
		} else if constexpr (std::is_same_v<T, std::array<Point2f, 4>>) {
			if (!arrays)
				return;
			double corners[8];
			for (std::size_t k = 0; k < 4; ++k) {
				corners[2 * k] = value[k].x;
				corners[2 * k + 1] = value[k].y;
			}
			addDoubleArray(s, field, corners, 8);
		} else {
			if (arrays)
				addDoubleArray(s, field, value.data(), static_cast<int>(value.size()));
		}
	});
}

void addIntArray(GstStructure *s, const char *field, const std::vector<int> &v)
{
	GValue array = G_VALUE_INIT;
	gst_value_array_init(&array, static_cast<guint>(v.size()));
	for (int x : v) {
		GValue item = G_VALUE_INIT;
		g_value_init(&item, G_TYPE_INT);
		g_value_set_int(&item, x);
		gst_value_array_append_and_take_value(&array, &item);
	}
	gst_structure_take_value(s, field, &array);
}

/* The message's bundle: the meta's fields (GstFrappeBundleMeta). */
GstStructure *bundleStructure(const frappe::Bundle &b, const frappe::BundlePose &p)
{
	GstStructure *s = gst_structure_new("bundle", "name", G_TYPE_STRING, b.name.c_str(), nullptr);
	addDoubleArray(s, "rvec", p.pose.rvec.data(), 3);
	addDoubleArray(s, "tvec", p.pose.tvec.data(), 3);
	gst_structure_set(s, "reprojection-error", G_TYPE_DOUBLE, p.pose.error, nullptr);
	addIntArray(s, "used", p.used);
	addIntArray(s, "rejected", p.rejected);
	return s;
}

/* The message's marker: every field of the library's list. */
GstStructure *markerStructure(const Marker &m, const std::optional<frappe::MarkerPose> &pose,
			      const char *dictionary)
{
	GstStructure *ms = gst_structure_new_empty("marker");
	addMarkerFields(ms, { &m, dictionary, pose ? &*pose : nullptr, true }, true);
	return ms;
}

} /* namespace */

void attachMarkerMetas(GstBuffer *buffer, gint width, gint height, const Result &result, const Poses &poses,
		       const char *dictionary, bool tracking)
{
	for (std::size_t i = 0; i < result.markers.size(); ++i) {
		const Marker &m = result.markers[i];
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
		GstFrappeMarkerMeta *meta = gst_buffer_add_frappe_marker_meta(buffer, m.id, dictionary, corners,
									      static_cast<guint>(m.hamming));
		if (meta) {
			meta->margin = m.margin;
			meta->tracking = tracking;
			meta->tracked = tracking && m.tracked;
		}
		if (meta && poses[i]) {
			meta->has_pose = TRUE;
			for (int k = 0; k < 3; ++k) {
				meta->rvec[k] = poses[i]->pose.rvec[static_cast<std::size_t>(k)];
				meta->tvec[k] = poses[i]->pose.tvec[static_cast<std::size_t>(k)];
			}
			meta->reprojection_error = poses[i]->pose.error;
			meta->alternative_reprojection_error = poses[i]->alternative.error;
		}

		/* The ROI covers the pixels the corners touch, clipped to the frame. */
		const gint x0 = std::clamp(static_cast<gint>(std::floor(minX + 0.5f)), 0, width - 1);
		const gint y0 = std::clamp(static_cast<gint>(std::floor(minY + 0.5f)), 0, height - 1);
		const gint x1 = std::clamp(static_cast<gint>(std::ceil(maxX + 0.5f)), x0 + 1, width);
		const gint y1 = std::clamp(static_cast<gint>(std::ceil(maxY + 0.5f)), y0 + 1, height);
		GstVideoRegionOfInterestMeta *roi = gst_buffer_add_video_region_of_interest_meta(
			buffer, GST_FRAPPE_ROI_TYPE, static_cast<guint>(x0), static_cast<guint>(y0),
			static_cast<guint>(x1 - x0), static_cast<guint>(y1 - y0));
		if (roi) {
			roi->id = static_cast<gint>(i);
			GstStructure *param = gst_structure_new_empty(GST_FRAPPE_ROI_TYPE);
			addMarkerFields(param, { &m, dictionary, nullptr }, false);
			gst_video_region_of_interest_meta_add_param(roi, param);
		}
	}
}

void attachBundleMeta(GstBuffer *buffer, const BundleOutput &bundle)
{
	if (!bundle.pose)
		return;
	const frappe::BundlePose &p = *bundle.pose;
	gst_buffer_add_frappe_bundle_meta(buffer, bundle.bundle->name.c_str(), p.pose.rvec.data(), p.pose.tvec.data(),
					  p.pose.error, p.used.data(), static_cast<guint>(p.used.size()),
					  p.rejected.data(), static_cast<guint>(p.rejected.size()));
}

GstStructure *frameMessage(GstBuffer *buffer, const GstSegment &segment, const Result &result, const Poses &poses,
			   const char *dictionary, const BundleOutput &bundle)
{
	GValue list = G_VALUE_INIT;
	g_value_init(&list, GST_TYPE_LIST);
	for (std::size_t i = 0; i < result.markers.size(); ++i) {
		GValue item = G_VALUE_INIT;
		g_value_init(&item, GST_TYPE_STRUCTURE);
		g_value_take_boxed(&item, markerStructure(result.markers[i], poses[i], dictionary));
		gst_value_list_append_and_take_value(&list, &item);
	}

	const GstClockTime pts = GST_BUFFER_PTS(buffer);
	GstClockTime running = GST_CLOCK_TIME_NONE, stream = GST_CLOCK_TIME_NONE;
	if (segment.format == GST_FORMAT_TIME) {
		running = gst_segment_to_running_time(&segment, GST_FORMAT_TIME, pts);
		stream = gst_segment_to_stream_time(&segment, GST_FORMAT_TIME, pts);
	}
	GstStructure *msg = gst_structure_new("frappedetect", "timestamp", G_TYPE_UINT64, pts, "stream-time",
					      G_TYPE_UINT64, stream, "running-time", G_TYPE_UINT64, running,
					      "duration", G_TYPE_UINT64, GST_BUFFER_DURATION(buffer), nullptr);
	gst_structure_take_value(msg, "markers", &list);
	if (bundle.pose) {
		GValue item = G_VALUE_INIT;
		g_value_init(&item, GST_TYPE_STRUCTURE);
		g_value_take_boxed(&item, bundleStructure(*bundle.bundle, *bundle.pose));
		gst_structure_take_value(msg, "bundle", &item);
	}
	return msg;
}

void reportDroppedCandidates(GstElement *element, guint64 frame, const Result &result, bool &warned)
{
	if (result.candidates_dropped == 0)
		return;
	GST_DEBUG_OBJECT(element, "frame %" G_GUINT64_FORMAT ": %d candidates over the cap not read", frame,
			 result.candidates_dropped);
	if (std::exchange(warned, true))
		return;
	GST_ELEMENT_WARNING(element, STREAM, FAILED, ("Too many marker candidates in a frame; some were not read"),
			    ("frame %" G_GUINT64_FORMAT ": %d candidates beyond the %d read (a frame full of "
			     "squares?); markers among them are missed. Later frames: the stats property",
			     frame, result.candidates_dropped, result.candidates));
}

GstStructure *statsStructure(guint64 frames, const Result &result, double poseMs, const char *backend,
			     bool pipelined, const char *overlap, guint qpuContexts)
{
	GstStructure *s = gst_structure_new("frappe-stats", "frames", G_TYPE_UINT64, frames, "markers",
					    G_TYPE_UINT, static_cast<guint>(result.markers.size()), "candidates",
					    G_TYPE_INT, result.candidates, "candidates-dropped", G_TYPE_INT,
					    result.candidates_dropped, "scale", G_TYPE_DOUBLE,
					    static_cast<double>(result.scale), nullptr);
	for (int i = 0; i < kStageCount; ++i) {
		std::string name(stageName(static_cast<Stage>(i)));
		std::replace(name.begin(), name.end(), '_', '-');
		name += "-ms";
		gst_structure_set(s, name.c_str(), G_TYPE_DOUBLE, result.times.ms[static_cast<std::size_t>(i)],
				  nullptr);
	}
	gst_structure_set(s, "pose-ms", G_TYPE_DOUBLE, poseMs, "total-ms", G_TYPE_DOUBLE,
			  result.times.total_ms + poseMs, "backend", G_TYPE_STRING, backend, "pipelined",
			  G_TYPE_BOOLEAN, static_cast<gboolean>(pipelined), "overlap", G_TYPE_STRING, overlap,
			  "qpu-contexts", G_TYPE_UINT, qpuContexts, "copied-bytes", G_TYPE_UINT64,
			  static_cast<guint64>(result.copy_bytes), nullptr);
	return s;
}

std::optional<std::string> StatsWindow::add(guint64 frames, const Result &result, double poseMs)
{
	times_.total_ms += result.times.total_ms + poseMs;
	for (std::size_t i = 0; i < result.times.ms.size(); ++i)
		times_.ms[i] += result.times.ms[i];
	poseMs_ += poseMs;
	if (frames % 100 != 0)
		return std::nullopt;

	std::string line;
	char part[64];
	for (int i = 0; i < kStageCount; ++i) {
		std::snprintf(part, sizeof(part), "%s %.2f, ", std::string(stageName(static_cast<Stage>(i))).c_str(),
			      times_.ms[static_cast<std::size_t>(i)] / 100.0);
		line += part;
	}
	std::snprintf(part, sizeof(part), "pose %.2f, total %.2f", poseMs_ / 100.0, times_.total_ms / 100.0);
	line += part;
	reset();
	return line;
}

void StatsWindow::reset()
{
	times_ = {};
	poseMs_ = 0.0;
}

} /* namespace frappe::gst */
