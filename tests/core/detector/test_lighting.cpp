// SPDX-License-Identifier: MIT
// Markers under hard light (issue 29): a dim room, the stripes of a blind's
// shadow, a cast shadow's edge across the marker, glare that clips, a frame
// overexposed. Each scene is rendered, then lit by a known light field (the
// marker's grey levels multiplied, as light multiplies reflectance), so the
// truth is exact; each is also run with Config::light_floor at 0.5, the
// paper's absolute thresholds, to show what the light-following ones add.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <initializer_list>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "decode.h"
#include "frappe/frappe.h"
#include "noise_floor.h"
#include "scene.h"

using namespace frappe;
using namespace frappe::test;

namespace {

/// Light as a function of the pixel: 1 is the light the scene was rendered in.
using LightField = std::function<float(float x, float y)>;

struct Scene {
	Image img;
	std::array<Point2f, 4> truth;
	int id;
};

/* Marker `id` of `dict` at a pose on a mid-grey ground, lit by `light`,
 * blurred a little, with sensor noise of `noise` grey levels added after
 * the light (a dim frame is as noisy as a bright one). */
Scene litScene(const Dictionary &dict, int id, float side, float roll, float tilt, const LightField &light,
	       float noise, unsigned seed, float sigma = 0.6f)
{
	const int size = static_cast<int>(side * 1.8f) + 40;
	Scene s{ Image(size, size, 120), squarePose(size / 2.0f + 0.3f, size / 2.0f - 0.2f, side, roll, tilt), id };
	RenderOptions opt;
	opt.black = 25;
	opt.white = 215;
	renderMarker(s.img.mut(), dict, id, s.truth, opt);
	blur(s.img, sigma);
	std::mt19937 rng(seed);
	std::normal_distribution<float> n(0.0f, noise);
	for (int y = 0; y < size; ++y)
		for (int x = 0; x < size; ++x) {
			const float v = s.img.at(x, y) * light(static_cast<float>(x), static_cast<float>(y)) + n(rng);
			s.img.at(x, y) = static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L));
		}
	return s;
}

/* Shadow stripes of a blind: `period` px apart at `angle` radians, the
 * shadowed half at `shade` of the light, edges softened over `soft` px. */
LightField blinds(float period, float angle, float shade, float soft = 2.0f)
{
	return [=](float x, float y) {
		const float t = (x * std::cos(angle) + y * std::sin(angle)) / period;
		const float f = t - std::floor(t);                      /* 0..1 across a period */
		const float d = std::min(std::abs(f - 0.25f), std::abs(f - 1.25f)) * period; /* from a lit centre */
		const float lit = std::clamp((0.25f * period - d) / soft + 0.5f, 0.0f, 1.0f);
		return shade + (1.0f - shade) * lit;
	};
}

struct Outcome {
	const Marker *marker = nullptr;
	float error = 0.0f;
	int others = 0; ///< detections that are not the marker (wrong ids, elsewhere)
};

Outcome detectIn(const Scene &s, const Dictionary &dict, float lightFloor, float perNoise = Config{}.light_floor_noise)
{
	Config cfg;
	cfg.dictionary = std::string(dict.name);
	cfg.light_floor = lightFloor;
	cfg.light_floor_noise = perNoise;
	static thread_local std::vector<Marker> keep;
	Detector det(cfg);
	keep = det.detect(s.img.view()).markers;
	Outcome o;
	o.marker = findMarker(keep, s.id);
	if (o.marker)
		o.error = meanCornerError(o.marker->corners, s.truth);
	o.others = static_cast<int>(keep.size()) - (o.marker ? 1 : 0);
	return o;
}

const Dictionary &dictionary(const char *name)
{
	const Dictionary *d = findDictionary(name);
	if (!d)
		throw std::runtime_error(std::string("no dictionary ") + name);
	return *d;
}

const float kDefault = Config{}.light_floor;
constexpr float kAbsolute = 0.5f;

/* Markers found over a sweep of rendered scenes, and the worst corner
 * error as a fraction of the side. */
struct Tally {
	int found = 0, scenes = 0;
	float worst = 0.0f;
};

