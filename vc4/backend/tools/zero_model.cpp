// SPDX-License-Identifier: MIT
// vc4-zero-model: frappedetect on a Raspberry Pi Zero, modelled (issue 33). For each frame
// of a set it takes the ARMv6 instructions of the CPU stages that scripts/arm-count.sh
// counted for that frame (its frames.csv), detects the frame here with the QPU front end and
// warp on the emulator (the slowest QPU's cycles, DRAM bytes, launches), adds the host's
// copies and cache syncs and the mailbox round trips, and plays the frames through the
// element unpipelined, pipelined over whole frames and pipelined over stages
// (model/zero_model.hpp). Prints the assumptions, the frame time and latency per frame
// (--per-frame) and per set, and the frame rate against the paper's.
//
//   vc4-zero-model --counts FRAMES.csv (--images DIR | --list FILE) [--mode normal|ascale]
//                  [--dictionary D] [--max N] [--pool N] [--copy-in] [--emulate-each]
//                  [--per-frame [--targeted]] [--name NAME]
//
// The QPU front end's counts depend on the frame's geometry only (its programs have no
// branch on pixel values), so they are emulated once per scaled size unless --emulate-each;
// the frame's EdgeMap then comes from the CPU front end, which is byte-identical.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "frappe/frappe.h"
#include "frontend/backend.hpp"
#include "frontend/qpu_context.hpp"
#include "frontend/vc4_front_end.hpp"
#include "frontend/vc4_warper.hpp"
#include "model/zero_model.hpp"

using namespace frappe;
using namespace frappe::vc4;
namespace fs = std::filesystem;

namespace {

/* One frame's ARMv6 instructions per stage, as arm_count_report.py writes them. */
struct ArmCounts {
	std::map<std::string, uint64_t> stage;
	int markers = -1;
};

/* frames.csv: the header names the columns; rows are found by the image's path, or by its
 * last two path components (the list arm-count ran may have had other prefixes). */
std::map<std::string, ArmCounts> readCounts(const std::string &path)
{
	std::ifstream in(path);
	if (!in)
		throw std::runtime_error("cannot read " + path);
	std::string line;
	std::getline(in, line);
	std::vector<std::string> head;
	for (std::stringstream ss(line); std::getline(ss, line, ',');)
		head.push_back(line);
	std::map<std::string, ArmCounts> out;
	for (std::string row; std::getline(in, row);) {
		if (row.empty())
			continue;
		std::vector<std::string> cells;
		for (std::stringstream ss(row); std::getline(ss, line, ',');)
			cells.push_back(line);
		ArmCounts c;
		for (std::size_t i = 1; i < cells.size() && i < head.size(); ++i) {
			if (head[i] == "frappe_markers")
				c.markers = std::stoi(cells[i]);
			else if (!cells[i].empty() && head[i] != "width" && head[i] != "height")
				c.stage[head[i]] = std::stoull(cells[i]);
		}
		out[cells[0]] = c;
		const fs::path p(cells[0]);
		out[(p.parent_path().filename() / p.filename()).string()] = c;
	}
	return out;
}

/* The QPU front end, emulated once per geometry (or every frame): its counts, and the
 * device's memory; the CPU front end makes the (identical) EdgeMap otherwise. */
class CountingFrontEnd final : public FrontEnd
{
public:
	CountingFrontEnd(std::unique_ptr<FrontEnd> qpu, bool each) : qpu_(std::move(qpu)), each_(each) {}
	const char *name() const override { return qpu_->name(); }
	bool makesRegionMap() const override { return true; }
	void run(const ImageView &image, float scale, const FrontEndParams &params, EdgeMap &out) override
	{
		const int w = scale < 1.0f ? scaledLength(image.width, scale) : image.width;
		const int h = scale < 1.0f ? scaledLength(image.height, scale) : image.height;
		const auto key = std::make_tuple(image.width, image.height, w, h);
		auto it = cache_.find(key);
		if (it == cache_.end() || each_) {
			qpu_->run(image, scale, params, out);
			Seen s;
			s.qpu = lastFrameCounts(*qpu_, s.counts);
			ContextInfo info;
			contextInfo(*qpu_, info);
			s.device_bytes = info.device_bytes;
			/* --emulate-each checks that the counts follow the geometry alone. */
			if (it != cache_.end() && !sameCounts(it->second.counts, s.counts))
				++varied_;
			it = cache_.insert_or_assign(key, s).first;
			++emulated_;
		} else {
			cpu_->run(image, scale, params, out);
		}
		last_ = it->second;
		w_ = w;
		h_ = h;
	}

