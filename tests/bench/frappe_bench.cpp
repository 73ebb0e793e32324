// SPDX-License-Identifier: MIT
// frappe-bench: frappe-core against OpenCV 4.6's aruco module on the same
// images, in the same process, interleaved, single-threaded.
//
//   frappe-bench --dictionary aruco_mip_36h12 --list LIST.txt [--repeat 5]
//                [--out-frappe F.jsonl] [--out-opencv O.jsonl] [--threads N]
//
// Prints median and p90 milliseconds per frame for each detector, their
// ratio, and each stage's share of frappe's time. OpenCV gets the same
// dictionary as a custom Dictionary, at most 5 corrected bits (capped by
// the dictionary's safe maximum), and no corner refinement, as in
// shared/design/DETECTOR-CONTRACT.md. Not a test: speed is never asserted.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <opencv2/aruco.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

#include "frappe/frappe.h"

namespace {

using Clock = std::chrono::steady_clock;

double ms(Clock::time_point a, Clock::time_point b)
{
	return std::chrono::duration<double, std::milli>(b - a).count();
}

double percentile(std::vector<double> v, double p)
{
	if (v.empty())
		return 0;
	std::sort(v.begin(), v.end());
	const double idx = p * static_cast<double>(v.size() - 1);
	const std::size_t lo = static_cast<std::size_t>(idx);
	const std::size_t hi = std::min(lo + 1, v.size() - 1);
	return v[lo] + (idx - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

cv::Ptr<cv::aruco::Dictionary> opencvDictionary(const frappe::Dictionary &d, int maxCorrection)
{
	auto dict = cv::makePtr<cv::aruco::Dictionary>();
	dict->markerSize = d.bits;
	dict->maxCorrectionBits = maxCorrection;
	const int n = d.bits;
	for (int id = 0; id < d.size(); ++id) {
		cv::Mat bits(n, n, CV_8UC1);
		for (int r = 0; r < n; ++r)
			for (int c = 0; c < n; ++c)
				bits.at<std::uint8_t>(r, c) =
					static_cast<std::uint8_t>((d.codes[id] >> (n * n - 1 - (r * n + c))) & 1u);
		dict->bytesList.push_back(cv::aruco::Dictionary::getByteListFromBits(bits));
	}
	return dict;
}

void writeLine(std::ofstream &out, const std::string &image, const std::vector<int> &ids,
	       const std::vector<std::array<frappe::Point2f, 4>> &corners, double t)
{
	if (!out.is_open())
		return;
	out << "{\"image\": \"" << image << "\", \"markers\": [";
	char buf[160];
	for (std::size_t i = 0; i < ids.size(); ++i) {
		const auto &c = corners[i];
		std::snprintf(buf, sizeof(buf), "%s{\"id\": %d, \"corners\": [[%.3f, %.3f], [%.3f, %.3f], [%.3f, %.3f], [%.3f, %.3f]]}",
			      i ? ", " : "", ids[i], c[0].x, c[0].y, c[1].x, c[1].y, c[2].x, c[2].y, c[3].x, c[3].y);
		out << buf;
	}
	std::snprintf(buf, sizeof(buf), "], \"time_ms\": %.4f}\n", t);
	out << buf;
}

} // namespace

int main(int argc, char **argv)
{
	std::string dictName = "aruco_mip_36h12", list, outF, outO;
	int repeat = 5, threads = 1;
	for (int i = 1; i < argc; ++i) {
		const std::string a = argv[i];
		auto value = [&]() -> std::string {
			if (i + 1 >= argc) {
				std::cerr << a << " needs a value\n";
				std::exit(2);
			}
			return argv[++i];
		};
		if (a == "--dictionary")
			dictName = value();
		else if (a == "--list")
			list = value();
		else if (a == "--repeat")
			repeat = std::max(1, std::stoi(value()));
		else if (a == "--threads")
			threads = std::stoi(value());
		else if (a == "--out-frappe")
			outF = value();
		else if (a == "--out-opencv")
			outO = value();
		else {
			std::cerr << "usage: frappe-bench --dictionary D --list L [--repeat N] [--threads T] "
				     "[--out-frappe F] [--out-opencv O]\n";
			return 2;
		}
	}
	const frappe::Dictionary *dict = frappe::findDictionary(dictName);
	if (!dict || list.empty()) {
		std::cerr << "frappe-bench: need a known --dictionary and a --list\n";
		return 2;
	}
	std::vector<std::string> paths;
	std::vector<cv::Mat> images;
	{
		std::ifstream in(list);
		for (std::string line; std::getline(in, line);) {
			if (line.empty() || line[0] == '#')
				continue;
			cv::Mat g = cv::imread(line, cv::IMREAD_GRAYSCALE);
			if (g.empty()) {
				std::cerr << "frappe-bench: cannot read " << line << "\n";
				continue;
			}
			paths.push_back(line);
			images.push_back(g);
		}
	}
	if (images.empty()) {
		std::cerr << "frappe-bench: no images\n";
		return 2;
	}
	cv::setNumThreads(1); /* OpenCV single-threaded, like frappe */

	frappe::Config cfg;
	cfg.dictionary = dictName;
	cfg.threads = threads;
	frappe::Detector frappeDet(cfg);
	const auto cvDict = opencvDictionary(*dict, std::min(5, frappeDet.maxHamming()));
	auto params = cv::aruco::DetectorParameters::create();
	params->cornerRefinementMethod = cv::aruco::CORNER_REFINE_NONE;

	std::ofstream fo, oo;
	if (!outF.empty())
		fo.open(outF);
	if (!outO.empty())
		oo.open(outO);

	std::vector<double> tF, tO;
	std::array<double, frappe::kStageCount> stageSum{};
	double totalSum = 0;
	std::vector<int> ids;
	std::vector<std::vector<cv::Point2f>> cvCorners;
	for (std::size_t k = 0; k < images.size(); ++k) {
		const cv::Mat &g = images[k];
		const frappe::ImageView view(g.data, g.cols, g.rows, static_cast<int>(g.step[0]));
		std::vector<double> a, b;
		for (int r = 0; r < repeat; ++r) {
			/* Interleaved: each repetition runs both, so drift hits both. */
			auto t0 = Clock::now();
			const frappe::Result &res = frappeDet.detect(view);
			auto t1 = Clock::now();
			cv::aruco::detectMarkers(g, cvDict, cvCorners, ids, params);
			auto t2 = Clock::now();
			a.push_back(ms(t0, t1));
			b.push_back(ms(t1, t2));
			if (r == repeat - 1) {
				for (int s = 0; s < frappe::kStageCount; ++s)
					stageSum[s] += res.times.ms[s];
				totalSum += res.times.total_ms;
				std::vector<int> fid;
				std::vector<std::array<frappe::Point2f, 4>> fc;
				for (const auto &m : res.markers) {
					fid.push_back(m.id);
					fc.push_back(m.corners);
				}
				writeLine(fo, paths[k], fid, fc, percentile(a, 0.5));
				std::vector<std::array<frappe::Point2f, 4>> oc;
				for (const auto &c : cvCorners)
					oc.push_back({ frappe::Point2f{ c[0].x, c[0].y }, { c[1].x, c[1].y }, { c[2].x, c[2].y }, { c[3].x, c[3].y } });
				writeLine(oo, paths[k], ids, oc, percentile(b, 0.5));
			}
		}
		tF.push_back(percentile(a, 0.5));
		tO.push_back(percentile(b, 0.5));
	}

	const double mf = percentile(tF, 0.5), mo = percentile(tO, 0.5);
	std::printf("%zu images, %s, %d repeats, frappe threads %d, OpenCV %s single thread\n", images.size(),
		    dictName.c_str(), repeat, threads, CV_VERSION);
	std::printf("%-22s %10s %10s\n", "detector", "median ms", "p90 ms");
	std::printf("%-22s %10.3f %10.3f\n", "frappe", mf, percentile(tF, 0.9));
	std::printf("%-22s %10.3f %10.3f\n", "opencv aruco", mo, percentile(tO, 0.9));
	std::printf("speed ratio (opencv / frappe, medians): %.2fx\n", mo / mf);
	std::printf("frappe stage shares:");
	for (int s = 0; s < frappe::kStageCount; ++s)
		std::printf(" %s %.1f%%", std::string(frappe::stageName(static_cast<frappe::Stage>(s))).c_str(),
			    100.0 * stageSum[s] / std::max(1e-9, totalSum));
	std::printf("\n");
	return 0;
}
