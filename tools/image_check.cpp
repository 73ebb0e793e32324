// SPDX-License-Identifier: MIT
#include "image_check.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string_view>

#include <fcntl.h>
#include <sys/mman.h>
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


/* The sizes of the other formats OpenCV 4.6 decodes, from their headers:
 * only the size, which is what the pixel limit needs before decoding. */

std::string_view textOf(const std::uint8_t *d, std::size_t n) { return { reinterpret_cast<const char *>(d), n }; }

/* "P7": WIDTH, HEIGHT ... ENDHDR lines. */
ImageHeader pam(const std::uint8_t *d, std::size_t n)
{
	ImageHeader h;
	h.format = ImageFormat::Pam;
	const std::string_view t = textOf(d, std::min<std::size_t>(n, 4096));
	for (std::size_t pos = 3; pos < t.size();) {
		const std::size_t end = std::min(t.find('\n', pos), t.size());
		const std::string_view line = t.substr(pos, end - pos);
		auto field = [&](std::string_view key, long long &v) {
			if (line.substr(0, key.size()) == key && line.size() > key.size())
				v = std::atoll(std::string(line.substr(key.size())).c_str());
		};
		field("WIDTH ", h.width);
		field("HEIGHT ", h.height);
		if (line.substr(0, 6) == "ENDHDR")
			return h;
		pos = end + 1;
	}
	h.error = "truncated or corrupt PAM header: no ENDHDR";
	return h;
}

/* "PF" / "Pf", whitespace, width, height, scale. */
ImageHeader pfm(const std::uint8_t *d, std::size_t n)
{
	ImageHeader h;
	h.format = ImageFormat::Pfm;
	const std::string t(textOf(d + 2, std::min<std::size_t>(n - 2, 256)));
	long long w = 0, hh = 0;
	if (std::sscanf(t.c_str(), "%lld %lld", &w, &hh) != 2) {
		h.error = "truncated or corrupt PFM header";
		return h;
	}
	h.width = w;
	h.height = hh;
	return h;
}

/* RIFF ... WEBP, then a VP8, VP8L or VP8X chunk. */
ImageHeader webp(const std::uint8_t *d, std::size_t n)
{
	ImageHeader h;
	h.format = ImageFormat::WebP;
	if (n < 30) {
		h.error = "truncated WebP header";
		return h;
	}
	if (std::memcmp(d + 12, "VP8 ", 4) == 0 && d[23] == 0x9d && d[24] == 0x01 && d[25] == 0x2a) {
		h.width = le16(d + 26) & 0x3fff;
		h.height = le16(d + 28) & 0x3fff;
	} else if (std::memcmp(d + 12, "VP8L", 4) == 0 && d[20] == 0x2f) {
		const u64 bits = le32(d + 21);
		h.width = static_cast<long long>((bits & 0x3fff) + 1);
		h.height = static_cast<long long>(((bits >> 14) & 0x3fff) + 1);
	} else if (std::memcmp(d + 12, "VP8X", 4) == 0) {
		h.width = static_cast<long long>((le32(d + 24) & 0xffffff) + 1);
		h.height = static_cast<long long>((le32(d + 27) & 0xffffff) + 1);
	} else {
		h.error = "corrupt WebP: no VP8, VP8L or VP8X chunk first";
	}
	return h;
}

/* The first directory's ImageWidth (256) and ImageLength (257), as
 * OpenCV's TIFF decoder reads the first page; BigTIFF too. */
ImageHeader tiff(const std::uint8_t *d, std::size_t n)
{
	ImageHeader h;
	h.format = ImageFormat::Tiff;
	const bool le = d[0] == 'I';
	auto get = [&](u64 at, int bytes) -> u64 {
		u64 v = 0;
		for (int i = 0; i < bytes; ++i)
			v |= u64(d[at + static_cast<u64>(le ? i : bytes - 1 - i)]) << (8 * i);
		return v;
	};
	const bool big = get(2, 2) == 43;
	const u64 ifd = big ? (n >= 16 ? get(8, 8) : 0) : get(4, 4);
	const u64 countBytes = big ? 8 : 2, entryBytes = big ? 20 : 12;
	if (ifd == 0 || ifd > n || n - ifd < countBytes) {
		h.error = "truncated or corrupt TIFF: no first directory";
		return h;
	}
	const u64 count = get(ifd, static_cast<int>(countBytes));
	if (count > (n - ifd - countBytes) / entryBytes) {
		h.error = "truncated TIFF: its first directory runs past the end of the file";
		return h;
	}
	for (u64 i = 0; i < count; ++i) {
		const u64 e = ifd + countBytes + i * entryBytes;
		const u64 tag = get(e, 2), type = get(e + 2, 2);
		const u64 at = e + (big ? 12 : 8);
		/* SHORT, LONG, LONG8: the value in the entry. */
		const u64 v = type == 3 ? get(at, 2) : type == 4 ? get(at, 4) : type == 16 && big ? get(at, 8) : 0;
		const long long value = static_cast<long long>(std::min<u64>(v, u64(1) << 40));
		if (tag == 256)
			h.width = value;
		else if (tag == 257)
			h.height = value;
	}
	return h;
}

