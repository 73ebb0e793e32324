// SPDX-License-Identifier: MIT
// frappe-track-bench: Mode::Track against Mode::Normal on a sequence, in the
// same process, frame by frame interleaved (each detector sees every frame
// in order), single-threaded.
//
//   frappe-track-bench --list SEQ.txt [--dictionary D] [--cover K]
//                      [--resize F | --canvas F] [--out-normal N.jsonl]
//                      [--out-track T.jsonl] [--only normal|track]
//
// Prints each mode's median and p90 milliseconds per frame, their ratio,
// the frames Track read whole, and the bytes each read per frame against
// one read of the frame. --resize F scales every frame by F (the same
// scene at a higher resolution: markers F times larger); --canvas F puts
// each frame in the middle of a frame F times larger, the rest the frame's
// own pixels mirrored (the same markers, in pixels, in a larger scene). The
// JSON lines are the contract's, for ../shared/tools/eval.py (with --resize
// or --canvas the truth's corners no longer apply). --only runs one mode,
// for instruction counts (valgrind --tool=callgrind
// --toggle-collect='frappe::Detector::detect(*'). Not a test: speed is
// never asserted.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <numeric>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "frappe/frappe.h"
#include "percentile.h"

namespace {

using Clock = std::chrono::steady_clock;

using frappe::bench::percentile;

void writeLine(std::ofstream &out, const std::string &image, const frappe::Result &r, double t)
{
	if (!out.is_open())
		return;
	out << "{\"image\": \"" << image << "\", \"markers\": [";
	char buf[200];
	for (std::size_t i = 0; i < r.markers.size(); ++i) {
		const auto &m = r.markers[i];
		const auto &c = m.corners;
		std::snprintf(buf, sizeof(buf),
			      "%s{\"id\": %d, \"corners\": [[%.3f, %.3f], [%.3f, %.3f], [%.3f, %.3f], [%.3f, %.3f]], "
			      "\"tracked\": %s}",
			      i ? ", " : "", m.id, c[0].x, c[0].y, c[1].x, c[1].y, c[2].x, c[2].y, c[3].x, c[3].y,
			      m.tracked ? "true" : "false");
		out << buf;
	}
	std::snprintf(buf, sizeof(buf), "], \"time_ms\": %.4f}\n", t);
	out << buf;
}

[[noreturn]] void usage(const std::string &why)
{
	std::cerr << "frappe-track-bench: " << why
		  << "\nusage: frappe-track-bench --list SEQ.txt [--dictionary D] [--cover K] [--resize F | --canvas F] "
		     "[--out-normal N.jsonl] [--out-track T.jsonl]\n";
	std::exit(2);
}

} // namespace

