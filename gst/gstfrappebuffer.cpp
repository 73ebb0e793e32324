/* SPDX-License-Identifier: MIT */
#include "gstfrappebuffer.h"

#include <algorithm>
#include <cstdarg>
#include <cstdint>
#include <utility>

#include <gst/allocators/gstdmabuf.h>

#include <frappe/config.h>
#include <frappe/detector.h>

#include "gstfrappepool.h"

GST_DEBUG_CATEGORY_EXTERN(gst_frappe_detect_debug);
#define GST_CAT_DEFAULT gst_frappe_detect_debug

namespace frappe::gst {

namespace {

Lie describe(std::array<char, kLieText> &why, Lie lie, const char *format, ...) G_GNUC_PRINTF(3, 4);

Lie describe(std::array<char, kLieText> &why, Lie lie, const char *format, ...)
{
	va_list args;
	va_start(args, format);
	g_vsnprintf(why.data(), static_cast<gulong>(why.size()), format, args);
	va_end(args);
	return lie;
}

/* Rows and bytes per row that a plane of `info`'s format holds at the
 * caps' size: the widest of its components (NV12's UV row is 2 * (w / 2)). */
void planeExtent(const GstVideoInfo *info, guint plane, guint64 &rows, guint64 &rowBytes)
{
	const GstVideoFormatInfo *finfo = info->finfo;
	gint comps[GST_VIDEO_MAX_COMPONENTS];
	gst_video_format_info_component(finfo, plane, comps);
	const gint width = GST_VIDEO_INFO_WIDTH(info);
	rows = static_cast<guint64>(GST_VIDEO_FORMAT_INFO_SCALE_HEIGHT(finfo, comps[0], GST_VIDEO_INFO_HEIGHT(info)));
	rowBytes = 0;
	for (guint k = 0; k < GST_VIDEO_MAX_COMPONENTS && comps[k] >= 0; ++k) {
		const gint c = comps[k];
		const auto w = static_cast<guint64>(GST_VIDEO_FORMAT_INFO_SCALE_WIDTH(finfo, c, width));
		const auto end = static_cast<guint64>(GST_VIDEO_FORMAT_INFO_POFFSET(finfo, c)) +
				 (w - 1) * static_cast<guint64>(GST_VIDEO_FORMAT_INFO_PSTRIDE(finfo, c)) + 1;
		rowBytes = std::max(rowBytes, end);
	}
}

} /* namespace */

Lie checkBuffer(GstBuffer *buffer, const GstVideoInfo *info, bool allPlanes, std::array<char, kLieText> &why)
{
	/* Before gst_buffer_peek_memory() or a map: both are CRITICALs on a
	 * buffer without memory. */
	if (gst_buffer_n_memory(buffer) == 0)
		return describe(why, Lie::NoMemory, "the buffer has no memory");

	const GstVideoMeta *meta = gst_buffer_get_video_meta(buffer);
	const guint planes = GST_VIDEO_INFO_N_PLANES(info);
	/* gst_video_frame_map() would take a larger meta's size as the frame's
	 * (and refuse a smaller or different one with a CRITICAL). */
	if (meta && (meta->format != GST_VIDEO_INFO_FORMAT(info) || meta->n_planes != planes ||
		     static_cast<gint>(meta->width) != GST_VIDEO_INFO_WIDTH(info) ||
		     static_cast<gint>(meta->height) != GST_VIDEO_INFO_HEIGHT(info)))
		return describe(why, Lie::Meta, "meta %ux%u %s n_planes %u, caps %dx%d %s n_planes %u",
				meta->width, meta->height, gst_video_format_to_string(meta->format), meta->n_planes,
				GST_VIDEO_INFO_WIDTH(info), GST_VIDEO_INFO_HEIGHT(info), GST_VIDEO_INFO_NAME(info),
				planes);

	const gsize size = gst_buffer_get_size(buffer);
	for (guint p = 0; p < planes; ++p) {
		const gsize offset = meta ? meta->offset[p] : GST_VIDEO_INFO_PLANE_OFFSET(info, p);
		const gint stride = meta ? meta->stride[p] : GST_VIDEO_INFO_PLANE_STRIDE(info, p);
		if (p > 0 && !allPlanes) {
			/* Neither read nor written, but gst_video_frame_map()
			 * maps the memory at each plane's offset: none there is
			 * a buffer it cannot map. */
			if (meta && offset >= size)
				return describe(why, Lie::Size, "plane %u starts at offset %" G_GSIZE_FORMAT
						", past the end of the buffer of %" G_GSIZE_FORMAT " bytes", p, offset, size);
			continue;
		}
		guint64 rows = 0, rowBytes = 0;
		planeExtent(info, p, rows, rowBytes);
		if (stride < 0 || static_cast<guint64>(stride) < rowBytes)
			return describe(why, Lie::Stride, "plane %u stride %d is shorter than a row of %" G_GUINT64_FORMAT
					" bytes", p, stride, rowBytes);
		/* Rows and stride are below 2^31: no overflow. */
		const guint64 need = (rows - 1) * static_cast<guint64>(stride) + rowBytes;
		if (offset > size || need > size - offset)
			return describe(why, Lie::Size, "plane %u needs %" G_GUINT64_FORMAT " bytes from offset %"
					G_GSIZE_FORMAT ", the buffer has %" G_GSIZE_FORMAT, p, need, offset, size);
		if (!meta)
			continue; /* gst_video_frame_map() maps the whole buffer */
		/* A meta maps, for each plane, only the memory its offset is in. */
		guint idx = 0, length = 0;
		gsize skip = 0;
		if (!gst_buffer_find_memory(buffer, offset, 1, &idx, &length, &skip) ||
		    need > gst_buffer_peek_memory(buffer, idx)->size - skip)
			return describe(why, Lie::Memory, "plane %u is not within one memory: %" G_GUINT64_FORMAT
					" bytes from offset %" G_GSIZE_FORMAT, p, need, offset);
	}
	/* Without a meta gst_video_frame_map() wants the caps' whole frame. */
	if (!meta && size < GST_VIDEO_INFO_SIZE(info))
		return describe(why, Lie::Size, "the buffer has %" G_GSIZE_FORMAT " bytes, a %dx%d %s frame %" G_GSIZE_FORMAT,
				size, GST_VIDEO_INFO_WIDTH(info), GST_VIDEO_INFO_HEIGHT(info), GST_VIDEO_INFO_NAME(info),
				GST_VIDEO_INFO_SIZE(info));
	return Lie::None;
}

void BufferLog::lie(GstElement *element, Lie lie, const char *why, GstBuffer *buffer)
{
	bool &warned = warnedLie_[static_cast<std::size_t>(lie)];
	/* An empty GAP buffer says it has nothing to show: not a lie. */
	const bool gap = lie == Lie::NoMemory && GST_BUFFER_FLAG_IS_SET(buffer, GST_BUFFER_FLAG_GAP);
	if (!warned && !gap) {
		warned = true;
		GST_ELEMENT_WARNING(element, STREAM, FORMAT,
				    ("Video buffer does not hold the frame it describes; passed through without detection"),
				    ("%s (buffer pts %" GST_TIME_FORMAT "); further buffers with this fault pass "
				     "through with a debug line only", why, GST_TIME_ARGS(GST_BUFFER_PTS(buffer))));
	} else {
		GST_DEBUG_OBJECT(element, "passing through %" GST_PTR_FORMAT ": %s", static_cast<void *>(buffer), why);
	}
}

void BufferLog::memory(GstElement *element, GstBuffer *buffer, const GstVideoInfo *info, bool annotate)
{
	GstMemory *mem = gst_buffer_peek_memory(buffer, 0);
	const bool dmabuf = mem && gst_is_dmabuf_memory(mem);
	if (!loggedMemory_) {
		loggedMemory_ = true;
		/* Without a meta, mapping several memories merges them. */
		const guint n = gst_buffer_get_video_meta(buffer) ? 1 : gst_buffer_n_memory(buffer);
		if (dmabuf)
			GST_DEBUG_OBJECT(element, "input is dmabuf memory (fd %d): mapped %s, %s",
					 gst_dmabuf_memory_get_fd(mem), annotate ? "read-write to annotate" : "read-only",
					 n > 1 ? "its memories merged into one (a copy)" : "not copied");
		else
			GST_DEBUG_OBJECT(element, "input is %s memory",
					 mem && mem->allocator ? mem->allocator->mem_type : "unknown");
	}
	/* Our own pool's buffers have the default layout without a meta. */
	if (dmabuf && !warnedStride_ && !gst_buffer_get_video_meta(buffer) && GST_VIDEO_INFO_WIDTH(info) % 64 != 0 &&
	    !isFramePool(buffer->pool)) {
		warnedStride_ = true;
		GST_WARNING_OBJECT(element, "dmabuf input %d pixels wide without GstVideoMeta: the "
				   "producer's stride may differ from the default one", GST_VIDEO_INFO_WIDTH(info));
	}
}

void BufferLog::copied(GstElement *element, const ImageView &image, bool dmabufInput, std::size_t bytes,
		       bool poolOffered)
{
	if (bytes == 0 || std::exchange(loggedCopy_, true))
		return;
	const char *why;
	if (image.dmabuf_fd >= 0 && (image.stride % 4 != 0 || image.dmabuf_offset % 4 != 0))
		why = "the luma rows in the dma-buf are not 4-byte aligned";
	else if (image.dmabuf_fd >= 0)
		why = "the backend did not read the dma-buf in place (its debug output says why)";
	else if (dmabufInput)
		why = "the luma plane is not within one dma-buf memory";
	else if (poolOffered)
		why = "system memory: upstream did not take the offered pool of GPU-visible buffers";
	else
		why = "system memory: no pool was offered (no ALLOCATION query, or no frame memory)";
	GST_DEBUG_OBJECT(element, "frame copied for the backend, %" G_GSIZE_FORMAT " bytes (luma stride %d, "
			 "dma-buf fd %d offset %" G_GSIZE_FORMAT "): %s; later copies are not logged", bytes,
			 image.stride, image.dmabuf_fd, image.dmabuf_offset, why);
}

bool acceptFrameSize(GstElement *element, const GstVideoInfo *info)
{
	const gint w = GST_VIDEO_INFO_WIDTH(info), h = GST_VIDEO_INFO_HEIGHT(info);
	GST_DEBUG_OBJECT(element, "%s %dx%d", GST_VIDEO_INFO_NAME(info), w, h);
	const long long maxPixels = frappe::Config{}.max_pixels;
	if (static_cast<long long>(w) * h > maxPixels) {
		GST_ELEMENT_ERROR(element, CORE, NEGOTIATION,
				  ("Frames of %dx%d are larger than the detector accepts (%lld pixels)", w, h, maxPixels),
				  (nullptr));
		return false;
	}
	/* What Detector::checkImage() refuses, refused here rather than at
	 * the first buffer. */
	if (w > frappe::kMaxImageSide || h > frappe::kMaxImageSide) {
		GST_ELEMENT_ERROR(element, CORE, NEGOTIATION,
				  ("Frames of %dx%d are wider or taller than the detector accepts (%d pixels a side)", w,
				   h, frappe::kMaxImageSide),
				  (nullptr));
		return false;
	}
	return true;
}

void askOneMoreBuffer(GstElement *element, GstQuery *query)
{
	for (guint i = 0; i < gst_query_get_n_allocation_pools(query); ++i) {
		GstBufferPool *pool = nullptr;
		guint size, min, max;
		gst_query_parse_nth_allocation_pool(query, i, &pool, &size, &min, &max);
		if (max != 0 && max < min + 1)
			max = min + 1;
		gst_query_set_nth_allocation_pool(query, i, pool, size, min + 1, max);
		GST_DEBUG_OBJECT(element, "asking for %u buffers in pool %u (one held)", min + 1, i);
		if (pool)
			gst_object_unref(pool);
	}
}

void addHeldFrameLatency(GstElement *element, GstQuery *query, const GstVideoInfo *info)
{
	gint n = GST_VIDEO_INFO_FPS_N(info), d = GST_VIDEO_INFO_FPS_D(info);
	if (n <= 0 || d <= 0) {
		n = 25;
		d = 1;
	}
	const GstClockTime frame = gst_util_uint64_scale_int(GST_SECOND, d, n);
	gboolean live;
	GstClockTime min, max;
	gst_query_parse_latency(query, &live, &min, &max);
	min += frame;
	if (GST_CLOCK_TIME_IS_VALID(max))
		max += frame;
	GST_DEBUG_OBJECT(element, "adding %" GST_TIME_FORMAT " of latency (one frame held)", GST_TIME_ARGS(frame));
	gst_query_set_latency(query, live, min, max);
}

} /* namespace frappe::gst */
