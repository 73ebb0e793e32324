// SPDX-License-Identifier: MIT
// Decoding that never lies: markers of five families side by side, and
// frames of clutter, read with every built-in dictionary. A dictionary
// finds its own family's markers with their exact ids and stays silent on
// everything else; where another dictionary holds the very same code (a
// prefix such as 4x4_100 of 4x4_50, or a code two families share), it may
// report it, with that dictionary's id for it.
#include <cmath>
#include <random>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "frappe/frappe.h"
#include "scene.h"

using namespace frappe;
using namespace frappe::test;

namespace {

using Quad = std::array<Point2f, 4>;

struct Placed {
	const Dictionary *dict;
	int id;
	Quad corners;
};

/* The id `dict` gives to the code of (family, id) in any rotation, or -1. */
int idIn(const Dictionary &dict, const Dictionary &family, int id)
{
	if (dict.bits != family.bits)
		return -1;
	std::uint64_t c = family.codes[static_cast<std::size_t>(id)];
	for (int r = 0; r < 4; ++r, c = rotateCode(c, family.bits)) {
		for (int j = 0; j < dict.size(); ++j)
			if (dict.codes[static_cast<std::size_t>(j)] == c)
				return j;
	}
	return -1;
}

/* A smooth grey texture with fine grain: wood, carpet, a cluttered desk. */
void texture(Image &img, std::mt19937 &rng)
{
	std::uniform_real_distribution<float> phase(0.0f, 6.2832f);
	const float a = phase(rng), b = phase(rng), c = phase(rng);
	std::normal_distribution<float> grain(0.0f, 12.0f);
	for (int y = 0; y < img.height; ++y) {
		for (int x = 0; x < img.width; ++x) {
			const float v = 130.0f + 45.0f * std::sin(0.031f * x + a) * std::cos(0.023f * y + b) +
					30.0f * std::sin(0.11f * (x + y) + c) + grain(rng);
			img.at(x, y) = static_cast<std::uint8_t>(std::clamp(v, 0.0f, 255.0f));
		}
	}
}

/* Two markers of each family in a 4 x 3 grid (the last two cells empty),
 * turned and tilted, with one or two cells of quiet zone. */
std::vector<Placed> renderFamilies(Image &img)
{
	const char *families[] = { "apriltag_36h11", "aruco_mip_36h12", "4x4_50", "6x6_250", "apriltag_16h5" };
	const int ids[][2] = { { 3, 200 }, { 17, 131 }, { 8, 41 }, { 29, 177 }, { 4, 21 } };
	std::vector<Placed> placed;
	int k = 0;
	for (int f = 0; f < 5; ++f) {
		const Dictionary &d = *findDictionary(families[f]);
		for (int j = 0; j < 2; ++j, ++k) {
			const float cx = 80.0f + 160.0f * static_cast<float>(k % 4);
			const float cy = 80.0f + 160.0f * static_cast<float>(k / 4);
			const Quad q = squarePose(cx + 0.3f, cy - 0.2f, 78.0f - 3.0f * k, 23.0f * k - 40.0f,
						  static_cast<float>((k * 13) % 45));
			RenderOptions opt;
			opt.quiet_cells = 1 + k % 2;
			opt.black = 25;
			opt.white = 235;
			renderMarker(img.mut(), d, ids[f][j], q, opt);
			placed.push_back({ &d, ids[f][j], q });
		}
	}
	return placed;
}

void expectOnlyTheirOwn(const Image &img, const std::vector<Placed> &placed, const std::string &scene)
{
	for (const Dictionary &dict : dictionaries()) {
		Config cfg;
		cfg.dictionary = std::string(dict.name);
		Detector det(cfg);
		const Result &res = det.detect(img.view());
		std::set<std::size_t> seen;
		for (const Marker &m : res.markers) {
			/* Each report is one of the placed markers, at its place, with
			 * the id this dictionary gives its code. */
			bool explained = false;
			for (std::size_t i = 0; i < placed.size(); ++i) {
				const Placed &p = placed[i];
				if (meanCornerError(m.corners, p.corners) > 2.0f)
					continue;
				const int want = idIn(dict, *p.dict, p.id);
				EXPECT_EQ(m.id, want) << scene << ": " << dict.name << " read " << p.dict->name << " id "
						      << p.id << " as " << m.id;
				explained = m.id == want;
				seen.insert(i);
			}
			EXPECT_TRUE(explained) << scene << ": " << dict.name << " reported id " << m.id << " at ("
					       << m.corners[0].x << ", " << m.corners[0].y << "), hamming " << m.hamming
					       << ", where no marker of it is";
		}
		/* Its own family's markers are all found. */
		for (std::size_t i = 0; i < placed.size(); ++i) {
			if (placed[i].dict == &dict) {
				EXPECT_TRUE(seen.count(i)) << scene << ": " << dict.name << " missed id " << placed[i].id;
			}
		}
	}
}

} // namespace

