// SPDX-License-Identifier: MIT
// Homographies, the perspective warp and binarisation on known inputs, the
// fixed-point warp's scalar form against its integer definition, and the
// vectorised warp against the scalar one on every Highway target.
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

#include "decode.h"
#include "every_target.h"
#include "frappe/fixed_warp.h"
#include "frappe/frappe.h"
#include "frappe/homography.h"
#include "frappe/render.h"
#include "scene.h"
#include "verify.h"
#include "warp_kernels.h"

using namespace frappe;
using frappe::test::Image;
using frappe::test::onEveryTarget;

TEST(Homography, MapsTheUnitSquareToTheQuad)
{
	const std::array<Point2f, 4> q = { Point2f{ 10, 20 }, { 110, 30 }, { 90, 140 }, { 5, 100 } };
	const auto H = Homography::fromUnitSquare(q);
	ASSERT_TRUE(H);
	const double u[4] = { 0, 1, 1, 0 }, v[4] = { 0, 0, 1, 1 };
	for (int i = 0; i < 4; ++i) {
		const Point2f p = H->map(u[i], v[i]);
		EXPECT_NEAR(p.x, q[i].x, 1e-4);
		EXPECT_NEAR(p.y, q[i].y, 1e-4);
	}
	const auto Hi = H->inverse();
	ASSERT_TRUE(Hi);
	const Point2f back = Hi->map(q[2].x, q[2].y);
	EXPECT_NEAR(back.x, 1.0, 1e-5);
	EXPECT_NEAR(back.y, 1.0, 1e-5);
	EXPECT_FALSE(Homography::fromUnitSquare({ Point2f{ 0, 0 }, { 1, 1 }, { 2, 2 }, { 3, 3 } }));
}

TEST(Warp, SamplesAtCellQuarterPoints)
{
	/* A linear ramp I(x, y) = x + 2y: bilinear sampling reproduces it
	 * exactly, so every sample's value says where it was taken. */
	Image img(200, 200);
	for (int y = 0; y < 200; ++y)
		for (int x = 0; x < 200; ++x)
			img.at(x, y) = static_cast<std::uint8_t>((x + 2 * y) / 3);
	Image ramp(200, 200);
	const std::array<Point2f, 4> q = { Point2f{ 20, 20 }, { 84, 20 }, { 84, 84 }, { 20, 84 } };
	detail::WarpedMarker w;
	ASSERT_TRUE(detail::warpMarker(img.view(), q, 6, w));
	ASSERT_EQ(w.side, 16);
	/* Sample i sits at 20 + 64 * (i + 0.5) / 16 = 22 + 4i. */
	for (int j = 0; j < 16; j += 5) {
		for (int i = 0; i < 16; i += 3) {
			const float x = 22.0f + 4.0f * i, y = 22.0f + 4.0f * j;
			const int xi = static_cast<int>(x), yi = static_cast<int>(y);
			EXPECT_EQ(w.at(i, j), static_cast<float>(img.at(xi, yi))) << i << "," << j;
		}
	}
}

TEST(Binarise, ReadsAnUprightMarker)
{
	const Dictionary &d = *findDictionary("aruco_mip_36h12");
	int side = 0;
	/* 8 px cells, one cell of quiet zone: the marker spans [8, 72). */
	std::vector<std::uint8_t> px = markerImage(d, 42, 8, 1, side);
	ASSERT_EQ(side, 80);
	const ImageView view(px.data(), side, side);
	const std::array<Point2f, 4> q = { Point2f{ 7.5f, 7.5f }, { 71.5f, 7.5f }, { 71.5f, 71.5f }, { 7.5f, 71.5f } };
	detail::WarpedMarker w;
	ASSERT_TRUE(detail::warpMarker(view, q, d.bits, w));
	const detail::Binarised b = detail::binarise(w, d.bits);
	EXPECT_EQ(b.code, d.codes[42]);
	EXPECT_EQ(b.border_errors, 0);
	EXPECT_NEAR(b.contrast, 255.0f, 1.0f);
	const detail::Decoded dec = detail::decode(d, b.code, 5);
	EXPECT_EQ(dec.id, 42);
	EXPECT_EQ(dec.rotation, 0);
	EXPECT_EQ(dec.hamming, 0);
}