ImageHeader sunRaster(const std::uint8_t *d, std::size_t n)
{
	ImageHeader h;
	h.format = ImageFormat::SunRaster;
	if (n < 12) {
		h.error = "truncated Sun raster header";
		return h;
	}
	h.width = static_cast<long long>(be32(d + 4));
	h.height = static_cast<long long>(be32(d + 8));
	return h;
}

/* "#?RADIANCE" lines up to a blank one, then "-Y height +X width" (any
 * signs and order). */
ImageHeader hdr(const std::uint8_t *d, std::size_t n)
{
	ImageHeader h;
	h.format = ImageFormat::Hdr;
	const std::string_view t = textOf(d, std::min<std::size_t>(n, 64 << 10));
	const std::size_t blank = t.find("\n\n");
	if (blank == std::string_view::npos) {
		h.error = "truncated or corrupt Radiance HDR header";
		return h;
	}
	const std::string line(t.substr(blank + 2, std::min<std::size_t>(t.size() - blank - 2, 64)));
	char s1 = 0, a1 = 0, s2 = 0, a2 = 0;
	long long v1 = 0, v2 = 0;
	if (std::sscanf(line.c_str(), "%c%c %lld %c%c %lld", &s1, &a1, &v1, &s2, &a2, &v2) != 6 ||
	    !((a1 == 'Y' && a2 == 'X') || (a1 == 'X' && a2 == 'Y'))) {
		h.error = "corrupt Radiance HDR: no resolution line";
		return h;
	}
	h.width = a1 == 'X' ? v1 : v2;
	h.height = a1 == 'Y' ? v1 : v2;
	return h;
}

/* A JP2 file's ihdr box (in jp2h), or a codestream's SIZ marker. */
ImageHeader jpeg2000(const std::uint8_t *d, std::size_t n)
{
	ImageHeader h;
	h.format = ImageFormat::Jpeg2000;
	if (d[0] == 0xff) { /* FF4F FF51: SIZ, Lsiz, Rsiz, Xsiz, Ysiz, XOsiz, YOsiz */
		if (n < 4 + 2 + 2 + 16) {
			h.error = "truncated JPEG 2000 codestream header";
			return h;
		}
		const u64 x = be32(d + 8), y = be32(d + 12), xo = be32(d + 16), yo = be32(d + 20);
		h.width = x > xo ? static_cast<long long>(x - xo) : 0;
		h.height = y > yo ? static_cast<long long>(y - yo) : 0;
		return h;
	}
	/* Boxes: length (32 bits, 1: 64 bits follow, 0: to the end), type. */
	for (std::size_t pos = 0; n - pos >= 8;) {
		u64 len = be32(d + pos);
		std::size_t head = 8;
		if (len == 1 && n - pos >= 16) {
			len = (be32(d + pos + 8) << 32) | be32(d + pos + 12);
			head = 16;
		} else if (len == 0) {
			len = n - pos;
		}
		if (std::memcmp(d + pos + 4, "jp2h", 4) == 0) {
			pos += head; /* into the superbox */
			continue;
		}
		if (std::memcmp(d + pos + 4, "ihdr", 4) == 0) {
			if (n - pos < head + 8)
				break;
			h.height = static_cast<long long>(be32(d + pos + head));
			h.width = static_cast<long long>(be32(d + pos + head + 4));
			return h;
		}
		if (len < head || len > n - pos)
			break;
		pos += static_cast<std::size_t>(len);
	}
	h.error = "truncated or corrupt JPEG 2000: no ihdr box";
	return h;
}

/* OpenEXR: attributes (name, type, size, value) up to an empty name;
 * dataWindow is a box2i. */
