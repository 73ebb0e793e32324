// SPDX-License-Identifier: MIT
// frappe-detect: the command-line detector.
//
//   frappe-detect photo.jpg [--annotate out.png]      people
//   frappe-detect --list L --out D.jsonl --repeat N   benchmarks (JSON lines: README.md)
//   frappe-detect --calibration C --marker-size M -   robots: pose, an image on stdin
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <deque>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <new>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <opencv2/imgcodecs.hpp>

#include "annotate.h"
#include "cli_pose.h"
#include "cli_text.h"
#include "image_check.h"
#include "frappe/frappe.h"
#include "frappe_backend.h"

namespace {

using frappe::Config;
using frappe::Detector;
using frappe::Marker;

const char kUsageHead[] =
	"usage: frappe-detect [options] IMAGE...   (- reads one image from standard input)\n"
	"       frappe-detect [options] --list LIST.txt --out DETS.jsonl [--repeat N]\n"
	"\n"
	"Finds square fiducial markers (ArUco, AprilTag) in 8-bit images.\n"
	"\n"
	"detector settings (frappe::Config; docs/settings.md says more of each):\n";

const char kUsageTail[] =
	"  -d NAME|FILE            --dictionary; a file is a dictionary of your own (the text\n"
	"                          format of frappe-core/dictionaries, or OpenCV's aruco YAML/XML)\n"
	"                          --threads: images detected at once; time_ms is then each\n"
	"                          image's own detection time, and the images per second of the\n"
	"                          whole list go to standard error\n"
	"\n"
	"options:\n"
	"  -a, --annotate PATH     write the image with the markers drawn (a folder for several images)\n"
	"      --json              print one JSON line per image instead of text\n"
	"      --stats             per-stage timings: a line of text, or with --json a \"stats\"\n"
	"                          object in each image's line; the first image's also gives\n"
	"                          the untimed warm-up detection run before it (warm_up_ms);\n"
	"                          bytes_read: what the front end read of the frame,\n"
	"                          whole_frame: whether all of it was searched (track)\n"
	"      --list FILE         images to process, one path per line (a regular file of\n"
	"                          at most 64 MiB and 1000000 images)\n"
	"      --out FILE          JSON lines output, one per listed image, in order; a\n"
	"                          name's bytes that are not UTF-8 are written \\u00XX\n"
	"      --repeat N          time each image over N runs, report the median (default 1);\n"
	"                          one untimed warm-up detection runs first either way\n"
	"      --dictionaries      list the built-in dictionaries\n"
	"      --version           print the version\n"
	"  -h, --help              this text\n"
	"\n"
	"pose (each marker's rvec, tvec in metres and reprojection error; OpenCV's frames):\n"
	"      --calibration FILE  camera calibration: ROS camera_info YAML or OpenCV YAML/XML;\n"
	"                          scaled to images of another size with the same aspect\n"
	"      --camera FX,FY,CX,CY  a pinhole camera without distortion, instead\n"
	"      --marker-size M     the markers' side in metres (the black border's outside)\n"
	"      --marker-sizes SPEC  sides of some ids, \"0:0.05,7:0.1\"; the others\n"
	"                          --marker-size's, or no pose\n"
	"      --bundle FILE       one pose from every marker of a rigid set: apriltag_ros's\n"
	"                          tags.yaml (tag_bundles) or a grid board (board: grid, rows,\n"
	"                          cols, size, gap, first_id); its sizes need no --marker-size\n"
	"\n"
	"Images are read one at a time and refused, with an error line, when larger\n"
	"than --max-pixels (read from the header, before decoding) or cut short.\n"
	"Exit status: 0, 1 when an image failed, 2 for bad options or files of options.\n";

/* `text` wrapped to 80 columns, each line indented by `indent`. */
std::string wrapped(const std::string &text, std::size_t indent)
{
	std::string out, line;
	std::istringstream words(text);
	std::string word;
	while (words >> word) {
		if (!line.empty() && indent + line.size() + 1 + word.size() > 80) {
			out += std::string(indent, ' ') + line + "\n";
			line.clear();
		}
		line += (line.empty() ? "" : " ") + word;
	}
	if (!line.empty())
		out += std::string(indent, ' ') + line + "\n";
	return out;
}

/* An option's line: its name at column 6, its text from column 26 (on
 * the next line when the name is longer). */
std::string optionHelp(const std::string &name, const std::string &text)
{
	const std::size_t column = 26;
	const std::string head = "      " + name;
	const std::string body = wrapped(text, column);
	if (head.size() + 1 >= column)
		return head + "\n" + body;
	return head + std::string(column - head.size(), ' ') + body.substr(column);
}

/* The help: the detector's settings from the library's table, then the
 * CLI's own options. */
std::string usage()
{
	std::string out = kUsageHead;
	const Config defaults;
	for (const frappe::Setting &s : frappe::settings()) {
		if (s.surfaces & frappe::kOnCli)
			out += optionHelp("--" + s.kebabName() + " " + std::string(s.metavar),
					  std::string(s.doc) + " (" + (s.isChoice() ? "" : "range ") + s.rangeText() +
						  "; default " + s.text(defaults) + ")");
	}
	std::string backends;
	for (const frappe::BackendName &b : frappe::backendNames())
		backends += std::string(backends.empty() ? "" : "; ") + std::string(b.name) + ": " + std::string(b.doc);
	out += optionHelp("--backend B", "where the front end runs: " + backends + " (default auto)");
	return out + kUsageTail;
}

struct Options {
	Config config;
	std::vector<std::string> images;
	std::string list, out, annotate, backend = "auto";
	int repeat = 1;
	bool json = false, stats = false;
	/* Pose: a camera and the sizes (or a bundle), or neither. */
	std::optional<frappe::Camera> camera;
	frappe::MarkerSizes sizes;
	std::optional<frappe::Bundle> bundle;
};

[[noreturn]] void usageError(const std::string &msg)
{
	std::cerr << "frappe-detect: " << msg << "\n(try --help)\n";
	std::exit(2);
}

template<typename T>
T parseNumber(const std::string &opt, const std::string &text)
{
	T v{};
	if (!frappe::cli::parseNumber(text, v))
		usageError(opt + " needs a number, got '" + text + "'");
	return v;
}

/* The list is read whole (paths only, no pixels): bounded so that a wrong
 * argument (/dev/zero, a huge file) fails at once instead of eating memory. */
constexpr std::size_t kMaxListBytes = 64u << 20;
constexpr std::size_t kMaxListImages = 1000000;

void readList(const std::string &list, std::vector<std::string> &images)
{
	std::vector<std::uint8_t> bytes;
	std::string error;
	if (!frappe::cli::readFileBounded(list, kMaxListBytes, bytes, error))
		usageError("--list: " + error + " (a list is a regular file of at most 64 MiB)");
	std::size_t begin = 0;
	while (begin < bytes.size()) {
		std::size_t end = begin;
		while (end < bytes.size() && bytes[end] != '\n')
			++end;
		std::string line(bytes.begin() + static_cast<std::ptrdiff_t>(begin), bytes.begin() + static_cast<std::ptrdiff_t>(end));
		begin = end + 1;
		while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t'))
			line.pop_back();
		if (line.empty() || line[0] == '#')
			continue;
		if (images.size() >= kMaxListImages)
			usageError("--list: " + list + " names more than " + std::to_string(kMaxListImages) + " images");
		images.push_back(std::move(line));
	}
}

/* A built-in name first ("4x4_50" is the built-in even beside a file of
 * that name; ./4x4_50 is the file), else a path to a file of one's own. */
void useDictionary(Options &o, const std::string &name)
{
	if (frappe::findDictionary(name)) {
		o.config.dictionary = name;
		return;
	}
	std::error_code ec;
	if (!std::filesystem::exists(name, ec))
		usageError("unknown dictionary '" + name + "': neither a built-in name (" + frappe::dictionaryNames() +
			   ") nor a file");
	try {
		o.config.custom_dictionary = frappe::loadDictionary(name);
	} catch (const std::exception &e) {
		usageError(std::string("--dictionary: ") + e.what());
	}
}

/* The pose options, checked together once all are read. */
void usePose(Options &o, const std::string &calibration, const std::string &camera, double size,
	     const std::string &sizes, const std::string &bundle)
{
	if (!bundle.empty()) {
		try {
			o.bundle = frappe::loadBundle(bundle);
		} catch (const std::exception &e) {
			usageError(std::string("--bundle: ") + e.what());
		}
	}
	if (!calibration.empty() && !camera.empty())
		usageError("--calibration and --camera: give one camera");
	if (!calibration.empty()) {
		try {
			o.camera = frappe::readCalibration(calibration);
		} catch (const std::exception &e) {
			usageError(std::string("--calibration: ") + e.what());
		}
	} else if (!camera.empty()) {
		frappe::Camera c;
		std::string error;
		if (!frappe::cli::parseCameraSpec(camera, c, error))
			usageError("--camera " + error);
		o.camera = c;
	}
	try {
		o.sizes = frappe::MarkerSizes::parse(sizes, size);
	} catch (const std::exception &e) {
		usageError(std::string("--marker-sizes: ") + e.what());
	}
	if (o.camera && !o.sizes.any() && !o.bundle)
		usageError("a camera without marker sizes: add --marker-size M (metres), --marker-sizes or --bundle");
	if (!o.camera && o.bundle)
		usageError("a bundle without a camera: add --calibration FILE or --camera fx,fy,cx,cy");
	if (!o.camera && o.sizes.any())
		usageError("marker sizes without a camera: add --calibration FILE or --camera fx,fy,cx,cy");
}

/* A detector setting the CLI offers, by its kebab-case name. */
const frappe::Setting *cliSetting(const std::string &name)
{
	if (name.find('_') != std::string::npos)
		return nullptr;
	const frappe::Setting *s = frappe::findSetting(name);
	return s && (s->surfaces & frappe::kOnCli) ? s : nullptr;
}

Options parse(int argc, char **argv)
{
	Options o;
	std::string calibration, camera, sizes, bundle;
	double size = 0.0;
	for (int i = 1; i < argc; ++i) {
		const std::string a = argv[i];
		auto value = [&]() -> std::string {
			if (i + 1 >= argc)
				usageError(a + " needs a value");
			return argv[++i];
		};
		if (a == "-h" || a == "--help") {
			std::cout << usage();
			std::exit(0);
		} else if (a == "--version") {
			std::cout << "frappe-detect " << frappe::version() << "\n";
			std::exit(0);
		} else if (a == "--dictionaries") {
			for (const auto &d : frappe::dictionaries())
				std::cout << d.name << "  ("
					  << (d.layout ? std::to_string(d.codeBits()) + " bits in a layout of " +
								 std::to_string(d.layout->size) + "x" + std::to_string(d.layout->size) + " cells"
						       : std::to_string(d.bits) + "x" + std::to_string(d.bits))
					  << ", " << d.size()
					  << " ids, min distance " << d.min_hamming << ", corrects "
					  << d.defaultMaxHamming() << ", " << d.weakMaxHamming() << " with weak cells)\n";
			std::exit(0);
		} else if (a == "-d" || a == "--dictionary") {
			useDictionary(o, value());
		} else if (a == "--calibration") {
			calibration = value();
			if (calibration.empty())
				usageError("--calibration needs a file");
		} else if (a == "--camera") {
			camera = value();
			if (camera.empty())
				usageError("--camera needs fx,fy,cx,cy");
		} else if (a == "--marker-size") {
			size = parseNumber<double>(a, value());
			if (!(size > 0.0 && std::isfinite(size)))
				usageError("--marker-size must be a side in metres above 0, got " + std::string(argv[i]));
		} else if (a == "--marker-sizes") {
			sizes = value();
		} else if (a == "--bundle") {
			bundle = value();
			if (bundle.empty())
				usageError("--bundle needs a file");
		} else if (a == "--backend") {
			o.backend = value();
			const auto names = frappe::backendNames();
			if (std::none_of(names.begin(), names.end(),
					 [&](const auto &b) { return b.name == o.backend; }))
				usageError("--backend takes " + frappe::backendNameList() + ", got '" + o.backend +
					   "'");
		} else if (const frappe::Setting *s = a.starts_with("--") ? cliSetting(a.substr(2)) : nullptr) {
			const std::string text = value();
			try {
				s->parse(o.config, text);
			} catch (const std::exception &e) {
				usageError(a + " " + e.what());
			}
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
	usePose(o, calibration, camera, size, sizes, bundle);
	if (!o.list.empty())
		readList(o.list, o.images);
	if (o.images.empty())
		usageError("no images given");
	if (std::count(o.images.begin(), o.images.end(), "-") > 1)
		usageError("- (standard input) can be read once only");
	return o;
}

using frappe::cli::jsonEscape;

/* What a line may carry beyond the contract's fields. */
struct LineExtras {
	const std::vector<std::optional<frappe::MarkerPose>> *poses = nullptr; /* one per marker */
	const frappe::Bundle *bundle = nullptr; /* with its pose, when one was found */
	const std::optional<frappe::BundlePose> *bundlePose = nullptr;
	std::string stats; /* `"stats": {...}`, or empty */
	bool tracking = false; /* Mode::Track: each marker says whether it was tracked */
};

/* The bundle's pose: `{"name": .., "rvec": .., "tvec": .., "pose_error": ..,
 * "used": [ids], "rejected": [ids]}`, or null when none. */
std::string bundleJson(const frappe::Bundle &b, const std::optional<frappe::BundlePose> &p)
{
	if (!p)
		return "null";
	auto ids = [](const std::vector<int> &v) {
		std::string s = "[";
		for (std::size_t i = 0; i < v.size(); ++i)
			s += (i ? ", " : "") + std::to_string(v[i]);
		return s + "]";
	};
	return "{\"name\": \"" + jsonEscape(b.name) + "\"" + frappe::cli::poseJson(p->pose) + ", \"used\": " + ids(p->used) +
	       ", \"rejected\": " + ids(p->rejected) + "}";
}

/* A line of the benchmarks' format: the image, its markers as the
 * library's one writer makes them (frappe/marker_record.h), the time. */
std::string jsonLine(const std::string &image, const std::vector<Marker> &markers, std::string_view dictionary,
		     double ms, const std::string &error, const LineExtras &extras = {})
{
	std::string o = "{\"image\": \"" + jsonEscape(image) + "\"";
	if (!error.empty())
		return o + ", \"markers\": [], \"error\": \"" + jsonEscape(error) + "\"}";
	o += ", \"markers\": [";
	for (std::size_t i = 0; i < markers.size(); ++i) {
		const frappe::MarkerPose *pose = extras.poses && (*extras.poses)[i] ? &*(*extras.poses)[i] : nullptr;
		if (i)
			o += ", ";
		frappe::appendMarkerJson(o, { &markers[i], dictionary, pose, extras.tracking },
					 frappe::JsonNumbers::Rounded);
	}
	char buf[64];
	std::snprintf(buf, sizeof(buf), "%.4f", ms);
	o += "], \"time_ms\": ";
	o += buf;
	if (extras.bundle)
		o += ", \"bundle\": " + bundleJson(*extras.bundle, *extras.bundlePose);
	if (!extras.stats.empty())
		o += ", " + extras.stats;
	return o + "}";
}

/* The per-stage times as a JSON member; the warm-up's wall time when one
 * ran before this image (below 0: none). */
std::string statsJson(const frappe::StageTimes &times, double warmUpMs, std::size_t bytesRead, bool wholeFrame)
{
	std::ostringstream o;
	char buf[32];
	o << "\"stats\": {";
	for (int s = 0; s < frappe::kStageCount; ++s) {
		std::snprintf(buf, sizeof(buf), "%.4f", times.ms[s]);
		o << (s ? ", " : "") << "\"" << frappe::stageName(static_cast<frappe::Stage>(s)) << "_ms\": " << buf;
	}
	std::snprintf(buf, sizeof(buf), "%.4f", times.total_ms);
	o << ", \"total_ms\": " << buf;
	/* What the front end read of the frame: all of it, or Track's regions. */
	o << ", \"bytes_read\": " << bytesRead << ", \"whole_frame\": " << (wholeFrame ? "true" : "false");
	if (warmUpMs >= 0.0) {
		std::snprintf(buf, sizeof(buf), "%.4f", warmUpMs);
		o << ", \"warm_up_ms\": " << buf;
	}
	o << "}";
	return o.str();
}

struct Frame {
	std::string path;
	cv::Mat gray;
	std::string error;
	std::vector<Marker> markers;
	frappe::StageTimes times;
	std::size_t bytes_read = 0; /* the last repetition's Result::bytes_read */
	bool whole_frame = true;
	std::vector<double> times_ms; /* one per repeat */
	int in_flight = 0;            /* pushes whose result has not come back */
	bool all_pushed = false;
	double warm_up_ms = -1.0;     /* the untimed warm-up run on it, when one was */
	std::vector<std::optional<frappe::MarkerPose>> poses; /* one per marker, with a camera */
	std::optional<frappe::BundlePose> bundlePose; /* with --bundle */
};

/* Reads, checks and decodes one image into f.gray, or sets f.error. The
 * size comes from the header and is refused before any decoding; a file
 * that ends before its format's end marker is refused too, where OpenCV
 * would return a partial image with a warning. */
void loadImage(Frame &f, long long maxPixels)
{
	const bool fromStdin = f.path == "-";
	const std::string name = fromStdin ? "standard input" : f.path;
	/* Enough for any frame of maxPixels at 8 bytes a pixel (16-bit RGBA
	 * stored raw) plus 16 MiB of metadata, 528 MiB by default; the bound on
	 * formats we cannot read the size of. Under 2 GiB: cv::Mat's int size. */
	const std::size_t fileLimit = static_cast<std::size_t>(
		std::min<long long>(8 * maxPixels + (16 << 20), std::numeric_limits<std::int32_t>::max()));
	/* Standard input grows in place: never twice its size in memory. */
	std::vector<std::uint8_t> file;
	frappe::cli::StreamBytes stream;
	try {
		if (fromStdin ? !frappe::cli::readStreamBounded(0, name, fileLimit, stream, f.error)
			  : !frappe::cli::readFileBounded(f.path, fileLimit, file, f.error))
			return;
	} catch (const std::bad_alloc &) { /* a 32-bit Pi may not find the room */
		f.error = "out of memory reading " + name;
		return;
	}
	const std::uint8_t *data = fromStdin ? stream.data() : file.data();
	const std::size_t size = fromStdin ? stream.size() : file.size();
	const frappe::cli::ImageHeader h = frappe::cli::inspectImage(data, size);
	if (!h.error.empty()) {
		f.error = name + ": " + h.error;
		return;
	}
	/* OpenCV decodes whatever it recognises before any limit applies (a
	 * 10 KB WebP to 1.1 GB): only formats whose size was read go on. */
	if (h.format == frappe::cli::ImageFormat::Unknown) {
		f.error = "cannot decode " + name + ": not an image of a format whose size frappe-detect reads before "
			  "decoding (PNG, JPEG, BMP, PNM, PAM, PFM, WebP, TIFF, Sun raster, Radiance HDR, JPEG 2000, "
			  "OpenEXR); not decoded";
		return;
	}
	if (h.width > maxPixels / h.height) {
		f.error = name + ": " + std::to_string(h.width) + " x " + std::to_string(h.height) + " " +
			  frappe::cli::formatName(h.format) + ", more than the limit of " + std::to_string(maxPixels) +
			  " pixels (Config::max_pixels); not decoded";
		return;
	}
	try {
		f.gray = cv::imdecode(cv::Mat(1, static_cast<int>(size), CV_8UC1, const_cast<std::uint8_t *>(data)),
				      cv::IMREAD_GRAYSCALE);
	} catch (const cv::Exception &e) {
		f.gray.release();
		f.error = "cannot decode " + name + " as an image (OpenCV: " + e.err + ")";
		return;
	} catch (const std::bad_alloc &) {
		f.error = "out of memory decoding " + name;
		return;
	}
	if (f.gray.empty()) {
		f.error = "cannot decode " + name + " as an image";
		return;
	}
	/* EXIF orientation may swap the sides, never the count. */
	if (static_cast<long long>(f.gray.cols) * f.gray.rows != h.width * h.height) {
		f.error = name + ": decoded " + std::to_string(f.gray.cols) + " x " + std::to_string(f.gray.rows) +
			  ", the header says " + std::to_string(h.width) + " x " + std::to_string(h.height);
		f.gray.release();
	}
}

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
	auto pipeline = std::make_unique<frappe::Pipeline>(opt.config, frappe::Pipeline::Overlap::Frames);
	std::string fallback;
	try {
		fallback = frappe::selectBackend(*pipeline, opt.backend);
	} catch (const frappe::BackendNotBuilt &) {
		throw std::runtime_error("backend " + opt.backend + " needs the vc4 part, which this build lacks");
	} catch (const std::exception &e) {
		throw std::runtime_error("backend " + opt.backend + " cannot be used: " + e.what());
	}
	if (!fallback.empty())
		std::cerr << "frappe-detect: the QPUs cannot be used (" << fallback << "); using the CPU front end\n";
	return pipeline;
}

/* Streams the images: each is read, decoded, detected `repeat` times and
 * written out in list order before the pipeline moves far past it, so at
 * most latency() + 1 decoded frames are held whatever the list's length.
 * With one thread each push runs its frame, and time_ms is the wall time of
 * that push; with more, frames overlap and time_ms is each frame's own
 * detection time (the sum of its stages). */
class Runner {
public:
	Runner(const Options &opt, frappe::Pipeline &pipeline, std::FILE *out)
		: opt_(opt), pipeline_(pipeline), out_(out), serial_(pipeline.latency() == 0),
		  many_(opt.images.size() > 1)
	{
	}

	void run()
	{
		using Clock = std::chrono::steady_clock;
		const auto t0 = Clock::now();
		/* The first good image is detected once untimed: its time_ms would
		 * otherwise include the buffers' growth and the threads' start. */
		bool warmed = false;
		for (const std::string &path : opt_.images) {
			Frame &f = window_.emplace_back();
			f.path = path;
			loadImage(f, opt_.config.max_pixels);
			if (!f.error.empty())
				std::cerr << "frappe-detect: " << f.error << "\n";
			if (f.error.empty() && !warmed) {
				const auto w0 = Clock::now();
				warmUp(f);
				f.warm_up_ms = std::chrono::duration<double, std::milli>(Clock::now() - w0).count();
				warmed = true;
			}
			for (int r = 0; r < opt_.repeat && f.error.empty(); ++r)
				push(f);
			f.all_pushed = true;
			writeFinished();
		}
		for (;;) {
			try {
				const frappe::Result *res = pipeline_.flush();
				if (!res)
					break;
				take(*res, 0.0);
			} catch (const std::exception &e) {
				fail(e);
			}
			writeFinished();
		}
		writeFinished();
		const double wall = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
		if (!serial_ && detected_ > 0)
			std::fprintf(stderr,
				     "frappe-detect: %zu detections on %d threads in %.1f ms (reading and decoding included): "
				     "%.1f per second\n",
				     detected_, pipeline_.threads(), wall, 1000.0 * static_cast<double>(detected_) / wall);
	}

	std::size_t failed() const { return failed_; }
	std::size_t total() const { return total_; }
	bool writeFailed() const { return writeFailed_; }
	bool annotateFailed() const { return annotateFailed_; }

private:
	static frappe::ImageView view(const Frame &f)
	{
		return { f.gray.data, f.gray.cols, f.gray.rows, static_cast<int>(f.gray.step[0]) };
	}

	/* Buffers and threads warm before timing, on the first good image;
	 * nothing is in flight yet. */
	void warmUp(const Frame &f)
	{
		try {
			for (int i = 0; i < pipeline_.threads(); ++i)
				pipeline_.push(view(f));
			while (pipeline_.flush()) {
			}
		} catch (const std::exception &) {
			/* the timed run reports it */
		}
		pipeline_.reset();
	}

	void push(Frame &f)
	{
		using Clock = std::chrono::steady_clock;
		try {
			pipeline_.detector().checkImage(view(f));
		} catch (const std::exception &e) {
			f.error = f.path + ": " + e.what();
			std::cerr << "frappe-detect: " << f.error << "\n";
			return;
		}
		inFlight_.push_back(&f);
		++f.in_flight;
		try {
			const auto p0 = Clock::now();
			const frappe::Result *res = pipeline_.push(view(f));
			if (res)
				take(*res, std::chrono::duration<double, std::milli>(Clock::now() - p0).count());
		} catch (const std::exception &e) {
			fail(e);
		}
	}

	void take(const frappe::Result &res, double wallMs)
	{
		Frame &f = *inFlight_.front();
		inFlight_.pop_front();
		--f.in_flight;
		f.times_ms.push_back(serial_ ? wallMs : res.times.total_ms);
		f.markers = res.markers; /* the last repetition's */
		f.times = res.times;
		f.bytes_read = res.bytes_read;
		f.whole_frame = res.whole_frame;
		++detected_;
	}

	/* The oldest push in flight failed: the next result is the following
	 * push's. */
	void fail(const std::exception &e)
	{
		Frame &f = *inFlight_.front();
		inFlight_.pop_front();
		--f.in_flight;
		if (f.error.empty()) {
			f.error = f.path + ": " + e.what();
			std::cerr << "frappe-detect: " << f.error << "\n";
		}
	}

	/* Writes and forgets the finished frames at the head of the window. */
	void writeFinished()
	{
		while (!window_.empty() && window_.front().all_pushed && window_.front().in_flight == 0) {
			write(window_.front());
			window_.pop_front();
		}
	}

	/* The markers' poses, with the camera fitted to the image's size. */
	void addPoses(Frame &f)
	{
		if (!opt_.camera || !f.error.empty())
			return;
		std::string note, error;
		const frappe::Camera *camera = fitter_->fit(f.gray.cols, f.gray.rows, note, error);
		if (!note.empty())
			std::cerr << "frappe-detect: " << note << "\n";
		if (!camera) {
			f.error = (f.path == "-" ? "standard input" : f.path) + ": " + error;
			std::cerr << "frappe-detect: " << f.error << "\n";
			return;
		}
		if (opt_.sizes.any())
			f.poses = frappe::cli::markerPoses(f.markers, opt_.sizes, *camera);
		if (opt_.bundle)
			f.bundlePose = frappe::estimateBundlePose(*opt_.bundle, f.markers, *camera);
	}

	void write(Frame &f)
	{
		addPoses(f);
		++total_;
		if (!f.error.empty())
			++failed_;
		const double ms = f.error.empty() && !f.times_ms.empty() ? median(f.times_ms) : 0.0;
		LineExtras extras;
		extras.tracking = opt_.config.mode == frappe::Mode::Track;
		if (!f.poses.empty())
			extras.poses = &f.poses;
		if (opt_.bundle && f.error.empty()) {
			extras.bundle = &*opt_.bundle;
			extras.bundlePose = &f.bundlePose;
		}
		if (out_) {
			/* The contract's line, with the poses when asked for. */
			const std::string line = jsonLine(f.path, f.markers, dictionary(), ms, f.error, extras) + "\n";
			/* a line at a time: a run cut short keeps what it found */
			if (std::fputs(line.c_str(), out_) < 0 || std::fflush(out_) != 0)
				writeFailed_ = true;
		}
		if (opt_.json) {
			/* The stats inside the line: every line stays one JSON object. */
			if (opt_.stats && f.error.empty())
				extras.stats = statsJson(f.times, f.warm_up_ms, f.bytes_read, f.whole_frame);
			std::cout << jsonLine(f.path, f.markers, dictionary(), ms, f.error, extras) << "\n";
		} else if (f.error.empty() && opt_.out.empty()) {
			std::printf("%s: %zu marker%s (%s) in %.2f ms\n", f.path.c_str(), f.markers.size(),
				    f.markers.size() == 1 ? "" : "s",
				    std::string(pipeline_.detector().dictionary().name).c_str(), ms);
			for (std::size_t i = 0; i < f.markers.size(); ++i) {
				const Marker &m = f.markers[i];
				std::printf("  id %4d  hamming %d  margin %.2f  corners", m.id, m.hamming, m.margin);
				for (const auto &p : m.corners)
					std::printf(" (%.2f, %.2f)", p.x, p.y);
				std::printf("\n");
				if (!f.poses.empty() && f.poses[i])
					std::printf("           %s\n", frappe::cli::poseText(f.poses[i]->pose).c_str());
			}
			if (f.bundlePose)
				std::printf("  bundle %s: %zu markers used, %zu rejected  %s\n", opt_.bundle->name.c_str(),
					    f.bundlePose->used.size(), f.bundlePose->rejected.size(),
					    frappe::cli::poseText(f.bundlePose->pose).c_str());
			else if (opt_.bundle)
				std::printf("  bundle %s: no pose\n", opt_.bundle->name.c_str());
			if (opt_.stats) {
				std::printf("  stages:");
				for (int s = 0; s < frappe::kStageCount; ++s)
					std::printf(" %s %.3f ms",
						    std::string(frappe::stageName(static_cast<frappe::Stage>(s))).c_str(),
						    f.times.ms[s]);
				std::printf("\n");
				if (f.warm_up_ms >= 0.0)
					std::printf("  warm-up before it, untimed: %.3f ms\n", f.warm_up_ms);
			}
		}
		std::fflush(stdout);
		if (!opt_.annotate.empty() && f.error.empty())
			annotate(f);
	}

	std::string_view dictionary() { return pipeline_.detector().dictionary().name; }

	void annotate(const Frame &f)
	{
		namespace fs = std::filesystem;
		if (many_ && !annotateDirMade_) {
			std::error_code ec;
			fs::create_directories(opt_.annotate, ec);
			annotateDirMade_ = true;
		}
		const std::string path =
			many_ ? (fs::path(opt_.annotate) / fs::path(f.path == "-" ? "stdin" : f.path).filename())
					.replace_extension(".png")
					.string()
			      : opt_.annotate;
		bool ok = false;
		try {
			ok = cv::imwrite(path, frappe::cli::annotate(f.gray, f.markers));
		} catch (const cv::Exception &) {
			ok = false;
		}
		if (!ok) {
			std::cerr << "frappe-detect: cannot write " << path << "\n";
			annotateFailed_ = true;
		}
	}

	const Options &opt_;
	std::optional<frappe::cli::CameraFitter> fitter_ =
		opt_.camera ? std::optional<frappe::cli::CameraFitter>(*opt_.camera) : std::nullopt;
	frappe::Pipeline &pipeline_;
	std::FILE *out_;
	const bool serial_, many_;
	std::deque<Frame> window_;      /* read, not yet written, in list order */
	std::deque<Frame *> inFlight_;  /* the frame of each push in flight; deque ends keep references */
	std::size_t detected_ = 0, failed_ = 0, total_ = 0;
	bool writeFailed_ = false, annotateDirMade_ = false, annotateFailed_ = false;
};

} // namespace

int main(int argc, char **argv)
{
#if defined(__GLIBC__)
	/* Each image's file and decoded frame are freed before the next of the
	 * same size is allocated. Under glibc's defaults a frame of 300 KB is
	 * mmap'ed and unmapped each time, and the top of the heap given back
	 * and taken again: page faults on every image, 3-4x the time of the
	 * detection itself on a list of small images. Kept, the same pages
	 * serve every image. (The values of the GLIBC_TUNABLES the peers are
	 * timed with: trim at 256 MiB, mmap from 32 MiB.) */
	mallopt(M_MMAP_THRESHOLD, 32 << 20);
	mallopt(M_TRIM_THRESHOLD, 256 << 20);
#endif
	Options opt = parse(argc, argv);
	if (opt.config.mode == frappe::Mode::Track && opt.config.threads != 1) {
		/* Frames on several detectors would each see a part of the video. */
		std::cerr << "frappe-detect: --mode track follows one video on one detector; using --threads 1\n";
		opt.config.threads = 1;
	}

	/* Opened before the run: a path that cannot be written fails now, not
	 * after an hour of detection. */
	std::FILE *out = nullptr;
	if (!opt.out.empty()) {
		out = std::fopen(opt.out.c_str(), "w");
		if (!out) {
			std::cerr << "frappe-detect: cannot write --out " << opt.out << ": " << std::strerror(errno) << "\n";
			return 2;
		}
	}

	std::unique_ptr<frappe::Pipeline> pipeline;
	try {
		pipeline = makePipeline(opt);
	} catch (const std::exception &e) {
		std::cerr << "frappe-detect: " << e.what() << "\n";
		return 2;
	}
	if (opt.config.mode != frappe::Mode::Normal && opt.repeat > 1) {
		std::cerr << "frappe-detect: --mode " << (opt.config.mode == frappe::Mode::AScale ? "ascale" : "track")
			  << " treats the list as a video; using --repeat 1\n";
		opt.repeat = 1;
	}

	Runner runner(opt, *pipeline, out);
	runner.run();
	if (out && (runner.writeFailed() || std::fclose(out) != 0)) {
		std::cerr << "frappe-detect: cannot write --out " << opt.out << ": " << std::strerror(errno) << "\n";
		return 2;
	}
	if (runner.failed() > 0)
		std::cerr << "frappe-detect: " << runner.failed() << " of " << runner.total() << " images failed\n";
	/* Every image has its line either way; a script that only looks at the
	 * exit status still learns that some failed (issue 16). */
	return runner.failed() > 0 || runner.annotateFailed() ? 1 : 0;
}
