// SPDX-License-Identifier: MIT
// The zero-copy camera path: with the QPUs (backend=vc4-emu here) the
// element offers upstream a pool of dma-buf buffers, 64-byte rows when a
// GstVideoMeta can say so; frames written into them are detected exactly as
// the CPU detects the same frame in system memory, pipelined or not, and the
// stats say nothing was copied. With backend=cpu no pool is offered.
#include <functional>
#include <string>
#include <vector>

#include <gst/allocators/gstdmabuf.h>
#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gst/video/video.h>
#include <gtest/gtest.h>

#include "gstfrappemeta.h"
#include "helpers.h"

using namespace frappe::gsttest;

static auto *const gstEnv = ::testing::AddGlobalTestEnvironment(new GstEnvironment);

namespace {

constexpr GstClockTime kFrame = GST_SECOND / 30;
constexpr const char *kDict = "aruco_mip_36h12";

/* Small frames (the emulator runs every pixel), 200 wide: GStreamer's
 * default stride is 200, the pool's with a GstVideoMeta 256. */
const FrameSpec kGray{ GST_VIDEO_FORMAT_GRAY8, 200, 150, 0 };
const FrameSpec kNv12{ GST_VIDEO_FORMAT_NV12, 200, 150, 0 };

std::vector<Placed> markersOf(int i)
{
	std::vector<Placed> m{ square(i + 1, 12.0f + 1.7f * static_cast<float>(i), 20.4f, 64.0f) };
	if (i % 2 == 0)
		m.push_back(tilted(i + 40, 150.0f, 90.0f, 56.0f, 0.3f + 0.05f * static_cast<float>(i)));
	return m;
}

GstCaps *capsOf(const FrameSpec &s)
{
	return gst_caps_from_string(capsString(s).c_str());
}

/* Frame i's markers on the background, into a luma plane. */
void drawLuma(std::uint8_t *data, int stride, const FrameSpec &s, int i)
{
	for (int y = 0; y < s.height; ++y)
		std::memset(data + static_cast<std::size_t>(y) * static_cast<std::size_t>(stride), s.background,
			    static_cast<std::size_t>(s.width));
	frappe::MutableImageView luma{ data, s.width, s.height, stride };
	for (const Placed &m : markersOf(i))
		frappe::renderMarker(luma, dict(kDict), m.id, m.corners);
}

void stamp(GstBuffer *buf, int i)
{
	GST_BUFFER_PTS(buf) = static_cast<GstClockTime>(i) * kFrame;
	GST_BUFFER_DURATION(buf) = kFrame;
}

/* Draws frame i into `buf` as its meta (or the caps) lays it out. */
void drawFrame(GstBuffer *buf, const FrameSpec &s, int i)
{
	GstVideoInfo info;
	gst_video_info_set_format(&info, s.format, static_cast<guint>(s.width), static_cast<guint>(s.height));
	GstVideoFrame frame;
	ASSERT_TRUE(gst_video_frame_map(&frame, &info, buf, GST_MAP_WRITE));
	for (guint p = 1; p < GST_VIDEO_FRAME_N_PLANES(&frame); ++p)
		std::memset(GST_VIDEO_FRAME_PLANE_DATA(&frame, p), 128,
			    static_cast<std::size_t>(GST_VIDEO_FRAME_PLANE_STRIDE(&frame, p)) *
				    static_cast<std::size_t>(GST_VIDEO_FRAME_COMP_HEIGHT(&frame, 1)));
	drawLuma(static_cast<std::uint8_t *>(GST_VIDEO_FRAME_PLANE_DATA(&frame, 0)),
		 GST_VIDEO_FRAME_PLANE_STRIDE(&frame, 0), s, i);
	gst_video_frame_unmap(&frame);
	stamp(buf, i);
}

guint64 copiedBytes(GstHarness *h)
{
	GstStructure *stats = nullptr;
	g_object_get(detector(h), "stats", &stats, nullptr);
	guint64 copied = G_MAXUINT64;
	EXPECT_TRUE(stats && gst_structure_get_uint64(stats, "copied-bytes", &copied));
	if (stats)
		gst_structure_free(stats);
	return copied;
}

/* Pushes n frames through the harness, each made by `make(i)`, and returns
 * each output's markers in order (timestamps checked) and, per output, the
 * stats' copied-bytes after it came out. */
template<typename Make>
std::vector<std::vector<Found>> runFrames(GstHarness *h, int n, Make make, std::vector<guint64> *copied = nullptr)
{
	std::vector<std::vector<Found>> frames;
	auto take = [&](GstBuffer *out) {
		EXPECT_EQ(GST_BUFFER_PTS(out), static_cast<GstClockTime>(frames.size()) * kFrame);
		frames.push_back(foundMarkers(out));
		if (copied)
			copied->push_back(copiedBytes(h));
		gst_buffer_unref(out);
	};
	for (int i = 0; i < n; ++i) {
		EXPECT_EQ(gst_harness_push(h, make(i)), GST_FLOW_OK) << "frame " << i;
		while (GstBuffer *out = gst_harness_try_pull(h))
			take(out);
	}
	EXPECT_TRUE(gst_harness_push_event(h, gst_event_new_eos()));
	while (GstBuffer *out = gst_harness_try_pull(h))
		take(out);
	EXPECT_EQ(frames.size(), static_cast<std::size_t>(n));
	return frames;
}

GstHarness *harness(const std::string &launch, const FrameSpec &s, bool downstreamMeta)
{
	GstHarness *h = gst_harness_new_parse(launch.c_str());
	if (downstreamMeta)
		gst_harness_add_propose_allocation_meta(h, GST_VIDEO_META_API_TYPE, nullptr);
	gst_harness_set_src_caps_str(h, capsString(s).c_str());
	return h;
}

/* What an application upstream does (appsrc): asks the element for a pool. */
GstQuery *askAllocation(GstHarness *h, const FrameSpec &s)
{
	GstCaps *caps = capsOf(s);
	GstQuery *q = gst_query_new_allocation(caps, TRUE);
	gst_caps_unref(caps);
	EXPECT_TRUE(gst_pad_peer_query(h->srcpad, q));
	return q;
}

/* A harness around `launch` whose downstream reads GstVideoMeta when
 * `meta`, and the first pool the element offered, configured and active as
 * upstream would take it (with the GstVideoMeta option when `meta`, its
 * buffers `extra` bytes larger than asked); pool is nullptr when none was
 * offered. */
struct PoolHarness {
	PoolHarness(const std::string &launch, const FrameSpec &s, bool meta, guint extra = 0)
		: h(harness(launch, s, meta)), query(askAllocation(h, s))
	{
		if (gst_query_get_n_allocation_pools(query) == 0)
			return;
		guint size = 0, max = 0;
		gst_query_parse_nth_allocation_pool(query, 0, &pool, &size, &min, &max);
		GstStructure *config = gst_buffer_pool_get_config(pool);
		GstCaps *caps = capsOf(s);
		gst_buffer_pool_config_set_params(config, caps, size + extra, min, max);
		gst_caps_unref(caps);
		if (meta)
			gst_buffer_pool_config_add_option(config, GST_BUFFER_POOL_OPTION_VIDEO_META);
		EXPECT_TRUE(gst_buffer_pool_set_config(pool, config));
		EXPECT_TRUE(gst_buffer_pool_set_active(pool, TRUE));
	}
	~PoolHarness()
	{
		if (pool) {
			gst_buffer_pool_set_active(pool, FALSE);
			gst_object_unref(pool);
		}
		gst_query_unref(query);
		gst_harness_teardown(h);
	}
	PoolHarness(const PoolHarness &) = delete;
	PoolHarness &operator=(const PoolHarness &) = delete;
	/* A buffer of the pool, which must be there. */
	GstBuffer *acquire()
	{
		GstBuffer *buf = nullptr;
		EXPECT_EQ(gst_buffer_pool_acquire_buffer(pool, &buf, nullptr), GST_FLOW_OK);
		return buf;
	}
	GstHarness *h;
	GstQuery *query;
	GstBufferPool *pool = nullptr;
	guint min = 0;
};

/* The CPU's markers for frames 0..n-1 in system memory. */
std::vector<std::vector<Found>> cpuMarkers(const FrameSpec &s, int n)
{
	GstHarness *h = harness("frappedetect backend=cpu", s, false);
	const auto frames = runFrames(h, n, [&](int i) {
		return makeFrame(s, markersOf(i), dict(kDict), static_cast<GstClockTime>(i) * kFrame, kFrame);
	});
	gst_harness_teardown(h);
	for (int i = 0; i < n; ++i)
		EXPECT_EQ(frames[static_cast<std::size_t>(i)].size(), markersOf(i).size()) << "cpu frame " << i;
	return frames;
}

} // namespace