/* The blinds' sweep: both 6x6 families, each value of `what` (`label`:
 * a shade or a glow), three angles and each of `sides`; render(dict, value,
 * angle, side) makes a scene. Nothing but the marker is found, and where it
 * is, its corners lie within `tolerance` of the side; `also(scene, dict)`
 * runs on every scene. */
template<typename Render, typename Also>
Tally blindsSweep(const char *label, std::initializer_list<float> what, std::initializer_list<float> sides,
		  float tolerance, Render render, Also also)
{
	Tally t;
	for (const char *name : { "aruco_mip_36h12", "apriltag_36h11" }) {
		const Dictionary &dict = dictionary(name);
		for (float value : what)
			for (float angle : { 0.3f, 1.1f, 2.2f })
				for (float side : sides) {
					const Scene s = render(dict, value, angle, side);
					const Outcome o = detectIn(s, dict, kDefault);
					EXPECT_EQ(o.others, 0)
						<< name << " " << label << " " << value << " angle " << angle;
					if (o.marker) {
						++t.found;
						t.worst = std::max(t.worst, o.error / side);
						EXPECT_LT(o.error, tolerance * side)
							<< name << " " << label << " " << value << " angle " << angle;
					}
					also(s, dict);
					++t.scenes;
				}
	}
	return t;
}

} // namespace

/* A dim room: 12% and 8% of the light, noise of 1.5 grey levels: black and
 * white 20 and 15 grey levels apart. Found at the right corners; with
 * absolute thresholds the edges are under the threshold and nothing is. */
TEST(Lighting, DimRoom)
{
	int lostWhenAbsolute = 0, scenes = 0;
	for (const char *name : { "aruco_mip_36h12", "apriltag_36h11", "4x4_50" }) {
		const Dictionary &dict = dictionary(name);
		for (float gain : { 0.12f, 0.08f })
			for (auto [side, roll, tilt] : { std::tuple{ 60.0f, 10.0f, 20.0f }, { 110.0f, -35.0f, 45.0f } }) {
				const Scene s = litScene(dict, 7, side, roll, tilt, [=](float, float) { return gain; }, 1.5f,
							 static_cast<unsigned>(side));
				const Outcome o = detectIn(s, dict, kDefault);
				ASSERT_NE(o.marker, nullptr) << name << " at " << gain << " of the light, side " << side;
				EXPECT_LT(o.error, 0.5f) << name << " at " << gain << ", side " << side;
				EXPECT_EQ(o.others, 0) << name;
				lostWhenAbsolute += detectIn(s, dict, kAbsolute).marker == nullptr;
				++scenes;
			}
	}
	EXPECT_EQ(lostWhenAbsolute, scenes);
}

/* Issue 29's criterion: a marker whose black and white differ by 10 grey
 * levels (5.3% of the light, the ground at 6 grey levels) in a frame with
 * noise of 1.5 grey levels is found, at the right corners, and nothing
 * else is; with absolute thresholds none is. (At 7 grey levels all of these
 * are found too, at 6 three of nine, at 5 none: docs/quality.md.) */
TEST(Lighting, TenGreyLevelsInANoisyFrame)
{
	int found = 0, scenes = 0, foundWhenAbsolute = 0;
	for (const char *name : { "aruco_mip_36h12", "apriltag_36h11", "4x4_50" }) {
		const Dictionary &dict = dictionary(name);
		for (auto [side, roll, tilt] :
		     { std::tuple{ 40.0f, 5.0f, 10.0f }, { 60.0f, 10.0f, 20.0f }, { 110.0f, -35.0f, 45.0f } }) {
			const float gain = 10.0f / 190.0f;
			const Scene s = litScene(
				dict, 7, side, roll, tilt, [=](float, float) { return gain; }, 1.5f,
				static_cast<unsigned>(side) + 3);
			const Outcome o = detectIn(s, dict, kDefault);
			EXPECT_EQ(o.others, 0) << name << ", side " << side;
			++scenes;
			foundWhenAbsolute += detectIn(s, dict, kAbsolute).marker != nullptr;
			if (!o.marker)
				continue;
			EXPECT_LT(o.error, 0.8f) << name << ", side " << side;
			++found;
		}
	}
	std::printf("10 grey levels, noise 1.5: %d of %d found\n", found, scenes);
	EXPECT_EQ(found, scenes);
	EXPECT_EQ(foundWhenAbsolute, 0);
}

