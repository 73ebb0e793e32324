// SPDX-License-Identifier: MIT
// test_overlay.cpp: the annotate=true overlay drawn into frames directly
// (no element): code cells untouched, labels beside their markers and
// inside the frame, glyphs that read at small sizes, colours where the
// format has them, axes where the pose projects them.
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <frappe/homography.h>

#include "../../gst/annotate.h"
#include "../../gst/overlay_font.h"
#include "helpers.h"

namespace frappe::gsttest {
namespace {

/// A frame of rendered markers mapped for writing, and a copy of its bytes
/// from before the overlay.
class Frame {
public:
	Frame(GstVideoFormat format, const std::vector<Placed> &markers, int width = 640, int height = 480,
	      std::uint8_t background = 128)
	{
		FrameSpec spec;
		spec.format = format;
		spec.width = width;
		spec.height = height;
		spec.padding = 6; /* bytes past every row, set to 77: no write may reach them */
		spec.background = background;
		buf_ = makeFrame(spec, markers, dict("aruco_mip_36h12"));
		gst_video_info_set_format(&info_, format, static_cast<guint>(width), static_cast<guint>(height));
		EXPECT_TRUE(gst_video_frame_map(&frame, &info_, buf_, GST_MAP_READWRITE));
		GstMapInfo map;
		gst_buffer_map(buf_, &map, GST_MAP_READ);
		before_.assign(map.data, map.data + map.size);
		gst_buffer_unmap(buf_, &map);
		for (const Placed &p : markers) {
			Marker m;
			m.id = p.id;
			m.corners = p.corners;
			result.markers.push_back(m);
		}
	}
	~Frame()
	{
		gst_video_frame_unmap(&frame);
		gst_buffer_unref(buf_);
	}

	std::uint8_t *at(int comp, int x, int y) const
	{
		auto *d = static_cast<std::uint8_t *>(GST_VIDEO_FRAME_COMP_DATA(&frame, comp));
		return d + static_cast<std::ptrdiff_t>(y) * GST_VIDEO_FRAME_COMP_STRIDE(&frame, comp) +
		       x * GST_VIDEO_FRAME_COMP_PSTRIDE(&frame, comp);
	}
	int luma(int x, int y) const { return *at(0, x, y); }
	int u(int x, int y) const { return *at(1, x / 2, y / 2); }
	int v(int x, int y) const { return *at(2, x / 2, y / 2); }
	/// The byte's value before the overlay.
	int was(const std::uint8_t *p) const
	{
		return before_[static_cast<std::size_t>(p - static_cast<std::uint8_t *>(frame.map[0].data))];
	}
	bool changed(int x, int y) const
	{
		bool c = *at(0, x, y) != was(at(0, x, y));
		if (GST_VIDEO_FRAME_N_COMPONENTS(&frame) >= 3)
			c = c || *at(1, x / 2, y / 2) != was(at(1, x / 2, y / 2)) ||
			    *at(2, x / 2, y / 2) != was(at(2, x / 2, y / 2));
		return c;
	}
	/// Bytes past the planes' rows that changed (0: the overlay kept to
	/// the image).
	int paddingWrites() const
	{
		int n = 0;
		const auto *base = static_cast<std::uint8_t *>(frame.map[0].data);
		for (std::size_t i = 0; i < before_.size(); ++i)
			if (before_[i] == 77 && base[i] != 77)
				++n;
		return n;
	}

	void annotate(const std::vector<std::optional<Pose>> &poses = {}, const MarkerSizes &sizes = {},
		      const Camera &camera = {})
	{
		gst::annotateMarkers(&frame, result, poses, sizes, camera);
	}

