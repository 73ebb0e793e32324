// SPDX-License-Identifier: MIT
// frappe/image.h: a non-owning view of an 8-bit luma plane.
#pragma once

#include <cstddef>
#include <cstdint>

namespace frappe {

/// A borrowed 8-bit single-channel image: the luma plane of a camera frame.
/// Row y starts at data + y * stride. The view owns nothing; the caller keeps
/// the pixels alive for the duration of the call that receives the view.
struct ImageView {
	const std::uint8_t *data = nullptr;
	int width = 0;
	int height = 0;
	int stride = 0; ///< bytes from one row to the next, >= width
	/// When the pixels live in a dma-buf (a camera's or a GPU-visible
	/// pool's buffer): its file descriptor, borrowed like the pixels, and
	/// the byte offset of `data` in it; -1 for ordinary memory. A backend
	/// that can read the dma-buf in place (the VC4's QPUs) imports it
	/// instead of copying the frame; the CPU ignores both fields.
	int dmabuf_fd = -1;
	std::size_t dmabuf_offset = 0;

	constexpr ImageView() = default;
	constexpr ImageView(const std::uint8_t *d, int w, int h, int s)
		: data(d), width(w), height(h), stride(s) {}
	constexpr ImageView(const std::uint8_t *d, int w, int h)
		: data(d), width(w), height(h), stride(w) {}

	const std::uint8_t *row(int y) const
	{
		return data + static_cast<std::ptrdiff_t>(y) * stride;
	}
	std::uint8_t at(int x, int y) const { return row(y)[x]; }
};

/// A point in pixel coordinates: (0, 0) is the centre of the top-left pixel.
struct Point2f {
	float x = 0.0f;
	float y = 0.0f;
};

} // namespace frappe