/* A blind's shadow: stripes at a third and a fifth of the light across the
 * marker, its quiet zone and its surroundings, 2.6 cells apart, at three
 * angles: harsher than the shared lighting set's blinds (there the stripes
 * are wider and softer). Most are read, with their id and corners within 4%
 * of the side (stripe edges that run along a side pull it); with absolute
 * thresholds and grey-level reads, none. */
TEST(Lighting, BlindStripesAcrossTheMarker)
{
	int lostWhenAbsolute = 0;
	const Tally t = blindsSweep(
		"shade", { 0.33f, 0.2f }, { 90.0f, 140.0f }, 0.04f,
		[](const Dictionary &dict, float shade, float angle, float side) {
			const float cell = side / static_cast<float>(dict.bits + 2);
			return litScene(dict, 23, side, 15.0f, 25.0f, blinds(2.6f * cell, angle, shade), 1.5f,
					static_cast<unsigned>(angle * 100));
		},
		[&](const Scene &s, const Dictionary &dict) {
			lostWhenAbsolute += detectIn(s, dict, kAbsolute).marker == nullptr;
		});
	std::printf("blind stripes: %d of %d found (%d lost with absolute thresholds)\n", t.found, t.scenes,
		    lostWhenAbsolute);
	EXPECT_GE(t.found, t.scenes / 2);
	EXPECT_EQ(lostWhenAbsolute, t.scenes);
}

/* Small markers under a blind (cells under 4 px: read at their centres,
 * sharpened against their neighbours), the shadow at about half the light,
 * as in the shared lighting set. Read on the log scale, the sharpened centre
 * of a white cell beside black ones lies about twice as far above black as
 * the cell does: in grey levels twice the paper's white, which no quiet zone
 * could match (issue 29 item 2: 7 of the lighting sets' blinds markers were
 * read exactly and then lost so). The quiet zone is now held against the
 * lightest centre before sharpening. */
TEST(Lighting, SmallMarkersUnderBlindsKeepTheirQuietZone)
{
	const Tally t = blindsSweep(
		"shade", { 0.45f, 0.55f }, { 29.0f, 31.0f }, 0.05f,
		[](const Dictionary &dict, float shade, float angle, float side) {
			const float cell = side / static_cast<float>(dict.bits + 2);
			return litScene(dict, 23, side, 15.0f, 25.0f, blinds(5.0f * cell, angle, shade), 1.5f,
					static_cast<unsigned>(angle * 100 + side));
		},
		[](const Scene &, const Dictionary &) {});
	std::printf("small markers under blinds: %d of %d found\n", t.found, t.scenes);
	EXPECT_GE(t.found, 20); /* 11 with the sharpened white */
}

/* A blind's stripes and a broad glow over one corner of the marker (light
 * that adds rather than multiplies: a lamp's reflection, as on lighting
 * 00169 id 218): the lit corner's black rises above the shaded whites on
 * any one scale, grey or log. Read with a threshold per cell between the
 * border's black and the quiet zone's white where the cell lies
 * (binariseInLight()). */