TEST(ZeroCopy, CpuBackendOffersNoPool)
{
	PoolHarness p("frappedetect backend=cpu", kGray, true);
	EXPECT_EQ(gst_query_get_n_allocation_pools(p.query), 0u);
	EXPECT_EQ(p.pool, nullptr);
}

/* The pool: dma-buf memory, one memory a buffer, 64-byte rows with a
 * GstVideoMeta (every plane), GStreamer's layout without; pipelined, one
 * more buffer for the one held. */
TEST(ZeroCopy, Vc4EmuOffersAPoolOfDmabufFrames)
{
	for (const FrameSpec &s : { kGray, kNv12 }) {
		for (bool pipelined : { false, true }) {
			PoolHarness p(std::string("frappedetect backend=vc4-emu pipelined=") +
					      (pipelined ? "true" : "false"),
				      s, true);
			ASSERT_NE(p.pool, nullptr);
			EXPECT_STREQ(G_OBJECT_TYPE_NAME(p.pool), "GstFrappePool");
			EXPECT_EQ(p.min, pipelined ? 3u : 2u);
			GstBuffer *buf = p.acquire();
			ASSERT_EQ(gst_buffer_n_memory(buf), 1u);
			EXPECT_TRUE(gst_is_dmabuf_memory(gst_buffer_peek_memory(buf, 0)));
			const GstVideoMeta *meta = gst_buffer_get_video_meta(buf);
			ASSERT_NE(meta, nullptr);
			EXPECT_EQ(meta->stride[0], 256);
			EXPECT_EQ(meta->offset[0], 0u);
			if (s.format == GST_VIDEO_FORMAT_NV12) {
				EXPECT_EQ(meta->stride[1], 256);
				EXPECT_EQ(meta->offset[1], 256u * 150u);
			}
			gst_buffer_unref(buf);
		}
	}

	/* A downstream that reads no GstVideoMeta: GStreamer's own layout. */
	PoolHarness p("frappedetect backend=vc4-emu", kGray, false);
	ASSERT_NE(p.pool, nullptr);
	GstBuffer *buf = p.acquire();
	EXPECT_TRUE(gst_is_dmabuf_memory(gst_buffer_peek_memory(buf, 0)));
	EXPECT_EQ(gst_buffer_get_video_meta(buf), nullptr);
	EXPECT_EQ(gst_buffer_get_size(buf), 200u * 150u);
	gst_buffer_unref(buf);
}