int main(int argc, char **argv)
{
	std::string list, dictionary = "aruco_mip_36h12", outNormal, outTrack, only;
	int cover = frappe::Config{}.track_cover_frames;
	double resize = 1.0, canvas = 1.0;
	for (int i = 1; i < argc; ++i) {
		const std::string a = argv[i];
		auto value = [&]() -> std::string {
			if (i + 1 >= argc)
				usage(a + " needs a value");
			return argv[++i];
		};
		if (a == "--list")
			list = value();
		else if (a == "--dictionary")
			dictionary = value();
		else if (a == "--cover")
			cover = std::stoi(value());
		else if (a == "--resize")
			resize = std::stod(value());
		else if (a == "--canvas")
			canvas = std::stod(value());
		else if (a == "--out-normal")
			outNormal = value();
		else if (a == "--out-track")
			outTrack = value();
		else if (a == "--only")
			only = value();
		else
			usage("unknown option " + a);
	}
	if (list.empty())
		usage("--list is required");
	if (!only.empty() && only != "normal" && only != "track")
		usage("--only takes normal or track");
	const bool runNormal = only != "track", runTrack = only != "normal";
	if (!(resize >= 1.0 && canvas >= 1.0) || (resize > 1.0 && canvas > 1.0))
		usage("one of --resize and --canvas, at least 1");

	std::ifstream in(list);
	if (!in)
		usage("cannot read " + list);
	std::vector<std::string> paths;
	for (std::string line; std::getline(in, line);)
		if (!line.empty() && line[0] != '#')
			paths.push_back(line);
	/* Decoded up front: the timed loop reads memory only. */
	std::vector<cv::Mat> frames;
	for (const std::string &p : paths) {
		cv::Mat g = cv::imread(p, cv::IMREAD_GRAYSCALE);
		if (g.empty())
			usage("cannot decode " + p);
		if (resize > 1.0) {
			cv::Mat r;
			cv::resize(g, r, cv::Size(), resize, resize, cv::INTER_LINEAR);
			g = r;
		} else if (canvas > 1.0) {
			const int w = static_cast<int>(g.cols * canvas + 0.5), h = static_cast<int>(g.rows * canvas + 0.5);
			const int l = (w - g.cols) / 2, t = (h - g.rows) / 2;
			cv::Mat c;
			cv::copyMakeBorder(g, c, t, h - g.rows - t, l, w - g.cols - l, cv::BORDER_REFLECT_101);
			g = c;
		}
		frames.push_back(g);
	}

	frappe::Config normalConfig;
	normalConfig.dictionary = dictionary;
	frappe::Config trackConfig = normalConfig;
	trackConfig.mode = frappe::Mode::Track;
	trackConfig.track_cover_frames = cover;
	frappe::Detector normal(normalConfig), track(trackConfig);
	auto view = [](const cv::Mat &g) {
		return frappe::ImageView(g.data, g.cols, g.rows, static_cast<int>(g.step[0]));
	};
	/* Warm both on the first frame, then forget it. */
	if (runNormal)
		normal.detect(view(frames[0]));
	if (runTrack)
		track.detect(view(frames[0]));
	track.reset();

	std::ofstream nOut, tOut;
	if (!outNormal.empty())
		nOut.open(outNormal);
	if (!outTrack.empty())
		tOut.open(outTrack);
	std::vector<double> nMs, tMs, tRead;
	std::size_t whole = 0, tracked = 0, found = 0;
	for (std::size_t f = 0; f < frames.size(); ++f) {
		const frappe::ImageView v = view(frames[f]);
		auto t0 = Clock::now();
		static const frappe::Result none;
		const frappe::Result &n = runNormal ? normal.detect(v) : none;
		auto t1 = Clock::now();
		const frappe::Result &t = runTrack ? track.detect(v) : none;
		auto t2 = Clock::now();
		const double nm = std::chrono::duration<double, std::milli>(t1 - t0).count();
		const double tm = std::chrono::duration<double, std::milli>(t2 - t1).count();
		nMs.push_back(nm);
		tMs.push_back(tm);
		writeLine(nOut, paths[f], n, nm);
		writeLine(tOut, paths[f], t, tm);
		tRead.push_back(static_cast<double>(t.bytes_read) / (static_cast<double>(v.width) * v.height));
		whole += t.whole_frame ? 1 : 0;
		for (const frappe::Marker &m : t.markers)
			tracked += m.tracked ? 1 : 0;
		found += t.markers.size();
	}
	const double nMed = percentile(nMs, 0.5), tMed = percentile(tMs, 0.5);
	std::printf("frames %zu at %dx%d, k = %d\n", frames.size(), frames[0].cols, frames[0].rows, cover);
	std::printf("normal: median %.3f ms, p90 %.3f ms; bytes read 1.00 of the frame\n", nMed, percentile(nMs, 0.9));
	std::printf("track:  median %.3f ms, p90 %.3f ms; bytes read median %.2f, mean %.2f of the frame; "
		    "%zu frames whole; %zu of %zu markers tracked\n",
		    tMed, percentile(tMs, 0.9), percentile(tRead, 0.5),
		    std::accumulate(tRead.begin(), tRead.end(), 0.0) / static_cast<double>(tRead.size()), whole, tracked,
		    found);
	std::printf("track / normal median: %.3f\n", tMed / nMed);
	return 0;
}