TEST(Lighting, StripesAndAGlowReadWithThresholdsThatFollowTheLight)
{
	/* The glow lifts the border's black at one corner: its sides are
	 * measured a little inside (within 5% of the side). */
	const Tally t = blindsSweep(
		"glow", { 150.0f, 200.0f }, { 90.0f, 120.0f }, 0.05f,
		[](const Dictionary &dict, float glow, float angle, float side) {
			const float cell = side / static_cast<float>(dict.bits + 2);
			Scene s = litScene(dict, 23, side, 15.0f, 25.0f, blinds(2.0f * cell, angle, 0.45f, 3.0f), 2.0f,
					   static_cast<unsigned>(angle * 100 + side), 1.2f);
			const Point2f c = s.truth[1]; /* centred on a corner */
			const float r = 0.35f * side;
			for (int y = 0; y < s.img.height; ++y)
				for (int x = 0; x < s.img.width; ++x) {
					const float d2 = (x - c.x) * (x - c.x) + (y - c.y) * (y - c.y);
					const float v = s.img.at(x, y) + glow * std::exp(-0.5f * d2 / (r * r));
					s.img.at(x, y) = static_cast<std::uint8_t>(std::min(v, 255.0f));
				}
			return s;
		},
		[](const Scene &, const Dictionary &) {});
	std::printf("stripes and a glow: %d of %d found, worst corner error %.3f of the side\n", t.found, t.scenes,
		    t.worst);
	EXPECT_GE(t.found, 16); /* 2 with one threshold on the log scale */
}

/* A cast shadow's edge through the marker: one side at a quarter of the
 * light, the edge softened over 6 px, at four angles and two offsets. */
TEST(Lighting, CastShadowEdgeThroughTheMarker)
{
	const Dictionary &dict = dictionary("aruco_mip_36h12");
	int found = 0, lostWhenAbsolute = 0, scenes = 0;
	for (float angle : { 0.0f, 0.8f, 1.9f, 2.9f })
		for (float offset : { -0.15f, 0.1f }) {
			const float side = 100.0f, size = side * 1.8f + 40.0f;
			const float c = std::cos(angle), sn = std::sin(angle);
			auto light = [=](float x, float y) {
				const float d = (x - size / 2) * c + (y - size / 2) * sn - offset * side;
				return 0.25f + 0.75f * std::clamp(d / 6.0f + 0.5f, 0.0f, 1.0f);
			};
			const Scene s = litScene(dict, 101, side, 5.0f, 30.0f, light, 1.5f, 3);
			const Outcome o = detectIn(s, dict, kDefault);
			EXPECT_EQ(o.others, 0) << "angle " << angle << " offset " << offset;
			if (o.marker) {
				++found;
				EXPECT_LT(o.error, 0.6f) << "angle " << angle << " offset " << offset;
			}
			lostWhenAbsolute += detectIn(s, dict, kAbsolute).marker == nullptr;
			++scenes;
		}
	std::printf("cast shadow edge: %d of %d found (%d lost with absolute thresholds)\n", found, scenes,
		    lostWhenAbsolute);
	EXPECT_GE(found, scenes * 3 / 4);
	EXPECT_GT(lostWhenAbsolute, found / 2);
}

/* Overexposed twice over: every white clips at 255, just above the
 * midpoint of the black border's edge, whose profile is cut on its bright
 * side. The marker is read; the corners lean towards the black by about
 * half a pixel (what the clip leaves of the bright side's fall is too
 * little to place the edge: see docs/quality.md). */
TEST(Lighting, OverexposedCornersStayInPlace)
{
	for (const char *name : { "aruco_mip_36h12", "apriltag_36h11" }) {
		const Dictionary &dict = dictionary(name);
		for (auto [side, roll, tilt] : { std::tuple{ 50.0f, 5.0f, 10.0f }, { 80.0f, 30.0f, 40.0f }, { 150.0f, -20.0f, 25.0f } }) {
			const Scene s = litScene(dict, 5, side, roll, tilt, [](float, float) { return 2.0f; }, 1.5f, 9);
			const Outcome o = detectIn(s, dict, kDefault);
			ASSERT_NE(o.marker, nullptr) << name << " side " << side;
			EXPECT_LT(o.error, 0.8f) << name << " side " << side;
		}
	}
}

/* Overexposed 2.5 times, small (22-31 px) and blurred: every white clips,
 * and the blur lifts a black cell among white ones to near the ceiling,
 * above the midpoint of black and the clipped white. The read on the
 * exponential scale places the threshold near the ceiling: most are read,
 * every one with its own id; without it (absolute thresholds: one read) 9
 * of the 24. */
