// SPDX-License-Identifier: MIT
// frappe-peers: frappe's modes against ArUco 3 (DM_FAST, DM_VIDEO_FAST),
// aruco_nano and OpenCV 4.6's aruco, in one process, over a list in its
// order, single-threaded (issue 35's peer table). Built only when meson is
// given -Daruco3_prefix=DIR, a scratch build of the peers (docs/speed.md):
// libaruco3.a in DIR/lib, ArUco's headers and aruco_nano.h in DIR/include.
//
//   frappe-peers --list LIST.txt [--sequence] [--dictionary D] [--passes 3]
//                [--warmup 10] [--out PREFIX] [--only NAME[,NAME...]]
//
// Every pass runs each detector once on every frame, frame after frame in
// the list's order, the detectors taking turns on each frame (who goes first
// rotates with the frame, so no one always meets a cold cache). A frame's
// time is its median over the passes; a detector's time is the median over
// the frames. Stateful detectors start each pass afresh: ArUco 3 carries its
// threshold from one call to the next even in DM_FAST, and DM_VIDEO_FAST and
// TRACK carry the markers' size and place, so images are never repeated back
// to back (that would hand them the answer). TRACK and DM_VIDEO_FAST run only
// with --sequence (a camera's frames in order). --out PREFIX writes the last
// pass's detections as PREFIX-NAME.jsonl, the contract's JSON lines, for
// ../shared/tools/eval.py. --only runs the detectors named; one alone is for
// instruction counts, valgrind --tool=callgrind
// --toggle-collect='peers_call_detector*' (with --warmup 0, the calls counted
// are the passes' alone). Two clocks are printed: the wall clock and this
// thread's CPU time. Run it with glibc's trimming off (GLIBC_TUNABLES, printed):
// ArUco 3 pays page faults for its per-call buffers under glibc's defaults.
// Not a test: speed is never asserted.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <time.h>

#include <opencv2/aruco.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

#include <aruco/markerdetector.h>
#include <aruco_nano.h>

#include "frappe/frappe.h"
#include "opencv_dictionary.h"
#include "percentile.h"

namespace {

using Clock = std::chrono::steady_clock;

/* This thread's CPU time: on a shared machine the wall clock also counts the
 * time other processes held the core, which on a loaded two-core machine is
 * most of it; the CPU clock does not (the cache they evicted still counts). */
double cpuMs()
{
	timespec t;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
	return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}
using Corners = std::array<frappe::Point2f, 4>;
using frappe::bench::percentile;

struct Found {
	std::vector<int> ids;
	std::vector<Corners> corners;
};

template<typename P>
Corners cornersOf(const P &c)
{
	return { frappe::Point2f{ c[0].x, c[0].y }, { c[1].x, c[1].y }, { c[2].x, c[2].y }, { c[3].x, c[3].y } };
}

/* One detector: detect() is what is timed; collect() copies its answer out
 * after the clock stops; restart() forgets what earlier frames taught it. */
class Peer {
public:
	explicit Peer(std::string name) : name(std::move(name)) {}
	virtual ~Peer() = default;
	virtual void detect(const cv::Mat &g) = 0;
	virtual void collect(Found &out) const = 0;
	virtual void restart() {}
	const std::string name;
};

class FrappePeer : public Peer {
public:
	FrappePeer(std::string name, const frappe::Config &c) : Peer(std::move(name)), det_(c) {}
	void detect(const cv::Mat &g) override
	{
		res_ = &det_.detect(frappe::ImageView(g.data, g.cols, g.rows, static_cast<int>(g.step[0])));
	}
	void collect(Found &out) const override
	{
		for (const frappe::Marker &m : res_->markers) {
			out.ids.push_back(m.id);
			out.corners.push_back(m.corners);
		}
	}
	void restart() override { det_.reset(); }
	frappe::Detector &detector() { return det_; }

private:
	frappe::Detector det_;
	const frappe::Result *res_ = nullptr;
};

class Aruco3Peer : public Peer {
public:
	Aruco3Peer(std::string name, std::string dict, aruco::DetectionMode mode)
		: Peer(std::move(name)), dict_(std::move(dict)), mode_(mode)
	{
		restart();
	}
	void detect(const cv::Mat &g) override { found_ = det_->detect(g); }
	void collect(Found &out) const override
	{
		for (const aruco::Marker &m : found_) {
			out.ids.push_back(m.id);
			out.corners.push_back(cornersOf(m));
		}
	}
	/* A new detector: the threshold and marker size learnt are members. */
	void restart() override
	{
		det_ = std::make_unique<aruco::MarkerDetector>(dict_);
		det_->setDetectionMode(mode_);
	}

private:
	std::string dict_;
	aruco::DetectionMode mode_;
	std::unique_ptr<aruco::MarkerDetector> det_;
	std::vector<aruco::Marker> found_;
};

class NanoPeer : public Peer {
public:
	NanoPeer(aruconano::MarkerDetector::Dict dict) : Peer("nano"), dict_(dict) {}
	void detect(const cv::Mat &g) override { found_ = aruconano::MarkerDetector::detect(g, 10, dict_); }
	void collect(Found &out) const override
	{
		for (const aruconano::Marker &m : found_) {
			out.ids.push_back(m.id);
			out.corners.push_back(cornersOf(m));
		}
	}

private:
	aruconano::MarkerDetector::Dict dict_;
	std::vector<aruconano::Marker> found_;
};

/* As frappe-bench: the same codewords, at most 5 corrected bits, no corner
 * refinement (the contract). */
class OpenCVPeer : public Peer {
public:
	OpenCVPeer(const cv::Ptr<cv::aruco::Dictionary> &dict) : Peer("opencv"), dict_(dict)
	{
		params_ = cv::aruco::DetectorParameters::create();
		params_->cornerRefinementMethod = cv::aruco::CORNER_REFINE_NONE;
	}
	void detect(const cv::Mat &g) override { cv::aruco::detectMarkers(g, dict_, corners_, ids_, params_); }
	void collect(Found &out) const override
	{
		out.ids = ids_;
		for (const auto &c : corners_)
			out.corners.push_back(cornersOf(c));
	}

private:
	cv::Ptr<cv::aruco::Dictionary> dict_;
	cv::Ptr<cv::aruco::DetectorParameters> params_;
	std::vector<int> ids_;
	std::vector<std::vector<cv::Point2f>> corners_;
};

void writeLine(std::ofstream &out, const std::string &image, const Found &f, double t)
{
	out << "{\"image\": \"" << image << "\", \"markers\": [";
	char buf[200];
	for (std::size_t i = 0; i < f.ids.size(); ++i) {
		const Corners &c = f.corners[i];
		std::snprintf(buf, sizeof(buf),
			      "%s{\"id\": %d, \"corners\": [[%.3f, %.3f], [%.3f, %.3f], [%.3f, %.3f], [%.3f, %.3f]]}",
			      i ? ", " : "", f.ids[i], c[0].x, c[0].y, c[1].x, c[1].y, c[2].x, c[2].y, c[3].x, c[3].y);
		out << buf;
	}
	std::snprintf(buf, sizeof(buf), "], \"time_ms\": %.4f}\n", t);
	out << buf;
}

[[noreturn]] void usage(const std::string &why)
{
	std::cerr << "frappe-peers: " << why
		  << "\nusage: frappe-peers --list LIST.txt [--sequence] [--dictionary D] [--passes N] [--warmup N] "
		     "[--out PREFIX] "
		     "[--only NAME,...]\n  NAME: normal ascale track dm_fast dm_video_fast nano opencv\n";
	std::exit(2);
}

} // namespace

