// SPDX-License-Identifier: MIT
// The whole detector with the QPU warp (vc4-emu) against the plain CPU detector: the same
// markers to the bit (ids, corners, Hamming distances, margins), as the warp is one
// fixed-point definition (frappe/fixed_warp.h) on both. Rendered scenes always run, built
// to put cells near the binarisation threshold (blur, noise, small and tilted markers,
// several dictionaries); the shared images (../shared/data) a spread sample by default,
// every one with FRAPPE_VC4_ALL=1, skipped (exit code 77) without the folder.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "frappe/frappe.h"
#include "frappe/render.h"
#include "frontend/vc4_warper.hpp"
#if FRAPPE_VC4_TEST_OPENCV
#include <opencv2/imgcodecs.hpp>
#endif

using namespace frappe;

namespace {

bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

std::string describe(const Marker &m)
{
	char s[160];
	std::snprintf(s, sizeof s, "id %d hamming %d margin %.9g corner0 (%.9g, %.9g)", m.id, m.hamming,
		      static_cast<double>(m.margin), static_cast<double>(m.corners[0].x),
		      static_cast<double>(m.corners[0].y));
	return s;
}

struct Comparison {
	std::size_t markers = 0;
	unsigned onQpus = 0;
};

// Detects `image` with the CPU warp and with the vc4-emu warp; every marker field equal
// to the bit. Adds to `c` how many markers and QPU-warped candidates there were.
void expectSameMarkers(const ImageView &image, const std::string &dictionary, const std::string &what, Comparison &c)
{
	Config config;
	config.dictionary = dictionary;
	Detector cpu(config), qpu(config);
	qpu.setWarper(vc4::makeWarper({ .emulate = true }));
	const Result want = cpu.detect(image);
	const Result &got = qpu.detect(image);
	vc4::WarpCounts counts;
	ASSERT_TRUE(vc4::lastWarpCounts(*qpu.warper(), counts));
	c.onQpus += counts.on_qpus;
	c.markers += want.markers.size();
	ASSERT_EQ(got.markers.size(), want.markers.size()) << what;
	for (std::size_t i = 0; i < want.markers.size(); ++i) {
		const Marker &a = want.markers[i], &b = got.markers[i];
		bool same = a.id == b.id && a.hamming == b.hamming && sameBits(a.margin, b.margin);
		for (int k = 0; k < 4; ++k)
			same = same && sameBits(a.corners[k].x, b.corners[k].x) && sameBits(a.corners[k].y, b.corners[k].y);
		EXPECT_TRUE(same) << what << ": marker " << i << ": cpu " << describe(a) << ", vc4-emu " << describe(b);
	}
}

// A 640 x 480 frame: a textured background, markers from 14 to 120 px under tilt, a box
// blur of `blur` passes and noise.
std::vector<std::uint8_t> renderScene(const Dictionary &dict, unsigned seed, int blur)
{
	constexpr int W = 640, H = 480;
	std::mt19937 rng(seed);
	std::uniform_real_distribution<float> u(0, 1);
	std::vector<std::uint8_t> px(static_cast<std::size_t>(W) * H);
	for (int y = 0; y < H; ++y)
		for (int x = 0; x < W; ++x)
			px[static_cast<std::size_t>(y) * W + x] =
				static_cast<std::uint8_t>(110 + 50 * std::sin(x * 0.043 + y * 0.027) + 40 * u(rng));
	MutableImageView m{ px.data(), W, H, W };
	for (int k = 0; k < 14; ++k) {
		const float side = 14 + 106 * u(rng) * u(rng);
		const auto q = perspectiveSquare(side + (W - 2 * side) * u(rng), side + (H - 2 * side) * u(rng), side,
						 360 * u(rng), 65 * u(rng));
		RenderOptions o;
		o.black = static_cast<std::uint8_t>(20 + 60 * u(rng));
		o.white = static_cast<std::uint8_t>(160 + 90 * u(rng));
		renderMarker(m, dict, static_cast<int>((k * 37 + seed) % static_cast<unsigned>(dict.size())), q, o);
	}
	std::vector<std::uint8_t> tmp(px.size());
	for (int pass = 0; pass < blur; ++pass) {
		for (int y = 0; y < H; ++y)
			for (int x = 0; x < W; ++x) {
				int s = 0;
				for (int dy = -1; dy <= 1; ++dy)
					for (int dx = -1; dx <= 1; ++dx)
						s += px[static_cast<std::size_t>(std::clamp(y + dy, 0, H - 1)) * W +
							static_cast<std::size_t>(std::clamp(x + dx, 0, W - 1))];
				tmp[static_cast<std::size_t>(y) * W + x] = static_cast<std::uint8_t>((s + 4) / 9);
			}
		px.swap(tmp);
	}
	std::normal_distribution<float> noise(0, 4);
	for (auto &p : px)
		p = static_cast<std::uint8_t>(std::clamp(p + noise(rng), 0.0f, 255.0f));
	return px;
}

} // namespace