TEST(Lighting, OverexposedBlurredSmallMarkersRead)
{
	int found = 0, foundAbsolute = 0, scenes = 0;
	for (const char *name : { "aruco_mip_36h12", "apriltag_36h11" }) {
		const Dictionary &dict = dictionary(name);
		for (int k = 0; k < 12; ++k) {
			const int id = (k * 37 + 11) % dict.size();
			const float side = 22.0f + 3.0f * static_cast<float>(k % 4);
			const Scene s = litScene(dict, id, side, 7.0f * static_cast<float>(k), 15.0f + 2.0f * static_cast<float>(k),
						 [](float, float) { return 2.5f; }, 1.5f, static_cast<unsigned>(k), 1.2f);
			const Outcome o = detectIn(s, dict, kDefault);
			EXPECT_EQ(o.others, 0) << name << " id " << id;
			found += o.marker != nullptr;
			foundAbsolute += detectIn(s, dict, kAbsolute).marker != nullptr;
			++scenes;
		}
	}
	std::printf("overexposed, blurred: %d of %d found (%d with absolute thresholds, one read)\n", found, scenes,
		    foundAbsolute);
	EXPECT_GE(found, scenes * 3 / 4);
	EXPECT_GE(found, foundAbsolute + scenes / 4);
}

namespace {

/* Marker `id`, its found square `side` px, under a glare of radius r at
 * (gx, gy) that lifts the light 13 times at its centre. */
Scene glareScene(const Dictionary &dict, int id, float side, float gx, float gy, float r, int seed)
{
	auto light = [=](float x, float y) {
		const float d2 = (x - gx) * (x - gx) + (y - gy) * (y - gy);
		return 1.0f + 12.0f * std::exp(-d2 / (2.0f * r * r));
	};
	return litScene(dict, id, side, 12.0f, 20.0f, light, 1.5f, static_cast<unsigned>(seed));
}

} // namespace

/* Overexposed twice, larger (40-75 px) and blurred over half a cell: the
 * blur lifts the black border towards the clipped white, so the probe's
 * midpoint threshold at the traced outline reads part of the border white.
 * Such a frame is not taken for clutter where the whites clip, and the
 * marker is read, each with its own id (14 of the 16; before, 5: the
 * rest skipped unread). */
TEST(Lighting, OverexposedBlurredMarkersAreNotClutter)
{
	int found = 0, scenes = 0;
	for (const char *name : { "aruco_mip_36h12", "apriltag_36h11" }) {
		const Dictionary &dict = dictionary(name);
		for (int k = 0; k < 8; ++k) {
			const int id = (k * 41 + 7) % dict.size();
			const float side = 40.0f + 5.0f * static_cast<float>(k);
			const Scene s = litScene(
				dict, id, side, 9.0f * static_cast<float>(k), 20.0f + 3.0f * static_cast<float>(k),
				[](float, float) { return 2.0f; }, 1.5f, static_cast<unsigned>(k + 40),
				0.45f * side / static_cast<float>(dict.bits + 2));
			const Outcome o = detectIn(s, dict, kDefault);
			EXPECT_EQ(o.others, 0) << name << " id " << id;
			found += o.marker != nullptr;
			++scenes;
		}
	}
	std::printf("overexposed, blurred over half a cell: %d of %d found\n", found, scenes);
	EXPECT_GE(found, scenes * 3 / 4);
}

/* Glare: a patch clipped to white over part of the code, at many places
 * and ids. The marker may be lost, or read with its own id and a margin
 * that says little is certain; never read as another id. */
TEST(Lighting, GlareNeverMakesAWrongId)
{
	int found = 0, scenes = 0;
	for (const char *name : { "aruco_mip_36h12", "apriltag_36h11", "4x4_50", "6x6_250" }) {
		const Dictionary &dict = dictionary(name);
		for (int k = 0; k < 12; ++k) {
			const int id = (k * 53 + 3) % dict.size();
			const float side = 90.0f, size = side * 1.8f + 40.0f;
			const float gx = size / 2 + (static_cast<float>(k % 4) - 1.5f) * 0.2f * side;
			const float gy = size / 2 + (static_cast<float>(k / 4) - 1.0f) * 0.25f * side;
			const float r = (0.12f + 0.03f * static_cast<float>(k % 3)) * side;
			const Outcome o = detectIn(glareScene(dict, id, side, gx, gy, r, k), dict, kDefault);
			EXPECT_EQ(o.others, 0) << name << " id " << id << " glare at " << gx << "," << gy;
			found += o.marker != nullptr;
			++scenes;
		}
	}
	std::printf("glare: %d of %d found with their own id\n", found, scenes);
	EXPECT_GT(found, scenes / 3);
}

