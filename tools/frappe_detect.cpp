// SPDX-License-Identifier: MIT
// frappe-detect: the command-line detector.
//
//   frappe-detect photo.jpg [--annotate out.png]      people
//   frappe-detect --list L --out D.jsonl --repeat N   benchmarks (DETECTOR-CONTRACT.md)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "annotate.h"
#include "frappe/frappe.h"
#include "frappe_backend.h"

namespace {

using frappe::Config;
using frappe::Detector;
using frappe::Marker;

const char kUsage[] =
	"usage: frappe-detect [options] IMAGE...\n"
	"       frappe-detect [options] --list LIST.txt --out DETS.jsonl [--repeat N]\n"
	"\n"
	"Finds square fiducial markers (ArUco, AprilTag) in 8-bit images.\n"
	"\n"
	"options:\n"
	"  -d, --dictionary NAME   marker family (default aruco_mip_36h12); see --dictionaries\n"
	"      --mode MODE         normal (default) or ascale (adaptive scaling over a sequence)\n"
	"      --threads T         images detected at once, each on a thread of its own:\n"
	"                          1 (default), 0 = one per core; time_ms is then each\n"
	"                          image's own detection time, and the images per second\n"
	"                          of the whole list go to standard error\n"
	"      --edge-threshold E  Sobel magnitude for an edge, intensities in [0,1] (default 0.27)\n"
	"      --corner-threshold C  Shi-Tomasi threshold for a corner (default 0.19)\n"
	"      --region-contrast R  contrast for the dark-region candidates that find blurred\n"
	"                          markers, intensities in [0,1]; 0 = off (default 0.16)\n"
	"      --max-hamming H     bits read clearly that may be corrected (default: the\n"
	"                          dictionary's careful default, see --dictionaries)\n"
	"      --weak-margin W     a cell nearer the threshold than W (of half the contrast)\n"
	"                          is a weak read, correctable beyond H (default 0.3; 0: off)\n"
	"      --backend B         front end: auto, cpu, vc4 (the Pi's QPUs), vc4-emu (the QPU\n"
	"                          kernels on an emulator: slow, bit-exact) (default auto)\n"
	"  -a, --annotate PATH     write the image with the markers drawn (a folder for several images)\n"
	"      --json              print one JSON line per image instead of text\n"
	"      --stats             print per-stage timings\n"
	"      --list FILE         images to process, one path per line\n"
	"      --out FILE          JSON lines output, one per listed image, in order\n"
	"      --repeat N          time each image over N runs, report the median (default 1)\n"
	"      --dictionaries      list the built-in dictionaries\n"
	"      --version           print the version\n"
	"  -h, --help              this text\n";

struct Options {
	Config config;
	std::vector<std::string> images;
	std::string list, out, annotate, backend = "auto";
	int repeat = 1;
	bool json = false, stats = false;
};

[[noreturn]] void usageError(const std::string &msg)
{
	std::cerr << "frappe-detect: " << msg << "\n(try --help)\n";
	std::exit(2);
}

template<typename T>
T parseNumber(const std::string &opt, const std::string &text)
{
	std::istringstream in(text);
	T v{};
	in >> v;
	if (in.fail() || !in.eof())
		usageError(opt + " needs a number, got '" + text + "'");
	return v;
}

Options parse(int argc, char **argv)
{
	Options o;
	for (int i = 1; i < argc; ++i) {
		const std::string a = argv[i];
		auto value = [&]() -> std::string {
			if (i + 1 >= argc)
				usageError(a + " needs a value");
			return argv[++i];
		};
		if (a == "-h" || a == "--help") {
			std::cout << kUsage;
			std::exit(0);
		} else if (a == "--version") {
			std::cout << "frappe-detect " << frappe::version() << "\n";
			std::exit(0);
		} else if (a == "--dictionaries") {
			for (const auto &d : frappe::dictionaries())
				std::cout << d.name << "  (" << d.bits << "x" << d.bits << ", " << d.size()
					  << " ids, min distance " << d.min_hamming << ", corrects "
					  << d.defaultMaxHamming() << ", " << d.weakMaxHamming() << " with weak cells)\n";
			std::exit(0);
		} else if (a == "-d" || a == "--dictionary") {
			o.config.dictionary = value();
		} else if (a == "--mode") {
			const std::string m = value();
			if (m == "normal")
				o.config.mode = frappe::Mode::Normal;
			else if (m == "ascale")
				o.config.mode = frappe::Mode::AScale;
			else
				usageError("--mode takes normal or ascale, got '" + m + "'");
		} else if (a == "--threads") {
			o.config.threads = parseNumber<int>(a, value());
		} else if (a == "--edge-threshold") {
			o.config.edge_threshold = parseNumber<float>(a, value());
		} else if (a == "--corner-threshold") {
			o.config.corner_threshold = parseNumber<float>(a, value());
		} else if (a == "--region-contrast") {
			o.config.region_contrast = parseNumber<float>(a, value());
		} else if (a == "--max-hamming") {
			o.config.max_hamming = parseNumber<int>(a, value());
		} else if (a == "--weak-margin") {
			o.config.weak_margin = parseNumber<float>(a, value());
		} else if (a == "--backend") {
			o.backend = value();
			if (o.backend != "auto" && o.backend != "cpu" && o.backend != "vc4" && o.backend != "vc4-emu")
				usageError("--backend takes auto, cpu, vc4 or vc4-emu, got '" + o.backend + "'");
		} else if (a == "-a" || a == "--annotate") {
			o.annotate = value();
		} else if (a == "--json") {
			o.json = true;
		} else if (a == "--stats") {
			o.stats = true;
		} else if (a == "--list") {
			o.list = value();
		} else if (a == "--out") {
			o.out = value();
		} else if (a == "--repeat") {
			o.repeat = parseNumber<int>(a, value());
			if (o.repeat < 1)
				usageError("--repeat must be at least 1");
		} else if (!a.empty() && a[0] == '-' && a != "-") {
			usageError("unknown option " + a);
		} else {
			o.images.push_back(a);
		}
	}
	if (!o.list.empty()) {
		std::ifstream in(o.list);
		if (!in)
			usageError("cannot read the list " + o.list);
		for (std::string line; std::getline(in, line);) {
			while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t'))
				line.pop_back();
			if (line.empty() || line[0] == '#')
				continue;
			o.images.push_back(line);
		}
	}
	if (o.images.empty())
		usageError("no images given");
	return o;
}

std::string jsonEscape(const std::string &s)
{
	std::string out;
	for (char c : s) {
		switch (c) {
		case '"': out += "\\\""; break;
		case '\\': out += "\\\\"; break;
		case '\n': out += "\\n"; break;
		case '\t': out += "\\t"; break;
		default:
			if (static_cast<unsigned char>(c) < 0x20) {
				char buf[8];
				std::snprintf(buf, sizeof(buf), "\\u%04x", c);
				out += buf;
			} else {
				out += c;
			}
		}
	}
	return out;
}

std::string jsonLine(const std::string &image, const std::vector<Marker> &markers, double ms,
		     const std::string &error)
{
	std::ostringstream o;
	o << "{\"image\": \"" << jsonEscape(image) << "\"";
	if (!error.empty()) {
		o << ", \"markers\": [], \"error\": \"" << jsonEscape(error) << "\"}";
		return o.str();
	}
	o << ", \"markers\": [";
	char buf[64];
	for (std::size_t i = 0; i < markers.size(); ++i) {
		const Marker &m = markers[i];
		o << (i ? ", " : "") << "{\"id\": " << m.id << ", \"corners\": [";
		for (int k = 0; k < 4; ++k) {
			std::snprintf(buf, sizeof(buf), "%s[%.3f, %.3f]", k ? ", " : "", m.corners[k].x, m.corners[k].y);
			o << buf;
		}
		std::snprintf(buf, sizeof(buf), "%.3f", m.margin);
		o << "], \"hamming\": " << m.hamming << ", \"margin\": " << buf << "}";
	}
	std::snprintf(buf, sizeof(buf), "%.4f", ms);
	o << "], \"time_ms\": " << buf << "}";
	return o.str();
}

struct Frame {
	std::string path;
	cv::Mat gray;
	std::string error;
	std::vector<Marker> markers;
	frappe::StageTimes times;
	double ms = 0;
};

double median(std::vector<double> v)
{
	std::sort(v.begin(), v.end());
	const std::size_t n = v.size();
	return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* The pipeline of the options, with the chosen front end on each of its
 * detectors; throws std::runtime_error saying what went wrong. */
std::unique_ptr<frappe::Pipeline> makePipeline(const Options &opt)
{
	auto pipeline = std::make_unique<frappe::Pipeline>(opt.config, frappe::Pipeline::Mode::Frames);
	for (int i = 0; i < pipeline->detectorCount(); ++i) {
		std::string fallback;
		try {
			fallback = frappe::selectBackend(pipeline->detector(i), opt.backend, 1);
		} catch (const frappe::BackendNotBuilt &) {
			throw std::runtime_error("backend " + opt.backend + " needs the vc4 part, which this build lacks");
		} catch (const std::exception &e) {
			throw std::runtime_error("backend " + opt.backend + " cannot be used: " + e.what());
		}
		if (!fallback.empty() && i == 0)
			std::cerr << "frappe-detect: the QPUs cannot be used (" << fallback
				  << "); using the CPU front end\n";
	}
	return pipeline;
}

/* Runs every readable frame `repeat` times through the pipeline, in order.
 * With one thread each push runs its frame, and time_ms is the wall time
 * of those pushes; with more, frames overlap and time_ms is each frame's
 * own detection time (the sum of its stages). */
void detectAll(frappe::Pipeline &pipeline, std::vector<Frame> &frames, int repeat)
{
	using Clock = std::chrono::steady_clock;
	const bool serial = pipeline.latency() == 0;
	std::vector<std::size_t> order; /* frame of each push still in flight */
	std::vector<std::vector<double>> times(frames.size());
	std::size_t detected = 0;
	auto take = [&](const frappe::Result *res, double wallMs) {
		Frame &f = frames[order.front()];
		times[order.front()].push_back(serial ? wallMs : res->times.total_ms);
		f.markers = res->markers;
		f.times = res->times;
		order.erase(order.begin());
		++detected;
	};
	auto fail = [&](const std::exception &e) {
		/* The oldest frame in flight failed: the next result is the
		 * following push's. */
		Frame &f = frames[order.front()];
		f.error = e.what();
		std::cerr << "frappe-detect: " << f.path << ": " << f.error << "\n";
		order.erase(order.begin());
	};

	const auto t0 = Clock::now();
	for (std::size_t i = 0; i < frames.size(); ++i) {
		Frame &f = frames[i];
		if (!f.error.empty())
			continue;
		const frappe::ImageView view(f.gray.data, f.gray.cols, f.gray.rows, static_cast<int>(f.gray.step[0]));
		for (int r = 0; r < repeat; ++r) {
			try {
				pipeline.detector().checkImage(view);
			} catch (const std::exception &e) {
				f.error = e.what();
				std::cerr << "frappe-detect: " << f.path << ": " << f.error << "\n";
				break;
			}
			order.push_back(i);
			try {
				const auto p0 = Clock::now();
				const frappe::Result *res = pipeline.push(view);
				if (res)
					take(res, std::chrono::duration<double, std::milli>(Clock::now() - p0).count());
			} catch (const std::exception &e) {
				fail(e);
			}
		}
	}
	for (;;) {
		try {
			const frappe::Result *res = pipeline.flush();
			if (!res)
				break;
			take(res, 0.0);
		} catch (const std::exception &e) {
			fail(e);
		}
	}
	const double wall = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
	for (std::size_t i = 0; i < frames.size(); ++i)
		if (frames[i].error.empty() && !times[i].empty())
			frames[i].ms = median(times[i]);
	if (!serial && detected > 0)
		std::fprintf(stderr, "frappe-detect: %zu detections on %d threads in %.1f ms: %.1f per second\n",
			     detected, pipeline.threads(), wall, 1000.0 * static_cast<double>(detected) / wall);
}

} // namespace

int main(int argc, char **argv)
{
	Options opt = parse(argc, argv);

	std::unique_ptr<frappe::Pipeline> pipeline;
	try {
		pipeline = makePipeline(opt);
	} catch (const std::exception &e) {
		std::cerr << "frappe-detect: " << e.what() << "\n";
		return 2;
	}
	if (opt.config.mode == frappe::Mode::AScale && opt.repeat > 1) {
		std::cerr << "frappe-detect: --mode ascale treats the list as a video; using --repeat 1\n";
		opt.repeat = 1;
	}

	/* Decode everything first: the timed loop does no I/O. */
	std::vector<Frame> frames(opt.images.size());
	for (std::size_t i = 0; i < frames.size(); ++i) {
		Frame &f = frames[i];
		f.path = opt.images[i];
		std::error_code ec;
		if (!std::filesystem::is_regular_file(f.path, ec)) {
			f.error = "cannot open " + f.path;
		} else {
			try {
				f.gray = cv::imread(f.path, cv::IMREAD_GRAYSCALE);
			} catch (const cv::Exception &e) {
				f.gray.release();
			}
			if (f.gray.empty())
				f.error = "cannot decode " + f.path + " as an image";
		}
		if (!f.error.empty())
			std::cerr << "frappe-detect: " << f.error << "\n";
	}

	/* Buffers and threads warm before timing, on the first good image. */
	if (opt.repeat > 1) {
		for (const Frame &f : frames) {
			if (!f.error.empty())
				continue;
			const frappe::ImageView view(f.gray.data, f.gray.cols, f.gray.rows,
						     static_cast<int>(f.gray.step[0]));
			try {
				for (int i = 0; i < pipeline->threads(); ++i)
					pipeline->push(view);
				while (pipeline->flush()) {
				}
			} catch (const std::exception &) {
				/* the timed run reports it */
			}
			pipeline->reset();
			break;
		}
	}
	detectAll(*pipeline, frames, opt.repeat);

	bool anyError = false;
	std::ofstream out;
	if (!opt.out.empty()) {
		out.open(opt.out);
		if (!out) {
			std::cerr << "frappe-detect: cannot write " << opt.out << "\n";
			return 2;
		}
	}
	for (const Frame &f : frames) {
		anyError = anyError || !f.error.empty();
		if (out.is_open())
			out << jsonLine(f.path, f.markers, f.ms, f.error) << "\n";
		if (!opt.out.empty() && !opt.json)
			continue;
		if (opt.json) {
			std::cout << jsonLine(f.path, f.markers, f.ms, f.error) << "\n";
		} else if (f.error.empty()) {
			std::printf("%s: %zu marker%s (%s) in %.2f ms\n", f.path.c_str(), f.markers.size(),
				    f.markers.size() == 1 ? "" : "s", std::string(pipeline->detector().dictionary().name).c_str(), f.ms);
			for (const Marker &m : f.markers) {
				std::printf("  id %4d  hamming %d  margin %.2f  corners", m.id, m.hamming, m.margin);
				for (const auto &p : m.corners)
					std::printf(" (%.2f, %.2f)", p.x, p.y);
				std::printf("\n");
			}
		}
		if (opt.stats && f.error.empty()) {
			std::printf("  stages:");
			for (int s = 0; s < frappe::kStageCount; ++s)
				std::printf(" %s %.3f ms", std::string(frappe::stageName(static_cast<frappe::Stage>(s))).c_str(),
					    f.times.ms[s]);
			std::printf("\n");
		}
	}

	if (!opt.annotate.empty()) {
		namespace fs = std::filesystem;
		const bool many = frames.size() > 1;
		if (many) {
			std::error_code ec;
			fs::create_directories(opt.annotate, ec);
		}
		for (const Frame &f : frames) {
			if (!f.error.empty())
				continue;
			const std::string path = many ? (fs::path(opt.annotate) / fs::path(f.path).filename()).replace_extension(".png").string()
						      : opt.annotate;
			bool ok = false;
			try {
				ok = cv::imwrite(path, frappe::cli::annotate(f.gray, f.markers));
			} catch (const cv::Exception &) {
				ok = false;
			}
			if (!ok) {
				std::cerr << "frappe-detect: cannot write " << path << "\n";
				anyError = true;
			}
		}
	}
	/* With --list/--out the contract wants exit 0 when the run completed:
	 * per-image errors are in the output. */
	if (!opt.out.empty())
		return 0;
	return anyError ? 1 : 0;
}