	struct Seen {
		bool qpu = false; /* false: a frame the QPUs do not take (tiny, or wider than 2048) */
		FrameCounts counts;
		uint64_t device_bytes = 0;
	};
	const Seen &last() const { return last_; }
	int width() const { return w_; }
	int height() const { return h_; }
	int emulated() const { return emulated_; }
	int varied() const { return varied_; }

private:
	static bool sameCounts(const FrameCounts &a, const FrameCounts &b)
	{
		auto same = [](const PassCounts &x, const PassCounts &y) {
			return x.instructions == y.instructions && x.slowest_cycles == y.slowest_cycles &&
			       x.dram_read == y.dram_read && x.dram_written == y.dram_written;
		};
		return same(a.pass[0], b.pass[0]) && same(a.pass[1], b.pass[1]) && same(a.region[0], b.region[0]) &&
		       same(a.region[1], b.region[1]);
	}

	std::unique_ptr<FrontEnd> qpu_;
	std::unique_ptr<FrontEnd> cpu_ = makeCpuFrontEnd(1);
	bool each_;
	std::map<std::tuple<int, int, int, int>, Seen> cache_;
	Seen last_;
	int w_ = 0, h_ = 0, emulated_ = 0, varied_ = 0;
};

struct Options {
	std::string counts, images, list, dictionary = "aruco_mip_36h12", name;
	bool ascale = false, perFrame = false, emulateEach = false, copyIn = false, targeted = false;
	int max = 0, pool = 4;
};

std::vector<std::string> imagePaths(const Options &o)
{
	std::vector<std::string> paths;
	if (!o.list.empty()) {
		std::ifstream in(o.list);
		for (std::string l; std::getline(in, l);)
			if (!l.empty() && l[0] != '#')
				paths.push_back(l);
	} else {
		for (const auto &e : fs::directory_iterator(o.images)) {
			const std::string ext = e.path().extension().string();
			if (e.is_regular_file() && (ext == ".png" || ext == ".jpg" || ext == ".pgm"))
				paths.push_back(e.path().string());
		}
		std::sort(paths.begin(), paths.end());
	}
	if (o.max > 0 && static_cast<int>(paths.size()) > o.max)
		paths.resize(static_cast<std::size_t>(o.max));
	return paths;
}

uint64_t stageOf(const ArmCounts &c, const char *s)
{
	const auto it = c.stage.find(s);
	return it == c.stage.end() ? 0 : it->second;
}

/* A front-end launch: the bytes that must cross DRAM are what it writes and the input it
 * reads once (the TMU gathers counted by the emulator mostly hit its caches). */
model::Launch launchOf(const PassCounts &p, uint64_t inputBytes, uint64_t syncBytes)
{
	return { p.slowest_cycles, inputBytes + p.dram_written, syncBytes };
}

struct Work {
	model::FrameWork all;      /* the runtime as it is: every live buffer synced a launch */
	model::FrameWork targeted; /* syncing only what the ARM writes or reads */
	std::string name;
	int width = 0, height = 0, markers = 0, armMarkers = -1;
};

double ms(double s) { return s * 1000.0; }

void printAssumptions(const model::Assumptions &a, const Options &o)
{
	std::printf("assumptions (fast / central / slow):\n");
	auto row = [](const char *what, const model::Figure &f, double scale, const char *unit) {
		std::printf("  %-22s %8.3g / %8.3g / %8.3g %s\n      %s\n", what, f.fast * scale, f.mid * scale,
			    f.slow * scale, unit, f.source);
	};
	row("ARM CPI", a.cpi, 1, a.cpi.unit);
	row("ARM clock", a.arm_hz, 1e-6, "MHz");
	row("V3D clock", a.v3d_hz, 1e-6, "MHz");
	row("DRAM for the QPUs", a.dram_bytes_s, 1e-9, "GB/s");
	row("mailbox round trip", a.mailbox_s, 1e6, "us");
	row("ARM time a launch", a.launch_cpu_s, 1e6, "us");
	row("ARM memcpy", a.copy_bytes_s, 1e-6, "MB/s");
	row("cache sync", a.sync_cycles, 1, a.sync_cycles.unit);
	std::printf("  frames in place: %s; camera buffers imported and synced a launch: %d\n"
		    "  (the runtime today syncs every buffer of the device and every import around each\n"
		    "   launch, DMA_BUF_IOCTL_SYNC END before and START after; 'targeted' syncs only what\n"
		    "   the ARM writes (uniforms) or reads back (edge, region and mask maps, warp samples))\n",
		    o.copyIn ? "no, copied in by the ARM" : "yes (the element's dma-buf pool)", o.pool);
}

} // namespace

