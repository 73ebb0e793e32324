// SPDX-License-Identifier: MIT
// image_check.h: what the CLI learns of an image file before decoding it.
//
// OpenCV 4.6 has no header-only query, and cv::imread both decodes a
// 30000 x 30000 PNG of 1 MB into 900 MB and accepts a JPEG cut in half with
// only a libjpeg warning. So the CLI reads the file itself (bounded), reads
// the size from the header and checks that the data reaches the format's end
// before handing the bytes to cv::imdecode.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace frappe::cli {

enum class ImageFormat { Unknown, Png, Jpeg, Bmp, Pnm, Pam, Pfm, WebP, Tiff, SunRaster, Hdr, Jpeg2000, Exr };

struct ImageHeader {
	ImageFormat format = ImageFormat::Unknown;
	long long width = 0, height = 0; /* 0 x 0 when the format is unknown */
	std::string error;               /* non-empty: malformed or truncated */
};

/// Reads the size and checks the completeness of PNG (IHDR ... IEND), JPEG
/// (SOFn, then EOI after the first scan), BMP and binary PNM (the pixel data
/// the header announces) files; reads the size of the other formats OpenCV
/// decodes (PAM, PFM, WebP, TIFF and BigTIFF, Sun raster, Radiance HDR,
/// JPEG 2000, OpenEXR) from their headers; anything else comes back
/// Unknown, without error, and is not to be decoded: its size is not
/// known before. Never reads outside [data, data + size).
ImageHeader inspectImage(const std::uint8_t *data, std::size_t size);

/// The name of a format, for messages.
const char *formatName(ImageFormat format);

/// Reads a regular file of at most `limit` bytes into `bytes`; on failure
/// returns false with `error` saying why ("cannot open X", "X is N bytes,
/// more than ...").
bool readFileBounded(const std::string &path, std::size_t limit, std::vector<std::uint8_t> &bytes,
		     std::string &error);

/// Bytes read from a stream of unknown length, in anonymous memory that
/// grows in place (mremap): never twice the stream in memory, as a
/// std::vector's doubling would be (528 MiB of standard input held 1.1 GB).
class StreamBytes {
public:
	StreamBytes() = default;
	~StreamBytes();
	StreamBytes(const StreamBytes &) = delete;
	StreamBytes &operator=(const StreamBytes &) = delete;

	const std::uint8_t *data() const { return data_; }
	std::size_t size() const { return size_; }
	bool empty() const { return size_ == 0; }
	std::uint8_t operator[](std::size_t i) const { return data_[i]; }
	void clear();

	/// Room for at least `n` bytes; false when the system has none.
	bool reserve(std::size_t n);
	std::uint8_t *end() { return data_ + size_; }
	std::size_t room() const { return capacity_ - size_; }
	void grow(std::size_t n) { size_ += n; }

private:
	std::uint8_t *data_ = nullptr;
	std::size_t size_ = 0, capacity_ = 0;
};

/// Reads a stream (standard input: fd 0) to its end, at most `limit`
/// bytes; false with `error` naming it ("standard input is empty", "...
/// holds more than the limit of N bytes", a read error).
bool readStreamBounded(int fd, const std::string &name, std::size_t limit, StreamBytes &bytes, std::string &error);

} // namespace frappe::cli