ImageHeader exr(const std::uint8_t *d, std::size_t n)
{
	ImageHeader h;
	h.format = ImageFormat::Exr;
	for (std::size_t pos = 8; pos < n && d[pos] != 0;) {
		const std::string_view rest = textOf(d + pos, n - pos);
		const std::size_t nameEnd = rest.find('\0');
		const std::size_t typeEnd = nameEnd == std::string_view::npos ? nameEnd : rest.find('\0', nameEnd + 1);
		if (typeEnd == std::string_view::npos || rest.size() - typeEnd - 1 < 4)
			break;
		const u64 size = le32(d + pos + typeEnd + 1);
		const std::size_t value = pos + typeEnd + 5;
		if (size > n - value)
			break;
		if (rest.substr(0, nameEnd) == "dataWindow" && size == 16) {
			const auto i32 = [&](std::size_t at) { return static_cast<long long>(static_cast<std::int32_t>(le32(d + at))); };
			h.width = i32(value + 8) - i32(value) + 1;
			h.height = i32(value + 12) - i32(value + 4) + 1;
			return h;
		}
		pos = value + static_cast<std::size_t>(size);
	}
	h.error = "truncated or corrupt OpenEXR header: no dataWindow";
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
	else if (size >= 3 && data[0] == 'P' && data[1] == '7' && (data[2] == '\n' || data[2] == ' '))
		h = pam(data, size);
	else if (size >= 3 && data[0] == 'P' && (data[1] == 'F' || data[1] == 'f') && std::isspace(data[2]))
		h = pfm(data, size);
	else if (size >= 12 && std::memcmp(data, "RIFF", 4) == 0 && std::memcmp(data + 8, "WEBP", 4) == 0)
		h = webp(data, size);
	else if (size >= 8 && (std::memcmp(data, "II*\0", 4) == 0 || std::memcmp(data, "MM\0*", 4) == 0 ||
			       std::memcmp(data, "II+\0", 4) == 0 || std::memcmp(data, "MM\0+", 4) == 0))
		h = tiff(data, size);
	else if (size >= 4 && be32(data) == 0x59a66a95u)
		h = sunRaster(data, size);
	else if (size >= 6 && (std::memcmp(data, "#?RADIANCE", std::min<std::size_t>(size, 10)) == 0 ||
			       std::memcmp(data, "#?RGBE", 6) == 0))
		h = hdr(data, size);
	else if ((size >= 12 && std::memcmp(data, "\0\0\0\x0cjP  \r\n\x87\n", 12) == 0) ||
		 (size >= 4 && std::memcmp(data, "\xff\x4f\xff\x51", 4) == 0))
		h = jpeg2000(data, size);
	else if (size >= 8 && std::memcmp(data, "\x76\x2f\x31\x01", 4) == 0)
		h = exr(data, size);
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
	case ImageFormat::Pam: return "PAM";
	case ImageFormat::Pfm: return "PFM";
	case ImageFormat::WebP: return "WebP";
	case ImageFormat::Tiff: return "TIFF";
	case ImageFormat::SunRaster: return "Sun raster";
	case ImageFormat::Hdr: return "Radiance HDR";
	case ImageFormat::Jpeg2000: return "JPEG 2000";
	case ImageFormat::Exr: return "OpenEXR";
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

StreamBytes::~StreamBytes()
{
	clear();
}

void StreamBytes::clear()
{
	if (data_)
		::munmap(data_, capacity_);
	data_ = nullptr;
	size_ = capacity_ = 0;
}

bool StreamBytes::reserve(std::size_t n)
{
	if (n <= capacity_)
		return true;
	void *p = data_ ? ::mremap(data_, capacity_, n, MREMAP_MAYMOVE)
			: ::mmap(nullptr, n, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
	if (p == MAP_FAILED)
		return false;
	data_ = static_cast<std::uint8_t *>(p);
	capacity_ = n;
	return true;
}

bool readStreamBounded(int fd, const std::string &name, std::size_t limit, StreamBytes &bytes, std::string &error)
{
	bytes.clear();
	for (;;) {
		if (bytes.room() == 0) {
			if (bytes.size() > limit) {
				error = name + " holds more than the limit of " + std::to_string(limit) + " bytes";
				bytes.clear();
				return false;
			}
			/* Doubling in place, to one byte past the limit at most:
			 * untouched pages cost nothing. */
			if (!bytes.reserve(std::min(limit + 1, std::max<std::size_t>(64 << 10, 2 * bytes.size())))) {
				error = "out of memory reading " + name;
				bytes.clear();
				return false;
			}
		}
		const ssize_t r = ::read(fd, bytes.end(), bytes.room());
		if (r < 0 && errno == EINTR)
			continue;
		if (r < 0) {
			error = "cannot read " + name + ": " + std::strerror(errno);
			bytes.clear();
			return false;
		}
		if (r == 0)
			break;
		bytes.grow(static_cast<std::size_t>(r));
	}
	if (bytes.size() > limit) {
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
