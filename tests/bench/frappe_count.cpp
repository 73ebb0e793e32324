// SPDX-License-Identifier: MIT
// frappe-count: the driver of scripts/arm-count.sh. Runs frappe-core and,
// when built with FRAPPE_COUNT_OPENCV, OpenCV's aruco module on the images
// of a list (the detector contract's list format), one detection per image
// each, interleaved, single-threaded, and brackets every detection with
// calls to empty marker functions (`armcount_mark_*`). Under qemu-arm or
// qemu-aarch64 with the frappecount plugin each marker call writes a snapshot of the
// instruction counters, so the counts between two markers are exactly the
// instructions of one detection (image decoding and the driver's own work
// fall outside them).
//
//   frappe-count --list LIST.txt [--dictionary aruco_mip_36h12] [--max N]
//                [--no-opencv] [--out-frappe F.jsonl] [--out-opencv O.jsonl]
//                [--region-contrast C] [--mode normal|ascale|track]
//                [--detectors N | --bands N | --pipeline N]
//
// --region-contrast sets Config::region_contrast (0 turns the region map and
// its candidates off), to measure what that path costs. --mode ascale runs
// the list as one video in its order (each frame scaled from the markers of
// the frames before it), for the Pi Zero model's ASCALE figures; --mode
// track likewise in Mode::Track, through Detector::detect() (which may run a
// frame twice: a marker lost), its whole count in the front end's column.
// frappe runs as Detector::detect() does, split into its two halves (the
// library's internal detail::DetectorStages: the front end, then the back
// end) with a marker between them; it links the static library. OpenCV gets the
// same setup as tests/bench/frappe_bench.cpp: the dictionary as a custom
// Dictionary, at most 5 corrected bits (capped by the dictionary's safe
// maximum), no corner refinement. Images: 8-bit PNG (libpng) or JPEG
// (libjpeg), converted to grey if needed. Prints one line per image on
// stdout: "image <index> <width> <height> <frappe markers> <opencv markers> <path>".
// Natively (without the plugin) the markers do nothing.
//
// Threads (issue 35 item 4), each a model of a four-core board:
// --detectors N runs frame k on detector k mod N, as a Pipeline of N threads
// does in a steady stream (each detector's AScale or Track state then comes
// from every N-th frame); the counts stay per frame, single-threaded.
// --bands N cuts the front end into N row bands on N threads (Config::threads)
// whose band kernel is wrapped in armcount_mark_band_begin/_end and run one
// band at a time (a lock), so each band's count is exact: a frame's latency
// on N cores is the front end's serial rest plus its largest band plus the
// back end. Run it on one host core (taskset), so that the worker threads
// never spin (frappe spins only with more than one core).
// --pipeline N pushes the whole list through a Pipeline of N threads
// (Overlap::Frames) between armcount_mark_pipeline_begin/_end; 0 runs the same
// loop on a bare Detector: with the plugin's vcpus=1 each thread's count,
// and the difference is what the pipeline adds.
#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <cctype>
#include <csetjmp>
#include <fstream>
#include <iostream>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <jpeglib.h>
#include <png.h>

#include "frappe/frappe.h"
#include "detector_stages.h" /* frappe-core/src: internal */
#include "front_end_rows.h"  /* frappe-core/src: internal (the band kernels) */

#ifdef FRAPPE_COUNT_OPENCV
#include <opencv2/core/utility.hpp>

#include "opencv_dictionary.h"
#endif

/* The marker functions: the plugin recognises them by name. They must stay
 * real calls (noinline) and differ in body so the linker does not fold them.
 * Aligned to 64 bytes (each is a few instructions) so none straddles a 4 KiB
 * page: QEMU would split it into two translation blocks (issue 15; the
 * plugin copes, and arm-count.sh checks the layout). */
#define FRAPPE_COUNT_MARK(name, n)                                                                 \
	extern "C" __attribute__((noinline, used, aligned(64))) void armcount_mark_##name()         \
	{                                                                                          \
		static volatile int sink;                                                         \
		sink = n;                                                                          \
	}
FRAPPE_COUNT_MARK(warmup, 1)
FRAPPE_COUNT_MARK(frappe_begin, 2)
FRAPPE_COUNT_MARK(frappe_front, 3)
FRAPPE_COUNT_MARK(frappe_back, 4)
FRAPPE_COUNT_MARK(opencv_begin, 5)
FRAPPE_COUNT_MARK(opencv_end, 6)
FRAPPE_COUNT_MARK(band_begin, 7)
FRAPPE_COUNT_MARK(band_end, 8)
FRAPPE_COUNT_MARK(pipeline_begin, 9)
FRAPPE_COUNT_MARK(pipeline_end, 10)

