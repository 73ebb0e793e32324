// SPDX-License-Identifier: MIT
// helpers.h: frames with rendered markers for the frappedetect tests.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <glib/gstdio.h>
#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gst/video/video.h>
#include <gtest/gtest.h>

#include <frappe/dictionary.h>
#include <frappe/render.h>

#include "gstfrappemeta.h"

namespace frappe::gsttest {

struct Placed {
	int id;
	std::array<Point2f, 4> corners;
};

/// A frame description: format, size and an optional padded luma stride.
struct FrameSpec {
	GstVideoFormat format = GST_VIDEO_FORMAT_GRAY8;
	int width = 640;
	int height = 480;
	int padding = 0; ///< extra bytes per row of every plane (adds a GstVideoMeta)
	std::uint8_t background = 128;
};

inline std::string capsString(const FrameSpec &s, int fps = 30)
{
	return "video/x-raw,format=" + std::string(gst_video_format_to_string(s.format)) +
	       ",width=" + std::to_string(s.width) + ",height=" + std::to_string(s.height) +
	       ",framerate=" + std::to_string(fps) + "/1";
}

/// Allocates a frame and draws the markers into its luma plane; chroma is
/// neutral grey. With padding the strides differ from GStreamer's default
/// and a GstVideoMeta says so.
inline GstBuffer *makeFrame(const FrameSpec &s, const std::vector<Placed> &markers,
			    const frappe::Dictionary &dict, GstClockTime pts = 0,
			    GstClockTime duration = GST_SECOND / 30)
{
	GstVideoInfo info;
	gst_video_info_set_format(&info, s.format, static_cast<guint>(s.width), static_cast<guint>(s.height));
	gsize offsets[GST_VIDEO_MAX_PLANES] = {};
	gint strides[GST_VIDEO_MAX_PLANES] = {};
	gsize size = GST_VIDEO_INFO_SIZE(&info);
	const guint planes = GST_VIDEO_INFO_N_PLANES(&info);
	/* Rows per plane as GStreamer lays them out by default. */
	auto planeRows = [&](guint p) {
		const gsize end = p + 1 < planes ? GST_VIDEO_INFO_PLANE_OFFSET(&info, p + 1) : GST_VIDEO_INFO_SIZE(&info);
		return static_cast<int>((end - GST_VIDEO_INFO_PLANE_OFFSET(&info, p)) /
					static_cast<gsize>(GST_VIDEO_INFO_PLANE_STRIDE(&info, p)));
	};
	for (guint p = 0; p < planes; ++p) {
		strides[p] = GST_VIDEO_INFO_PLANE_STRIDE(&info, p);
		offsets[p] = GST_VIDEO_INFO_PLANE_OFFSET(&info, p);
	}
	if (s.padding) {
		size = 0;
		for (guint p = 0; p < planes; ++p) {
			strides[p] += s.padding;
			offsets[p] = size;
			size += static_cast<gsize>(strides[p]) * static_cast<gsize>(planeRows(p));
		}
	}
	GstBuffer *buf = gst_buffer_new_allocate(nullptr, size, nullptr);
	if (s.padding)
		gst_buffer_add_video_meta_full(buf, GST_VIDEO_FRAME_FLAG_NONE, s.format, static_cast<guint>(s.width),
					       static_cast<guint>(s.height), planes, offsets, strides);
	GstMapInfo map;
	gst_buffer_map(buf, &map, GST_MAP_WRITE);
	/* Padding bytes get a value no marker has, to catch stride mistakes. */
	std::memset(map.data, 77, map.size);
	for (guint p = 0; p < planes; ++p) {
		const int rows = planeRows(p);
		const int rowBytes = GST_VIDEO_INFO_PLANE_STRIDE(&info, p);
		for (int y = 0; y < rows; ++y)
			std::memset(map.data + offsets[p] + static_cast<gsize>(y) * static_cast<gsize>(strides[p]),
				    p == 0 ? s.background : 128, static_cast<std::size_t>(rowBytes));
	}
	frappe::MutableImageView luma{ map.data + offsets[0], s.width, s.height, strides[0] };
	for (const Placed &m : markers)
		frappe::renderMarker(luma, dict, m.id, m.corners);
	gst_buffer_unmap(buf, &map);
	GST_BUFFER_PTS(buf) = pts;
	GST_BUFFER_DURATION(buf) = duration;
	return buf;
}

/// An upright square marker with top-left corner (x, y) and side `side`.
inline Placed square(int id, float x, float y, float side)
{
	return { id, { Point2f{ x, y }, { x + side, y }, { x + side, y + side }, { x, y + side } } };
}

/// A slightly rotated and skewed marker around (cx, cy).
inline Placed tilted(int id, float cx, float cy, float side, float angle)
{
	Placed p{ id, {} };
	const float c = std::cos(angle), s = std::sin(angle);
	const float h = side / 2;
	const float local[4][2] = { { -h, -h }, { h, -h * 0.95f }, { h * 1.05f, h }, { -h, h } };
	for (int i = 0; i < 4; ++i)
		p.corners[static_cast<std::size_t>(i)] = { cx + c * local[i][0] - s * local[i][1],
							   cy + s * local[i][0] + c * local[i][1] };
	return p;
}

inline std::vector<GstFrappeMarkerMeta *> markerMetas(GstBuffer *buf)
{
	std::vector<GstFrappeMarkerMeta *> out;
	gpointer state = nullptr;
	GstMeta *m;
	while ((m = gst_buffer_iterate_meta_filtered(buf, &state, GST_FRAPPE_MARKER_META_API_TYPE)))
		out.push_back(reinterpret_cast<GstFrappeMarkerMeta *>(m));
	return out;
}

/// Asserts that every placed marker is in the metas with corners within tol.
inline void expectMarkers(GstBuffer *buf, const std::vector<Placed> &placed, const char *dictName,
			  float tol = 0.3f)
{
	const auto metas = markerMetas(buf);
	ASSERT_EQ(metas.size(), placed.size());
	for (const Placed &p : placed) {
		const GstFrappeMarkerMeta *found = nullptr;
		for (const auto *m : metas)
			if (m->id == p.id)
				found = m;
		ASSERT_NE(found, nullptr) << "marker " << p.id << " missing";
		EXPECT_STREQ(found->dictionary, dictName);
		EXPECT_EQ(found->hamming, 0u);
		for (int k = 0; k < 4; ++k) {
			EXPECT_NEAR(found->corners[2 * k], p.corners[static_cast<std::size_t>(k)].x, tol)
				<< "marker " << p.id << " corner " << k;
			EXPECT_NEAR(found->corners[2 * k + 1], p.corners[static_cast<std::size_t>(k)].y, tol)
				<< "marker " << p.id << " corner " << k;
		}
	}
}

/// A marker as a meta gives it: id and corners, to compare exactly.
struct Found {
	int id;
	std::array<float, 8> corners;
	bool operator==(const Found &o) const { return id == o.id && corners == o.corners; }
};

/// A buffer's markers by id.
inline std::vector<Found> foundMarkers(GstBuffer *buf)
{
	std::vector<Found> f;
	for (const GstFrappeMarkerMeta *m : markerMetas(buf)) {
		Found x{ m->id, {} };
		std::copy(m->corners, m->corners + 8, x.corners.begin());
		f.push_back(x);
	}
	std::sort(f.begin(), f.end(), [](const Found &a, const Found &b) { return a.id < b.id; });
	return f;
}

/// Waits (30 s at most) for the pipeline's EOS, which must come before any error.
inline void waitForEos(GstElement *pipeline)
{
	GstBus *bus = gst_element_get_bus(pipeline);
	GstMessage *msg = gst_bus_timed_pop_filtered(bus, 30 * GST_SECOND,
						     static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
	ASSERT_NE(msg, nullptr);
	EXPECT_EQ(GST_MESSAGE_TYPE(msg), GST_MESSAGE_EOS);
	gst_message_unref(msg);
	gst_object_unref(bus);
}

/// The frappedetect element of a harness (gst_harness_new_parse wraps it in a bin).
inline GstElement *detector(GstHarness *h)
{
	if (!GST_IS_BIN(h->element))
		return h->element;
	GstElement *found = nullptr;
	GstIterator *it = gst_bin_iterate_elements(GST_BIN(h->element));
	GValue item = G_VALUE_INIT;
	while (!found && gst_iterator_next(it, &item) == GST_ITERATOR_OK) {
		auto *e = GST_ELEMENT(g_value_get_object(&item));
		if (g_str_has_prefix(GST_OBJECT_NAME(e), "frappedetect"))
			found = e;
		g_value_reset(&item);
	}
	g_value_unset(&item);
	gst_iterator_free(it);
	return found; /* the bin holds the reference */
}

/// A harness around `launch` whose element has a bus of its own, for its
/// warnings and errors.
struct BusHarness {
	/* The bus before the caps: warnings at negotiation reach it. */
	BusHarness(const char *launch, const FrameSpec &spec) : h(gst_harness_new_parse(launch)), bus(gst_bus_new())
	{
		gst_element_set_bus(h->element, bus);
		gst_harness_set_src_caps_str(h, capsString(spec).c_str());
	}
	~BusHarness()
	{
		gst_element_set_bus(h->element, nullptr);
		gst_object_unref(bus);
		gst_harness_teardown(h);
	}
	BusHarness(const BusHarness &) = delete;
	BusHarness &operator=(const BusHarness &) = delete;
	GstHarness *h;
	GstBus *bus;
};

/// Every message on the bus, oldest first (gst_bus_pop_filtered would
/// throw away the others).
struct BusMessages {
	explicit BusMessages(GstBus *bus)
	{
		while (GstMessage *m = gst_bus_pop(bus))
			all.push_back(m);
	}
	~BusMessages()
	{
		for (GstMessage *m : all)
			gst_message_unref(m);
	}
	BusMessages(const BusMessages &) = delete;
	BusMessages &operator=(const BusMessages &) = delete;
	std::vector<GstMessage *> of(GstMessageType type) const
	{
		std::vector<GstMessage *> out;
		for (GstMessage *m : all)
			if (GST_MESSAGE_TYPE(m) == type)
				out.push_back(m);
		return out;
	}
	std::vector<GstMessage *> all;
};

/// The text and domain of a WARNING or ERROR message.
struct MessageError {
	MessageError() = default;
	explicit MessageError(GstMessage *m)
	{
		GError *err = nullptr;
		gchar *dbg = nullptr;
		if (GST_MESSAGE_TYPE(m) == GST_MESSAGE_ERROR)
			gst_message_parse_error(m, &err, &dbg);
		else
			gst_message_parse_warning(m, &err, &dbg);
		domain = err->domain;
		code = err->code;
		text = err->message;
		debug = dbg ? dbg : "";
		g_error_free(err);
		g_free(dbg);
	}
	GQuark domain = 0;
	gint code = 0;
	std::string text, debug;
};

/// Exactly one warning on the bus since it was last read, no error: a
/// GST_RESOURCE_ERROR_SETTINGS one whose text holds `words`.
inline void expectOneSettingsWarning(GstBus *bus, const std::string &words)
{
	const BusMessages msgs(bus);
	EXPECT_TRUE(msgs.of(GST_MESSAGE_ERROR).empty());
	const auto warnings = msgs.of(GST_MESSAGE_WARNING);
	ASSERT_EQ(warnings.size(), 1u);
	const MessageError w(warnings[0]);
	EXPECT_EQ(w.domain, GST_RESOURCE_ERROR);
	EXPECT_EQ(w.code, GST_RESOURCE_ERROR_SETTINGS);
	EXPECT_NE(w.text.find(words), std::string::npos) << w.text;
}

/// The element error that keeps the pipeline `launch`, whose frappedetect is
/// named "d", from starting (state change to PAUSED fails).
inline MessageError startError(const std::string &launch)
{
	GstElement *pipeline = gst_parse_launch(launch.c_str(), nullptr);
	EXPECT_NE(pipeline, nullptr);
	EXPECT_EQ(gst_element_set_state(pipeline, GST_STATE_PAUSED), GST_STATE_CHANGE_FAILURE);
	GstBus *bus = gst_element_get_bus(pipeline);
	GstMessage *msg = gst_bus_pop_filtered(bus, GST_MESSAGE_ERROR);
	EXPECT_NE(msg, nullptr);
	EXPECT_STREQ(msg ? GST_OBJECT_NAME(GST_MESSAGE_SRC(msg)) : "", "d");
	const MessageError e = msg ? MessageError(msg) : MessageError();
	if (msg)
		gst_message_unref(msg);
	gst_object_unref(bus);
	gst_element_set_state(pipeline, GST_STATE_NULL);
	gst_object_unref(pipeline);
	return e;
}

/// A rotation matrix, row-major, of `angle` radians about the unit axis.
inline std::array<double, 9> rotation(const std::array<double, 3> &axis, double angle)
{
	const double c = std::cos(angle), s = std::sin(angle), t = 1 - c;
	const double x = axis[0], y = axis[1], z = axis[2];
	return { t * x * x + c,     t * x * y - s * z, t * x * z + s * y, t * x * y + s * z, t * y * y + c,
		 t * y * z - s * x, t * x * z - s * y, t * y * z + s * x, t * z * z + c };
}

/// The marker-to-camera rotation of a marker turned by `r` (row-major) from
/// facing the camera: the aruco frame (z out of the marker, towards the
/// camera) flipped by 180 degrees about x first.
inline std::array<double, 9> facingCamera(const std::array<double, 9> &r)
{
	const double flip[9] = { 1, 0, 0, 0, -1, 0, 0, 0, -1 };
	std::array<double, 9> m{};
	for (int i = 0; i < 3; ++i)
		for (int j = 0; j < 3; ++j)
			m[3 * i + j] = r[3 * i] * flip[j] + r[3 * i + 1] * flip[3 + j] + r[3 * i + 2] * flip[6 + j];
	return m;
}

/// A marker of side `side` (metres) at rotation `m` (marker to camera,
/// row-major) and translation `t`, seen through a pinhole camera.
inline Placed posedMarker(int id, double fx, double fy, double cx, double cy, double side,
			  const std::array<double, 9> &m, const std::array<double, 3> &t)
{
	const double hs = side / 2;
	const double obj[4][3] = { { -hs, hs, 0 }, { hs, hs, 0 }, { hs, -hs, 0 }, { -hs, -hs, 0 } };
	Placed placed{ id, {} };
	for (int k = 0; k < 4; ++k) {
		double p[3];
		for (int i = 0; i < 3; ++i)
			p[i] = m[3 * i] * obj[k][0] + m[3 * i + 1] * obj[k][1] + m[3 * i + 2] * obj[k][2] + t[i];
		placed.corners[static_cast<std::size_t>(k)] = { static_cast<float>(fx * p[0] / p[2] + cx),
								static_cast<float>(fy * p[1] / p[2] + cy) };
	}
	return placed;
}

/// A directory of its own for the files a test writes; removed with them.
struct TempDir {
	TempDir()
	{
		gchar *dir = g_dir_make_tmp("frappe-gst-XXXXXX", nullptr);
		EXPECT_NE(dir, nullptr);
		path = dir ? dir : "";
		g_free(dir);
	}
	~TempDir()
	{
		for (const std::string &f : files)
			g_remove(f.c_str());
		g_rmdir(path.c_str());
	}
	TempDir(const TempDir &) = delete;
	TempDir &operator=(const TempDir &) = delete;
	/// Writes `text` to the file `name` in the directory; its path.
	std::string write(const std::string &name, const std::string &text)
	{
		const std::string file = path + "/" + name;
		EXPECT_TRUE(g_file_set_contents(file.c_str(), text.data(), static_cast<gssize>(text.size()), nullptr));
		files.push_back(file);
		return file;
	}
	std::string path;
	std::vector<std::string> files;
};

inline const frappe::Dictionary &dict(const char *name)
{
	return *frappe::findDictionary(name);
}

class GstEnvironment : public ::testing::Environment {
public:
	void SetUp() override { gst_init(nullptr, nullptr); }
};

} // namespace frappe::gsttest
