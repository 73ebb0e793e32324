// SPDX-License-Identifier: MIT
// The CLI's checks of an image file before decoding (tools/image_check.h)
// and its JSON strings and numbers (tools/cli_text.h), on bytes made here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include "cli_text.h"
#include "image_check.h"

using namespace frappe::cli;
using Bytes = std::vector<std::uint8_t>;

namespace {

void put32be(Bytes &b, std::uint32_t v)
{
	for (int s = 24; s >= 0; s -= 8)
		b.push_back(static_cast<std::uint8_t>(v >> s));
}
void put32le(Bytes &b, std::uint32_t v)
{
	for (int s = 0; s < 32; s += 8)
		b.push_back(static_cast<std::uint8_t>(v >> s));
}
void put16le(Bytes &b, unsigned v)
{
	b.push_back(static_cast<std::uint8_t>(v));
	b.push_back(static_cast<std::uint8_t>(v >> 8));
}
void chunk(Bytes &b, const char *type, const Bytes &data)
{
	put32be(b, static_cast<std::uint32_t>(data.size()));
	b.insert(b.end(), type, type + 4);
	b.insert(b.end(), data.begin(), data.end());
	put32be(b, 0); /* the CRC: libpng checks it, the inspector does not */
}

Bytes png(std::uint32_t w, std::uint32_t h)
{
	Bytes b = { 0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n' };
	Bytes ihdr;
	put32be(ihdr, w);
	put32be(ihdr, h);
	ihdr.insert(ihdr.end(), { 8, 0, 0, 0, 0 });
	chunk(b, "IHDR", ihdr);
	chunk(b, "IDAT", Bytes(100, 0x55));
	chunk(b, "IEND", {});
	return b;
}

/* SOI, APP0, SOF0 (h, w), SOS, entropy-coded bytes with a stuffed 0xff, EOI. */
Bytes jpeg(unsigned w, unsigned h, bool thumbnailEoi = false)
{
	Bytes b = { 0xff, 0xd8, 0xff, 0xe0, 0x00, 0x08, 'J', 'F', 'I', 'F', 0, 1 };
	if (thumbnailEoi) /* an APP1 holding an FFD9 of its own, as EXIF thumbnails do */
		b.insert(b.end(), { 0xff, 0xe1, 0x00, 0x06, 0xff, 0xd8, 0xff, 0xd9 });
	b.insert(b.end(), { 0xff, 0xc0, 0x00, 0x0b, 8, static_cast<std::uint8_t>(h >> 8), static_cast<std::uint8_t>(h),
			    static_cast<std::uint8_t>(w >> 8), static_cast<std::uint8_t>(w), 1, 1, 0x11, 0 });
	b.insert(b.end(), { 0xff, 0xda, 0x00, 0x08, 1, 1, 0, 0, 63, 0 });
	b.insert(b.end(), { 0x12, 0x34, 0xff, 0x00, 0x56, 0xff, 0xd0, 0x78 });
	b.insert(b.end(), { 0xff, 0xd9 });
	return b;
}

Bytes bmp(std::int32_t w, std::int32_t h, unsigned bits)
{
	const std::uint32_t stride = (static_cast<std::uint32_t>(w) * bits + 31) / 32 * 4;
	const std::uint32_t pixels = stride * static_cast<std::uint32_t>(h < 0 ? -h : h);
	Bytes b = { 'B', 'M' };
	put32le(b, 54 + pixels);
	put32le(b, 0);
	put32le(b, 54);
	put32le(b, 40);
	put32le(b, static_cast<std::uint32_t>(w));
	put32le(b, static_cast<std::uint32_t>(h));
	put16le(b, 1);
	put16le(b, bits);
	for (int i = 0; i < 6; ++i)
		put32le(b, 0);
	b.resize(b.size() + pixels, 0x80);
	return b;
}

Bytes text(const std::string &s) { return Bytes(s.begin(), s.end()); }

ImageHeader inspect(const Bytes &b) { return inspectImage(b.data(), b.size()); }

/* A complete file of that format and size. */
void expectWhole(const Bytes &b, ImageFormat format, long long width, long long height)
{
	const ImageHeader h = inspect(b);
	EXPECT_EQ(h.format, format);
	EXPECT_EQ(h.width, width);
	EXPECT_EQ(h.height, height);
	EXPECT_EQ(h.error, "");
}

/* A header read as that format and size. */
void expectSize(const ImageHeader &h, ImageFormat format, long long width, long long height)
{
	EXPECT_EQ(formatName(h.format), std::string(formatName(format)));
	EXPECT_EQ(h.width, width) << formatName(format);
	EXPECT_EQ(h.height, height) << formatName(format);
	EXPECT_EQ(h.error, "") << formatName(format);
}

Bytes cut(Bytes b, std::size_t n)
{
	b.resize(n);
	return b;
}

} // namespace

TEST(ImageCheck, PngSizeFromIhdr)
{
	expectWhole(png(30000, 20000), ImageFormat::Png, 30000, 20000);
}

TEST(ImageCheck, PngCutAnywhereIsAnError)
{
	const Bytes whole = png(64, 48);
	for (std::size_t n = 8; n < whole.size(); ++n)
		EXPECT_NE(inspect(cut(whole, n)).error, "") << "cut at " << n;
	EXPECT_NE(inspect(cut(whole, whole.size() - 12)).error.find("no IEND"), std::string::npos);
	EXPECT_NE(inspect(cut(whole, 60)).error.find("runs past the end"), std::string::npos);
}

TEST(ImageCheck, PngZeroSizeOrHugeChunk)
{
	EXPECT_NE(inspect(png(0, 10)).error, "");
	Bytes b = png(4, 4);
	b[33] = 0xff; /* the IDAT length's top byte: 2^31 and more */
	EXPECT_NE(inspect(b).error.find("corrupt PNG"), std::string::npos);
}

TEST(ImageCheck, JpegSizeFromSof)
{
	expectWhole(jpeg(65535, 480), ImageFormat::Jpeg, 65535, 480);
	EXPECT_EQ(inspect(jpeg(640, 480, true)).error, "");
}

TEST(ImageCheck, JpegWithoutEoiIsTruncated)
{
	const Bytes whole = jpeg(640, 480);
	for (std::size_t n = 3; n < whole.size() - 1; ++n)
		EXPECT_NE(inspect(cut(whole, n)).error, "") << "cut at " << n;
	EXPECT_NE(inspect(cut(whole, whole.size() - 2)).error.find("no end-of-image marker"), std::string::npos);
	/* the thumbnail's FFD9 comes before the scan: not the image's end */
	const Bytes thumb = jpeg(640, 480, true);
	EXPECT_NE(inspect(cut(thumb, thumb.size() - 2)).error, "");
	/* bytes after EOI are allowed */
	Bytes trailing = whole;
	trailing.insert(trailing.end(), { 1, 2, 3 });
	EXPECT_EQ(inspect(trailing).error, "");
}

TEST(ImageCheck, BmpSizeAndTruncation)
{
	expectWhole(bmp(30, -20, 24), ImageFormat::Bmp, 30, 20);
	const Bytes whole = bmp(30, 20, 8);
	EXPECT_NE(inspect(cut(whole, whole.size() - 1)).error.find("truncated BMP"), std::string::npos);
	EXPECT_NE(inspect(cut(whole, 20)).error, "");
	/* a huge claim in a small file: no overflow, truncated */
	Bytes huge = bmp(1, 1, 8);
	huge[18] = huge[19] = huge[20] = 0xff, huge[21] = 0x7f;
	huge[22] = huge[23] = huge[24] = 0xff, huge[25] = 0x7f;
	const ImageHeader hh = inspect(huge);
	EXPECT_EQ(hh.width, 0x7fffffff);
	EXPECT_NE(hh.error, "");
}

TEST(ImageCheck, PnmSizeCommentsAndTruncation)
{
	Bytes pgm = text("P5\n# a comment\n4 3\n255\n");
	pgm.resize(pgm.size() + 12, 7);
	expectWhole(pgm, ImageFormat::Pnm, 4, 3);
	EXPECT_NE(inspect(cut(pgm, pgm.size() - 1)).error.find("truncated PNM"), std::string::npos);
	Bytes ppm16 = text("P6 2 2 65535\n");
	ppm16.resize(ppm16.size() + 2 * 2 * 3 * 2);
	EXPECT_EQ(inspect(ppm16).error, "");
	EXPECT_NE(inspect(cut(ppm16, ppm16.size() - 1)).error, "");
	EXPECT_EQ(inspect(text("P2 2 1 255\n1 2\n")).error, ""); /* plain: not length-checked */
	EXPECT_NE(inspect(text("P5 2 1 0\n\1\2")).error.find("maxval"), std::string::npos);
	const ImageHeader big = inspect(text("P5 99999999999999999999 99999999999999999999 255\n"));
	EXPECT_GT(big.width, 1LL << 30);
	EXPECT_NE(big.error, "");
	EXPECT_NE(inspect(text("P5 12")).error, "");
}

TEST(ImageCheck, UnknownFormatsPassWithoutSize)
{
	const ImageHeader h = inspect(text("GIF89a, say"));
	EXPECT_EQ(h.format, ImageFormat::Unknown);
	EXPECT_EQ(h.error, "");
	EXPECT_EQ(inspect(Bytes{}).format, ImageFormat::Unknown);
}

/* Issue 34: only PNG, JPEG, BMP and PNM had their size read; a 10 KB WebP
 * decoded to 1.1 GB and a 1.8 MB TIFF to 0.94 GB before the pixel limit.
 * Every other format OpenCV decodes has its size read from its header. */
TEST(ImageCheck, EveryOtherOpenCvFormatGivesItsSize)
{
	auto bytes = [](std::initializer_list<int> v) {
		Bytes b;
		for (int x : v)
			b.push_back(static_cast<std::uint8_t>(x));
		return b;
	};
	auto plus = [](Bytes a, const Bytes &b) {
		a.insert(a.end(), b.begin(), b.end());
		return a;
	};
	const Bytes riff = plus(text("RIFF"), bytes({ 0, 1, 0, 0 }));
	/* VP8X: canvas 16383 x 16383 (minus one, 24 bits each). */
	expectSize(inspect(plus(plus(riff, text("WEBPVP8X")), bytes({ 10, 0, 0, 0, 0, 0, 0, 0, 0xfe, 0x3f, 0, 0xfe, 0x3f, 0, 0, 0 }))),
		   ImageFormat::WebP, 16383, 16383);
	/* VP8L: 0x2f, then 14 bits of width - 1 and of height - 1. */
	const unsigned l = (1000 - 1) | (500 - 1) << 14;
	expectSize(inspect(plus(plus(riff, text("WEBPVP8L")), bytes({ 9, 0, 0, 0, 0x2f, int(l & 255), int(l >> 8 & 255),
									  int(l >> 16 & 255), int(l >> 24), 0, 0, 0, 0, 0 }))),
		   ImageFormat::WebP, 1000, 500);
	/* VP8: the key frame's start code, then 14-bit sizes. */
	expectSize(inspect(plus(plus(riff, text("WEBPVP8 ")), bytes({ 9, 0, 0, 0, 0, 0, 0, 0x9d, 0x01, 0x2a, 0x80, 0x02,
									  0xe0, 0x01, 0, 0 }))),
		   ImageFormat::WebP, 640, 480);
	/* TIFF: ImageWidth LONG 40000, ImageLength SHORT 30000, both byte orders. */
	expectSize(inspect(bytes({ 'I', 'I', 42, 0, 8, 0, 0, 0, 2, 0, 0, 1, 4, 0, 1, 0, 0, 0, 0x40, 0x9c, 0, 0, 1, 1, 3, 0,
				   1, 0, 0, 0, 0x30, 0x75, 0, 0 })),
		   ImageFormat::Tiff, 40000, 30000);
	expectSize(inspect(bytes({ 'M', 'M', 0, 42, 0, 0, 0, 8, 0, 2, 1, 0, 0, 4, 0, 0, 0, 1, 0, 0, 0x9c, 0x40, 1, 1, 0, 3,
				   0, 0, 0, 1, 0x75, 0x30, 0, 0 })),
		   ImageFormat::Tiff, 40000, 30000);
	/* BigTIFF: version 43, 8-byte offsets and counts, LONG8 values. */
	expectSize(inspect(bytes({ 'I', 'I', 43, 0, 8, 0, 0, 0, 16, 0, 0, 0, 0, 0, 0, 0, 2, 0, 0, 0, 0, 0, 0, 0,
				   0, 1, 16, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0x40, 0x9c, 0, 0, 0, 0, 0, 0,
				   1, 1, 4, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0x30, 0x75, 0, 0, 0, 0, 0, 0 })),
		   ImageFormat::Tiff, 40000, 30000);
	EXPECT_NE(inspect(bytes({ 'I', 'I', 42, 0, 8, 0, 0, 0, 9, 0 })).error.find("truncated TIFF"), std::string::npos);
	expectSize(inspect(text("P7\nWIDTH 30000\nHEIGHT 20000\nDEPTH 1\nMAXVAL 255\nTUPLTYPE GRAYSCALE\nENDHDR\n")),
		   ImageFormat::Pam, 30000, 20000);
	expectSize(inspect(text("Pf\n3000 2000\n-1.0\n")), ImageFormat::Pfm, 3000, 2000);
	expectSize(inspect(bytes({ 0x59, 0xa6, 0x6a, 0x95, 0, 0, 0x75, 0x30, 0, 0, 0x4e, 0x20, 0, 0, 0, 8 })),
		   ImageFormat::SunRaster, 30000, 20000);
	expectSize(inspect(text("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 200 +X 300\n")), ImageFormat::Hdr, 300, 200);
	/* JP2: signature box, ftyp, then jp2h holding ihdr (height, width). */
	expectSize(inspect(plus(plus(bytes({ 0, 0, 0, 12, 'j', 'P', ' ', ' ', 13, 10, 0x87, 10, 0, 0, 0, 20 }),
				     text("ftypjp2 ")),
				bytes({ 0, 0, 0, 0, 'j', 'p', '2', ' ', 0, 0, 0, 45, 'j', 'p', '2', 'h', 0, 0, 0, 22, 'i', 'h',
					'd', 'r', 0, 0, 0x4e, 0x20, 0, 0, 0x75, 0x30, 0, 1, 7, 7, 0, 0 }))),
		   ImageFormat::Jpeg2000, 30000, 20000);
	/* A codestream: SIZ's Xsiz, Ysiz less the offsets XOsiz, YOsiz. */
	expectSize(inspect(bytes({ 0xff, 0x4f, 0xff, 0x51, 0, 41, 0, 0, 0, 0, 0x75, 0x40, 0, 0, 0x4e, 0x30, 0, 0, 0, 0x10,
				   0, 0, 0, 0x10 })),
		   ImageFormat::Jpeg2000, 30000, 20000);
	/* OpenEXR: attributes up to dataWindow, a box2i (x0 y0 x1 y1). */
	expectSize(inspect(plus(plus(bytes({ 0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0 }), text("dataWindow")),
				plus(bytes({ 0 }), plus(text("box2i"), bytes({ 0, 16, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
									     0x2f, 0x75, 0, 0, 0x1f, 0x4e, 0, 0 }))))),
		   ImageFormat::Exr, 30000, 20000);
}

TEST(ReadFileBounded, RefusesWhatIsNotARegularFileOrTooBig)
{
	char dir[] = "/tmp/frappe-cli-io-XXXXXX";
	ASSERT_NE(mkdtemp(dir), nullptr);
	const std::string file = std::string(dir) + "/f";
	std::ofstream(file) << "0123456789";
	Bytes b;
	std::string error;
	EXPECT_TRUE(readFileBounded(file, 10, b, error)) << error;
	EXPECT_EQ(b.size(), 10u);
	EXPECT_FALSE(readFileBounded(file, 9, b, error));
	EXPECT_NE(error.find("more than the limit of 9"), std::string::npos) << error;
	EXPECT_FALSE(readFileBounded(dir, 100, b, error));
	EXPECT_NE(error.find("a directory"), std::string::npos) << error;
	EXPECT_FALSE(readFileBounded("/dev/zero", 100, b, error));
	EXPECT_NE(error.find("not a regular file"), std::string::npos) << error;
	EXPECT_FALSE(readFileBounded(std::string(dir) + "/missing", 100, b, error));
	EXPECT_NE(error.find("cannot open"), std::string::npos) << error;
	std::remove(file.c_str());
	rmdir(dir);
}

/* Standard input as a pipe: read whole, refused when empty or beyond the
 * limit, however the writer splits it. */
TEST(ReadStreamBounded, WholeEmptyOrOverTheLimit)
{
	auto through = [](const std::string &data, std::size_t limit, StreamBytes &b, std::string &error) {
		int fds[2];
		EXPECT_EQ(pipe(fds), 0);
		/* Written by a child process: a pipe holds only 64 KiB. */
		const pid_t child = fork();
		if (child == 0) {
			close(fds[0]);
			std::size_t at = 0;
			while (at < data.size()) {
				const ssize_t w = write(fds[1], data.data() + at, std::min<std::size_t>(1000, data.size() - at));
				if (w <= 0)
					break;
				at += static_cast<std::size_t>(w);
			}
			_exit(0);
		}
		close(fds[1]);
		const bool ok = readStreamBounded(fds[0], "standard input", limit, b, error);
		close(fds[0]);
		int status = 0;
		waitpid(child, &status, 0);
		return ok;
	};
	StreamBytes b;
	std::string error;
	std::string big(200000, 'x');
	big[123456] = 'y';
	ASSERT_TRUE(through(big, 200000, b, error)) << error;
	ASSERT_EQ(b.size(), 200000u);
	EXPECT_EQ(b[123456], 'y');
	EXPECT_FALSE(through(big, 199999, b, error));
	EXPECT_EQ(error, "standard input holds more than the limit of 199999 bytes");
	EXPECT_TRUE(b.empty());
	EXPECT_FALSE(through("", 100, b, error));
	EXPECT_EQ(error, "standard input is empty");
}

TEST(JsonEscape, ValidUtf8IsKept)
{
	EXPECT_EQ(jsonEscape("synth/00012.png"), "synth/00012.png");
	EXPECT_EQ(jsonEscape("caf\xc3\xa9/\xe6\x97\xa5\xf0\x9f\x98\x80.png"), "caf\xc3\xa9/\xe6\x97\xa5\xf0\x9f\x98\x80.png");
	EXPECT_EQ(jsonEscape("a\"b\\c\nd\te\x01"), "a\\\"b\\\\c\\nd\\te\\u0001");
}

TEST(JsonEscape, InvalidBytesBecomeU00XX)
{
	EXPECT_EQ(jsonEscape("caf\xe9.png"), "caf\\u00e9.png");   /* Latin-1 */
	EXPECT_EQ(jsonEscape("\xc0\xaf"), "\\u00c0\\u00af");       /* overlong '/' */
	EXPECT_EQ(jsonEscape("\xed\xa0\x80"), "\\u00ed\\u00a0\\u0080"); /* a surrogate */
	EXPECT_EQ(jsonEscape("\xf4\x90\x80\x80"), "\\u00f4\\u0090\\u0080\\u0080"); /* above U+10FFFF */
	EXPECT_EQ(jsonEscape("\xe6\x97"), "\\u00e6\\u0097");       /* cut short */
	EXPECT_EQ(jsonEscape("\xff" "a"), "\\u00ffa");
}

TEST(ParseNumber, WholeTextInRange)
{
	int i = -1;
	EXPECT_TRUE(parseNumber("42", i));
	EXPECT_EQ(i, 42);
	EXPECT_TRUE(parseNumber("+7", i));
	EXPECT_EQ(i, 7);
	EXPECT_TRUE(parseNumber("-3", i));
	EXPECT_EQ(i, -3);
	for (const char *bad : { "", "x", "12x", " 5", "5 ", "1e3", "99999999999", "--1", "+" })
		EXPECT_FALSE(parseNumber(bad, i)) << bad;
	float f = 0;
	EXPECT_TRUE(parseNumber("0.27", f));
	EXPECT_FLOAT_EQ(f, 0.27f);
	EXPECT_FALSE(parseNumber("0.2.7", f));
	EXPECT_FALSE(parseNumber("1e999", f));
}