/* An application writing into the offered pool (as appsrc would): the
 * markers are exactly the CPU's on the same frames in system memory, every
 * buffer comes out once in order, pipelined too (a held frame's dma-buf
 * stays valid: its buffer is held), and nothing was copied. */
TEST(ZeroCopy, FramesInThePoolAreReadInPlaceWithTheCpuMarkers)
{
	const int n = 4;
	const auto cpu = cpuMarkers(kGray, n);
	for (bool pipelined : { false, true }) {
		PoolHarness p(std::string("frappedetect backend=vc4-emu pipelined=") + (pipelined ? "true" : "false"),
			      kGray, true);
		ASSERT_NE(p.pool, nullptr);
		std::vector<guint64> copied;
		const auto emu = runFrames(
			p.h, n,
			[&](int i) {
				GstBuffer *buf = p.acquire();
				drawFrame(buf, kGray, i);
				/* Written in place, not into a copy. */
				EXPECT_TRUE(gst_is_dmabuf_memory(gst_buffer_peek_memory(buf, 0)));
				return buf;
			},
			&copied);
		EXPECT_EQ(emu, cpu) << "pipelined=" << pipelined;
		EXPECT_EQ(copied, std::vector<guint64>(n, 0)) << "pipelined=" << pipelined;
	}
}

/* The luma plane away from its dma-buf's start: in a memory that starts
 * 256 bytes into the fd, 64 bytes into that memory by its GstVideoMeta.
 * The QPUs must read it at fd offset 320 and find the CPU's markers. */