namespace {

struct Gray {
	std::vector<std::uint8_t> pixels;
	int width = 0, height = 0;
};

bool endsWith(const std::string &s, const char *suffix)
{
	const std::size_t n = std::strlen(suffix);
	if (s.size() < n)
		return false;
	for (std::size_t i = 0; i < n; ++i)
		if (std::tolower(static_cast<unsigned char>(s[s.size() - n + i])) != suffix[i])
			return false;
	return true;
}

bool readPng(const std::string &path, Gray &g)
{
	png_image img;
	std::memset(&img, 0, sizeof img);
	img.version = PNG_IMAGE_VERSION;
	if (!png_image_begin_read_from_file(&img, path.c_str()))
		return false;
	img.format = PNG_FORMAT_GRAY; /* libpng converts colour and strips alpha */
	g.width = static_cast<int>(img.width);
	g.height = static_cast<int>(img.height);
	g.pixels.resize(PNG_IMAGE_SIZE(img));
	if (!png_image_finish_read(&img, nullptr, g.pixels.data(), 0, nullptr)) {
		png_image_free(&img);
		return false;
	}
	return true;
}

struct JpegError {
	jpeg_error_mgr mgr;
	std::jmp_buf jump;
};

bool readJpeg(const std::string &path, Gray &g)
{
	FILE *f = std::fopen(path.c_str(), "rb");
	if (!f)
		return false;
	jpeg_decompress_struct cinfo;
	JpegError err;
	cinfo.err = jpeg_std_error(&err.mgr);
	err.mgr.error_exit = [](j_common_ptr c) { std::longjmp(reinterpret_cast<JpegError *>(c->err)->jump, 1); };
	if (setjmp(err.jump)) {
		jpeg_destroy_decompress(&cinfo);
		std::fclose(f);
		return false;
	}
	jpeg_create_decompress(&cinfo);
	jpeg_stdio_src(&cinfo, f);
	jpeg_read_header(&cinfo, TRUE);
	cinfo.out_color_space = JCS_GRAYSCALE;
	jpeg_start_decompress(&cinfo);
	g.width = static_cast<int>(cinfo.output_width);
	g.height = static_cast<int>(cinfo.output_height);
	g.pixels.resize(static_cast<std::size_t>(g.width) * g.height);
	while (cinfo.output_scanline < cinfo.output_height) {
		JSAMPROW row = g.pixels.data() + static_cast<std::size_t>(cinfo.output_scanline) * g.width;
		jpeg_read_scanlines(&cinfo, &row, 1);
	}
	jpeg_finish_decompress(&cinfo);
	jpeg_destroy_decompress(&cinfo);
	std::fclose(f);
	return true;
}

bool readImage(const std::string &path, Gray &g)
{
	if (endsWith(path, ".jpg") || endsWith(path, ".jpeg"))
		return readJpeg(path, g);
	return readPng(path, g);
}

void writeLine(std::ofstream &out, const std::string &image, const std::vector<int> &ids,
	       const std::vector<std::array<frappe::Point2f, 4>> &corners)
{
	if (!out.is_open())
		return;
	out << "{\"image\": \"" << image << "\", \"markers\": [";
	char buf[200];
	for (std::size_t i = 0; i < ids.size(); ++i) {
		const auto &c = corners[i];
		std::snprintf(buf, sizeof(buf),
			      "%s{\"id\": %d, \"corners\": [[%.3f, %.3f], [%.3f, %.3f], [%.3f, %.3f], [%.3f, %.3f]]}",
			      i ? ", " : "", ids[i], c[0].x, c[0].y, c[1].x, c[1].y, c[2].x, c[2].y, c[3].x, c[3].y);
		out << buf;
	}
	out << "], \"time_ms\": 0}\n";
}

/* --bands: one band at a time, so that the plugin's shared counters see
 * only that band between its markers. */
std::mutex bandLock;

void countedBand(const frappe::detail::BandJob &job)
{
	std::lock_guard<std::mutex> guard(bandLock);
	armcount_mark_band_begin();
	frappe::detail::bestBandKernels().band(job);
	armcount_mark_band_end();
}

const frappe::detail::BandKernels countedBandKernels{ "counted", countedBand };

} // namespace

