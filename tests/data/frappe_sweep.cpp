// SPDX-License-Identifier: MIT
// frappe-sweep: the driver of the heavy data tests and scripts/quality.py.
// Decodes each listed image once and runs several detections on it: every
// dictionary (the wrong-id matrix) and upsampled copies (the resolution
// checks). PNG decoding costs more than a detection, so one pass over the
// list replaces one frappe-detect run per dictionary and scale.
//
//   frappe-sweep --list LIST.txt --run DICTIONARY:SCALE:INTERP:OUT.jsonl [--run ...]
//
// Each run writes OUT.jsonl in frappe-detect's --out format (one line per
// listed image, the path as listed, so the lines score against the original
// truth once its corners are scaled). SCALE is a whole factor, 1 = the image
// as read; INTERP is linear or nearest, or lightG (SCALE 1) for the image
// exposed G times as long (0.15, 2, ...): round(v G + n), n drawn from
// N(0, 1.5^2) (sensor noise) seeded by the image's line in the list,
// clipped to 0..255; the truth is the original's. For a whole factor both of OpenCV's
// resize modes put output pixel x at input x' = (x + 0.5) / s - 0.5, so
// truth corners scale as x' = (x + 0.5) s - 0.5. Detection is frappe-detect's
// at defaults: a Detector of the default Config, single thread, CPU front
// end; `time_ms` is that one detection.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <random>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "frappe/frappe.h"

namespace {

struct Run {
	std::string dictionary, out;
	int scale = 1;
	int interp = cv::INTER_LINEAR;
	double light = 0.0; /* > 0: an exposed copy, no resampling */
	std::unique_ptr<frappe::Detector> detector;
	std::ofstream file;
};

[[noreturn]] void usage(const std::string &msg)
{
	std::cerr << "frappe-sweep: " << msg << "\n"
		  << "usage: frappe-sweep --list LIST.txt --run DICTIONARY:SCALE:linear|nearest:OUT.jsonl [--run ...]\n";
	std::exit(2);
}

Run parseRun(const std::string &spec)
{
	/* The output path is last so that it may hold colons. */
	std::vector<std::string> f;
	std::size_t from = 0;
	for (int k = 0; k < 3; ++k) {
		const std::size_t at = spec.find(':', from);
		if (at == std::string::npos)
			usage("bad --run '" + spec + "'");
		f.push_back(spec.substr(from, at - from));
		from = at + 1;
	}
	f.push_back(spec.substr(from));
	Run r;
	r.dictionary = f[0];
	r.out = f[3];
	try {
		std::size_t used = 0;
		r.scale = std::stoi(f[1], &used);
		if (used != f[1].size() || r.scale < 1 || r.scale > 8)
			throw std::invalid_argument(f[1]);
	} catch (const std::exception &) {
		usage("the scale of --run '" + spec + "' is not a whole factor 1..8");
	}
	if (f[2] == "linear")
		r.interp = cv::INTER_LINEAR;
	else if (f[2] == "nearest")
		r.interp = cv::INTER_NEAREST;
	else if (f[2].rfind("light", 0) == 0) {
		char *end = nullptr;
		r.light = std::strtod(f[2].c_str() + 5, &end);
		if (end == f[2].c_str() + 5 || *end || !(r.light > 0.0 && r.light <= 16.0) || r.scale != 1)
			usage("the exposure of --run '" + spec + "' is not lightG with 0 < G <= 16 at scale 1");
	} else
		usage("the interpolation of --run '" + spec + "' is not linear, nearest or lightG");
	if (r.out.empty())
		usage("--run '" + spec + "' has no output file");
	return r;
}

/* frappe-detect's line (the library's one marker writer, rounded). */
void writeLine(std::ofstream &out, const std::string &image, const std::vector<frappe::Marker> &markers,
	       std::string_view dictionary, double ms, const std::string &error)
{
	std::string line = "{\"image\": ";
	frappe::appendJsonString(line, image);
	line += ", \"markers\": [";
	for (std::size_t i = 0; i < markers.size(); ++i) {
		if (i)
			line += ", ";
		frappe::appendMarkerJson(line, { &markers[i], dictionary, nullptr }, frappe::JsonNumbers::Rounded);
	}
	line += "]";
	if (!error.empty()) {
		line += ", \"error\": ";
		frappe::appendJsonString(line, error);
	}
	char buf[64];
	std::snprintf(buf, sizeof(buf), ", \"time_ms\": %.4f}\n", ms);
	out << line << buf;
}

/* The image exposed `light` times as long, with sensor noise of 1.5 grey
 * levels, the same for every run and every machine's standard library
 * (a fixed generator, Box-Muller by hand). */
void expose(const cv::Mat &gray, double light, unsigned seed, cv::Mat &out)
{
	out.create(gray.rows, gray.cols, CV_8UC1);
	std::mt19937 rng(seed * 2654435761u + 12345u);
	auto uniform = [&] { return (static_cast<double>(rng()) + 0.5) / 4294967296.0; };
	for (int y = 0; y < gray.rows; ++y)
		for (int x = 0; x < gray.cols; ++x) {
			const double n = 1.5 * std::sqrt(-2.0 * std::log(uniform())) * std::cos(6.283185307179586 * uniform());
			const long v = std::lround(gray.at<std::uint8_t>(y, x) * light + n);
			out.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(std::clamp(v, 0L, 255L));
		}
}

} // namespace