TEST(ZeroCopy, LumaPlaneAtAnOffsetInItsDmabuf)
{
	const int n = 2;
	const auto cpu = cpuMarkers(kGray, n);
	PoolHarness p("frappedetect backend=vc4-emu", kGray, true, 1024);
	ASSERT_NE(p.pool, nullptr);
	std::vector<guint64> copied;
	const auto emu = runFrames(
		p.h, n,
		[&](int i) {
			GstBuffer *whole = p.acquire();
			GstMemory *mem = gst_buffer_peek_memory(whole, 0);
			const gint stride = 256;
			const gsize bytes = 64 + static_cast<gsize>(stride) * 150;
			EXPECT_GE(mem->size, 256 + bytes);
			/* Drawn before it is shared: a shared memory is read-only,
			 * and mapping it to write would copy it. */
			GstMapInfo map;
			EXPECT_TRUE(gst_memory_map(mem, &map, GST_MAP_WRITE));
			drawLuma(map.data + 256 + 64, stride, kGray, i);
			gst_memory_unmap(mem, &map);
			GstBuffer *buf = gst_buffer_new();
			gst_buffer_append_memory(buf, gst_memory_share(mem, 256, static_cast<gssize>(bytes)));
			gsize offset[GST_VIDEO_MAX_PLANES] = { 64 };
			gint strides[GST_VIDEO_MAX_PLANES] = { stride };
			gst_buffer_add_video_meta_full(buf, GST_VIDEO_FRAME_FLAG_NONE, GST_VIDEO_FORMAT_GRAY8, 200, 150,
						       1, offset, strides);
			EXPECT_TRUE(gst_is_dmabuf_memory(gst_buffer_peek_memory(buf, 0)));
			stamp(buf, i);
			gst_buffer_unref(whole); /* the shared memory keeps its fd */
			return buf;
		},
		&copied);
	EXPECT_EQ(emu, cpu);
	EXPECT_EQ(copied, std::vector<guint64>(n, 0));
}

/* The CPU reads system memory in place: nothing copied. */
TEST(ZeroCopy, SystemMemoryCopiedBytesOnTheCpuAreZero)
{
	GstHarness *h = harness("frappedetect backend=cpu", kGray, false);
	std::vector<guint64> copied;
	runFrames(
		h, 2, [&](int i) { return makeFrame(kGray, markersOf(i), dict(kDict), static_cast<GstClockTime>(i) * kFrame); },
		&copied);
	EXPECT_EQ(copied, std::vector<guint64>(2, 0));
	gst_harness_teardown(h);
}

/* The element's debug lines that hold `words`, while it lives. */
struct DebugLines {
	explicit DebugLines(const char *words) : words(words)
	{
		gst_debug_set_threshold_for_name("frappedetect", GST_LEVEL_DEBUG);
		/* The function, not its macro (which compares with a function pointer as void *). */
		(gst_debug_add_log_function)(&DebugLines::log, this, nullptr);
	}
	~DebugLines()
	{
		gst_debug_remove_log_function_by_data(this);
		gst_debug_set_threshold_for_name("frappedetect", GST_LEVEL_WARNING);
	}
	DebugLines(const DebugLines &) = delete;
	DebugLines &operator=(const DebugLines &) = delete;
	static void log(GstDebugCategory *cat, GstDebugLevel, const gchar *, const gchar *, gint, GObject *,
			GstDebugMessage *message, gpointer data)
	{
		auto *self = static_cast<DebugLines *>(data);
		const std::string text = gst_debug_message_get(message);
		if (g_str_equal(gst_debug_category_get_name(cat), "frappedetect") &&
		    text.find(self->words) != std::string::npos)
			self->lines.push_back(text);
	}
	std::string words;
	std::vector<std::string> lines;
};

/* Frame i in system memory. */
GstBuffer *systemFrame(int i)
{
	return makeFrame(kGray, markersOf(i), dict(kDict), static_cast<GstClockTime>(i) * kFrame);
}

/* Frame i split at its middle byte over two dma-buf memories of the pool. */
GstBuffer *splitFrame(PoolHarness &p, int i)
{
	GstBuffer *sys = systemFrame(i);
	GstMapInfo in;
	EXPECT_TRUE(gst_buffer_map(sys, &in, GST_MAP_READ));
	GstBuffer *out = gst_buffer_new();
	const gsize half = in.size / 2, sizes[2] = { half, in.size - half };
	for (int k = 0; k < 2; ++k) {
		GstBuffer *whole = p.acquire();
		GstMemory *mem = gst_buffer_peek_memory(whole, 0);
		GstMapInfo map;
		EXPECT_TRUE(gst_memory_map(mem, &map, GST_MAP_WRITE));
		std::memcpy(map.data, in.data + (k ? half : 0), sizes[k]);
		gst_memory_unmap(mem, &map);
		gst_buffer_append_memory(out, gst_memory_share(mem, 0, static_cast<gssize>(sizes[k])));
		gst_buffer_unref(whole);
	}
	gst_buffer_unmap(sys, &in);
	gst_buffer_unref(sys);
	stamp(out, i);
	return out;
}

