// SPDX-License-Identifier: MIT
//
// render-sample: renders a short video of moving markers with frappe's
// marker renderer and encodes it with GStreamer (appsrc ! videoconvert !
// vp8enc ! webmmux ! filesink), so the examples have something to chew on.
//
//   render-sample [OUTPUT.webm] [FRAMES]
//
// The markers are from aruco_mip_36h12 (frappedetect's default dictionary):
// ids 0, 7, 23 and 42, 5 cm wide, turning, travelling and tilting in front
// of a 700 px pinhole camera centred on the image (see kF below), so the
// element's pose output can be checked against the scene. The file is VP8
// in WebM, which Debian's gstreamer1.0-plugins-good decodes.
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <gst/app/gstappsrc.h>
#include <gst/gst.h>

#include <frappe/dictionary.h>
#include <frappe/render.h>

namespace {

constexpr int kWidth = 640;
constexpr int kHeight = 480;
constexpr int kFps = 30;
constexpr double kPi = 3.14159265358979323846;

using Quad = std::array<frappe::Point2f, 4>;

/* The camera the sample video is seen through: a pinhole, no distortion.
 * frappedetect camera-matrix="<700.0,0.0,319.5,0.0,700.0,239.5,0.0,0.0,1.0>"
 * marker-size=0.05 recovers the poses below. */
constexpr double kF = 700.0, kCx = 319.5, kCy = 239.5;
constexpr double kMarkerSize = 0.05; /* metres, the black square's side */

/* A marker whose centre projects to pixel (u, v) at depth z metres, turned
 * in the image plane by `roll` and about its own vertical axis by `tilt`
 * (radians), in OpenCV aruco's marker frame (x right, y up, z out). */
Quad pose(double u, double v, double z, double roll, double tilt)
{
	const double h = kMarkerSize / 2;
	const double local[4][2] = { { -h, h }, { h, h }, { h, -h }, { -h, -h } };
	const double t[3] = { (u - kCx) * z / kF, (v - kCy) * z / kF, z };
	Quad q;
	for (int i = 0; i < 4; ++i) {
		/* Marker frame to camera frame: flip (y up -> down, z out -> towards
		 * the camera), tilt about y, roll about the optical axis. */
		double x = local[i][0], y = -local[i][1], zz = 0.0;
		const double xt = x * std::cos(tilt) + zz * std::sin(tilt);
		const double zt = -x * std::sin(tilt) + zz * std::cos(tilt);
		x = xt;
		zz = zt;
		const double xr = x * std::cos(roll) - y * std::sin(roll);
		const double yr = x * std::sin(roll) + y * std::cos(roll);
		const double X = xr + t[0], Y = yr + t[1], Z = zz + t[2];
		q[static_cast<std::size_t>(i)] = { static_cast<float>(kF * X / Z + kCx),
						   static_cast<float>(kF * Y / Z + kCy) };
	}
	return q;
}

void drawFrame(std::vector<std::uint8_t> &img, int frame, const frappe::Dictionary &dict)
{
	const double t = static_cast<double>(frame) / kFps;
	/* A soft diagonal gradient with a few darker blobs, like a desk. */
	for (int y = 0; y < kHeight; ++y)
		for (int x = 0; x < kWidth; ++x) {
			double v = 150.0 + 50.0 * (x + y) / (kWidth + kHeight);
			v -= 25.0 * std::exp(-((x - 520.0) * (x - 520.0) + (y - 90.0) * (y - 90.0)) / 3000.0);
			img[static_cast<std::size_t>(y) * kWidth + static_cast<std::size_t>(x)] =
				static_cast<std::uint8_t>(v);
		}
	frappe::MutableImageView view{ img.data(), kWidth, kHeight, kWidth };
	const std::array<Quad, 4> quads = {
		pose(150 + 40 * std::sin(t * 1.3), 130 + 20 * std::cos(t), 0.27, 0.3 * t, 0.0),
		pose(470 - 60 * std::sin(t * 0.9), 150, 0.32, -0.2, 0.8 * std::sin(t * 1.7)),
		pose(190 + 60 * std::sin(t * 0.8), 350, 0.38 - 0.08 * std::sin(t * 2.0), 0.15, 0.0),
		pose(470, 340 + 30 * std::sin(t * 2.1), 0.26, 2.0 + 0.5 * t, 0.4),
	};
	const std::array<int, 4> ids = { 0, 7, 23, 42 };
	for (std::size_t i = 0; i < quads.size(); ++i)
		frappe::renderMarker(view, dict, ids[i], quads[i]);
}

} // namespace

int main(int argc, char **argv)
{
	gst_init(&argc, &argv);
	const std::string output = argc > 1 ? argv[1] : "markers.webm";
	const int frames = argc > 2 ? std::atoi(argv[2]) : 120;
	const frappe::Dictionary *dict = frappe::findDictionary("aruco_mip_36h12");

	GError *err = nullptr;
	const std::string launch =
		"appsrc name=src format=time ! videoconvert ! video/x-raw,format=I420 ! "
		"vp8enc target-bitrate=1500000 keyframe-max-dist=30 deadline=1 ! webmmux ! filesink location=\"" +
		output + "\"";
	GstElement *pipeline = gst_parse_launch(launch.c_str(), &err);
	if (!pipeline || err) {
		std::fprintf(stderr, "render-sample: %s (needs gstreamer1.0-plugins-good)\n",
			     err ? err->message : "no pipeline");
		return 1;
	}
	GstElement *src = gst_bin_get_by_name(GST_BIN(pipeline), "src");
	GstCaps *caps = gst_caps_new_simple("video/x-raw", "format", G_TYPE_STRING, "GRAY8", "width", G_TYPE_INT,
					    kWidth, "height", G_TYPE_INT, kHeight, "framerate", GST_TYPE_FRACTION,
					    kFps, 1, nullptr);
	gst_app_src_set_caps(GST_APP_SRC(src), caps);
	gst_caps_unref(caps);
	gst_element_set_state(pipeline, GST_STATE_PLAYING);

	std::vector<std::uint8_t> img(static_cast<std::size_t>(kWidth) * kHeight);
	for (int i = 0; i < frames; ++i) {
		drawFrame(img, i, *dict);
		GstBuffer *buf = gst_buffer_new_memdup(img.data(), img.size());
		GST_BUFFER_PTS(buf) = gst_util_uint64_scale_int(static_cast<guint64>(i), GST_SECOND, kFps);
		GST_BUFFER_DURATION(buf) = gst_util_uint64_scale_int(1, GST_SECOND, kFps);
		if (gst_app_src_push_buffer(GST_APP_SRC(src), buf) != GST_FLOW_OK)
			break;
	}
	gst_app_src_end_of_stream(GST_APP_SRC(src));

	GstBus *bus = gst_element_get_bus(pipeline);
	GstMessage *msg = gst_bus_timed_pop_filtered(bus, GST_CLOCK_TIME_NONE,
						     static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
	int rc = 0;
	if (GST_MESSAGE_TYPE(msg) == GST_MESSAGE_ERROR) {
		GError *e = nullptr;
		gst_message_parse_error(msg, &e, nullptr);
		std::fprintf(stderr, "render-sample: %s\n", e->message);
		g_error_free(e);
		rc = 1;
	} else {
		std::printf("wrote %d frames of %dx%d to %s\n", frames, kWidth, kHeight, output.c_str());
	}
	gst_message_unref(msg);
	gst_object_unref(bus);
	gst_element_set_state(pipeline, GST_STATE_NULL);
	gst_object_unref(src);
	gst_object_unref(pipeline);
	return rc;
}