TEST(MixedFamilies, PlainBackground)
{
	Image img(640, 480, 140);
	const std::vector<Placed> placed = renderFamilies(img);
	blur(img, 0.6f);
	std::mt19937 rng(5);
	addNoise(img, 2.0f, rng);
	expectOnlyTheirOwn(img, placed, "plain");
}

TEST(MixedFamilies, TexturedBackground)
{
	Image img(640, 480);
	std::mt19937 rng(17);
	texture(img, rng);
	const std::vector<Placed> placed = renderFamilies(img);
	blur(img, 0.8f);
	addNoise(img, 3.0f, rng);
	expectOnlyTheirOwn(img, placed, "textured");
}

namespace {

void fillQuad(Image &img, const Quad &q, std::uint8_t v)
{
	/* Convex quads, clockwise on screen: inside when right of every side. */
	int x0 = img.width, y0 = img.height, x1 = 0, y1 = 0;
	for (const Point2f &p : q) {
		x0 = std::min(x0, static_cast<int>(std::floor(p.x)));
		y0 = std::min(y0, static_cast<int>(std::floor(p.y)));
		x1 = std::max(x1, static_cast<int>(std::ceil(p.x)));
		y1 = std::max(y1, static_cast<int>(std::ceil(p.y)));
	}
	for (int y = std::max(0, y0); y <= std::min(img.height - 1, y1); ++y) {
		for (int x = std::max(0, x0); x <= std::min(img.width - 1, x1); ++x) {
			bool in = true;
			for (int i = 0; i < 4 && in; ++i) {
				const Point2f a = q[i], b = q[(i + 1) & 3];
				in = (b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x) >= 0.0f;
			}
			if (in)
				img.at(x, y) = v;
		}
	}
}

/* A square of `side` px at (cx, cy), turned by `roll` degrees. */
Quad turned(float cx, float cy, float side, float roll)
{
	return squarePose(cx, cy, side, roll, 0.0f);
}

/* Clutter of one kind at one scale, on a light page. */
Image clutter(int kind, float scale, std::mt19937 &rng)
{
	Image img(480, 360, 215);
	std::uniform_real_distribution<float> u(0.0f, 1.0f);
	switch (kind) {
	case 0: /* blocks of random noise, fine and coarse */
		for (int b = 0; b < 6; ++b) {
			const int px = std::max(1, static_cast<int>(scale * (1 + b % 3)));
			const int x0 = 20 + (b % 3) * 150, y0 = 30 + (b / 3) * 170;
			for (int y = 0; y < 120; ++y)
				for (int x = 0; x < 120; ++x) {
					std::uint32_t h = static_cast<std::uint32_t>((x / px) * 73856093u ^ (y / px) * 19349663u ^ b * 83492791u);
					h ^= h >> 13;
					h *= 0x5bd1e995u;
					img.at(x0 + x, y0 + y) = (h >> 15) & 1 ? 240 : 20;
				}
		}
		break;
	case 1: /* text-like blobs: strokes in lines of glyphs */
		for (int line = 0; line < 9; ++line) {
			const float h = 9.0f * scale;
			for (float x = 15.0f; x < 460.0f - h; x += 0.9f * h) {
				const float y = 20.0f + line * 1.8f * h * 1.2f;
				if (y + h > 350.0f)
					break;
				for (int s = 0; s < 3; ++s) {
					const float sx = x + u(rng) * 0.6f * h, sy = y + u(rng) * 0.6f * h;
					const float w = 0.15f * h + u(rng) * 0.5f * h, t = 0.15f * h + u(rng) * 0.5f * h;
					fillQuad(img, { Point2f{ sx, sy }, { sx + w, sy }, { sx + w, sy + t }, { sx, sy + t } }, 30);
				}
			}
		}
		break;
	case 2: /* tiles: dark squares with light grout, some with a glint (a
		 * light spot the size of a whole code cell would make the tile a
		 * 4x4 marker) */
		for (float y = 10.0f; y < 340.0f; y += 22.0f * scale)
			for (float x = 10.0f; x < 460.0f; x += 22.0f * scale) {
				const float s = 18.0f * scale;
				fillQuad(img, turned(x + s / 2, y + s / 2, s, 3.0f), 40);
				if (u(rng) < 0.3f) {
					/* One draw a statement, in the order x86 has drawn them: a call's
					 * arguments are evaluated in an unspecified order (GCC for ARM
					 * draws them in another, rendering other scenes). */
					const float gy = u(rng);
					const float gx = u(rng);
					fillQuad(img,
						 turned(x + s * (0.3f + 0.4f * gx), y + s * (0.3f + 0.4f * gy),
							s * 0.08f, 30.0f),
						 200);
				}
			}
		break;
	case 3: /* checkerboards */
		for (int b = 0; b < 2; ++b) {
			const float sq = 8.0f * scale * (1 + b);
			const float x0 = 20.0f + 230.0f * b, y0 = 40.0f;
			for (int r = 0; r < 8; ++r)
				for (int c = 0; c < 8; ++c)
					if ((r + c) % 2 == 0 && x0 + (c + 1) * sq < 470 && y0 + (r + 1) * sq < 350)
						fillQuad(img, turned(x0 + (c + 0.5f) * sq, y0 + (r + 0.5f) * sq, sq, 0.0f), 25);
		}
		break;
	default: /* nested squares: black, white, black, ... */
		for (int n = 0; n < 6; ++n) {
			const float side = (30.0f + 25.0f * n) * scale * 0.5f + 20.0f;
			const float cx = 70.0f + (n % 3) * 160.0f, cy = 90.0f + (n / 3) * 170.0f;
			const float roll = 11.0f * n;
			for (int ring = 0; ring < 2 + n % 3; ++ring) {
				const float s = side * (1.0f - 0.3f * ring);
				fillQuad(img, turned(cx, cy, s, roll), ring % 2 ? 220 : 30);
			}
		}
		break;
	}
	blur(img, 0.5f + 0.3f * scale);
	addNoise(img, 3.0f, rng);
	return img;
}

} // namespace

TEST(MixedFamilies, ClutterIsNeverAMarker)
{
	const char *kinds[] = { "noise", "text", "tiles", "checkerboards", "nested squares" };
	std::mt19937 rng(23);
	std::vector<Image> frames;
	std::vector<std::string> names;
	for (int kind = 0; kind < 5; ++kind) {
		for (float scale : { 1.0f, 2.0f, 3.5f }) {
			frames.push_back(clutter(kind, scale, rng));
			names.push_back(std::string(kinds[kind]) + " x" + std::to_string(scale).substr(0, 3));
		}
	}
	for (const Dictionary &dict : dictionaries()) {
		Config cfg;
		cfg.dictionary = std::string(dict.name);
		Detector det(cfg);
		for (std::size_t f = 0; f < frames.size(); ++f) {
			const Result &res = det.detect(frames[f].view());
			for (const Marker &m : res.markers)
				ADD_FAILURE() << dict.name << " reported id " << m.id << " (hamming " << m.hamming << ", margin "
					      << m.margin << ") in " << names[f] << " at (" << m.corners[0].x << ", "
					      << m.corners[0].y << ")";
		}
	}
}