/* Waits for the vc4 side's copy counter (issue 14, the lead enables it at
 * the merge): the QPUs copy a 200x150 frame of stride 200 that is not in
 * one dma-buf, 30000 bytes, on every frame, with the CPU's markers, and one
 * debug line says why, once a stream: no pool was offered (nobody asked),
 * upstream asked and did not use it, or the frame spans two memories. */
TEST(ZeroCopy, FramesNotInOneDmabufAreCopiedForTheQpus)
{
	const auto cpu = cpuMarkers(kGray, 2);
	auto expectCopied = [&](GstHarness *h, const std::function<GstBuffer *(int)> &make, const char *why) {
		DebugLines copies("frame copied for the backend");
		std::vector<guint64> copied;
		const auto emu = runFrames(h, 2, make, &copied);
		EXPECT_EQ(copied, std::vector<guint64>(2, 200u * 150u)) << why;
		EXPECT_EQ(emu, cpu) << why;
		ASSERT_EQ(copies.lines.size(), 1u) << why;
		EXPECT_NE(copies.lines[0].find("30000 bytes"), std::string::npos) << copies.lines[0];
		EXPECT_NE(copies.lines[0].find(why), std::string::npos) << copies.lines[0];
	};
	GstHarness *h = harness("frappedetect backend=vc4-emu", kGray, false);
	expectCopied(h, systemFrame, "no pool was offered");
	gst_harness_teardown(h);
	{
		PoolHarness p("frappedetect backend=vc4-emu", kGray, false);
		expectCopied(p.h, systemFrame, "upstream did not take the offered pool");
	}
	PoolHarness p("frappedetect backend=vc4-emu", kGray, false);
	expectCopied(p.h, [&](int i) { return splitFrame(p, i); }, "not within one dma-buf memory");
}

namespace {

/* Runs videotestsrc into frappedetect `backend` and counts the buffers the
 * element receives and how many of them are dma-buf memory. */
void countInput(const char *backend, int &buffers, int &dmabufs)
{
	const std::string launch = std::string("videotestsrc num-buffers=3 ! ") + capsString(kGray) +
				   " ! frappedetect name=d backend=" + backend + " ! fakesink sync=false";
	GstElement *pipeline = gst_parse_launch(launch.c_str(), nullptr);
	ASSERT_NE(pipeline, nullptr);
	GstElement *d = gst_bin_get_by_name(GST_BIN(pipeline), "d");
	GstPad *sink = gst_element_get_static_pad(d, "sink");
	struct Count {
		int buffers = 0, dmabufs = 0;
	} count;
	gst_pad_add_probe(
		sink, GST_PAD_PROBE_TYPE_BUFFER,
		[](GstPad *, GstPadProbeInfo *info, gpointer data) {
			auto *c = static_cast<Count *>(data);
			GstBuffer *b = GST_PAD_PROBE_INFO_BUFFER(info);
			++c->buffers;
			if (gst_buffer_n_memory(b) == 1 && gst_is_dmabuf_memory(gst_buffer_peek_memory(b, 0)))
				++c->dmabufs;
			return GST_PAD_PROBE_OK;
		},
		&count, nullptr);
	ASSERT_NE(gst_element_set_state(pipeline, GST_STATE_PLAYING), GST_STATE_CHANGE_FAILURE);
	waitForEos(pipeline);
	gst_element_set_state(pipeline, GST_STATE_NULL);
	gst_object_unref(sink);
	gst_object_unref(d);
	gst_object_unref(pipeline);
	buffers = count.buffers;
	dmabufs = count.dmabufs;
}

} // namespace

/* videotestsrc takes the pool the element offers and writes into it. */
TEST(ZeroCopy, VideotestsrcWritesIntoTheOfferedPool)
{
	int buffers = 0, dmabufs = 0;
	countInput("vc4-emu", buffers, dmabufs);
	EXPECT_EQ(buffers, 3);
	EXPECT_EQ(dmabufs, 3);
	countInput("cpu", buffers, dmabufs);
	EXPECT_EQ(buffers, 3);
	EXPECT_EQ(dmabufs, 0);
}
