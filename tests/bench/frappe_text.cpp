// SPDX-License-Identifier: MIT
// frappe-text: how often printed text reads as a marker (issue 34), frappe
// against OpenCV 4.6's aruco module on the same frames.
//
//   frappe-text [--frames N] [--seed S] [--dictionary NAME]... [--no-opencv]
//               [--check] [--verbose] [--save-worst DIR]
//
// Renders N frames of text (seeded, so every run sees the same frames):
// lines of random words and letter shapes in OpenCV's Hershey fonts, at
// sizes from 12 to 110 px a letter, strokes of 1 to 9 px, upright, italic,
// turned, seen at a tilt, blurred a little, on paper lit unevenly, with
// sensor noise. No frame holds a marker: every detection is a false one.
// Runs each dictionary (default: every built-in one) through frappe at its
// defaults, and through OpenCV with the same codewords (custom Dictionary,
// at most 5 corrected bits capped by frappe's careful default, as
// frappe-bench does; a layout family has no such peer, and must read
// nothing), and prints detections per 1,000 frames for both and the
// largest margin frappe gave one; --verbose each of frappe's detections,
// --save-worst the frames where a dictionary's largest margin grew.
// --check exits 1 when frappe's rate is above OpenCV's for some dictionary
// or a detection's margin is above kWeakMargin (the text test in tests/
// meson.build).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include <opencv2/aruco.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "frappe/frappe.h"
#include "opencv_dictionary.h"