// Scenes of each dictionary at each blur, seeds from `seed` on, compared.
Comparison compareScenes(std::initializer_list<const char *> names, std::initializer_list<int> blurs, unsigned seed)
{
	Comparison c;
	for (const char *name : names) {
		const Dictionary &dict = *findDictionary(name);
		for (int blur : blurs) {
			const auto px = renderScene(dict, seed++, blur);
			expectSameMarkers(ImageView(px.data(), 640, 480, 640), name,
					  std::string(name) + " blur " + std::to_string(blur), c);
		}
	}
	return c;
}

TEST(Vc4WarperDetector, RenderedScenesGiveTheCpuMarkersToTheBit)
{
	const Comparison c = compareScenes(
		{ "aruco_mip_36h12", "4x4_50", "5x5_100", "apriltag_36h11", "apriltag_16h5", "7x7_50" }, { 0, 2, 4 }, 1);
	std::printf("rendered scenes: %zu markers, %u candidates warped on the QPUs\n", c.markers, c.onQpus);
	EXPECT_GT(c.markers, 150u);
	EXPECT_GT(c.onQpus, 200u);
}

// AprilTag 3's layout families (issue 32): each candidate's sample grid is the layout's
// whole grid, one sample a cell (11 to 13 a side), warped from the detected square: one
// more quad for the QPUs, and the same markers to the bit.
TEST(Vc4WarperDetector, LayoutFamiliesGiveTheCpuMarkersToTheBit)
{
	const Comparison c = compareScenes({ "apriltag_standard41h12", "apriltag_standard52h13", "apriltag_circle21h7",
					     "apriltag_circle49h12", "apriltag_custom48h12" },
					   { 0, 2 }, 100);
	std::printf("layout scenes: %zu markers, %u candidates warped on the QPUs\n", c.markers, c.onQpus);
	EXPECT_GT(c.markers, 60u);
	EXPECT_GT(c.onQpus, 100u);
}

#if FRAPPE_VC4_TEST_OPENCV
namespace {

// The truth's family of a data folder (its truth.jsonl's first record), or "".
std::string familyOf(const std::filesystem::path &folder)
{
	std::ifstream f(folder / "truth.jsonl");
	std::string line;
	std::getline(f, line);
	const std::string key = "\"family\": \"";
	const auto at = line.find(key);
	if (at == std::string::npos)
		return {};
	const auto end = line.find('"', at + key.size());
	return line.substr(at + key.size(), end - at - key.size());
}

} // namespace

TEST(Vc4WarperDetector, SharedImages)
{
	const char *shared = std::getenv("FRAPPE_SHARED");
	if (!shared)
		GTEST_SKIP() << "FRAPPE_SHARED is not set";
	const std::filesystem::path root = std::filesystem::path(shared) / "data";
	if (!std::filesystem::is_directory(root)) {
		std::printf("no shared data at %s: skipped\n", root.string().c_str());
		std::exit(77);
	}
	// Every image with a truth file above it, sorted; by default a spread of 120.
	std::vector<std::pair<std::filesystem::path, std::string>> files;
	for (const auto &e : std::filesystem::recursive_directory_iterator(root)) {
		const auto ext = e.path().extension().string();
		if (!e.is_regular_file() || (ext != ".png" && ext != ".jpg"))
			continue;
		std::string family;
		for (auto dir = e.path().parent_path(); family.empty() && dir.string().size() > root.string().size();
		     dir = dir.parent_path())
			family = familyOf(dir);
		if (!family.empty())
			files.emplace_back(e.path(), family);
	}
	std::sort(files.begin(), files.end());
	ASSERT_FALSE(files.empty());
	const bool all = std::getenv("FRAPPE_VC4_ALL") && std::string(std::getenv("FRAPPE_VC4_ALL")) == "1";
	const std::size_t step = all ? 1 : std::max<std::size_t>(1, files.size() / 120);
	Comparison c;
	std::size_t images = 0;
	for (std::size_t i = 0; i < files.size(); i += step, ++images) {
		const auto &[path, family] = files[i];
		const cv::Mat m = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
		ASSERT_FALSE(m.empty()) << path;
		ASSERT_TRUE(findDictionary(family)) << path << ": unknown family " << family;
		expectSameMarkers(ImageView(m.data, m.cols, m.rows, static_cast<int>(m.step)), family, path.string(), c);
	}
	std::printf("shared images: %zu images, %zu markers, %u candidates warped on the QPUs\n", images, c.markers,
		    c.onQpus);
	EXPECT_GT(c.onQpus, 0u);
}
#endif
