/* SPDX-License-Identifier: MIT
 *
 * gstfrappeframe.cpp: a buffer mapped for detection, and the dma-buf its
 * luma plane lies in.
 */
#include "gstfrappeframe.h"

#include <cstdint>
#include <utility>

#include <gst/allocators/gstdmabuf.h>

namespace frappe::gst {

namespace {

/* The dma-buf the luma plane lies in, for a backend that reads it in place
 * (the QPUs): only when the whole plane is in one dma-buf memory, at the
 * offset of that memory in its fd (a shared memory starts past its fd's
 * start) plus the plane's offset in the memory. */
void lumaDmabuf(GstBuffer *buffer, const GstVideoFrame &frame, ImageView &image)
{
	const gsize offset = GST_VIDEO_FRAME_PLANE_OFFSET(&frame, 0); /* the meta's, if any */
	const gsize bytes = static_cast<gsize>(image.height - 1) * static_cast<gsize>(image.stride) +
			    static_cast<gsize>(image.width);
	guint idx = 0, length = 0;
	gsize skip = 0;
	if (image.width <= 0 || image.height <= 0 ||
	    !gst_buffer_find_memory(buffer, offset, bytes, &idx, &length, &skip) || length != 1)
		return;
	GstMemory *mem = gst_buffer_peek_memory(buffer, idx);
	if (!gst_is_dmabuf_memory(mem))
		return;
	image.dmabuf_fd = gst_dmabuf_memory_get_fd(mem);
	image.dmabuf_offset = mem->offset + skip;
}

} /* namespace */

bool MappedFrame::map(GstBuffer *buf, const GstVideoInfo *info, bool forAnnotation)
{
	buffer = buf;
	writable = forAnnotation;
	/* NO_REF: a mapped frame holding a second ref would make the buffer
	 * read-only for the metas; we own the buffer until it is pushed. */
	const auto flags = static_cast<GstMapFlags>(static_cast<int>(writable ? GST_MAP_READWRITE : GST_MAP_READ) |
						    static_cast<int>(GST_VIDEO_FRAME_MAP_FLAG_NO_REF));
	/* Mapping a buffer of several memories without a meta merges them
	 * into system memory (and replaces them). */
	dmabufInput = gst_is_dmabuf_memory(gst_buffer_peek_memory(buffer, 0));
	if (!gst_video_frame_map(&frame, const_cast<GstVideoInfo *>(info), buffer, flags)) {
		buffer = nullptr; /* still the caller's */
		return false;
	}
	image = ImageView(static_cast<const std::uint8_t *>(GST_VIDEO_FRAME_COMP_DATA(&frame, 0)),
			  GST_VIDEO_FRAME_COMP_WIDTH(&frame, 0), GST_VIDEO_FRAME_COMP_HEIGHT(&frame, 0),
			  GST_VIDEO_FRAME_COMP_STRIDE(&frame, 0));
	lumaDmabuf(buffer, frame, image);
	return true;
}

GstBuffer *MappedFrame::release()
{
	gst_video_frame_unmap(&frame);
	return std::exchange(buffer, nullptr);
}

void MappedFrame::discard()
{
	gst_buffer_unref(release());
}

} /* namespace frappe::gst */
