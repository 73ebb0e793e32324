/* SPDX-License-Identifier: MIT
 *
 * gstfrappebuffer.h: what the element checks and logs about an input
 * buffer before it maps it: whether its memory holds the frame its caps and
 * GstVideoMeta describe (a buffer that lies would make the detector read,
 * or annotation write, past its end), which memory it is and why the
 * backend copied it; and the one
 * more buffer it asks of upstream's pools when it holds one (pipelined).
 */
#pragma once

#include <array>
#include <cstddef>

#include <gst/video/video.h>

#include <frappe/image.h>

namespace frappe::gst {

/* The kinds of lie, each warned about once per stream. */
enum class Lie : unsigned {
	None,
	NoMemory,     /* gst_buffer_n_memory() == 0 */
	Meta,         /* GstVideoMeta format, size or planes differ from the caps */
	Stride,       /* a stride negative or shorter than a row */
	Size,         /* a plane ends past the buffer */
	Memory,       /* a plane is not within the one memory its meta maps */
	Map,          /* gst_video_frame_map() failed all the same */
	Count,
};

/* Room for the description of a lie: filled on every lie, never allocated. */
constexpr std::size_t kLieText = 192;

/* Whether `buffer` holds the frame of the negotiated `info` as its
 * GstVideoMeta (or, without one, `info`) lays it out: the luma plane the
 * detector reads, and every plane when `allPlanes` (annotation writes the
 * chroma planes too); otherwise at least what gst_video_frame_map() needs
 * of the chroma planes (an offset inside the buffer; without a meta, the
 * caps' frame size). Arithmetic only: nothing is mapped or read. */
Lie checkBuffer(GstBuffer *buffer, const GstVideoInfo *info, bool allPlanes, std::array<char, kLieText> &why);

/* Warnings and debug lines about input buffers, once per stream (reset
 * at start). */
class BufferLog {
public:
	void reset() { *this = BufferLog(); }

	/* A GST_ELEMENT_WARNING the first time a kind of lie is seen, a debug
	 * line after: a producer that lies usually lies on every frame, and a
	 * warning per frame would flood the bus. An empty GAP buffer gets
	 * the debug line only. */
	void lie(GstElement *element, Lie lie, const char *why, GstBuffer *buffer);

	/* Which memory the first buffer is (dmabuf: not copied), and a
	 * warning for dmabuf input without a GstVideoMeta at a width whose
	 * default stride a producer may not use. */
	void memory(GstElement *element, GstBuffer *buffer, const GstVideoInfo *info, bool annotate);

	/* One debug line, the first time the backend copied a frame (`bytes`
	 * > 0) of `image` (from dma-buf memory when `dmabufInput`) before
	 * reading it, saying why: system memory (upstream did not
	 * take the offered pool, or none was offered), a luma plane not in one
	 * dma-buf memory, rows not 4-byte aligned in the dma-buf, or else the
	 * backend's own reason. */
	void copied(GstElement *element, const ImageView &image, bool dmabufInput, std::size_t bytes,
		    bool poolOffered);

private:
	std::array<bool, static_cast<std::size_t>(Lie::Count)> warnedLie_{};
	bool loggedMemory_ = false;
	bool warnedStride_ = false;
	bool loggedCopy_ = false;
};

/* Whether frames of `info`'s size are within frappe::Config's max_pixels
 * (the element leaves it at its default) and frappe::kMaxImageSide; a
 * GST_ELEMENT_ERROR if not, at negotiation rather than at every buffer. */
bool acceptFrameSize(GstElement *element, const GstVideoInfo *info);

/* Raises every pool's minimum (and a lower maximum) in an ALLOCATION
 * query by one: the buffer held while pipelined. */
void askOneMoreBuffer(GstElement *element, GstQuery *query);

/* Adds one frame of `info`'s frame rate (25 fps when unknown or variable)
 * to a LATENCY query's answer: the buffer held while pipelined. */
void addHeldFrameLatency(GstElement *element, GstQuery *query, const GstVideoInfo *info);

} /* namespace frappe::gst */
