// SPDX-License-Identifier: MIT
// frappe-render: draws markers, for printing or for test scenes.
//
//   frappe-render --dictionary aruco_mip_36h12 --id 7 --cell 40 marker7.png
//   frappe-render --scene --dictionary apriltag_36h11 --seed 3 scene.png   (+ scene.json truth)
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <random>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "frappe/frappe.h"
#include "frappe/render.h"

#include "cli_text.h"

namespace {

const char kUsage[] =
	"usage: frappe-render [--dictionary NAME] [--id N] [--cell PX] [--quiet CELLS] OUT.png\n"
	"       frappe-render --scene [--dictionary NAME] [--seed S] [--count N] [--hard] OUT.png\n"
	"       frappe-render --board ROWSxCOLS [--dictionary NAME] [--cell PX] [--gap CELLS]\n"
	"                     [--first-id N] [--marker-size M] OUT.png\n"
	"\n"
	"The first form draws one marker upright, for printing. The second draws a\n"
	"640x480 scene of markers under perspective, blur and noise, and writes their\n"
	"ids and corners (OpenCV order, pixel centres at integers) to OUT.json.\n"
	"--hard: smaller markers (25-80 px), tilted up to 65 degrees, more blur and noise.\n"
	"The third draws a grid board (ids row-major from --first-id, --gap cells between\n"
	"markers, 2 by default) and writes its bundle file, for frappe-detect --bundle, to\n"
	"OUT.yaml: the markers' side --marker-size metres (0.04 by default) as printed.\n";

[[noreturn]] void fail(const std::string &m)
{
	std::cerr << "frappe-render: " << m << "\n" << kUsage;
	std::exit(2);
}

/* An integer option in [lo, hi]; anything else is a usage error, never an
 * exception out of main. */
int intOption(const std::string &opt, const std::string &text, int lo, int hi)
{
	int v = 0;
	if (!frappe::cli::parseNumber(text, v) || v < lo || v > hi)
		fail(opt + " needs a whole number in " + std::to_string(lo) + ".." + std::to_string(hi) + ", got '" +
		     text + "'");
	return v;
}

/* cv::imwrite throws for a name without a known extension. */
bool writeImage(const std::string &path, const cv::Mat &img)
{
	try {
		if (cv::imwrite(path, img))
			return true;
	} catch (const cv::Exception &) {
	}
	std::cerr << "frappe-render: cannot write " << path << "\n";
	return false;
}

} // namespace

