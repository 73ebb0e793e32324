// SPDX-License-Identifier: MIT
// frappe-bench: frappe-core against OpenCV 4.6's aruco module on the same
// images, in the same process, interleaved, single-threaded.
//
//   frappe-bench --dictionary aruco_mip_36h12 --list LIST.txt [--repeat 5]
//                [--out-frappe F.jsonl] [--out-opencv O.jsonl]
//                [--out-apriltag PREFIX] [--threads N] [--no-extras]
//
// Prints median and p90 milliseconds per frame for each detector, their
// ratio, and each stage's share of frappe's time. When the light floor
// leaves the lighting path on (issue 29), frappe runs a second time with
// it off (light_floor 0.5: the paper's absolute thresholds, no shade map,
// no second read on the log scale), interleaved, and the path's share of a
// frame is printed. OpenCV gets the same
// dictionary as a custom Dictionary, at most 5 corrected bits (capped by
// the dictionary's safe maximum), and no corner refinement, as in
// ../shared/design/DETECTOR-CONTRACT.md (the team's folder beside the
// checkout). For AprilTag families, AprilTag 3.3 (Debian's libapriltag)
// runs too, single-threaded, at decimate 1 and 2.
//
// Then, unless --no-extras: throughput with two threads (front-end bands,
// the staged pipeline, whole frames on two detectors at latency 2 and at the
// element's latency 1) against one; the cost
// of the same frames at 1280x960 against 640x480; and of a frame with 24
// markers against one.
// Not a test: speed is never asserted.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <opencv2/aruco.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

#include <opencv2/imgproc.hpp>

#include "frappe/frappe.h"
#include "percentile.h"
#include "frappe/render.h"
#include "opencv_dictionary.h"

#ifdef FRAPPE_BENCH_APRILTAG
#include <apriltag/apriltag.h>
#include <apriltag/tag16h5.h>
#include <apriltag/tag25h9.h>
#include <apriltag/tag36h11.h>
#endif

namespace {

using Clock = std::chrono::steady_clock;

double ms(Clock::time_point a, Clock::time_point b)
{
	return std::chrono::duration<double, std::milli>(b - a).count();
}

using frappe::bench::percentile;


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

#ifdef FRAPPE_BENCH_APRILTAG
/* AprilTag 3.3 as a peer, for the families both libraries know. */
class AprilTagPeer
{
public:
	AprilTagPeer(const std::string &dictionary, float decimate)
	{
		if (dictionary == "apriltag_36h11")
			family_ = tag36h11_create(), destroy_ = tag36h11_destroy;
		else if (dictionary == "apriltag_25h9")
			family_ = tag25h9_create(), destroy_ = tag25h9_destroy;
		else if (dictionary == "apriltag_16h5")
			family_ = tag16h5_create(), destroy_ = tag16h5_destroy;
		if (!family_)
			return;
		det_ = apriltag_detector_create();
		apriltag_detector_add_family_bits(det_, family_, 2);
		det_->nthreads = 1;
		det_->quad_decimate = decimate;
	}
	~AprilTagPeer()
	{
		if (det_)
			apriltag_detector_destroy(det_);
		if (family_)
			destroy_(family_);
	}
	explicit operator bool() const { return det_ != nullptr; }