TEST(Binarise, TheQuietZoneOutlineReadsAsAWhiteFrame)
{
	const Dictionary &d = *findDictionary("aruco_mip_36h12");
	int side = 0;
	std::vector<std::uint8_t> px = markerImage(d, 7, 8, 2, side);
	const ImageView view(px.data(), side, side);
	/* Outline one cell outside the marker: its frame is the white margin. */
	const float a = 7.5f, b = 87.5f;
	std::array<Point2f, 4> q = { Point2f{ a, a }, { b, a }, { b, b }, { a, b } };
	detail::WarpedMarker w;
	ASSERT_TRUE(detail::warpMarker(view, q, d.bits, w));
	EXPECT_EQ(detail::binarise(w, d.bits).border_errors, 28);
	/* One cell inside it lies the marker, which insetQuad recovers. */
	ASSERT_TRUE(detail::insetQuad(view, q, d.bits, w));
	EXPECT_NEAR(q[0].x, 15.5f, 0.2f);
	EXPECT_NEAR(q[2].y, 79.5f, 0.2f);
	EXPECT_EQ(detail::decode(d, detail::binarise(w, d.bits).code, 5).id, 7);
}

/* Cells of 2 px under a blur of half a cell: warpMarker's quarter-cell
 * samples lie half a pixel from the neighbouring cells and misread a third
 * of these markers (a code cell, or border cells read white); one sharpened
 * sample at each cell's centre reads every one. */
TEST(Warp, CellCentresReadSmallBlurredCells)
{
	const Dictionary &d = *findDictionary("4x4_50");
	int quarterMisreads = 0;
	for (float at : { 9.5f, 9.75f, 10.0f }) {
		for (int id : { 3, 17, 29, 44 }) {
			Image img(40, 40, 230);
			/* 6 cells of 2 px, a cell of quiet zone around them. */
			const std::array<Point2f, 4> q = { Point2f{ at, at }, { at + 12, at }, { at + 12, at + 12 }, { at, at + 12 } };
			RenderOptions opt;
			opt.black = 25;
			opt.white = 230;
			renderMarker(img.mut(), d, id, q, opt);
			frappe::test::blur(img, 1.0f);
			detail::WarpedMarker w;
			ASSERT_TRUE(detail::warpMarker(img.view(), q, d.bits, w));
			const detail::Binarised quarters = detail::binarise(w, d.bits);
			quarterMisreads += quarters.code != d.codes[static_cast<std::size_t>(id)] ||
					   quarters.border_errors > detail::allowedBorderErrors(d.bits);
			float reference = 0.0f;
			ASSERT_TRUE(detail::warpCellCentres(img.view(), q, d.bits, 0.25f, w, &reference));
			EXPECT_EQ(w.side, d.bits + 2);
			const detail::Binarised centres = detail::binarise(w, d.bits);
			EXPECT_EQ(centres.code, d.codes[static_cast<std::size_t>(id)]) << "id " << id << " at " << at;
			EXPECT_EQ(centres.border_errors, 0) << "id " << id << " at " << at;
			/* Halfway between the black border and the white ring around
			 * it, both greyed by the blur. */
			EXPECT_GT(reference, 100.0f);
			EXPECT_LT(reference, 160.0f);
		}
	}
	EXPECT_GE(quarterMisreads, 4);
}