/* Glare over AprilTag 3's layout families (frappe/layout.h), whose bits
 * lie inside and outside the black ring: a clipped patch over the ring and
 * the cells beside it, at many places and ids. Never another id; found
 * where the patch leaves the code within reach, the clipped bits unknown. */
TEST(Lighting, GlareOnLayoutFamiliesNeverMakesAWrongId)
{
	int found = 0, scenes = 0, unknown = 0;
	for (const char *name : { "apriltag_standard41h12", "apriltag_standard52h13", "apriltag_circle21h7",
				  "apriltag_circle49h12", "apriltag_custom48h12" }) {
		const Dictionary &dict = dictionary(name);
		int foundHere = 0;
		for (int k = 0; k < 12; ++k) {
			const int id = (k * 53 + 3) % dict.size();
			/* side: the detected square, 5 to 6 of the layout's 9 to 10
			 * cells; the patch's centre on the black ring or beside it. */
			const float side = 90.0f, size = side * 1.8f + 40.0f;
			const float a = 0.5f * static_cast<float>(k),
				    d = (0.45f + 0.05f * static_cast<float>(k % 3)) * side;
			const float gx = size / 2 + d * std::cos(a), gy = size / 2 + d * std::sin(a);
			const float r = (0.15f + 0.07f * static_cast<float>(k % 3)) * side;
			const Outcome o = detectIn(glareScene(dict, id, side, gx, gy, r, k), dict, kDefault);
			EXPECT_EQ(o.others, 0) << name << " id " << id << " glare at " << gx << "," << gy;
			foundHere += o.marker != nullptr;
			unknown += o.marker && o.marker->margin == 0.0f;
			++scenes;
		}
		std::printf("glare on %s: %d of 12 found with their own id\n", name, foundHere);
		found += foundHere;
	}
	std::printf("glare on the layout families: %d of %d found with their own id, %d through unknown cells\n", found,
		    scenes, unknown);
	/* 43 when clipped cells read as white (commit 3991ae9); the misses
	 * are patches over the square's edge, which no candidate outlines. */
	EXPECT_GE(found, 44);
	EXPECT_GT(unknown, 0) << "clipped cells under glare read as unknown (margin 0)";
}

/* The log scale: 0 and 255 stay, order is kept, and well above the floor
 * a light that multiplies two grey levels leaves their difference. */
TEST(Lighting, LogScaleTurnsLightIntoAShift)
{
	const detail::Tone tone{ 16.0f };
	EXPECT_FLOAT_EQ(tone.apply(0.0f), 0.0f);
	EXPECT_NEAR(tone.apply(255.0f), 255.0f, 1e-3f);
	for (float v = 1.0f; v < 255.0f; v += 1.0f)
		EXPECT_LT(tone.apply(v - 1.0f), tone.apply(v));
	const float lit = tone.apply(200.0f) - tone.apply(40.0f);
	const float shaded = tone.apply(200.0f * 0.3f) - tone.apply(40.0f * 0.3f);
	EXPECT_GT(shaded, 0.7f * lit); /* grey levels: 0.3 of it */
	EXPECT_TRUE(detail::Tone{}.linear());
	EXPECT_FLOAT_EQ(detail::Tone{}.apply(77.0f), 77.0f);
}

/* The table the detector gives its second reads: whole grey levels read as
 * the logs give them, any other level within 0.05 of a grey level of the
 * curve, on either scale, and the order of samples kept. */