	GstVideoFrame frame{};
	Result result;

private:
	GstBuffer *buf_ = nullptr;
	GstVideoInfo info_{};
	std::vector<std::uint8_t> before_;
};

/// Maps pixels to the marker's cells (of its 8x8, border included).
class Cells {
public:
	explicit Cells(const Placed &p) : h_(*Homography::fromUnitSquare(p.corners)->inverse()) {}
	Point2f at(int x, int y) const
	{
		const Point2f q = h_.map(x, y);
		return { q.x * 8.0f, q.y * 8.0f };
	}

private:
	Homography h_;
};

double distanceToQuad(const std::array<Point2f, 4> &c, double x, double y)
{
	double d = 1e9;
	for (std::size_t k = 0; k < 4; ++k) {
		const Point2f a = c[k], b = c[(k + 1) & 3];
		const double dx = b.x - a.x, dy = b.y - a.y;
		const double t = std::clamp(((x - a.x) * dx + (y - a.y) * dy) / (dx * dx + dy * dy), 0.0, 1.0);
		d = std::min(d, std::hypot(x - a.x - t * dx, y - a.y - t * dy));
	}
	return d;
}

double meanSide(const std::array<Point2f, 4> &c)
{
	double s = 0.0;
	for (std::size_t k = 0; k < 4; ++k)
		s += std::hypot(c[k].x - c[(k + 1) & 3].x, c[k].y - c[(k + 1) & 3].y) / 4.0;
	return s;
}

std::string idText(int id)
{
	return std::to_string(id);
}

const std::vector<Placed> kScene = {
	square(0, 60, 120, 120), tilted(7, 330, 250, 110, 0.3f), square(12, 470, 300, 70), tilted(5, 200, 400, 60, -0.5f),
};

class OverlayFormats : public ::testing::TestWithParam<GstVideoFormat> {};

/* The code cells, shrunk by a quarter cell, are exactly as rendered: the
 * overlay (without axes) draws only on the border and outside. */
TEST_P(OverlayFormats, CodeCellsUntouched)
{
	Frame f(GetParam(), kScene);
	f.annotate();
	for (const Placed &p : kScene) {
		const Cells cells(p);
		int code = 0, border = 0;
		for (int y = 0; y < 480; ++y)
			for (int x = 0; x < 640; ++x) {
				const Point2f c = cells.at(x, y);
				if (c.x > 1.25f && c.x < 6.75f && c.y > 1.25f && c.y < 6.75f) {
					++code;
					EXPECT_FALSE(f.changed(x, y)) << "marker " << p.id << " pixel " << x << "," << y;
				}
				if (distanceToQuad(p.corners, x, y) < 0.5)
					border += f.changed(x, y);
			}
		EXPECT_GT(code, 500) << p.id;
		/* ... while the outline is drawn all round. */
		EXPECT_GT(border, 3.5 * meanSide(p.corners)) << p.id;
	}
	EXPECT_EQ(f.paddingWrites(), 0);
}

/* Every pixel the overlay changes far from an outline belongs to a label
 * placed outside its marker's bounding box and inside the frame, and each
 * label holds its id: colour on colour formats, white on GRAY8. */
TEST_P(OverlayFormats, LabelsBesideMarkers)
{
	Frame f(GetParam(), kScene);
	f.annotate();
	const bool colour = GetParam() != GST_VIDEO_FORMAT_GRAY8;
	std::vector<gst::Label> labels;
	for (const Placed &p : kScene) {
		labels.push_back(gst::placeLabel(p.corners, idText(p.id), 640, 480,
						 colour ? gst::colours::label : gst::colours::white));
		const gst::Label &l = labels.back();
		const double m = l.pen.width / 2 + l.pen.halo;
		EXPECT_GE(l.left - m, 0.0);
		EXPECT_GE(l.top - m, 0.0);
		EXPECT_LE(l.left + l.width + m, 639.0);
		EXPECT_LE(l.top + l.height + m, 479.0);
		EXPECT_GE(l.height, 12.0);
		EXPECT_NEAR(l.height, 0.3 * meanSide(p.corners), 0.5) << "sized with the marker";
		/* Clear of the marker's outline (and so of its code). */
		for (const Point2f &c : p.corners)
			EXPECT_FALSE(c.x > l.left - m && c.x < l.left + l.width + m && c.y > l.top - m &&
				     c.y < l.top + l.height + m);
		double y0 = 1e9;
		for (const Point2f &c : p.corners)
			y0 = std::min<double>(y0, c.y);
		EXPECT_LT(l.top + l.height + m, y0) << p.id << ": above the marker";
	}
	int stray = 0;
	std::vector<int> ink(kScene.size()), halo(kScene.size()), tinted(kScene.size());
	for (int y = 0; y < 480; ++y)
		for (int x = 0; x < 640; ++x) {
			if (!f.changed(x, y))
				continue;
			bool near = false;
			for (const Placed &p : kScene)
				near = near || distanceToQuad(p.corners, x, y) < meanSide(p.corners) / 12.0 + 3.0;
			bool inLabel = false;
			for (std::size_t i = 0; i < labels.size(); ++i) {
				const gst::Label &l = labels[i];
				const double m = l.pen.width / 2 + l.pen.halo + 1.0;
				if (x < l.left - m || x > l.left + l.width + m || y < l.top - m || y > l.top + l.height + m)
					continue;
				inLabel = true;
				ink[i] += colour ? f.luma(x, y) == gst::colours::label.y : f.luma(x, y) == 235;
				halo[i] += f.luma(x, y) == gst::kHalo.y;
				tinted[i] += colour && f.u(x, y) == gst::colours::label.u &&
					     f.v(x, y) == gst::colours::label.v;
			}
			stray += !near && !inLabel;
		}
	EXPECT_EQ(stray, 0);
	for (std::size_t i = 0; i < labels.size(); ++i) {
		const double area = labels[i].width * labels[i].height;
		EXPECT_GT(ink[i], 0.08 * area) << kScene[i].id;
		EXPECT_GT(halo[i], 0.08 * area) << kScene[i].id;
		if (colour) {
			EXPECT_GT(tinted[i], 0.02 * area) << kScene[i].id << ": chroma carries the colour";
		}
	}
	EXPECT_EQ(f.paddingWrites(), 0);
}

INSTANTIATE_TEST_SUITE_P(Formats, OverlayFormats,
			 ::testing::Values(GST_VIDEO_FORMAT_I420, GST_VIDEO_FORMAT_YV12, GST_VIDEO_FORMAT_NV12,
					   GST_VIDEO_FORMAT_NV21, GST_VIDEO_FORMAT_GRAY8),
			 [](const auto &info) { return std::string(gst_video_format_to_string(info.param)); });

/* At the frame's edges the label moves inside: below a marker at the top,
 * beside one as tall as the frame, along for one cut by the right edge. */
TEST(Overlay, LabelsClampedInsideFrame)
{
	const std::vector<Placed> scene = {
		square(3, 2, 2, 90), square(44, 585, 300, 100), square(9, 160, 4, 470),
	};
	for (const Placed &p : scene) {
		const gst::Label l = gst::placeLabel(p.corners, idText(p.id), 640, 480, gst::colours::label);
		const double m = l.pen.width / 2 + l.pen.halo;
		EXPECT_GE(l.left - m, 0.0) << p.id;
		EXPECT_GE(l.top - m, 0.0) << p.id;
		EXPECT_LE(l.left + l.width + m, 639.0) << p.id;
		EXPECT_LE(l.top + l.height + m, 479.0) << p.id;
		double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
		for (const Point2f &c : p.corners) {
			x0 = std::min<double>(x0, c.x);
			y0 = std::min<double>(y0, c.y);
			x1 = std::max<double>(x1, c.x);
			y1 = std::max<double>(y1, c.y);
		}
		const bool apart = l.left - m > x1 || l.left + l.width + m < x0 || l.top - m > y1 ||
				   l.top + l.height + m < y0;
		EXPECT_TRUE(apart) << p.id << " label over its marker";
	}
	const gst::Label top = gst::placeLabel(scene[0].corners, "3", 640, 480, gst::colours::label);
	EXPECT_GT(top.top, 92.0) << "below";
	const gst::Label tall = gst::placeLabel(scene[2].corners, "9", 640, 480, gst::colours::label);
	EXPECT_LT(tall.left + tall.width, 160.0) << "beside, on the left";
	EXPECT_NEAR(tall.top + tall.height / 2, 239.0, 1.0);

	/* Drawn, each label is whole inside the frame: its ink is all there. */
	Frame f(GST_VIDEO_FORMAT_I420, scene);
	f.annotate();
	for (const Placed &p : scene) {
		const gst::Label l = gst::placeLabel(p.corners, idText(p.id), 640, 480, gst::colours::label);
		int ink = 0;
		for (int y = static_cast<int>(l.top); y <= l.top + l.height; ++y)
			for (int x = static_cast<int>(l.left); x <= l.left + l.width; ++x)
				ink += f.luma(x, y) == gst::colours::label.y;
		EXPECT_GT(ink, 0.08 * l.width * l.height) << p.id;
	}
	EXPECT_EQ(f.paddingWrites(), 0);
}

/* A frame smaller than a label, and corners far outside it, are drawn
 * clipped: nothing written past the planes. */
TEST(Overlay, TinyFrameAndFarCorners)
{
	for (GstVideoFormat format : { GST_VIDEO_FORMAT_GRAY8, GST_VIDEO_FORMAT_NV12 }) {
		Frame f(format, {}, 10, 6);
		Marker m;
		m.id = 1234567;
		m.corners = { Point2f{ -3e6f, -2e6f }, { 4e6f, -1e6f }, { 3e6f, 5e6f }, { -1e6f, 2e6f } };
		f.result.markers.push_back(m);
		m.id = 8;
		m.corners = { Point2f{ 2, 1 }, { 8, 1 }, { 8, 5 }, { 2, 5 } };
		f.result.markers.push_back(m);
		f.annotate();
		EXPECT_EQ(f.paddingWrites(), 0);
		int changed = 0;
		for (int y = 0; y < 6; ++y)
			for (int x = 0; x < 10; ++x)
				changed += f.changed(x, y);
		EXPECT_GT(changed, 0);
	}
}

/* A label that would cover a neighbour goes to the next side that is
 * clear: the lower marker's below it, not over the upper one. */
TEST(Overlay, LabelsAvoidOtherMarkers)
{
	const std::vector<Placed> scene = { square(2, 200, 120, 100), square(1, 200, 250, 100) };
	Frame f(GST_VIDEO_FORMAT_I420, scene);
	const gst::Label alone = gst::placeLabel(scene[1].corners, "1", 640, 480, gst::colours::label);
	EXPECT_LT(alone.top, 250.0) << "above, when nothing is in the way";
	const gst::Label upper = gst::placeLabel(scene[0].corners, "2", 640, 480, gst::colours::label,
						 f.result.markers);
	const gst::Label lower = gst::placeLabel(scene[1].corners, "1", 640, 480, gst::colours::label,
						 f.result.markers);
	EXPECT_LT(upper.top + upper.height, 120.0) << "above";
	EXPECT_GT(lower.top, 350.0) << "below";

	/* Drawn so: the upper marker's quiet zone and code are untouched. */
	f.annotate();
	for (int y = 128; y < 213; ++y)
		for (int x = 208; x < 293; ++x)
			ASSERT_FALSE(f.changed(x, y)) << x << "," << y;
}

/* A glyph's cell (plus its overhang) `height` pixels tall at (left, top)
 * in a luma plane, averaged onto a 12x20 grid, zero mean, unit norm. */
std::vector<double> sampleGlyph(const GstVideoFrame &frame, double left, double top, double height)
{
	const auto *luma = static_cast<const std::uint8_t *>(GST_VIDEO_FRAME_COMP_DATA(&frame, 0));
	const int stride = GST_VIDEO_FRAME_COMP_STRIDE(&frame, 0);
	auto at = [&](int x, int y) { return luma[static_cast<std::ptrdiff_t>(y) * stride + x]; };
	const double over = 0.1 * height;
	const double x0 = left - over, y0 = top - over;
	const double w = 0.6 * height + 2 * over, h = height + 2 * over;
	std::vector<double> grid(12 * 20);
	double mean = 0.0;
	for (int gy = 0; gy < 20; ++gy)
		for (int gx = 0; gx < 12; ++gx) {
			double sum = 0.0;
			for (int sy = 0; sy < 4; ++sy)
				for (int sx = 0; sx < 4; ++sx) {
					/* Bilinear samples of the plane. */
					const double px = x0 + (gx + (sx + 0.5) / 4) * w / 12 - 0.5;
					const double py = y0 + (gy + (sy + 0.5) / 4) * h / 20 - 0.5;
					const int ix = static_cast<int>(std::floor(px)), iy = static_cast<int>(std::floor(py));
					const double fx = px - ix, fy = py - iy;
					sum += (1 - fx) * (1 - fy) * at(ix, iy) + fx * (1 - fy) * at(ix + 1, iy) +
					       (1 - fx) * fy * at(ix, iy + 1) + fx * fy * at(ix + 1, iy + 1);
				}
			grid[static_cast<std::size_t>(gy * 12 + gx)] = sum / 16;
			mean += sum / 16 / 240;
		}
	double norm = 0.0;
	for (double &g : grid) {
		g -= mean;
		norm += g * g;
	}
	for (double &g : grid)
		g /= std::sqrt(norm);
	return grid;
}

/* A glyph drawn alone, white ink on black. */
std::vector<double> glyphGrid(char ch, double height)
{
	/* Room for the overhang sampled and the bilinear neighbours. */
	const double origin = std::ceil(0.1 * height) + 4.0;
	const int size = static_cast<int>(height + 2 * origin);
	Frame f(GST_VIDEO_FORMAT_GRAY8, {}, size, size, 0);
	gst::Path path;
	EXPECT_TRUE(gst::addText(path, std::string(1, ch), origin, origin, height));
	gst::Canvas canvas(&f.frame);
	canvas.stroke(path, gst::textPen(height, gst::colours::white), gst::Canvas::Ink);
	return sampleGlyph(f.frame, origin, origin, height);
}

double correlation(const std::vector<double> &a, const std::vector<double> &b)
{
	double s = 0.0;
	for (std::size_t i = 0; i < a.size(); ++i)
		s += a[i] * b[i];
	return s;
}

const std::string kChars = "0123456789-id";

/* The glyphs drawn 120 pixels tall: what the small ones must look like. */
const std::vector<std::vector<double>> &templates()
{
	static const std::vector<std::vector<double>> t = [] {
		std::vector<std::vector<double>> out;
		for (char c : kChars)
			out.push_back(glyphGrid(c, 120));
		return out;
	}();
	return t;
}

/* The template that `grid` matches best, and by how much it beats the
 * runner-up (correlation). */
std::pair<char, double> recognise(const std::vector<double> &grid)
{
	std::size_t best = 0;
	double first = -2, second = -2;
	for (std::size_t j = 0; j < kChars.size(); ++j) {
		const double r = correlation(grid, templates()[j]);
		if (r > first) {
			second = first;
			first = r;
			best = j;
		} else if (r > second) {
			second = r;
		}
	}
	return { kChars[best], first - second };
}

/* Each glyph drawn at 12 and 40 pixels is recognised, by template
 * matching against the glyphs drawn at 120, as itself, with a margin over
 * the runner-up: no two glyphs look alike even small. */
TEST(Overlay, GlyphsReadAtSmallSizes)
{
	for (char c : kChars)
		EXPECT_TRUE(gst::hasGlyph(c)) << c;
	EXPECT_FALSE(gst::hasGlyph('Q'));
	for (double height : { 12.0, 40.0 }) {
		for (char c : kChars) {
			const auto [got, margin] = recognise(glyphGrid(c, height));
			EXPECT_EQ(got, c) << "at " << height << " px";
			EXPECT_GT(margin, 0.15) << c << " at " << height << " px";
		}
	}
}

/* Small markers' ids, drawn on markers and grey and then through JPEG at
 * quality 75, still read: every digit of every label is recognised. */
TEST(Overlay, LabelsReadAfterJpeg)
{
	for (const char *name : { "jpegenc", "jpegdec" }) {
		GstElementFactory *factory = gst_element_factory_find(name);
		if (!factory)
			GTEST_SKIP() << name << " (gst-plugins-good) is not installed";
		gst_object_unref(factory);
	}
	std::vector<Placed> scene;
	const int ids[] = { 0, 13, 26, 38, 47, 59, 61, 72, 84, 95, 108, 219 };
	for (int i = 0; i < 12; ++i)
		scene.push_back(tilted(ids[i], 70.0f + 100.0f * (i % 6), 140.0f + 200.0f * (i / 6),
				       35.0f + 1.0f * i, 0.1f * i));
	Frame f(GST_VIDEO_FORMAT_I420, scene);
	f.annotate();

	GstHarness *h = gst_harness_new_parse("jpegenc quality=75 ! jpegdec");
	gst_harness_set_src_caps_str(h, "video/x-raw,format=I420,width=640,height=480,framerate=30/1");
	/* The frame has padded rows; the encoder gets GStreamer's layout. */
	GstVideoInfo plain;
	gst_video_info_set_format(&plain, GST_VIDEO_FORMAT_I420, 640, 480);
	GstBuffer *in = gst_buffer_new_allocate(nullptr, GST_VIDEO_INFO_SIZE(&plain), nullptr);
	GstVideoFrame copy;
	ASSERT_TRUE(gst_video_frame_map(&copy, &plain, in, GST_MAP_WRITE));
	ASSERT_TRUE(gst_video_frame_copy(&copy, &f.frame));
	gst_video_frame_unmap(&copy);
	ASSERT_EQ(gst_harness_push(h, in), GST_FLOW_OK);
	GstBuffer *out = gst_harness_pull(h);
	ASSERT_NE(out, nullptr);
	GstVideoInfo info;
	GstCaps *caps = gst_pad_get_current_caps(h->sinkpad);
	ASSERT_TRUE(gst_video_info_from_caps(&info, caps));
	gst_caps_unref(caps);
	GstVideoFrame decoded;
	ASSERT_TRUE(gst_video_frame_map(&decoded, &info, out, GST_MAP_READ));

	int read = 0;
	for (const Placed &p : scene) {
		const std::string text = idText(p.id);
		const gst::Label l = gst::placeLabel(p.corners, text, 640, 480, gst::colours::label, f.result.markers);
		EXPECT_LT(l.height, 14.0) << "small labels";
		for (std::size_t i = 0; i < text.size(); ++i) {
			const auto [got, margin] = recognise(sampleGlyph(decoded, l.left + i * 0.9 * l.height, l.top,
									  l.height));
			EXPECT_EQ(got, text[i]) << "id " << p.id << " digit " << i;
			read += got == text[i];
		}
	}
	EXPECT_EQ(read, 25);
	gst_video_frame_unmap(&decoded);
	gst_buffer_unref(out);
	gst_harness_teardown(h);
}

/* Text width scales with height; a full path refuses strokes. */
TEST(Overlay, TextMetrics)
{
	EXPECT_DOUBLE_EQ(gst::textWidth("7", 20), 12.0);
	EXPECT_DOUBLE_EQ(gst::textWidth("123", 20), 48.0);
	EXPECT_DOUBLE_EQ(gst::textWidth("", 20), 0.0);
	gst::Path path;
	EXPECT_TRUE(gst::addText(path, "0000000000000000", 0, 0, 10)); /* 4 strokes each: 64 */
	EXPECT_FALSE(gst::addText(path, "1", 0, 0, 10));
	EXPECT_EQ(path.strokes().size(), gst::Path::kCapacity);
}

/* The test's own projection: Rodrigues and a pinhole. */
Point2f project(const Pose &pose, const std::array<double, 3> &p, double f, double cx, double cy)
{
	const auto &r = pose.rvec;
	const double th = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
	const double k[3] = { r[0] / th, r[1] / th, r[2] / th };
	const double c = std::cos(th), s = std::sin(th);
	const double kp = k[0] * p[0] + k[1] * p[1] + k[2] * p[2];
	const double cross[3] = { k[1] * p[2] - k[2] * p[1], k[2] * p[0] - k[0] * p[2], k[0] * p[1] - k[1] * p[0] };
	double q[3];
	for (int i = 0; i < 3; ++i)
		q[i] = p[static_cast<std::size_t>(i)] * c + cross[i] * s + k[i] * kp * (1 - c) + pose.tvec[static_cast<std::size_t>(i)];
	return { static_cast<float>(f * q[0] / q[2] + cx), static_cast<float>(f * q[1] / q[2] + cy) };
}

/* The axes run from the projected centre to the projected ends, each in
 * its colour: pixels along each centre line carry it exactly. */
TEST(Overlay, AxesWhereProjected)
{
	const Camera camera = Camera::pinhole(700, 700, 319.5, 239.5, 640, 480);
	Pose pose;
	pose.rvec = { 2.7, 0.6, -0.7 }; /* face on is (pi, 0, 0); turned so the axes part */
	pose.tvec = { 0.02, -0.01, 0.6 };
	const double size = 0.1;
	std::array<Point2f, 4> corners;
	const double h = size / 2;
	const std::array<std::array<double, 3>, 4> local{ { { -h, h, 0 }, { h, h, 0 }, { h, -h, 0 }, { -h, -h, 0 } } };
	for (std::size_t k = 0; k < 4; ++k)
		corners[k] = project(pose, local[k], 700, 319.5, 239.5);
	Frame f(GST_VIDEO_FORMAT_I420, { Placed{ 3, corners } });
	f.annotate({ pose }, MarkerSizes(size), camera);

	const Point2f o = project(pose, { 0, 0, 0 }, 700, 319.5, 239.5);
	const std::array<std::array<double, 3>, 3> ends{ { { h, 0, 0 }, { 0, h, 0 }, { 0, 0, h } } };
	const std::array<gst::Yuv, 3> inks{ gst::colours::axisX, gst::colours::axisY, gst::colours::axisZ };
	for (std::size_t a = 0; a < 3; ++a) {
		const Point2f e = project(pose, ends[a], 700, 319.5, 239.5);
		EXPECT_GT(std::hypot(e.x - o.x, e.y - o.y), 20.0) << "axis " << a << " too short to test";
		for (double t : { 0.35, 0.6, 0.85 }) {
			const int x = static_cast<int>(std::lround(o.x + t * (e.x - o.x)));
			const int y = static_cast<int>(std::lround(o.y + t * (e.y - o.y)));
			EXPECT_EQ(f.luma(x, y), inks[a].y) << "axis " << a << " at " << t;
			EXPECT_NEAR(f.u(x, y), inks[a].u, 12) << "axis " << a << " at " << t;
			EXPECT_NEAR(f.v(x, y), inks[a].v, 12) << "axis " << a << " at " << t;
		}
		/* ... and end there: past the end, no ink. */
		const int x = static_cast<int>(std::lround(o.x + 1.3 * (e.x - o.x)));
		const int y = static_cast<int>(std::lround(o.y + 1.3 * (e.y - o.y)));
		EXPECT_NE(f.luma(x, y), inks[a].y) << "axis " << a << " past its end";
	}
}

/* A pose with the axis ends behind the camera draws the axes it can and
 * nothing absurd; without a size for the id, no axes at all. */
TEST(Overlay, AxesBehindCameraOrUnsized)
{
	const Camera camera = Camera::pinhole(700, 700, 319.5, 239.5, 640, 480);
	Pose pose;
	pose.rvec = { 3.14159, 0, 0 };
	pose.tvec = { 0.0, 0.0, 0.6 };
	Pose behind = pose;
	behind.tvec = { 0.0, 0.0, 0.02 }; /* the z axis's end at z = -0.03 */
	const std::vector<Placed> scene = { square(1, 280, 200, 80) };
	{
		Frame f(GST_VIDEO_FORMAT_I420, scene);
		f.annotate({ behind }, MarkerSizes(0.1), camera);
		EXPECT_EQ(f.paddingWrites(), 0);
		/* x projects far right, y far up, both clipped to the frame;
		 * z would be behind the camera: not drawn. */
		EXPECT_EQ(f.luma(450, 240), gst::colours::axisX.y);
		EXPECT_EQ(f.luma(320, 150), gst::colours::axisY.y);
		int blue = 0;
		for (int y = 0; y < 480; ++y)
			for (int x = 0; x < 640; ++x)
				blue += f.luma(x, y) == gst::colours::axisZ.y && f.u(x, y) == gst::colours::axisZ.u;
		EXPECT_EQ(blue, 0);
	}
	{
		Frame f(GST_VIDEO_FORMAT_I420, scene);
		f.annotate({ pose }, MarkerSizes::parse("2:0.1"), camera);
		for (int y = 215; y < 265; ++y)
			for (int x = 295; x < 345; ++x)
				EXPECT_FALSE(f.changed(x, y)) << "axes drawn for a marker without size";
	}
}

} // namespace
} // namespace frappe::gsttest

int main(int argc, char **argv)
{
	::testing::InitGoogleTest(&argc, argv);
	::testing::AddGlobalTestEnvironment(new frappe::gsttest::GstEnvironment);
	return RUN_ALL_TESTS();
}