int main(int argc, char **argv)
{
	Options o;
	for (int i = 1; i < argc; ++i) {
		const std::string a = argv[i];
		auto value = [&]() -> std::string {
			if (i + 1 >= argc) {
				std::fprintf(stderr, "vc4-zero-model: %s needs a value\n", a.c_str());
				std::exit(2);
			}
			return argv[++i];
		};
		if (a == "--counts")
			o.counts = value();
		else if (a == "--images")
			o.images = value();
		else if (a == "--list")
			o.list = value();
		else if (a == "--mode")
			o.ascale = value() == "ascale";
		else if (a == "--dictionary")
			o.dictionary = value();
		else if (a == "--max")
			o.max = std::stoi(value());
		else if (a == "--pool")
			o.pool = std::stoi(value());
		else if (a == "--name")
			o.name = value();
		else if (a == "--copy-in")
			o.copyIn = true;
		else if (a == "--emulate-each")
			o.emulateEach = true;
		else if (a == "--per-frame")
			o.perFrame = true;
		else if (a == "--targeted")
			o.targeted = true;
		else {
			std::fprintf(stderr,
				     "usage: vc4-zero-model --counts FRAMES.csv (--images DIR | --list FILE) "
				     "[--mode normal|ascale] [--dictionary D] [--max N] [--pool N] [--copy-in] "
				     "[--emulate-each] [--per-frame [--targeted]] [--name NAME]\n");
			return 2;
		}
	}
	if (o.counts.empty() || (o.images.empty() && o.list.empty())) {
		std::fprintf(stderr, "vc4-zero-model: need --counts (scripts/arm-count.sh's frames.csv) and images\n");
		return 2;
	}
	std::map<std::string, ArmCounts> counts;
	try {
		counts = readCounts(o.counts);
	} catch (const std::exception &e) {
		std::fprintf(stderr, "vc4-zero-model: %s\n", e.what());
		return 2;
	}
	const std::vector<std::string> paths = imagePaths(o);
	if (paths.empty()) {
		std::fprintf(stderr, "vc4-zero-model: no images\n");
		return 2;
	}

	Config config;
	config.dictionary = o.dictionary;
	config.mode = o.ascale ? Mode::AScale : Mode::Normal;
	config.threads = 1;
	Detector detector(config);
	/* The warper on a context of its own: the element's shares the front end's, whose
	 * staged frame it reads, but here the front end mostly runs on the CPU and stages
	 * nothing, so the warper copies each frame (its counts are the same). */
	std::unique_ptr<CandidateWarper> qpuWarper = makeWarper(FrontEndOptions{ .emulate = true });
	const CandidateWarper *warper = qpuWarper.get();
	auto front = std::make_unique<CountingFrontEnd>(makeFrontEnd(FrontEndOptions{ .emulate = true }), o.emulateEach);
	CountingFrontEnd *fe = front.get();
	detector.setFrontEnd(std::move(front));
	detector.setWarper(std::move(qpuWarper));

	std::vector<Work> works;
	int missing = 0, mismatched = 0;
	for (const std::string &path : paths) {
		const cv::Mat m = cv::imread(path, cv::IMREAD_GRAYSCALE);
		if (m.empty()) {
			std::fprintf(stderr, "vc4-zero-model: cannot read %s\n", path.c_str());
			continue;
		}
		const fs::path p(path);
		auto it = counts.find(path);
		if (it == counts.end())
			it = counts.find((p.parent_path().filename() / p.filename()).string());
		if (it == counts.end()) {
			++missing;
			continue;
		}
		const ImageView view(m.data, m.cols, m.rows, static_cast<int>(m.step));
		const Result &r = detector.detect(view);
		const ArmCounts &c = it->second;
		WarpCounts wc;
		lastWarpCounts(*warper, wc);
		const CountingFrontEnd::Seen &seen = fe->last();

		Work w;
		w.name = p.filename().string();
		w.width = m.cols;
		w.height = m.rows;
		w.markers = static_cast<int>(r.markers.size());
		w.armMarkers = c.markers;
		mismatched += c.markers >= 0 && c.markers != w.markers;
		model::FrameWork &f = w.all;
		f.front_insns = stageOf(c, "adaptive_scale");
		f.trace_insns = stageOf(c, "trace");
		f.finish_insns = stageOf(c, "refine") + stageOf(c, "warp") + stageOf(c, "decode") +
				 stageOf(c, "detector") + stageOf(c, "other");
		const uint64_t sw = static_cast<uint64_t>(fe->width()), sh = static_cast<uint64_t>(fe->height());
		const uint64_t rw = sw / 2, rh = sh / 2;
		/* The ARM reads back the edge bytes, the region map and the tile masks. */
		const uint64_t readBack = sw * sh + (seen.counts.region[0].programs ? rw * rh : 0) + sw * sh / 256 * 4;
		f.copy_bytes = readBack + (o.copyIn ? static_cast<uint64_t>(m.cols) * m.rows : 0);
		const uint64_t imports = static_cast<uint64_t>(o.pool) * m.cols * m.rows * 3 / 2; /* NV12 */
		/* The warper's own buffers are a few KB (and its frame copy exists only here). */
		const uint64_t live = seen.device_bytes + imports;
		if (seen.qpu) {
			const FrameCounts &k = seen.counts;
			f.front_launches.push_back(launchOf(k.pass[0], sw * sh, live));
			f.front_launches.push_back(launchOf(k.pass[1], k.pass[0].dram_written, live));
			if (k.region[0].programs) {
				f.front_launches.push_back(launchOf(k.region[0], sw * sh, live));
				f.front_launches.push_back(launchOf(k.region[1], k.region[0].dram_written, live));
			}
		} else {
			/* The CPU front end ran: its instructions are in the counts. */
			f.front_insns += stageOf(c, "front_end") + stageOf(c, "region_map");
		}
		for (unsigned l = 0; l < wc.launches; ++l) {
			const unsigned cands = std::min(32u, wc.on_qpus - std::min(wc.on_qpus, 32u * l));
			f.warp_launches.push_back({ wc.slowest_cycles / wc.launches, uint64_t{ cands } * (256 + 1024), live });
		}
		w.targeted = f;
		for (auto &l : w.targeted.front_launches)
			l.sync_bytes = 0;
		if (!w.targeted.front_launches.empty())
			w.targeted.front_launches.back().sync_bytes = readBack; /* one START over the maps read back */
		for (std::size_t l = 0; l < w.targeted.warp_launches.size(); ++l)
			w.targeted.warp_launches[l].sync_bytes = 32 * 256;
		works.push_back(std::move(w));
	}
	if (works.empty()) {
		std::fprintf(stderr, "vc4-zero-model: no frame had counts in %s (%d missing)\n", o.counts.c_str(), missing);
		return 2;
	}

	const model::Assumptions a = model::piZero();
	const char *modeName = o.ascale ? "ASCALE" : "NORMAL";
	std::printf("Pi Zero model of frappedetect: %s, %zu frames (%dx%d first), mode %s, dictionary %s\n",
		    o.name.empty() ? (o.images.empty() ? o.list.c_str() : o.images.c_str()) : o.name.c_str(), works.size(),
		    works[0].width, works[0].height, modeName, o.dictionary.c_str());
	std::printf("QPU front end emulated %d times%s; %d frames without counts skipped; "
		    "%d frames whose marker count differs from the ARM run's\n",
		    fe->emulated(), o.emulateEach ? " (every frame)" : " (once a frame geometry)", missing, mismatched);
	if (o.emulateEach)
		std::printf("QPU counts differed between frames of one geometry on %d frames\n", fe->varied());
	if (fe->last().qpu) {
		const FrameCounts &k = fe->last().counts;
		std::printf("QPU front end, last frame (%dx%d traced): slowest QPU %llu + %llu + %llu + %llu cycles "
			    "(pass 1, pass 2, region means, region dark); %.2f MB written\n",
			    fe->width(), fe->height(), static_cast<unsigned long long>(k.pass[0].slowest_cycles),
			    static_cast<unsigned long long>(k.pass[1].slowest_cycles),
			    static_cast<unsigned long long>(k.region[0].slowest_cycles),
			    static_cast<unsigned long long>(k.region[1].slowest_cycles),
			    static_cast<double>(k.pass[0].dram_written + k.pass[1].dram_written + k.region[0].dram_written +
						k.region[1].dram_written) / 1e6);
	}
	printAssumptions(a, o);

	std::vector<model::FrameWork> all, targeted;
	for (const Work &w : works) {
		all.push_back(w.all);
		targeted.push_back(w.targeted);
	}
	const model::Overlap overlaps[] = { model::Overlap::None, model::Overlap::Frames, model::Overlap::Stages };
	const model::End ends[] = { model::End::Fast, model::End::Mid, model::End::Slow };

	/* Per frame, central figures, today's runtime (or --targeted syncs). */
	model::Timeline mid[3];
	for (int k = 0; k < 3; ++k)
		mid[k] = model::simulate(o.targeted ? targeted : all, overlaps[k], a, model::End::Mid);
	if (o.perFrame) {
		std::printf("\nper frame (central figures, %s): frame time / latency, ms\n",
			    o.targeted ? "targeted syncs" : "runtime as it is");
		std::printf("%-14s %7s %5s  %15s  %15s  %15s\n", "frame", "size", "marks", "unpipelined", "whole frames",
			    "staged");
		for (std::size_t i = 0; i < works.size(); ++i) {
			std::printf("%-14s %3dx%-3d %5d ", works[i].name.c_str(), works[i].width, works[i].height,
				    works[i].markers);
			for (const model::Timeline &t : mid) {
				const double ft = i ? t.out[i] - t.out[i - 1] : t.out[0] - t.in[0];
				std::printf("  %6.2f / %6.2f", ms(ft), ms(t.out[i] - t.in[i]));
			}
			std::printf("\n");
		}
	}

	std::printf("\n%s, %zu frames as fast as the element takes them: frame time (mean, ms) and frame rate at\n"
		    "fast / central / slow figures; latency (push to output) p50 / p90 at central figures\n",
		    modeName, works.size());
	std::printf("%-13s | %-20s %-15s | %-20s %-15s | %-13s %s\n", "", "runtime as it is: ms", "Hz",
		    "targeted sync: ms", "Hz", "latency as is", "targeted");
	for (int k = 0; k < 3; ++k) {
		double ft[2][3];
		for (int v = 0; v < 2; ++v)
			for (int e = 0; e < 3; ++e)
				ft[v][e] = model::summarise(model::simulate(v ? targeted : all, overlaps[k], a, ends[e])).frame_time;
		const model::Summary s = model::summarise(model::simulate(all, overlaps[k], a, model::End::Mid));
		const model::Summary st =
			model::summarise(model::simulate(targeted, overlaps[k], a, model::End::Mid));
		std::printf("%-13s | %6.2f %6.2f %6.2f  %4.0f %4.0f %4.0f | %6.2f %6.2f %6.2f  %4.0f %4.0f %4.0f | "
			    "%5.1f / %5.1f  %5.1f / %5.1f\n",
			    model::overlapName(overlaps[k]), ms(ft[0][0]), ms(ft[0][1]), ms(ft[0][2]), 1 / ft[0][0],
			    1 / ft[0][1], 1 / ft[0][2], ms(ft[1][0]), ms(ft[1][1]), ms(ft[1][2]), 1 / ft[1][0], 1 / ft[1][1],
			    1 / ft[1][2], ms(s.latency_p50), ms(s.latency_p90), ms(st.latency_p50), ms(st.latency_p90));
	}
	/* A camera at 30 Hz: the latency a robot sees, from capture to output. */
	std::printf("camera at 30 Hz, central figures: latency p50 / p90 / max, ms (runtime as it is | targeted sync)\n");
	for (int k = 0; k < 3; ++k) {
		const model::Summary s = model::summarise(model::simulate(all, overlaps[k], a, model::End::Mid, 1.0 / 30));
		const model::Summary st =
			model::summarise(model::simulate(targeted, overlaps[k], a, model::End::Mid, 1.0 / 30));
		std::printf("%-13s | %5.1f / %5.1f / %6.1f | %5.1f / %5.1f / %6.1f\n", model::overlapName(overlaps[k]),
			    ms(s.latency_p50), ms(s.latency_p90), ms(s.latency_max), ms(st.latency_p50), ms(st.latency_p90),
			    ms(st.latency_max));
	}
	const double span = mid[2].out.back();
	std::printf("staged, central, %s: ARM busy %.0f%%, QPUs and mailbox busy %.0f%% of the run\n",
		    o.targeted ? "targeted syncs" : "runtime as it is", 100 * mid[2].cpuBusy / span,
		    100 * mid[2].gpuBusy / span);
	std::printf("GPU memory a QPU context holds: %.1f MB (whole frames: two contexts)\n",
		    static_cast<double>(fe->last().device_bytes) / 1e6);

	/* Stage shares, one frame at a time (unpipelined), against Algorithm 1's: with targeted
	 * syncs, as the paper's implementation had no such sweep. */
	model::StageTimes sum[2];
	for (const Work &w : works) {
		for (int v = 0; v < 2; ++v) {
			const model::StageTimes s = model::stageTimes(v ? w.targeted : w.all, a, model::End::Mid);
			model::StageTimes &t = sum[v];
			t.front_cpu += s.front_cpu;
			t.front_gpu += s.front_gpu;
			t.trace += s.trace;
			t.finish_cpu += s.finish_cpu;
			t.warp_gpu += s.warp_gpu;
			t.sync += s.sync;
			t.copies += s.copies;
			t.mailbox += s.mailbox;
		}
	}
	const double n = static_cast<double>(works.size());
	const model::StageTimes &st = sum[1];
	const double total = st.total();
	std::printf("\nstages one frame at a time, targeted sync (central, mean ms and share; Algorithm 1's "
		    "shares in brackets):\n"
		    "  QPU front end (passes + mailbox) %.2f ms %.0f%% [QPU1,2 28%% + VPU1 empty tiles 5%%]\n"
		    "  ARM in the front end (scale, launches, syncs, maps read back) %.2f ms %.0f%%\n"
		    "  trace %.2f ms %.0f%% [CPU1 51%%]\n"
		    "  refine, decode, glue, warp launches on the ARM %.2f ms %.0f%% [CPU2 8%% + VPU2 4%%]\n"
		    "  QPU warp (+ mailbox) %.2f ms %.0f%% [QPU3 4%%]\n"
		    "  of which cache syncs %.2f ms, copies %.2f ms, mailbox waits %.2f ms; total %.2f ms\n"
		    "runtime as it is: cache syncs %.2f ms a frame, total %.2f ms\n",
		    ms(st.front_gpu / n), 100 * st.front_gpu / total, ms(st.front_cpu / n), 100 * st.front_cpu / total,
		    ms(st.trace / n), 100 * st.trace / total, ms(st.finish_cpu / n), 100 * st.finish_cpu / total,
		    ms(st.warp_gpu / n), 100 * st.warp_gpu / total, ms(st.sync / n), ms(st.copies / n),
		    ms(st.mailbox / n), ms(total / n), ms(sum[0].sync / n), ms(sum[0].total() / n));
	std::printf("paper (Pi Zero, 640x480): NORMAL 13.1 ms (76 Hz, Office) and 18.8 ms (53 Hz, Arena); "
		    "ASCALE 10.6 ms (94 Hz) and 14.3 ms (70 Hz): over 60 Hz\n");
	return 0;
}