int main(int argc, char **argv)
{
	std::string list;
	std::vector<Run> runs;
	for (int i = 1; i < argc; ++i) {
		const std::string a = argv[i];
		if (i + 1 >= argc)
			usage(a + " needs a value");
		if (a == "--list")
			list = argv[++i];
		else if (a == "--run")
			runs.push_back(parseRun(argv[++i]));
		else
			usage("unknown option " + a);
	}
	if (list.empty() || runs.empty())
		usage("need --list and at least one --run");

	for (Run &r : runs) {
		frappe::Config cfg;
		cfg.dictionary = r.dictionary;
		cfg.threads = 1;
		try {
			r.detector = std::make_unique<frappe::Detector>(cfg);
		} catch (const std::exception &e) {
			usage(e.what());
		}
		r.file.open(r.out);
		if (!r.file)
			usage("cannot write " + r.out);
	}

	std::ifstream in(list);
	if (!in)
		usage("cannot read the list " + list);
	using Clock = std::chrono::steady_clock;
	/* One resampled copy per (scale, interpolation) and image, shared by its
	 * runs; the buffers live across images so that big copies are not
	 * allocated (and faulted in) again for every image. */
	std::map<std::pair<int, int>, cv::Mat> copies;
	std::set<std::pair<int, int>> made;
	std::map<double, cv::Mat> exposed;
	unsigned line = 0;
	for (std::string path; std::getline(in, path);) {
		if (path.empty() || path[0] == '#')
			continue;
		const cv::Mat gray = cv::imread(path, cv::IMREAD_GRAYSCALE);
		made.clear();
		++line;
		for (Run &r : runs) {
			std::string error;
			std::vector<frappe::Marker> markers;
			double ms = 0;
			if (gray.empty()) {
				error = "cannot decode " + path + " as an image";
			} else {
				const std::pair<int, int> key{ r.scale, r.interp };
				cv::Mat &img = r.light > 0.0 ? exposed[r.light] : copies[key];
				if (r.light > 0.0)
					expose(gray, r.light, line, img);
				else if (r.scale == 1)
					img = gray;
				else if (made.insert(key).second)
					cv::resize(gray, img, cv::Size(gray.cols * r.scale, gray.rows * r.scale), 0, 0, r.interp);
				try {
					const auto t0 = Clock::now();
					const frappe::Result &res = r.detector->detect(
						{ img.data, img.cols, img.rows, static_cast<int>(img.step[0]) });
					ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
					markers = res.markers;
				} catch (const std::exception &e) {
					error = e.what();
				}
			}
			if (!error.empty())
				std::cerr << "frappe-sweep: " << path << ": " << error << "\n";
			writeLine(r.file, path, markers, r.detector->dictionary().name, ms, error);
		}
	}
	for (Run &r : runs) {
		r.file.close();
		if (!r.file) {
			std::cerr << "frappe-sweep: cannot write " << r.out << "\n";
			return 1;
		}
	}
	return 0;
}