TEST(Lighting, ToneTableFollowsTheCurve)
{
	for (detail::Tone exact : { detail::Tone{ 16.0f }, detail::Tone{ 0.0f, 48.0f } }) {
		std::array<float, 256> table{};
		exact.fillTable(table.data());
		detail::Tone tabled = exact;
		tabled.table = table.data();
		detail::WarpedMarker a;
		a.side = CandidateSamples::kMaxSide;
		for (int i = 0; i < a.side * a.side; ++i)
			a.samples[static_cast<std::size_t>(i)] = i % 2 ? static_cast<float>(i % 256) : 0.37f * static_cast<float>(i % 700);
		detail::WarpedMarker b = a;
		tabled.apply(b);
		for (int i = 0; i < a.side * a.side; ++i) {
			const float v = a.samples[static_cast<std::size_t>(i)], t = b.samples[static_cast<std::size_t>(i)];
			if (i % 2) {
				EXPECT_EQ(t, table[static_cast<std::size_t>(v)]) << v;
			}
			EXPECT_NEAR(t, exact.apply(std::min(v, 255.0f)), 0.05f) << "sample " << v << " expScale " << exact.expScale;
		}
		detail::WarpedMarker ramp;
		ramp.side = CandidateSamples::kMaxSide;
		for (int i = 0; i < ramp.side * ramp.side; ++i)
			ramp.samples[static_cast<std::size_t>(i)] = 255.0f * static_cast<float>(i) / static_cast<float>(ramp.side * ramp.side - 1);
		tabled.apply(ramp);
		for (int i = 1; i < ramp.side * ramp.side; ++i)
			EXPECT_LT(ramp.samples[static_cast<std::size_t>(i - 1)], ramp.samples[static_cast<std::size_t>(i)]) << i;
	}
}

/* The frame's noise (noise_floor.h): Gaussian noise of a known deviation on
 * a flat grey and on a scene of edges (a tiled wall: an eighth of its
 * samples straddle an edge) is measured within a tenth, and the floor is
 * half the configured one at a quiet sensor's 1.5 grey levels, the
 * configured one from 3 on. A clipped or tiny frame has no estimate and
 * keeps the configured floor. */
TEST(Lighting, NoiseOfTheFrame)
{
	const int mult = detail::noiseFloorMultiplier(Config{}.light_floor_noise);
	const int cap = static_cast<int>(std::lround(Config{}.light_floor * 255.0f));
	ASSERT_EQ(cap, 16);
	for (bool tiles : { false, true })
		for (float sigma : { 1.0f, 1.5f, 2.0f, 3.0f, 4.0f }) {
			Image img(640, 480, 70);
			if (tiles)
				squareGrid(img, 24, 32, 40);
			std::mt19937 rng(static_cast<unsigned>(sigma * 10) + tiles);
			addNoise(img, sigma, rng);
			const int m = detail::noiseMedian(img.view());
			/* +- 0.55: the median of whole |L| values, less than a tenth of them at 1.5 */
			EXPECT_NEAR(m / 4.047f, sigma, 0.1f * sigma + 0.55f / 4.047f)
				<< sigma << (tiles ? " tiles" : "");
			const int floor = detail::noiseLightFloor(m, mult, cap);
			if (sigma <= 1.5f)
				EXPECT_EQ(floor, 8) << sigma;
			if (sigma >= 3.0f)
				EXPECT_EQ(floor, 16) << sigma;
		}
	Image clipped(200, 200, 0);
	EXPECT_EQ(detail::noiseMedian(clipped.view()), -1);
	EXPECT_EQ(detail::noiseLightFloor(-1, mult, cap), cap);
	EXPECT_EQ(detail::noiseMedian(Image(2, 40, 9).view()), -1);
	/* Half the cap at least, the cap at most, the cap when turned off or absolute. */
	EXPECT_EQ(detail::noiseLightFloor(0, mult, cap), 8);
	EXPECT_EQ(detail::noiseLightFloor(63, mult, cap), 16);
	EXPECT_EQ(detail::noiseLightFloor(6, 0, cap), 16);
	EXPECT_EQ(detail::noiseLightFloor(6, mult, 128), 128);
}