	/* Corners in the contract's order and coordinates: AprilTag's run the
	 * other way round, starting one corner later (checked against the
	 * synth truth), with pixel centres at +0.5 where the contract has them
	 * at integers. */
	void detect(const cv::Mat &g, std::vector<int> &ids, std::vector<std::array<frappe::Point2f, 4>> &corners)
	{
		image_u8_t im{ g.cols, g.rows, static_cast<int32_t>(g.step[0]), g.data };
		zarray_t *found = apriltag_detector_detect(det_, &im);
		ids.clear();
		corners.clear();
		for (int i = 0; i < zarray_size(found); ++i) {
			apriltag_detection_t *d;
			zarray_get(found, i, &d);
			ids.push_back(d->id);
			std::array<frappe::Point2f, 4> c;
			for (int k = 0; k < 4; ++k) {
				const int from = (1 - k) & 3;
				c[k] = { static_cast<float>(d->p[from][0] - 0.5), static_cast<float>(d->p[from][1] - 0.5) };
			}
			corners.push_back(c);
		}
		apriltag_detections_destroy(found);
	}

private:
	apriltag_family_t *family_ = nullptr;
	void (*destroy_)(apriltag_family_t *) = nullptr;
	apriltag_detector_t *det_ = nullptr;
};
#endif

frappe::ImageView viewOf(const cv::Mat &g)
{
	return { g.data, g.cols, g.rows, static_cast<int>(g.step[0]) };
}

/* Seconds per frame over all images, `repeat` times, frame after frame. */
template<typename F>
double throughputMs(const std::vector<cv::Mat> &images, int repeat, F &&run)
{
	const auto t0 = Clock::now();
	for (int r = 0; r < repeat; ++r)
		for (const cv::Mat &g : images)
			run(g);
	return ms(t0, Clock::now()) / static_cast<double>(repeat * images.size());
}

void reportThroughput(const frappe::Config &base, const std::vector<cv::Mat> &images, int repeat)
{
	frappe::Config one = base, two = base;
	one.threads = 1;
	two.threads = 2;
	frappe::Detector d1(one), d2(two);
	frappe::Pipeline pipe(one, frappe::Pipeline::Overlap::Stages), frames(two, frappe::Pipeline::Overlap::Frames),
		held(two, frappe::Pipeline::Overlap::Frames, 1);
	std::size_t sink = 0;
	auto single = [&](const cv::Mat &g) { sink += d1.detect(viewOf(g)).markers.size(); };
	auto bands = [&](const cv::Mat &g) { sink += d2.detect(viewOf(g)).markers.size(); };
	auto pipelined = [&](const cv::Mat &g) {
		if (const frappe::Result *r = pipe.push(viewOf(g)))
			sink += r->markers.size();
	};
	auto whole = [&](const cv::Mat &g) {
		if (const frappe::Result *r = frames.push(viewOf(g)))
			sink += r->markers.size();
	};
	auto wholeHeld = [&](const cv::Mat &g) { /* the element's pipelined mode */
		if (const frappe::Result *r = held.push(viewOf(g)))
			sink += r->markers.size();
	};
	/* Warm-up: buffers and worker threads. */
	throughputMs(images, 1, single);
	throughputMs(images, 1, bands);
	throughputMs(images, 1, pipelined);
	while (pipe.flush()) {}
	throughputMs(images, 1, whole);
	while (frames.flush()) {}
	throughputMs(images, 1, wholeHeld);
	while (held.flush()) {}
	double t1 = 0, t2 = 0, tp = 0, tf = 0, th = 0;
	for (int r = 0; r < repeat; ++r) { /* interleaved runs */
		t1 += throughputMs(images, 1, single);
		t2 += throughputMs(images, 1, bands);
		tp += throughputMs(images, 1, pipelined);
		while (pipe.flush()) {}
		tf += throughputMs(images, 1, whole);
		while (frames.flush()) {}
		th += throughputMs(images, 1, wholeHeld);
		while (held.flush()) {}
	}
	std::printf("\nthroughput, frames per second over %zu frames x %d:\n", images.size(), repeat);
	std::printf("  1 thread                     %8.1f fps\n", 1000.0 * repeat / t1);
	std::printf("  2 threads, front-end bands   %8.1f fps  (%.2fx)\n", 1000.0 * repeat / t2, t1 / t2);
	std::printf("  2 threads, pipelined (3 stg) %8.1f fps  (%.2fx)\n", 1000.0 * repeat / tp, t1 / tp);
	std::printf("  2 threads, whole frames      %8.1f fps  (%.2fx)\n", 1000.0 * repeat / tf, t1 / tf);
	std::printf("  2 threads, whole, latency 1  %8.1f fps  (%.2fx)\n", 1000.0 * repeat / th, t1 / th);
	if (sink == 0)
		std::printf("  (no markers found)\n");
}

/* Median per-frame ms of frappe and OpenCV over the images, interleaved;
 * with `stages`, also the median ms of each of frappe's stages. */
std::pair<double, double> medians(frappe::Detector &det, const std::vector<cv::Mat> &images, int repeat,
				  const cv::Ptr<cv::aruco::Dictionary> &cvDict,
				  const cv::Ptr<cv::aruco::DetectorParameters> &params,
				  std::array<double, frappe::kStageCount> *stages = nullptr)
{
	std::vector<double> tf, to;
	std::array<std::vector<double>, frappe::kStageCount> perStage;
	std::vector<int> ids;
	std::vector<std::vector<cv::Point2f>> corners;
	for (const cv::Mat &g : images) {
		std::vector<double> a, b;
		std::array<std::vector<double>, frappe::kStageCount> s;
		for (int r = 0; r < repeat; ++r) {
			const auto t0 = Clock::now();
			const frappe::Result &res = det.detect(viewOf(g));
			const auto t1 = Clock::now();
			for (int k = 0; k < frappe::kStageCount; ++k)
				s[k].push_back(res.times.ms[k]);
			cv::aruco::detectMarkers(g, cvDict, corners, ids, params);
			const auto t2 = Clock::now();
			a.push_back(ms(t0, t1));
			b.push_back(ms(t1, t2));
		}
		tf.push_back(percentile(a, 0.5));
		to.push_back(percentile(b, 0.5));
		for (int k = 0; k < frappe::kStageCount; ++k)
			perStage[k].push_back(percentile(s[k], 0.5));
	}
	if (stages)
		for (int k = 0; k < frappe::kStageCount; ++k)
			(*stages)[k] = percentile(perStage[k], 0.5);
	return { percentile(tf, 0.5), percentile(to, 0.5) };
}

void reportScaling(frappe::Detector &det, const std::vector<cv::Mat> &images, int repeat,
		   const cv::Ptr<cv::aruco::Dictionary> &cvDict,
		   const cv::Ptr<cv::aruco::DetectorParameters> &params)
{
	/* The same frames at twice the resolution. */
	std::vector<cv::Mat> small, large;
	for (std::size_t i = 0; i < images.size() && i < 60; ++i) {
		small.push_back(images[i]);
		cv::Mat big;
		cv::resize(images[i], big, cv::Size(images[i].cols * 2, images[i].rows * 2), 0, 0, cv::INTER_LINEAR);
		large.push_back(big);
	}
	const auto s = medians(det, small, repeat, cvDict, params);
	const auto l = medians(det, large, repeat, cvDict, params);
	std::printf("\nresolution: %dx%d -> %dx%d, %zu frames, median ms\n", small[0].cols, small[0].rows,
		    large[0].cols, large[0].rows, small.size());
	std::printf("  frappe  %7.3f -> %7.3f  (%.2fx)\n", s.first, l.first, l.first / s.first);
	std::printf("  opencv  %7.3f -> %7.3f  (%.2fx)\n", s.second, l.second, l.second / s.second);

	/* One marker against 24 on the same cluttered ground. */
	const frappe::Dictionary &dict = det.dictionary();
	cv::Mat ground(480, 640, CV_8UC1);
	cv::RNG rng(7);
	rng.fill(ground, cv::RNG::NORMAL, 120, 4);
	for (int k = 0; k < 40; ++k) {
		const cv::Point a(rng.uniform(0, 640), rng.uniform(0, 480));
		cv::rectangle(ground, a, a + cv::Point(rng.uniform(5, 60), rng.uniform(5, 60)),
			      cv::Scalar(rng.uniform(40, 220)), cv::FILLED);
	}
	cv::GaussianBlur(ground, ground, cv::Size(3, 3), 0.8);
	std::vector<cv::Mat> one, many;
	for (int v = 0; v < 8; ++v) {
		cv::Mat a = ground.clone(), b = ground.clone();
		frappe::MutableImageView va{ a.data, a.cols, a.rows, static_cast<int>(a.step[0]) };
		frappe::MutableImageView vb{ b.data, b.cols, b.rows, static_cast<int>(b.step[0]) };
		frappe::renderMarker(va, dict, v, frappe::perspectiveSquare(320, 240, 70, 10.0f * v, 20));
		for (int k = 0; k < 24; ++k)
			frappe::renderMarker(vb, dict, (v * 24 + k) % dict.size(),
					     frappe::perspectiveSquare(55.0f + 105.0f * (k % 6), 60.0f + 120.0f * (k / 6), 62,
								       10.0f * v + 7.0f * k, 20));
		one.push_back(a);
		many.push_back(b);
	}
	std::array<double, frappe::kStageCount> so{}, sm{};
	const auto o = medians(det, one, repeat, cvDict, params, &so);
	const auto m = medians(det, many, repeat, cvDict, params, &sm);
	const std::size_t found = det.detect(viewOf(many[0])).markers.size();
	std::printf("\nmarkers per frame: 1 -> 24 (%zu found in the first 24-marker frame), median ms\n", found);
	std::printf("  frappe  %7.3f -> %7.3f  (%.2fx)\n", o.first, m.first, m.first / o.first);
	std::printf("  opencv  %7.3f -> %7.3f  (%.2fx)\n", o.second, m.second, m.second / o.second);
	/* Where the extra time goes, each stage's growth as a share of the
	 * one-marker frame (the target allows 0.5 in all). */
	std::printf("  frappe stages:");
	for (int k = 0; k < frappe::kStageCount; ++k)
		std::printf(" %s %.3f -> %.3f (+%.2f)", std::string(frappe::stageName(static_cast<frappe::Stage>(k))).c_str(),
			    so[k], sm[k], (sm[k] - so[k]) / o.first);
	std::printf("\n");
}

} // namespace

