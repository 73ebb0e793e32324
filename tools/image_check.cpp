// SPDX-License-Identifier: MIT
#include "image_check.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <limits>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace frappe::cli {

namespace {

using u64 = std::uint64_t;

/* Products of header fields saturate: a header may claim anything. */
u64 satMul(u64 a, u64 b)
{
	if (a != 0 && b > std::numeric_limits<u64>::max() / a)
		return std::numeric_limits<u64>::max();
	return a * b;
}

u64 be32(const std::uint8_t *p) { return (u64(p[0]) << 24) | (u64(p[1]) << 16) | (u64(p[2]) << 8) | p[3]; }
unsigned be16(const std::uint8_t *p) { return (unsigned(p[0]) << 8) | p[1]; }
u64 le32(const std::uint8_t *p) { return (u64(p[3]) << 24) | (u64(p[2]) << 16) | (u64(p[1]) << 8) | p[0]; }
unsigned le16(const std::uint8_t *p) { return (unsigned(p[1]) << 8) | p[0]; }

ImageHeader png(const std::uint8_t *d, std::size_t n)
{
	ImageHeader h;
	h.format = ImageFormat::Png;
	/* signature, then IHDR: length 13, type, width, height, ... */
	if (n < 8 + 8 + 13 + 4 || be32(d + 8) != 13 || std::memcmp(d + 12, "IHDR", 4) != 0) {
		h.error = "truncated or corrupt PNG: no IHDR chunk";
		return h;
	}
	h.width = static_cast<long long>(be32(d + 16));
	h.height = static_cast<long long>(be32(d + 20));
	/* Every chunk must lie inside the file and the last be IEND: a file cut
	 * anywhere fails one or the other. */
	std::size_t pos = 8;
	while (n - pos >= 12) {
		const u64 len = be32(d + pos);
		if (len > 0x7fffffffu) {
			h.error = "corrupt PNG: chunk length " + std::to_string(len) + " at byte " + std::to_string(pos);
			return h;
		}
		if (len > n - pos - 12) {
			h.error = "truncated PNG: the " + std::string(reinterpret_cast<const char *>(d + pos + 4), 4) +
				  " chunk at byte " + std::to_string(pos) + " runs past the end of the file";
			return h;
		}
		if (std::memcmp(d + pos + 4, "IEND", 4) == 0)
			return h;
		pos += 12 + static_cast<std::size_t>(len);
	}
	h.error = "truncated PNG: no IEND chunk";
	return h;
}

ImageHeader jpeg(const std::uint8_t *d, std::size_t n)
{
	ImageHeader h;
	h.format = ImageFormat::Jpeg;
	bool frame = false;
	std::size_t pos = 2;
	for (;;) {
		if (n - pos < 2) {
			h.error = "truncated JPEG: the file ends in its headers";
			return h;
		}
		if (d[pos] != 0xff) {
			h.error = "corrupt JPEG: no marker at byte " + std::to_string(pos);
			return h;
		}
		const std::uint8_t m = d[pos + 1];
		if (m == 0xff) { /* fill byte before a marker */
			++pos;
			continue;
		}
		if (m == 0x01 || (m >= 0xd0 && m <= 0xd8)) { /* markers without a length */
			pos += 2;
			continue;
		}
		if (m == 0xd9) {
			h.error = "corrupt JPEG: end of image before any scan";
			return h;
		}
		if (n - pos < 4) {
			h.error = "truncated JPEG: the file ends in its headers";
			return h;
		}
		const std::size_t len = be16(d + pos + 2);
		if (len < 2 || len > n - pos - 2) {
			h.error = "truncated JPEG: the segment at byte " + std::to_string(pos) + " runs past the end of the file";
			return h;
		}
		/* SOF0..SOF15 but DHT (C4), JPG (C8) and DAC (CC): P, Y, X */
		if (m >= 0xc0 && m <= 0xcf && m != 0xc4 && m != 0xc8 && m != 0xcc) {
			if (len < 7) {
				h.error = "corrupt JPEG: short frame header";
				return h;
			}
			h.height = be16(d + pos + 5);
			h.width = be16(d + pos + 7);
			frame = true;
		}
		pos += 2 + len;
		if (m == 0xda)
			break;
	}
	if (!frame) {
		h.error = "corrupt JPEG: a scan before any frame header";
		return h;
	}
	/* In entropy-coded data 0xff is followed by 0x00 or a restart marker,
	 * so the first FFD9 after the first scan is the end of the image; data
	 * after it (some cameras append some) is allowed. */
	for (std::size_t i = pos; i + 1 < n; ++i)
		if (d[i] == 0xff && d[i + 1] == 0xd9)
			return h;
	h.error = "truncated JPEG: no end-of-image marker (FFD9) after the scan";
	return h;
}

ImageHeader bmp(const std::uint8_t *d, std::size_t n)
{
	ImageHeader h;
	h.format = ImageFormat::Bmp;
	if (n < 26) {
		h.error = "truncated BMP: the file ends in its header";
		return h;
	}
	const u64 offset = le32(d + 10), info = le32(d + 14);
	u64 bits = 0, compression = 0;
	if (info == 12) { /* OS/2 core header: 16-bit sizes */
		h.width = le16(d + 18);
		h.height = le16(d + 20);
		bits = le16(d + 24);
	} else {
		if (info < 40 || n < 34) {
			h.error = "truncated or corrupt BMP header";
			return h;
		}
		h.width = static_cast<std::int32_t>(le32(d + 18));
		/* negative: rows top-down */
		h.height = std::abs(static_cast<long long>(static_cast<std::int32_t>(le32(d + 22))));
		bits = le16(d + 28);
		compression = le32(d + 30);
	}
	if (h.width < 0) {
		h.error = "corrupt BMP: negative width";
		return h;
	}
	/* Uncompressed (BI_RGB, BI_BITFIELDS): rows of whole 32-bit words. */
	if (compression == 0 || compression == 3) {
		const u64 stride = (satMul(static_cast<u64>(h.width), bits) + 31) / 32 * 4;
		const u64 need = satMul(stride, static_cast<u64>(h.height));
		if (need > n || offset > n - need)
			h.error = "truncated BMP: " + std::to_string(n) + " bytes, the header announces more pixel data";
	}
	return h;
}

/* Netpbm: "P5", whitespace and # comments, width, height, maxval, one
 * whitespace byte, the samples. */
ImageHeader pnm(const std::uint8_t *d, std::size_t n)
{
	ImageHeader h;
	h.format = ImageFormat::Pnm;
	const char kind = static_cast<char>(d[1]);
	const int fields = (kind == '1' || kind == '4') ? 2 : 3;
	u64 v[3] = {};
	std::size_t pos = 2;
	for (int f = 0; f < fields; ++f) {
		for (;;) {
			if (pos < n && d[pos] == '#') {
				while (pos < n && d[pos] != '\n' && d[pos] != '\r')
					++pos;
			} else if (pos < n && std::strchr(" \t\r\n\v\f", d[pos]) && d[pos]) {
				++pos;
			} else {
				break;
			}
		}
		if (pos >= n || d[pos] < '0' || d[pos] > '9') {
			h.error = "truncated or corrupt PNM header";
			return h;
		}
		for (; pos < n && d[pos] >= '0' && d[pos] <= '9'; ++pos)
			v[f] = std::min<u64>(satMul(v[f], 10) + (d[pos] - '0'), u64(1) << 40);
	}
	h.width = static_cast<long long>(v[0]);
	h.height = static_cast<long long>(v[1]);
	if (fields == 3 && (v[2] == 0 || v[2] > 65535)) {
		h.error = "corrupt PNM: maxval " + std::to_string(v[2]);
		return h;
	}
	if (kind < '4') /* plain (ASCII) samples: no fixed length to check */
		return h;
	const u64 sample = fields == 3 && v[2] > 255 ? 2 : 1;
	const u64 rowBytes = kind == '4' ? (v[0] + 7) / 8 : satMul(satMul(v[0], kind == '6' ? 3 : 1), sample);
	const u64 need = satMul(rowBytes, v[1]);
	const u64 have = pos < n ? n - pos - 1 : 0;
	if (need > have)
		h.error = "truncated PNM: " + std::to_string(have) + " bytes of samples, the header announces " +
			  std::to_string(need);
	return h;
}

} // namespace

