/* SPDX-License-Identifier: MIT
 *
 * gstfrappepool.h: the pool of GPU-visible buffers frappedetect offers
 * upstream in the ALLOCATION query when the QPUs detect: dma-buf memory
 * from frappe::allocateFrameMemory() that they read in place, so that a
 * producer writing into system memory writes straight into it.
 */
#pragma once

#include <gst/video/video.h>

namespace frappe::gst {

/* Row alignment of the pool's frames when a GstVideoMeta says how they are
 * laid out, as a camera's; without one, GStreamer's default layout (rows
 * 4-byte aligned for every format the element takes). */
constexpr guint kPoolStrideAlign = 64;

/* Buffers the pool keeps at least (one being written, one being read). */
constexpr guint kPoolMinBuffers = 2;

/* A GstFrappePool of frame memory for `backend` ("vc4" or "vc4-emu"). */
GstBufferPool *newFramePool(const char *backend);

/* Whether `pool` is a GstFrappePool (its buffers' layout is known). */
bool isFramePool(GstBufferPool *pool);

/* Puts a pool of frame memory for `backend` first in an ALLOCATION query
 * (upstream takes the first pool it can use; downstream's stay after it),
 * its rows 64-byte aligned when the query has GstVideoMeta. False, with a
 * debug line, when the query has no video caps or the backend gives no
 * frame memory: upstream then allocates as before and the frames are
 * copied. */
bool offerFramePool(GstElement *element, GstQuery *query, const char *backend);

} /* namespace frappe::gst */