int main(int argc, char **argv)
{
	std::string dictName = "aruco_mip_36h12", out;
	int id = 0, cell = 20, quiet = 1, seed = 1, count = 6;
	bool scene = false, hard = false;
	int boardRows = 0, boardCols = 0, gap = 2, firstId = 0;
	double markerSize = 0.04;
	for (int i = 1; i < argc; ++i) {
		const std::string a = argv[i];
		auto value = [&]() -> std::string {
			if (i + 1 >= argc)
				fail(a + " needs a value");
			return argv[++i];
		};
		if (a == "-h" || a == "--help") {
			std::cout << kUsage;
			return 0;
		} else if (a == "--dictionary" || a == "-d") {
			dictName = value();
		} else if (a == "--id") {
			id = intOption(a, value(), 0, 1 << 20); /* the dictionary's bound below */
		} else if (a == "--cell") {
			cell = intOption(a, value(), 1, 1000);
		} else if (a == "--quiet") {
			quiet = intOption(a, value(), 0, 100);
		} else if (a == "--seed") {
			seed = intOption(a, value(), 0, std::numeric_limits<int>::max());
		} else if (a == "--count") {
			count = intOption(a, value(), 1, 30); /* more only piles markers on each other */
		} else if (a == "--scene") {
			scene = true;
		} else if (a == "--hard") {
			hard = true;
		} else if (a == "--board") {
			const std::string v = value();
			const auto x = v.find('x');
			if (x == std::string::npos)
				fail("--board needs ROWSxCOLS, got '" + v + "'");
			boardRows = intOption(a, v.substr(0, x), 1, 100);
			boardCols = intOption(a, v.substr(x + 1), 1, 100);
		} else if (a == "--gap") {
			gap = intOption(a, value(), 0, 100);
		} else if (a == "--first-id") {
			firstId = intOption(a, value(), 0, 1 << 20);
		} else if (a == "--marker-size") {
			const std::string v = value();
			if (!frappe::cli::parseNumber(v, markerSize) || !(markerSize > 0.0) || !std::isfinite(markerSize))
				fail("--marker-size needs metres above 0, got '" + v + "'");
		} else if (a.empty()) {
			fail("an empty argument");
		} else if (a[0] == '-') {
			fail("unknown option " + a);
		} else if (!out.empty()) {
			fail("one output file, got '" + out + "' and '" + a + "'");
		} else {
			out = a;
		}
	}
	const frappe::Dictionary *dict = frappe::findDictionary(dictName);
	if (!dict)
		fail("unknown dictionary '" + dictName + "'; known: " + frappe::dictionaryNames());
	if (out.empty())
		fail("no output file");

	if (boardRows > 0) {
		/* A grid board: each marker's whole layout, `gap` cells apart and
		 * from the edge; the bundle measures between the found squares. */
		if (firstId + boardRows * boardCols > dict->size())
			fail("ids " + std::to_string(firstId) + ".." + std::to_string(firstId + boardRows * boardCols - 1) + " are not all in " +
			     std::string(dict->name));
		const int whole = dict->layout ? dict->layout->size : dict->bits + 2, square = dict->bits + 2;
		const long long pitch = static_cast<long long>(whole + gap) * cell;
		if (pitch * std::max(boardRows, boardCols) + static_cast<long long>(gap) * cell > 32768)
			fail("the board would be wider than 32768 pixels");
		const int W = static_cast<int>(pitch * boardCols + gap * cell), H = static_cast<int>(pitch * boardRows + gap * cell);
		cv::Mat img(H, W, CV_8UC1, cv::Scalar(255));
		for (int r = 0; r < boardRows; ++r)
			for (int c = 0; c < boardCols; ++c) {
				int side = 0;
				auto px = frappe::markerImage(*dict, firstId + r * boardCols + c, cell, 0, side);
				cv::Mat(side, side, CV_8UC1, px.data())
					.copyTo(img(cv::Rect(static_cast<int>(gap * cell + c * pitch), static_cast<int>(gap * cell + r * pitch), side, side)));
			}
		const std::string yamlPath = std::filesystem::path(out).replace_extension(".yaml").string();
		std::ofstream yaml(yamlPath);
		char buf[256];
		std::snprintf(buf, sizeof buf, "board: grid\nrows: %d\ncols: %d\nsize: %.9g\ngap: %.9g\nfirst_id: %d\n", boardRows,
			      boardCols, markerSize, markerSize * static_cast<double>(whole - square + gap) / square, firstId);
		yaml << "# " << dict->name << " board by frappe-render; size: the found square's side, metres\n" << buf;
		if (!yaml.flush()) {
			std::cerr << "frappe-render: cannot write " << yamlPath << "\n";
			return 1;
		}
		return writeImage(out, img) ? 0 : 1;
	}

	if (!scene) {
		if (id < 0 || id >= dict->size())
			fail("id must be in 0.." + std::to_string(dict->size() - 1));
		/* the side in pixels stays within what an image file holds */
		if (static_cast<long long>(cell) * ((dict->layout ? dict->layout->size : dict->bits + 2) + 2 * quiet) > 32768)
			fail("--cell " + std::to_string(cell) + " with --quiet " + std::to_string(quiet) +
			     " makes a marker wider than 32768 pixels");
		int side = 0;
		auto px = frappe::markerImage(*dict, id, cell, quiet, side);
		cv::Mat img(side, side, CV_8UC1, px.data());
		return writeImage(out, img) ? 0 : 1;
	}

	/* A scene: a textured backdrop, markers in a loose grid, then optics. */
	std::mt19937 rng(seed);
	std::uniform_real_distribution<double> U(0, 1);
	cv::Mat img(480, 640, CV_8UC1);
	for (int y = 0; y < 480; ++y)
		for (int x = 0; x < 640; ++x)
			img.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(
				90 + 40 * std::sin(x * 0.021 + y * 0.013) + 25 * std::sin(x * 0.11) * std::cos(y * 0.07));
	frappe::MutableImageView view{ img.data, 640, 480, static_cast<int>(img.step[0]) };
	const std::string jsonPath = std::filesystem::path(out).replace_extension(".json").string();
	std::ofstream json(jsonPath);
	if (!json) {
		std::cerr << "frappe-render: cannot write " << jsonPath << "\n";
		return 1;
	}
	json << "{\"image\": \"" << frappe::cli::jsonEscape(std::filesystem::path(out).filename().string())
	     << "\", \"family\": \"" << dict->name << "\", \"markers\": [";
	const int cols = 3, rows = (count + cols - 1) / cols;
	for (int k = 0; k < count; ++k) {
		const int mid = static_cast<int>(U(rng) * dict->size());
		const double cx = 110 + (k % cols) * 210 + 20 * (U(rng) - 0.5);
		const double cy = 480.0 / (rows + 1) * (k / cols + 1) + 20 * (U(rng) - 0.5);
		/* A layout's square is part of its marker: the whole marker as large as today's. */
		const double fit = dict->layout ? static_cast<double>(dict->bits + 2) / dict->layout->size : 1.0;
		const double side = (hard ? 25 + 55 * U(rng) : 50 + 70 * U(rng)) * fit;
		const auto q = frappe::perspectiveSquare(static_cast<float>(cx), static_cast<float>(cy), static_cast<float>(side),
							 static_cast<float>(360 * U(rng)), static_cast<float>((hard ? 65 : 50) * U(rng)));
		frappe::RenderOptions opt;
		opt.black = static_cast<std::uint8_t>(15 + 20 * U(rng));
		opt.white = static_cast<std::uint8_t>(200 + 50 * U(rng));
		frappe::renderMarker(view, *dict, mid, q, opt);
		char buf[256];
		std::snprintf(buf, sizeof(buf), "%s{\"id\": %d, \"corners\": [[%.3f, %.3f], [%.3f, %.3f], [%.3f, %.3f], [%.3f, %.3f]]}",
			      k ? ", " : "", mid, q[0].x, q[0].y, q[1].x, q[1].y, q[2].x, q[2].y, q[3].x, q[3].y);
		json << buf;
	}
	json << "]}\n";
	cv::GaussianBlur(img, img, cv::Size(0, 0), hard ? 1.1 : 0.7);
	cv::Mat noise(img.size(), CV_16SC1);
	cv::randn(noise, 0, hard ? 6 : 3);
	cv::Mat wide;
	img.convertTo(wide, CV_16SC1);
	wide += noise;
	wide.convertTo(img, CV_8UC1);
	json.flush();
	if (!json) {
		std::cerr << "frappe-render: cannot write " << jsonPath << "\n";
		return 1;
	}
	return writeImage(out, img) ? 0 : 1;
}