int main(int argc, char **argv)
{
	std::string dictName = "aruco_mip_36h12", list, outF, outO, outA;
	int repeat = 5, threads = 1;
	float regionContrast = frappe::Config{}.region_contrast;
	float lightFloor = frappe::Config{}.light_floor;
	bool extras = true;
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
		else if (a == "--out-apriltag")
			outA = value();
		else if (a == "--region-contrast")
			regionContrast = std::stof(value());
		else if (a == "--light-floor")
			lightFloor = std::stof(value());
		else if (a == "--no-extras")
			extras = false;
		else {
			std::cerr << "usage: frappe-bench --dictionary D --list L [--repeat N] [--threads T] "
				     "[--out-frappe F] [--out-opencv O] [--out-apriltag PREFIX] [--region-contrast C] [--light-floor L] [--no-extras]\n";
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
	cfg.region_contrast = regionContrast;
	cfg.light_floor = lightFloor;
	frappe::Detector frappeDet(cfg);
	/* The same detector without the lighting path, when it is on. */
	frappe::Config absoluteCfg = cfg;
	absoluteCfg.light_floor = 0.5f;
	const bool withAbsolute = frappeDet.frontEndParams().light_floor < frappe::FrontEndParams::kLightReference;
	frappe::Detector absoluteDet(absoluteCfg);
	const auto cvDict = opencvDictionary(*dict, std::min(5, frappeDet.maxHamming()));
	auto params = cv::aruco::DetectorParameters::create();
	params->cornerRefinementMethod = cv::aruco::CORNER_REFINE_NONE;

	std::ofstream fo, oo;
	if (!outF.empty())
		fo.open(outF);
	if (!outO.empty())
		oo.open(outO);

#ifdef FRAPPE_BENCH_APRILTAG
	AprilTagPeer at1(dictName, 1.0f), at2(dictName, 2.0f);
	const bool withAprilTag = static_cast<bool>(at1);
#else
	const bool withAprilTag = false;
#endif
	std::ofstream a1o, a2o;
	if (withAprilTag && !outA.empty()) {
		a1o.open(outA + "-d1.jsonl");
		a2o.open(outA + "-d2.jsonl");
	}
	std::vector<double> tF, tO, tA1, tA2, tAbs;
	std::vector<int> atIds;
	std::vector<std::array<frappe::Point2f, 4>> atCorners;
	std::array<double, frappe::kStageCount> stageSum{};
	double totalSum = 0;
	std::vector<int> ids;
	std::vector<std::vector<cv::Point2f>> cvCorners;
	for (std::size_t k = 0; k < images.size(); ++k) {
		const cv::Mat &g = images[k];
		const frappe::ImageView view(g.data, g.cols, g.rows, static_cast<int>(g.step[0]));
		std::vector<double> a, b, c1, c2, abs;
		for (int r = 0; r < repeat; ++r) {
			/* Interleaved: each repetition runs both, so drift hits both. */
			auto t0 = Clock::now();
			const frappe::Result &res = frappeDet.detect(view);
			auto t1 = Clock::now();
			cv::aruco::detectMarkers(g, cvDict, cvCorners, ids, params);
			auto t2 = Clock::now();
			a.push_back(ms(t0, t1));
			b.push_back(ms(t1, t2));
			if (withAbsolute) {
				const auto t3 = Clock::now();
				absoluteDet.detect(view);
				abs.push_back(ms(t3, Clock::now()));
			}
#ifdef FRAPPE_BENCH_APRILTAG
			if (withAprilTag) {
				const auto t3 = Clock::now();
				at1.detect(g, atIds, atCorners);
				const auto t4 = Clock::now();
				if (r == repeat - 1)
					writeLine(a1o, paths[k], atIds, atCorners, ms(t3, t4));
				const auto t5 = Clock::now();
				at2.detect(g, atIds, atCorners);
				const auto t6 = Clock::now();
				if (r == repeat - 1)
					writeLine(a2o, paths[k], atIds, atCorners, ms(t5, t6));
				c1.push_back(ms(t3, t4));
				c2.push_back(ms(t5, t6));
			}
#endif
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
		if (withAbsolute)
			tAbs.push_back(percentile(abs, 0.5));
		if (withAprilTag) {
			tA1.push_back(percentile(c1, 0.5));
			tA2.push_back(percentile(c2, 0.5));
		}
	}

	const double mf = percentile(tF, 0.5), mo = percentile(tO, 0.5);
	std::printf("%zu images, %s, %d repeats, frappe threads %d, OpenCV %s single thread\n", images.size(),
		    dictName.c_str(), repeat, threads, CV_VERSION);
	std::printf("%-22s %10s %10s\n", "detector", "median ms", "p90 ms");
	std::printf("%-22s %10.3f %10.3f\n", "frappe", mf, percentile(tF, 0.9));
	if (withAbsolute)
		std::printf("%-22s %10.3f %10.3f\n", "frappe, light floor 0.5", percentile(tAbs, 0.5),
			    percentile(tAbs, 0.9));
	std::printf("%-22s %10.3f %10.3f\n", "opencv aruco", mo, percentile(tO, 0.9));
	if (withAprilTag) {
		std::printf("%-22s %10.3f %10.3f\n", "apriltag 3.3 decimate 1", percentile(tA1, 0.5), percentile(tA1, 0.9));
		std::printf("%-22s %10.3f %10.3f\n", "apriltag 3.3 decimate 2", percentile(tA2, 0.5), percentile(tA2, 0.9));
	}
	std::printf("speed ratio (opencv / frappe, medians): %.2fx\n", mo / mf);
	if (withAbsolute) {
		/* Per frame, then the median: the path's cost where it is paid. */
		std::vector<double> share(tF.size());
		for (std::size_t k = 0; k < tF.size(); ++k)
			share[k] = 1.0 - tAbs[k] / std::max(1e-9, tF[k]);
		std::printf(
			"lighting path's share of a frame at defaults (1 - light floor 0.5 / defaults): median "
			"%.1f%%, of the medians %.1f%%; opencv / frappe at light floor 0.5: %.2fx\n",
			100.0 * percentile(share, 0.5), 100.0 * (1.0 - percentile(tAbs, 0.5) / mf),
			mo / percentile(tAbs, 0.5));
	}
	if (withAprilTag)
		std::printf("speed ratio (apriltag decimate 2 / frappe, medians): %.2fx; decimate 1: %.2fx\n",
			    percentile(tA2, 0.5) / mf, percentile(tA1, 0.5) / mf);
	std::printf("frappe stage shares:");
	for (int s = 0; s < frappe::kStageCount; ++s)
		std::printf(" %s %.1f%%", std::string(frappe::stageName(static_cast<frappe::Stage>(s))).c_str(),
			    100.0 * stageSum[s] / std::max(1e-9, totalSum));
	std::printf("\nfrappe stage means, ms:");
	const double runs = static_cast<double>(tF.size());
	for (int s = 0; s < frappe::kStageCount; ++s)
		std::printf(" %s %.4f", std::string(frappe::stageName(static_cast<frappe::Stage>(s))).c_str(),
			    stageSum[s] / std::max(1.0, runs));
	std::printf(" (all %.4f)\n", totalSum / std::max(1.0, runs));

	if (extras) {
		reportThroughput(cfg, images, std::max(2, repeat));
		frappe::Config single = cfg;
		single.threads = 1;
		frappe::Detector scalingDet(single);
		reportScaling(scalingDet, images, repeat, cvDict, params);
	}
	return 0;
}