ImageHeader inspectImage(const std::uint8_t *data, std::size_t size)
{
	static const std::uint8_t kPng[8] = { 0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n' };
	ImageHeader h;
	if (size >= 8 && std::memcmp(data, kPng, 8) == 0)
		h = png(data, size);
	else if (size >= 3 && data[0] == 0xff && data[1] == 0xd8 && data[2] == 0xff)
		h = jpeg(data, size);
	else if (size >= 2 && data[0] == 'B' && data[1] == 'M')
		h = bmp(data, size);
	else if (size >= 2 && data[0] == 'P' && data[1] >= '1' && data[1] <= '6')
		h = pnm(data, size);
	if (h.error.empty() && h.format != ImageFormat::Unknown && (h.width <= 0 || h.height <= 0))
		h.error = std::string("corrupt ") + formatName(h.format) + ": size " + std::to_string(h.width) + " x " +
			  std::to_string(h.height);
	return h;
}

const char *formatName(ImageFormat format)
{
	switch (format) {
	case ImageFormat::Png: return "PNG";
	case ImageFormat::Jpeg: return "JPEG";
	case ImageFormat::Bmp: return "BMP";
	case ImageFormat::Pnm: return "PNM";
	default: return "image";
	}
}

namespace {

/* Reads fd to its end into `bytes`, never more than max bytes: false with
 * `error` on a read error. `truncated` says whether more was there. */
bool readUpTo(int fd, const std::string &name, std::size_t max, std::vector<std::uint8_t> &bytes, bool &truncated,
	      std::string &error)
{
	std::size_t got = 0;
	truncated = false;
	for (;;) {
		if (got == bytes.size()) {
			if (got > max) {
				truncated = true;
				break;
			}
			/* Grow geometrically, to one byte past the limit at most. */
			bytes.resize(std::min(max + 1, std::max<std::size_t>(64 << 10, 2 * got)));
		}
		const ssize_t r = ::read(fd, bytes.data() + got, bytes.size() - got);
		if (r < 0 && errno == EINTR)
			continue;
		if (r < 0) {
			error = "cannot read " + name + ": " + std::strerror(errno);
			bytes.clear();
			return false;
		}
		if (r == 0)
			break;
		got += static_cast<std::size_t>(r);
	}
	bytes.resize(got);
	return true;
}

} // namespace

bool readFileBounded(const std::string &path, std::size_t limit, std::vector<std::uint8_t> &bytes, std::string &error)
{
	bytes.clear();
	/* O_NONBLOCK: opening a FIFO must not wait for a writer; fstat then
	 * refuses it. */
	const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
	if (fd < 0) {
		error = "cannot open " + path + ": " + std::strerror(errno);
		return false;
	}
	struct stat st {};
	bool ok = false;
	if (::fstat(fd, &st) != 0) {
		error = "cannot open " + path + ": " + std::strerror(errno);
	} else if (S_ISDIR(st.st_mode)) {
		error = "cannot open " + path + ": a directory, not a file";
	} else if (!S_ISREG(st.st_mode)) {
		error = "cannot open " + path + ": not a regular file (a device, FIFO or socket)";
	} else if (static_cast<unsigned long long>(st.st_size) > limit) {
		error = path + " is " + std::to_string(st.st_size) + " bytes, more than the limit of " +
			std::to_string(limit);
	} else {
		/* The file may grow while we read: never past its size + 1. */
		bytes.reserve(static_cast<std::size_t>(st.st_size) + 1);
		bool grew = false;
		ok = readUpTo(fd, path, static_cast<std::size_t>(st.st_size), bytes, grew, error);
		if (ok && grew) {
			error = path + " grew while being read";
			bytes.clear();
			ok = false;
		}
	}
	::close(fd);
	return ok;
}

bool readStreamBounded(int fd, const std::string &name, std::size_t limit, std::vector<std::uint8_t> &bytes,
		       std::string &error)
{
	bytes.clear();
	bool over = false;
	if (!readUpTo(fd, name, limit, bytes, over, error))
		return false;
	if (over) {
		error = name + " holds more than the limit of " + std::to_string(limit) + " bytes";
		bytes.clear();
		return false;
	}
	if (bytes.empty()) {
		error = name + " is empty";
		return false;
	}
	return true;
}

} // namespace frappe::cli