namespace {

/* Random pixels in a buffer that ends where the image's last row does, with
 * unreadable pages on either side where the system has them: a read past
 * either end of the image faults. */
class GuardedImage
{
public:
	GuardedImage(int width, int height, int stride, std::mt19937 &rng)
		: width_(width), height_(height), stride_(stride)
	{
		const std::size_t bytes = static_cast<std::size_t>(height - 1) * stride + width;
#if defined(__linux__)
		page_ = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
		const std::size_t inner = (bytes + page_ - 1) / page_ * page_;
		size_ = inner + 2 * page_;
		void *m = mmap(nullptr, size_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
		EXPECT_NE(m, MAP_FAILED);
		map_ = static_cast<std::uint8_t *>(m);
		mprotect(map_, page_, PROT_NONE);
		mprotect(map_ + page_ + inner, page_, PROT_NONE);
		data_ = map_ + page_ + inner - bytes;
#else
		own_.resize(bytes);
		data_ = own_.data();
#endif
		std::uniform_int_distribution<int> px(0, 255);
		for (std::size_t i = 0; i < bytes; ++i)
			data_[i] = static_cast<std::uint8_t>(px(rng));
	}
	GuardedImage(const GuardedImage &) = delete;
	GuardedImage &operator=(const GuardedImage &) = delete;
	~GuardedImage()
	{
#if defined(__linux__)
		munmap(map_, size_);
#endif
	}
	ImageView view() const { return { data_, width_, height_, stride_ }; }

private:
	int width_, height_, stride_;
	std::uint8_t *data_ = nullptr;
#if defined(__linux__)
	std::uint8_t *map_ = nullptr;
	std::size_t page_ = 0, size_ = 0;
#else
	std::vector<std::uint8_t> own_;
#endif
};

using Quad = std::array<Point2f, 4>;

/* Quads of every kind the warp may meet: convex ones inside the image, with
 * corners on its last sampleable row and column or on the border itself,
 * partly and wholly outside, tiny ones, collinear (degenerate), concave and
 * self-crossing ones (whose homography crosses infinity), and NaN corners. */
std::vector<Quad> makeQuads(int width, int height, std::mt19937 &rng)
{
	const float w = static_cast<float>(width), h = static_cast<float>(height);
	std::uniform_real_distribution<float> unit(0.0f, 1.0f);
	auto around = [&](float cx, float cy, float r) {
		/* A convex quad: four corners at increasing angles, clockwise on screen. */
		Quad q;
		const float a0 = 6.2832f * unit(rng);
		for (int i = 0; i < 4; ++i) {
			const float a = a0 + 1.5708f * i + 0.6f * (unit(rng) - 0.5f);
			const float ri = r * (0.6f + 0.4f * unit(rng));
			q[i] = { cx + ri * std::cos(a), cy + ri * std::sin(a) };
		}
		return q;
	};
	std::vector<Quad> quads;
	for (int k = 0; k < 60; ++k) {
		const float r = std::max(w, h) * (0.05f + 0.5f * unit(rng));
		/* One draw a statement, in the order x86 has drawn them: a call's
		 * arguments are evaluated in an unspecified order (GCC for ARM
		 * draws them in another, rendering other scenes). */
		/* anywhere, often across the border */
		float y = unit(rng);
		float x = unit(rng);
		quads.push_back(around(w * x, h * y, r));
		/* mostly inside */
		float s = unit(rng);
		y = unit(rng);
		x = unit(rng);
		quads.push_back(around(w * (0.3f + 0.4f * x), h * (0.3f + 0.4f * y), std::min(w, h) * 0.25f * s));
		/* tiny */
		s = unit(rng);
		y = unit(rng);
		x = unit(rng);
		quads.push_back(around(w * x, h * y, 0.01f + s));
		s = unit(rng);
		y = unit(rng);
		x = unit(rng);
		quads.push_back(around(w * (4.0f * x - 1.5f), h * (4.0f * y - 1.5f), w * s));
	}
	const float xs = w - 2.0f, ys = h - 2.0f; /* the last corners that need no clamps */
	quads.push_back({ Point2f{ 0, 0 }, { xs, 0 }, { xs, ys }, { 0, ys } });
	quads.push_back({ Point2f{ 0, 0 }, { w - 1, 0 }, { w - 1, h - 1 }, { 0, h - 1 } });
	quads.push_back({ Point2f{ -0.5f, -0.5f }, { w - 0.5f, -0.5f }, { w - 0.5f, h - 0.5f }, { -0.5f, h - 0.5f } });
	quads.push_back({ Point2f{ xs, ys }, { xs, 0 }, { 0, 0 }, { 0, ys } });		/* counter-clockwise */
	quads.push_back({ Point2f{ 0, 0 }, { xs, ys }, { xs, 0 }, { 0, ys } });		/* self-crossing */
	quads.push_back({ Point2f{ 0, 0 }, { xs, 0 }, { xs * 0.2f, ys * 0.2f }, { 0, ys } }); /* concave */
	quads.push_back({ Point2f{ 1, 1 }, { 2, 2 }, { 3, 3 }, { 4, 4 } });		/* collinear */
	quads.push_back({ Point2f{ 0.5f, 0.5f }, { 0.5f, 0.5f }, { 0.5f, 0.5f }, { 0.5f, 0.5f } });
	quads.push_back({ Point2f{ -1e6f, -1e6f }, { 1e6f, -1e6f }, { 1e6f, 1e6f }, { -1e6f, 1e6f } });
	const float nan = std::numeric_limits<float>::quiet_NaN();
	quads.push_back({ Point2f{ 0, 0 }, { nan, 0 }, { xs, ys }, { 0, ys } });
	return quads;
}

struct Warped {
	bool ok;
	detail::WarpedMarker samples;
};

bool sameBits(const Warped &a, const Warped &b)
{
	if (a.ok != b.ok)
		return false;
	if (!a.ok)
		return true;
	const std::size_t n = static_cast<std::size_t>(a.samples.side) * a.samples.side;
	return a.samples.side == b.samples.side &&
	       std::memcmp(a.samples.samples.data(), b.samples.samples.data(), n * sizeof(float)) == 0;
}

} // namespace

/* Every grid side up to the largest, on images from the smallest a 2x2
 * neighbourhood fits to odd widths with and without row padding. */
TEST(Warp, VectorFormMatchesTheScalarOne)
{
	struct Size {
		int width, height, stride;
	};
	const Size sizes[] = { { 2, 2, 2 }, { 3, 7, 3 }, { 2, 33, 5 }, { 17, 5, 17 }, { 64, 48, 64 },
			       { 101, 67, 103 }, { 333, 211, 333 }, { 640, 480, 672 } };
	std::mt19937 rng(11);
	int compared = 0;
	for (const Size &size : sizes) {
		const GuardedImage image(size.width, size.height, size.stride, rng);
		const ImageView view = image.view();
		const std::vector<Quad> quads = makeQuads(size.width, size.height, rng);
		std::vector<Warped> scalar;
		for (const Quad &q : quads) {
			for (int side = 1; side <= CandidateSamples::kMaxSide; ++side) {
				Warped fine;
				fine.ok = detail::warpToGridScalar(view, q, side, fine.samples, true);
				scalar.push_back(fine);
				Warped s;
				s.ok = detail::warpToGridScalar(view, q, side, s.samples);
				/* The float fallback's no-clamp shortcut changes nothing. */
				if (s.ok && !quantiseWarp(q, side)) {
					Warped clamped{ true, {} };
					clamped.samples.side = side;
					detail::warpSamplesScalar(view, *Homography::fromUnitSquare(q), side, false,
								  clamped.samples.samples.data());
					ASSERT_TRUE(sameBits(s, clamped)) << size.width << "x" << size.height << " side " << side;
				}
				scalar.push_back(s);
			}
		}
		onEveryTarget([&](const char *target) {
			std::size_t n = 0;
			for (const Quad &q : quads) {
				for (int side = 1; side <= CandidateSamples::kMaxSide; ++side) {
					for (const bool fine : { true, false }) {
						Warped v;
						v.ok = detail::warpToGrid(view, q, side, v.samples, fine);
						ASSERT_TRUE(sameBits(v, scalar[n++]))
							<< target << ", " << size.width << "x" << size.height << " stride "
							<< size.stride << ", quad " << n / (2 * CandidateSamples::kMaxSide)
							<< ", side " << side << (fine ? ", fine" : "");
						++compared;
					}
				}
			}
		});
	}
	EXPECT_GT(compared, 10000);
}

/* The fixed-point warp on known geometry: an outline 32 px a side starting
 * half a sample before pixel (a, b) puts sample (i, j) on pixel
 * (a + 2i, b + 2j), weights 0; shifted by half a pixel, every sample lies
 * midway between two pixels: their mean rounded half up. */
TEST(FixedWarp, PixelCentresAndHalfPixels)
{
	std::mt19937 rng(3);
	const GuardedImage image(80, 60, 83, rng);
	const ImageView v = image.view();
	for (const float a : { 7.0f, 7.5f }) {
		const float b = 5;
		const std::array<Point2f, 4> q = { Point2f{ a - 1, b - 1 }, { a + 31, b - 1 }, { a + 31, b + 31 },
						   { a - 1, b + 31 } };
		const auto w = quantiseWarp(q, 16);
		ASSERT_TRUE(w);
		EXPECT_EQ(w->d.di, 0);
		EXPECT_EQ(w->d.dj, 0);
		detail::WarpedMarker out;
		ASSERT_TRUE(detail::warpToGrid(v, q, 16, out));
		for (int j = 0; j < 16; ++j) {
			for (int i = 0; i < 16; ++i) {
				const int l = v.at(7 + 2 * i, 5 + 2 * j), r = v.at(8 + 2 * i, 5 + 2 * j);
				const int want = a == 7.0f ? l : (l + r + 1) / 2;
				ASSERT_EQ(fixedWarpSample(v, *w, i, j), want) << a << ": " << i << "," << j;
				ASSERT_EQ(out.at(i, j), static_cast<float>(want)) << a << ": " << i << "," << j;
			}
		}
	}
}

TEST(FixedWarp, RefusesWhatTheFixedPointCannotHoldAndSaysWhy)
{
	const char *why = nullptr;
	const std::array<Point2f, 4> line = { Point2f{ 0, 0 }, { 10, 0 }, { 20, 0 }, { 30, 0 } };
	EXPECT_FALSE(quantiseWarp(line, 16, &why));
	EXPECT_STREQ(why, "degenerate quad");
	const std::array<Point2f, 4> huge = { Point2f{ 0, 0 }, { 3000, 0 }, { 3000, 3000 }, { 0, 3000 } };
	EXPECT_FALSE(quantiseWarp(huge, 16, &why));
	EXPECT_STREQ(why, "quad wider than 2046 pixels");
	const std::array<Point2f, 4> fine = { Point2f{ 0, 0 }, { 2000, 0 }, { 2000, 2000 }, { 0, 2000 } };
	for (int side : { 1, 16, 20 })
		EXPECT_TRUE(quantiseWarp(fine, side)) << side;
	EXPECT_FALSE(quantiseWarp(fine, 21, &why));
	EXPECT_STREQ(why, "grid side out of range");
	EXPECT_FALSE(quantiseWarp(fine, 0, &why));
	/* A bow tie: the line at infinity crosses the sample grid. */
	const std::array<Point2f, 4> bowtie = { Point2f{ 0, 0 }, { 100, 0 }, { 0, 100 }, { 100, 100 } };
	EXPECT_FALSE(quantiseWarp(bowtie, 16, &why));
	EXPECT_STREQ(why, "the sample grid reaches the horizon");
	/* Refused quads still warp, in float: exactly the float sampler. */
	const std::array<Point2f, 4> big = { Point2f{ -900, -900 }, { 1700, -1000 }, { 1800, 1500 }, { -1000, 1400 } };
	EXPECT_FALSE(quantiseWarp(big, 16));
	Image img(120, 90, 0);
	for (int y = 0; y < 90; ++y)
		for (int x = 0; x < 120; ++x)
			img.at(x, y) = static_cast<std::uint8_t>((7 * x + 13 * y) % 251);
	detail::WarpedMarker got, want;
	ASSERT_TRUE(detail::warpToGrid(img.view(), big, 16, got));
	want.side = 16;
	detail::warpSamplesScalar(img.view(), *Homography::fromUnitSquare(big), 16, false, want.samples.data());
	EXPECT_EQ(0, std::memcmp(got.samples.data(), want.samples.data(), 256 * sizeof(float)));
}

/* The scalar form (double divisions) against the definition (64-bit integer
 * divisions) on every quad the fixed point takes and every grid side. */
TEST(FixedWarp, ScalarFormIsTheIntegerDefinition)
{
	std::mt19937 rng(17);
	int compared = 0;
	for (const auto &[width, height, stride] : { std::array{ 2, 2, 2 }, { 3, 7, 3 }, { 101, 67, 103 },
						     { 640, 480, 672 }, { 1900, 1200, 1900 } }) {
		const GuardedImage image(width, height, stride, rng);
		const ImageView view = image.view();
		for (const Quad &q : makeQuads(width, height, rng)) {
			for (int side = 1; side <= CandidateSamples::kMaxSide; ++side) {
				const auto w = quantiseWarp(q, side);
				if (!w)
					continue;
				std::array<float, CandidateSamples::kMaxSide * CandidateSamples::kMaxSide> got, fine;
				detail::warpFixedSamplesScalar(view, *w, false, got.data());
				detail::warpFixedSamplesScalar(view, *w, true, fine.data());
				for (int j = 0; j < side; ++j) {
					for (int i = 0; i < side; ++i) {
						const auto k = static_cast<std::size_t>(j * side + i);
						ASSERT_EQ(got[k], static_cast<float>(fixedWarpSample(view, *w, i, j)))
							<< width << "x" << height << " side " << side << " (" << i << "," << j << ")";
						const std::uint32_t v = fixedWarpValue(view, *w, i, j);
						ASSERT_EQ(got[k], static_cast<float>((v + (1u << 19)) >> 20));
						ASSERT_EQ(fine[k], static_cast<float>(v) / 1048576.0f);
					}
				}
				++compared;
			}
		}
	}
	EXPECT_GT(compared, 2000);
}