namespace {

/* A detection in text is a wrong read; one with a margin above this says
 * it is sure, which a wrong read must not. */
constexpr float kWeakMargin = 0.5f;

const char kLetters[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
/* Letter shapes that are squares and corners, in bulk. */
const char *const kShapes[] = { "LLL", "TTT", "EEE", "HHH", "FFF", "[]", "#", "=", "III", "UUU", "nnn", "OOO",
				"88", "00", "ZZ", "mmm", "www" };

std::string word(std::mt19937 &rng)
{
	std::uniform_int_distribution<int> kind(0, 4), len(1, 9), letter(0, static_cast<int>(sizeof(kLetters)) - 2);
	if (kind(rng) == 0)
		return kShapes[std::uniform_int_distribution<int>(0, std::size(kShapes) - 1)(rng)];
	std::string w;
	for (int n = len(rng); n > 0; --n)
		w += kLetters[letter(rng)];
	return w;
}

/* Frame k of the run: always the same for the same seed. */
cv::Mat textFrame(unsigned seed, int k)
{
	std::mt19937 rng(seed * 7919u + static_cast<unsigned>(k));
	auto uni = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
	const int W = 640, H = 480;
	/* Paper, lit from one side. */
	const double paper = uni(150, 245), fall = uni(0.0, 0.45);
	const double lx = uni(-1, 1), ly = uni(-1, 1);
	cv::Mat page(H, W, CV_8UC1);
	for (int y = 0; y < H; ++y)
		for (int x = 0; x < W; ++x) {
			const double t = 0.5 + 0.5 * (lx * (x - W / 2.0) + ly * (y - H / 2.0)) / (W / 2.0);
			page.at<std::uint8_t>(y, x) = cv::saturate_cast<std::uint8_t>(paper * (1.0 - fall * t));
		}
	static const int fonts[] = { cv::FONT_HERSHEY_SIMPLEX, cv::FONT_HERSHEY_PLAIN, cv::FONT_HERSHEY_DUPLEX,
				     cv::FONT_HERSHEY_COMPLEX, cv::FONT_HERSHEY_TRIPLEX, cv::FONT_HERSHEY_COMPLEX_SMALL,
				     cv::FONT_HERSHEY_SCRIPT_SIMPLEX, cv::FONT_HERSHEY_SCRIPT_COMPLEX };
	const int ink = static_cast<int>(uni(0, 60));
	const int lines = static_cast<int>(uni(2, 9));
	for (int l = 0; l < lines; ++l) {
		int font = fonts[std::uniform_int_distribution<int>(0, std::size(fonts) - 1)(rng)];
		if (uni(0, 1) < 0.2)
			font |= cv::FONT_ITALIC;
		const double scale = uni(0.4, 3.6);
		const int thick = std::max(1, static_cast<int>(scale * uni(0.8, 3.0)));
		std::string text;
		for (int n = static_cast<int>(uni(1, 6)); n > 0; --n)
			text += word(rng) + " ";
		const cv::Point at(static_cast<int>(uni(-40, W - 60)), static_cast<int>(uni(20, H + 20)));
		cv::putText(page, text, at, font, scale, cv::Scalar(ink), thick, uni(0, 1) < 0.5 ? cv::LINE_AA : cv::LINE_8);
	}
	/* Seen at an angle: a turn and a tilt of the page. */
	const double turn = uni(-35, 35) * CV_PI / 180.0, tilt = uni(0, 0.35);
	std::vector<cv::Point2f> from = { { 0, 0 }, { W, 0 }, { W, H }, { 0, H } }, to;
	for (const cv::Point2f &p : from) {
		const double x = p.x - W / 2.0, y = p.y - H / 2.0;
		const double s = 1.0 + tilt * y / H;
		to.emplace_back(static_cast<float>(W / 2.0 + s * (x * std::cos(turn) - y * std::sin(turn))),
				static_cast<float>(H / 2.0 + s * (x * std::sin(turn) + y * std::cos(turn))));
	}
	cv::Mat frame;
	cv::warpPerspective(page, frame, cv::getPerspectiveTransform(from, to), page.size(), cv::INTER_LINEAR,
			    cv::BORDER_CONSTANT, cv::Scalar(uni(40, 200)));
	const double sigma = uni(0.0, 1.2);
	if (sigma > 0.3)
		cv::GaussianBlur(frame, frame, cv::Size(0, 0), sigma);
	cv::Mat noise(frame.size(), CV_16SC1);
	cv::randn(noise, 0, 2.0);
	cv::Mat wide;
	frame.convertTo(wide, CV_16SC1);
	wide += noise;
	wide.convertTo(frame, CV_8UC1);
	return frame;
}

struct Count {
	std::string name;
	bool peer = true; ///< OpenCV reads the dictionary
	int frappe = 0, opencv = 0;
	float worstMargin = 0.0f;
};

} // namespace

int main(int argc, char **argv)
{
	int frames = 1000;
	unsigned seed = 1;
	bool withOpencv = true, check = false, verbose = false;
	std::string saveDir;
	std::vector<std::string> names;
	for (int i = 1; i < argc; ++i) {
		const std::string a = argv[i];
		auto next = [&]() -> std::string {
			if (i + 1 >= argc) {
				std::fprintf(stderr, "frappe-text: %s needs a value\n", a.c_str());
				std::exit(2);
			}
			return argv[++i];
		};
		if (a == "--frames")
			frames = std::max(1, std::atoi(next().c_str()));
		else if (a == "--seed")
			seed = static_cast<unsigned>(std::strtoul(next().c_str(), nullptr, 10));
		else if (a == "--dictionary")
			names.push_back(next());
		else if (a == "--no-opencv")
			withOpencv = false;
		else if (a == "--check")
			check = true;
		else if (a == "--verbose")
			verbose = true;
		else if (a == "--save-worst")
			saveDir = next();
		else {
			std::fprintf(stderr, "usage: frappe-text [--frames N] [--seed S] [--dictionary NAME]... "
					     "[--no-opencv] [--check] [--verbose] [--save-worst DIR]\n");
			return 2;
		}
	}
	if (names.empty())
		for (const frappe::Dictionary &d : frappe::dictionaries())
			names.emplace_back(d.name);
	cv::setNumThreads(1);

	std::vector<Count> counts;
	std::vector<frappe::Detector> detectors;
	std::vector<cv::Ptr<cv::aruco::Dictionary>> cvDicts;
	for (const std::string &n : names) {
		const frappe::Dictionary *d = frappe::findDictionary(n);
		if (!d) {
			std::fprintf(stderr, "frappe-text: unknown dictionary '%s'; known: %s\n", n.c_str(),
				     frappe::dictionaryNames().c_str());
			return 2;
		}
		frappe::Config cfg;
		cfg.dictionary = n;
		detectors.emplace_back(cfg);
		counts.push_back({ std::string(d->name) });
		/* OpenCV reads n x n codes only: a layout family has no peer, and
		 * frappe must read no text at all in it. */
		counts.back().peer = d->layout == nullptr;
		cvDicts.push_back(counts.back().peer ? opencvDictionary(*d, std::min(5, detectors.back().maxHamming()))
						     : cv::Ptr<cv::aruco::Dictionary>());
	}
	auto params = cv::aruco::DetectorParameters::create();
	params->cornerRefinementMethod = cv::aruco::CORNER_REFINE_NONE;

	for (int k = 0; k < frames; ++k) {
		const cv::Mat frame = textFrame(seed, k);
		const frappe::ImageView view(frame.data, frame.cols, frame.rows, static_cast<int>(frame.step));
		for (std::size_t i = 0; i < names.size(); ++i) {
			const frappe::Result &r = detectors[i].detect(view);
			for (const frappe::Marker &m : r.markers) {
				++counts[i].frappe;
				if (verbose)
					std::printf("frame %d: %s id %d, hamming %d, margin %.3f, first side %.1f px\n", k,
						    counts[i].name.c_str(), m.id, m.hamming, m.margin,
						    std::hypot(m.corners[0].x - m.corners[1].x, m.corners[0].y - m.corners[1].y));
				if (m.margin > counts[i].worstMargin && !saveDir.empty())
					cv::imwrite(saveDir + "/" + counts[i].name + "-" + std::to_string(k) + ".png", frame);
				counts[i].worstMargin = std::max(counts[i].worstMargin, m.margin);
			}
			if (withOpencv && counts[i].peer) {
				std::vector<int> ids;
				std::vector<std::vector<cv::Point2f>> corners, rejected;
				cv::aruco::detectMarkers(frame, cvDicts[i], corners, ids, params, rejected);
				counts[i].opencv += static_cast<int>(ids.size());
			}
		}
	}

	const double per = 1000.0 / frames;
	std::printf("%d frames of text, seed %u: detections per 1,000 frames (each one false)\n", frames, seed);
	std::printf("| dictionary | frappe | OpenCV 4.6 | frappe's largest margin |\n|---|---:|---:|---:|\n");
	bool ok = true;
	for (const Count &c : counts) {
		char opencvRate[32] = "-";
		if (withOpencv && c.peer)
			std::snprintf(opencvRate, sizeof(opencvRate), "%.1f", c.opencv * per);
		std::printf("| %s | %.1f | %s | %.3f |\n", c.name.c_str(), c.frappe * per, opencvRate, c.worstMargin);
		if (check && ((withOpencv && c.frappe > (c.peer ? c.opencv : 0)) || c.worstMargin > kWeakMargin)) {
			std::printf("  ^ %s: %d detections (OpenCV %d), largest margin %.3f (at most %.2f)\n", c.name.c_str(),
				    c.frappe, c.opencv, c.worstMargin, kWeakMargin);
			ok = false;
		}
	}
	return ok ? 0 : 1;
}