/* Issue 29's darkened frames lose the markers of under 10 grey levels of
 * contrast. Where the frame is as quiet as a good sensor's (noise 1.5),
 * its floor (8 grey levels, not 16) keeps markers of 6 grey levels: 7 of
 * the 9 found where the fixed floor finds 3, with their ids and nothing
 * else. Their corners: within 6% of the side (at a signal of four noise
 * deviations refinement places some 2.3-4.5 px off; the fixed floor the
 * one 40 px marker both find, 2.3 px too). */
TEST(Lighting, SixGreyLevelsInAQuietFrame)
{
	int found = 0, foundFixed = 0;
	for (const char *name : { "aruco_mip_36h12", "apriltag_36h11", "4x4_50" }) {
		const Dictionary &dict = dictionary(name);
		for (auto [side, roll, tilt] :
		     { std::tuple{ 40.0f, 5.0f, 10.0f }, { 60.0f, 10.0f, 20.0f }, { 110.0f, -35.0f, 45.0f } }) {
			const float gain = 6.0f / 190.0f;
			const Scene s = litScene(
				dict, 7, side, roll, tilt, [=](float, float) { return gain; }, 1.5f,
				static_cast<unsigned>(side) + 3);
			const Outcome o = detectIn(s, dict, kDefault);
			EXPECT_EQ(o.others, 0) << name << ", side " << side;
			foundFixed += detectIn(s, dict, kDefault, 0.0f).marker != nullptr;
			if (!o.marker)
				continue;
			EXPECT_LT(o.error, 0.06f * side) << name << ", side " << side;
			++found;
		}
	}
	std::printf("6 grey levels, noise 1.5: %d of 9 found, %d with the fixed floor\n", found, foundFixed);
	EXPECT_GE(found, 7);
	EXPECT_LE(foundFixed, 3);
}

/* A dark room seen by a noisy sensor (noise 3 and 4 grey levels, as a real
 * one at high gain): tiles, boxes and their shadows at 4-30 grey levels,
 * no marker. Its floor stays the configured one and nothing is reported in
 * any of the families most prone to read noise; a fixed floor of 8 grey
 * levels would trace the noise. */
TEST(Lighting, NoisyDarkRoomReportsNothing)
{
	const int mult = detail::noiseFloorMultiplier(Config{}.light_floor_noise);
	int reported = 0, reportedLowFloor = 0;
	for (float sigma : { 3.0f, 4.0f })
		for (unsigned seed = 0; seed < 3; ++seed) {
			std::mt19937 rng(seed * 7 + static_cast<unsigned>(sigma));
			Image img(320, 240, 14);
			squareGrid(img, 10 + 6 * static_cast<int>(seed), 24 + 8 * static_cast<int>(seed), 5);
			std::uniform_int_distribution<int> pos(0, 300), len(8, 60), grey(4, 30);
			for (int k = 0; k < 25; ++k) {
				const int x0 = pos(rng) % 320, y0 = pos(rng) % 240, w = len(rng), h = len(rng);
				const auto g = static_cast<std::uint8_t>(grey(rng));
				for (int y = y0; y < std::min(240, y0 + h); ++y)
					for (int x = x0; x < std::min(320, x0 + w); ++x)
						img.at(x, y) = g;
			}
			blur(img, 0.8f);
			addNoise(img, sigma, rng);
			EXPECT_EQ(detail::noiseLightFloor(detail::noiseMedian(img.view()), mult, 16), 16) << sigma;
			for (const char *name :
			     { "4x4_1000", "4x4_50", "aruco_original", "apriltag_16h5", "aruco_mip_36h12" }) {
				Config cfg;
				cfg.dictionary = name;
				reported += static_cast<int>(Detector(cfg).detect(img.view()).markers.size());
				cfg.light_floor = 8.0f / 255.0f;
				reportedLowFloor += static_cast<int>(Detector(cfg).detect(img.view()).markers.size());
			}
		}
	std::printf("noisy dark room: %d reported, %d with a fixed floor of 8\n", reported, reportedLowFloor);
	EXPECT_EQ(reported, 0);
}