/* Outside any namespace and never inlined: the name callgrind's
 * --toggle-collect looks for, so that only detection is counted. */
__attribute__((noinline)) void peers_call_detector(Peer &p, const cv::Mat &g)
{
	p.detect(g);
}

int main(int argc, char **argv)
{
	std::string list, dictName = "aruco_mip_36h12", outPrefix, only;
	int passes = 3, warmup = 10;
	bool sequence = false;
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
			dictName = value();
		else if (a == "--passes")
			passes = std::max(1, std::stoi(value()));
		else if (a == "--out")
			outPrefix = value();
		else if (a == "--only")
			only = value();
		else if (a == "--warmup")
			warmup = std::max(0, std::stoi(value()));
		else if (a == "--sequence")
			sequence = true;
		else
			usage("unknown option " + a);
	}
	const frappe::Dictionary *dict = frappe::findDictionary(dictName);
	if (!dict || list.empty())
		usage("need a known --dictionary and a --list");

	std::vector<std::string> paths;
	std::vector<cv::Mat> frames;
	{
		std::ifstream in(list);
		if (!in)
			usage("cannot read " + list);
		for (std::string line; std::getline(in, line);) {
			if (line.empty() || line[0] == '#')
				continue;
			cv::Mat g = cv::imread(line, cv::IMREAD_GRAYSCALE);
			if (g.empty())
				usage("cannot decode " + line);
			paths.push_back(line);
			frames.push_back(g);
		}
	}
	if (frames.empty())
		usage("no frames");
	cv::setNumThreads(1); /* every detector on one thread */

	frappe::Config base;
	base.dictionary = dictName;
	base.threads = 1;
	std::vector<std::unique_ptr<Peer>> peers;
	auto frappeMode = [&](const char *name, frappe::Mode mode) {
		frappe::Config c = base;
		c.mode = mode;
		peers.push_back(std::make_unique<FrappePeer>(name, c));
	};
	frappeMode("normal", frappe::Mode::Normal);
	frappeMode("ascale", frappe::Mode::AScale);
	if (sequence)
		frappeMode("track", frappe::Mode::Track);
	/* The peers' own names of the dictionary; they know few. */
	std::string arucoDict, skipped;
	if (dictName == "aruco_mip_36h12")
		arucoDict = "ARUCO_MIP_36h12";
	if (!arucoDict.empty()) {
		peers.push_back(std::make_unique<Aruco3Peer>("dm_fast", arucoDict, aruco::DM_FAST));
		if (sequence)
			peers.push_back(std::make_unique<Aruco3Peer>("dm_video_fast", arucoDict, aruco::DM_VIDEO_FAST));
	} else
		skipped += " ArUco 3 (only ARUCO_MIP_36h12 is in the scratch build)";
	if (dictName == "aruco_mip_36h12")
		peers.push_back(std::make_unique<NanoPeer>(aruconano::MarkerDetector::ARUCO_MIP_36h12));
	else if (dictName == "apriltag_36h11")
		peers.push_back(std::make_unique<NanoPeer>(aruconano::MarkerDetector::APRILTAG_36h11));
	else
		skipped += " aruco_nano (ARUCO_MIP_36h12 and APRILTAG_36h11 only)";
	{
		auto &normal = static_cast<FrappePeer &>(*peers[0]);
		peers.push_back(std::make_unique<OpenCVPeer>(
			opencvDictionary(*dict, std::min(5, normal.detector().maxHamming()))));
	}
	if (!only.empty()) {
		const std::string names = "," + only + ",";
		std::erase_if(peers, [&](const std::unique_ptr<Peer> &p) {
			return names.find("," + p->name + ",") == std::string::npos;
		});
		if (peers.empty())
			usage("--only " + only + ": no such detector here");
	}
	const std::size_t nd = peers.size(), nf = frames.size();

	/* Warm-up: buffers, OpenCV's lazy tables, the code in the caches. */
	for (auto &p : peers) {
		for (std::size_t f = 0; f < std::min<std::size_t>(nf, static_cast<std::size_t>(warmup)); ++f)
			peers_call_detector(*p, frames[f]);
		p->restart();
	}

	std::vector<std::vector<std::vector<double>>> ms(nd, std::vector<std::vector<double>>(nf)), cpu = ms;
	std::vector<std::vector<Found>> last(nd, std::vector<Found>(nf));
	for (int pass = 0; pass < passes; ++pass) {
		for (auto &p : peers)
			p->restart();
		for (std::size_t f = 0; f < nf; ++f)
			for (std::size_t j = 0; j < nd; ++j) {
				const std::size_t d = (f + j) % nd;
				const double c0 = cpuMs();
				const auto t0 = Clock::now();
				peers_call_detector(*peers[d], frames[f]);
				const auto t1 = Clock::now();
				cpu[d][f].push_back(cpuMs() - c0);
				ms[d][f].push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
				if (pass == passes - 1)
					peers[d]->collect(last[d][f]);
			}
	}

	const char *tunables = std::getenv("GLIBC_TUNABLES");
	std::printf("%zu frames (%s), %s, %d passes, single thread; OpenCV %s; GLIBC_TUNABLES=%s\n", nf,
		    sequence ? "a sequence, in order" : "images", dictName.c_str(), passes, CV_VERSION,
		    tunables ? tunables : "(unset: glibc's defaults)");
	if (!skipped.empty())
		std::printf("not run:%s\n", skipped.c_str());
	/* A frame's time: its median over the passes; the JSON lines get the wall one. */
	auto perFrame = [&](const std::vector<std::vector<std::vector<double>>> &t, std::size_t d) {
		std::vector<double> v(nf);
		for (std::size_t f = 0; f < nf; ++f)
			v[f] = percentile(t[d][f], 0.5);
		return v;
	};
	if (!outPrefix.empty())
		for (std::size_t d = 0; d < nd; ++d) {
			std::ofstream out(outPrefix + "-" + peers[d]->name + ".jsonl");
			const std::vector<double> wall = perFrame(ms, d);
			for (std::size_t f = 0; f < nf; ++f)
				writeLine(out, paths[f], last[d][f], wall[f]);
		}
	/* Ratios against frappe's modes in this run: peer / frappe. */
	std::vector<std::size_t> ours;
	for (std::size_t d = 0; d < nd; ++d)
		if (dynamic_cast<FrappePeer *>(peers[d].get()))
			ours.push_back(d);
	for (const auto *clock : { &ms, &cpu }) {
		std::printf("%s\n%-14s %10s %10s", clock == &ms ? "wall clock:" : "this thread's CPU time:", "detector",
			    "median ms", "p90 ms");
		for (std::size_t o : ours)
			std::printf("   /%-7s", peers[o]->name.c_str());
		std::printf("\n");
		std::vector<double> med(nd), p90(nd);
		for (std::size_t d = 0; d < nd; ++d) {
			const std::vector<double> v = perFrame(*clock, d);
			med[d] = percentile(v, 0.5);
			p90[d] = percentile(v, 0.9);
		}
		for (std::size_t d = 0; d < nd; ++d) {
			std::printf("%-14s %10.3f %10.3f", peers[d]->name.c_str(), med[d], p90[d]);
			for (std::size_t o : ours)
				std::printf("   %7.2fx", med[d] / med[o]);
			std::printf("\n");
		}
	}
	return 0;
}
