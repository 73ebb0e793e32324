/* SPDX-License-Identifier: MIT
 *
 * gstfrappeframe.h: a buffer mapped for detection, from its push into the
 * frappe::Pipeline to its output.
 */
#pragma once

#include <gst/video/video.h>

#include <frappe/image.h>

namespace frappe::gst {

struct MappedFrame {
	GstBuffer *buffer = nullptr; /* writable, owned */
	GstVideoFrame frame{};       /* mapped until finished or discarded */
	bool writable = false;       /* mapped for annotation */
	ImageView image;             /* the luma plane, and its dma-buf when it lies in one */
	bool dmabufInput = false;    /* dma-buf memory before mapping merged several memories */

	/* Maps `buffer` (taking it) read-only, or read-write to annotate;
	 * false, the buffer left to the caller, when it cannot be mapped. */
	bool map(GstBuffer *buffer, const GstVideoInfo *info, bool writable);
	/* Unmaps the frame and gives the buffer to the caller. */
	GstBuffer *release();
	/* Unmaps the frame and drops the buffer. */
	void discard();
};

} /* namespace frappe::gst */