int main(int argc, char **argv)
{
	std::string dictName = "aruco_mip_36h12", list, outF, outO;
	int maxImages = 0;
	bool useOpencv = true;
	float regionContrast = -1.0f; /* < 0: the Config default */
	std::string mode = "normal";
	int detectors = 1, bands = 0, pipelineThreads = -1;
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
		else if (a == "--max")
			maxImages = std::stoi(value());
		else if (a == "--no-opencv")
			useOpencv = false;
		else if (a == "--out-frappe")
			outF = value();
		else if (a == "--out-opencv")
			outO = value();
		else if (a == "--mode")
			mode = value();
		else if (a == "--detectors")
			detectors = std::stoi(value());
		else if (a == "--bands")
			bands = std::stoi(value());
		else if (a == "--pipeline")
			pipelineThreads = std::stoi(value());
		else if (a == "--region-contrast")
			regionContrast = std::stof(value());
		else {
			std::cerr << "usage: frappe-count --list L [--dictionary D] [--max N] [--no-opencv] "
				     "[--out-frappe F] [--out-opencv O] [--region-contrast C] [--mode "
				     "normal|ascale|track] "
				     "[--detectors N | --bands N | --pipeline N]\n";
			return 2;
		}
	}
#ifndef FRAPPE_COUNT_OPENCV
	useOpencv = false;
#endif
	const frappe::Dictionary *dict = frappe::findDictionary(dictName);
	if (!dict || list.empty()) {
		std::cerr << "frappe-count: need a known --dictionary and a --list\n";
		return 2;
	}
	std::vector<std::string> paths;
	std::vector<Gray> images;
	{
		std::ifstream in(list);
		if (!in) {
			std::cerr << "frappe-count: cannot read " << list << "\n";
			return 2;
		}
		for (std::string line; std::getline(in, line);) {
			while (!line.empty() && (line.back() == '\r' || line.back() == ' '))
				line.pop_back();
			if (line.empty() || line[0] == '#')
				continue;
			if (maxImages > 0 && static_cast<int>(images.size()) >= maxImages)
				break;
			Gray g;
			if (!readImage(line, g)) {
				std::cerr << "frappe-count: cannot read " << line << "\n";
				continue;
			}
			paths.push_back(line);
			images.push_back(std::move(g));
		}
	}
	if (images.empty()) {
		std::cerr << "frappe-count: no images\n";
		return 2;
	}

	frappe::Config cfg;
	cfg.dictionary = dictName;
	cfg.threads = 1;
	if (mode == "ascale")
		cfg.mode = frappe::Mode::AScale;
	else if (mode == "track")
		cfg.mode = frappe::Mode::Track;
	else if (mode != "normal") {
		std::cerr << "frappe-count: --mode is normal, ascale or track, not " << mode << "\n";
		return 2;
	}
	if (regionContrast >= 0.0f)
		cfg.region_contrast = regionContrast;
	if (detectors < 1 || detectors > 64 || bands < 0 || bands > 64 || pipelineThreads > 64 ||
	    (detectors > 1) + (bands > 0) + (pipelineThreads >= 0) > 1 ||
	    (bands > 0 && cfg.mode == frappe::Mode::Track)) {
		std::cerr << "frappe-count: one of --detectors N, --bands N, --pipeline N (N <= 64); "
			     "--bands not in track mode (its front end runs over rectangles)\n";
		return 2;
	}
	if (pipelineThreads >= 0) {
		/* No per-frame markers: the threads overlap. Results are only counted
		 * in the loop, so that the caller's work is the pipeline's. */
		cfg.threads = std::max(1, pipelineThreads);
		std::unique_ptr<frappe::Pipeline> pipe;
		std::unique_ptr<frappe::Detector> bare;
		if (pipelineThreads > 0)
			pipe = std::make_unique<frappe::Pipeline>(cfg, frappe::Pipeline::Overlap::Frames);
		else
			bare = std::make_unique<frappe::Detector>(cfg);
		auto pushAll = [&](std::size_t n, std::vector<int> *found) {
			auto take = [&](const frappe::Result *r) {
				if (r && found)
					found->push_back(static_cast<int>(r->markers.size()));
			};
			for (std::size_t k = 0; k < n; ++k) {
				const Gray &g = images[k];
				const frappe::ImageView view(g.pixels.data(), g.width, g.height);
				take(pipe ? pipe->push(view) : &bare->detect(view));
			}
			while (pipe && pipe->pending())
				take(pipe->flush());
		};
		/* warm-up: every detector sees frames (sizes, tables), then forgets them */
		pushAll(std::min<std::size_t>(images.size(), 4 * static_cast<std::size_t>(cfg.threads)), nullptr);
		if (pipe)
			pipe->reset();
		else
			bare->reset();
		armcount_mark_warmup();
		std::vector<int> found;
		found.reserve(images.size());
		armcount_mark_pipeline_begin();
		pushAll(images.size(), &found);
		armcount_mark_pipeline_end();
		for (std::size_t k = 0; k < images.size(); ++k)
			std::printf("image %zu %d %d %d -1 %s\n", k, images[k].width, images[k].height,
				    k < found.size() ? found[k] : -1, paths[k].c_str());
		std::fflush(stdout);
		return 0;
	}
	if (bands > 0)
		cfg.threads = bands;
	std::vector<std::unique_ptr<frappe::Detector>> dets;
	for (int i = 0; i < detectors; ++i) {
		dets.push_back(std::make_unique<frappe::Detector>(cfg));
		if (bands > 0)
			dets.back()->setFrontEnd(frappe::detail::makeCpuFrontEnd(bands, countedBandKernels));
	}
	frappe::Detector &det = *dets[0];
	std::ofstream fo, oo;
	if (!outF.empty())
		fo.open(outF);
	if (!outO.empty())
		oo.open(outO);

