/* SPDX-License-Identifier: MIT */
#include "gstfrappeframe.h"

#include <cstdint>
#include <utility>

namespace frappe::gst {

bool MappedFrame::map(GstBuffer *buf, const GstVideoInfo *info, bool forAnnotation)
{
	buffer = buf;
	writable = forAnnotation;
	/* NO_REF: a mapped frame holding a second ref would make the buffer
	 * read-only for the metas; we own the buffer until it is pushed. */
	const auto flags = static_cast<GstMapFlags>(static_cast<int>(writable ? GST_MAP_READWRITE : GST_MAP_READ) |
						    static_cast<int>(GST_VIDEO_FRAME_MAP_FLAG_NO_REF));
	if (!gst_video_frame_map(&frame, const_cast<GstVideoInfo *>(info), buffer, flags)) {
		gst_buffer_unref(buffer);
		buffer = nullptr;
		return false;
	}
	image = ImageView(static_cast<const std::uint8_t *>(GST_VIDEO_FRAME_COMP_DATA(&frame, 0)),
			  GST_VIDEO_FRAME_COMP_WIDTH(&frame, 0), GST_VIDEO_FRAME_COMP_HEIGHT(&frame, 0),
			  GST_VIDEO_FRAME_COMP_STRIDE(&frame, 0));
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