#ifdef FRAPPE_COUNT_OPENCV
	cv::setNumThreads(1);
	const auto cvDict = opencvDictionary(*dict, std::min(5, det.maxHamming()));
	auto params = cv::aruco::DetectorParameters::create();
	params->cornerRefinementMethod = cv::aruco::CORNER_REFINE_NONE;
	std::vector<int> ids;
	std::vector<std::vector<cv::Point2f>> cvCorners;
#endif

	/* One uncounted warm-up detection each: buffers are sized on the first
	 * frame of a size, dictionaries and lazy tables are built. */
	{
		const Gray &g = images[0];
		for (auto &d : dets)
			d->detect(frappe::ImageView(g.pixels.data(), g.width, g.height));
#ifdef FRAPPE_COUNT_OPENCV
		if (useOpencv) {
			cv::Mat m(g.height, g.width, CV_8UC1, const_cast<std::uint8_t *>(g.pixels.data()));
			cv::aruco::detectMarkers(m, cvDict, cvCorners, ids, params);
		}
#endif
		armcount_mark_warmup();
		for (auto &d : dets)
			d->reset(); /* the video starts at its first frame */
	}

	for (std::size_t k = 0; k < images.size(); ++k) {
		const Gray &g = images[k];
		const frappe::ImageView view(g.pixels.data(), g.width, g.height);
		frappe::Detector &dk = *dets[k % dets.size()];
		armcount_mark_frappe_begin();
		const frappe::Result *r = nullptr;
		if (cfg.mode == frappe::Mode::Track) {
			r = &dk.detect(view);
			armcount_mark_frappe_front();
		} else {
			frappe::detail::DetectorStages::frontEnd(dk, view, 0);
			armcount_mark_frappe_front();
			r = &frappe::detail::DetectorStages::backEnd(dk, view, 0);
		}
		armcount_mark_frappe_back();
		const frappe::Result &res = *r;
		const int nf = static_cast<int>(res.markers.size());
		if (fo.is_open()) {
			std::vector<int> fid;
			std::vector<std::array<frappe::Point2f, 4>> fc;
			for (const auto &m : res.markers) {
				fid.push_back(m.id);
				fc.push_back(m.corners);
			}
			writeLine(fo, paths[k], fid, fc);
		}
		int no = -1;
#ifdef FRAPPE_COUNT_OPENCV
		if (useOpencv) {
			cv::Mat m(g.height, g.width, CV_8UC1, const_cast<std::uint8_t *>(g.pixels.data()));
			armcount_mark_opencv_begin();
			cv::aruco::detectMarkers(m, cvDict, cvCorners, ids, params);
			armcount_mark_opencv_end();
			no = static_cast<int>(ids.size());
			if (oo.is_open()) {
				std::vector<std::array<frappe::Point2f, 4>> oc;
				for (const auto &c : cvCorners)
					oc.push_back({ frappe::Point2f{ c[0].x, c[0].y }, { c[1].x, c[1].y },
						       { c[2].x, c[2].y }, { c[3].x, c[3].y } });
				writeLine(oo, paths[k], ids, oc);
			}
		}
#endif
		std::printf("image %zu %d %d %d %d %s\n", k, g.width, g.height, nf, no, paths[k].c_str());
	}
	std::fflush(stdout);
	return 0;
}
