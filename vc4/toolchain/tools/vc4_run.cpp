// SPDX-License-Identifier: MIT
// vc4-run: runs a QPU tile program on the emulator over an 8-bit PGM image.
//
// The image is cut into 64x16 tiles (padded with zeros); every tile is one QPU job with
// the uniforms (src tile address, dst tile address, src pitch, dst pitch), up to 12 jobs
// per launch. Without --code the built-in tile program (copy and brighten by 1) runs.
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#include <fstream>
#include <sstream>

#include "asm/text.hpp"
#include "emu/v3d.hpp"
#include "samples/samples.hpp"
#include "tools/listing.hpp"
#include "tools/pgm.hpp"

namespace {
void usage()
{
	std::fprintf(stderr,
	             "usage: vc4-run [--code FILE] [--qpus N] [--random SEED] [--lenient] IN.pgm OUT.pgm\n"
	             "  --code FILE    hex listing, binary, or .qasm listing in vc4-dis syntax of a tile\n"
	             "                 program (default: built-in tile copy)\n"
	             "  --qpus N       QPUs per launch, 1..12 (default 12)\n"
	             "  --random SEED  seeded random interleaving instead of round robin\n"
	             "  --lenient      do not fault on documented hazards\n");
}
} // namespace

int main(int argc, char **argv)
{
	using namespace frappe::vc4;
	std::string code_path, in_path, out_path;
	unsigned qpus = 12;
	emu::LaunchOptions options;
	emu::Config config;
	for (int i = 1; i < argc; ++i) {
		const std::string arg = argv[i];
		if (arg == "--code" && i + 1 < argc)
			code_path = argv[++i];
		else if (arg == "--qpus" && i + 1 < argc)
			qpus = static_cast<unsigned>(std::stoul(argv[++i]));
		else if (arg == "--random" && i + 1 < argc)
			options = {emu::Schedule::Random, std::stoull(argv[++i])};
		else if (arg == "--lenient")
			config.strict = false;
		else if (arg == "-h" || arg == "--help") {
			usage();
			return 0;
		} else if (in_path.empty())
			in_path = arg;
		else if (out_path.empty())
			out_path = arg;
		else {
			usage();
			return 2;
		}
	}
	if (in_path.empty() || out_path.empty() || qpus < 1 || qpus > emu::kQpus) {
		usage();
		return 2;
	}
	try {
		std::vector<uint64_t> code;
		if (code_path.empty()) {
			code = samples::tileCopy().code;
		} else if (code_path.size() > 5 && code_path.substr(code_path.size() - 5) == ".qasm") {
			std::ifstream f(code_path);
			std::ostringstream text;
			text << f.rdbuf();
			code = qasm::assembleText(text.str());
		} else {
			code = tools::readCodeFile(code_path);
		}
		const tools::GreyImage in = tools::readPgm(in_path);
		const unsigned tiles_x = (in.width + 63) / 64, tiles_y = (in.height + 15) / 16;
		const uint32_t pitch = tiles_x * 64, rows = tiles_y * 16;

		emu::Memory memory(2 * pitch * rows + (1u << 20));
		emu::V3d v3d(memory, config);
		const uint32_t src = memory.alloc(pitch * rows), dst = memory.alloc(pitch * rows);
		auto s = memory.bytes(src, pitch * rows);
		for (unsigned y = 0; y < in.height; ++y)
			std::memcpy(&s[y * pitch], &in.pixels[size_t{y} * in.width], in.width);
		const uint32_t program = memory.load(code);

		std::vector<emu::Job> all;
		for (unsigned ty = 0; ty < tiles_y; ++ty)
			for (unsigned tx = 0; tx < tiles_x; ++tx) {
				const uint32_t offset = ty * 16 * pitch + tx * 64;
				all.push_back({memory.load(std::vector<uint32_t>{src + offset, dst + offset, pitch, pitch}), program});
			}
		uint64_t instructions = 0, cycles = 0, launches = 0;
		std::vector<uint64_t> per_qpu(qpus, 0);
		for (size_t first = 0; first < all.size(); first += qpus) {
			const size_t n = std::min<size_t>(qpus, all.size() - first);
			const auto stats = v3d.launch(std::span(all).subspan(first, n), options);
			instructions += stats.instructions;
			cycles += stats.cycles;
			++launches;
			for (size_t q = 0; q < n; ++q)
				per_qpu[q] += stats.qpus[q].instructions;
		}

		tools::GreyImage out{in.width, in.height, std::vector<uint8_t>(in.pixels.size())};
		auto d = memory.bytes(dst, pitch * rows);
		for (unsigned y = 0; y < in.height; ++y)
			std::memcpy(&out.pixels[size_t{y} * in.width], &d[y * pitch], in.width);
		tools::writePgm(out_path, out);

		std::printf("tiles %zu, launches %llu, instructions %llu, modelled cycles %llu\n", all.size(),
		            static_cast<unsigned long long>(launches), static_cast<unsigned long long>(instructions),
		            static_cast<unsigned long long>(cycles));
		for (unsigned q = 0; q < qpus; ++q)
			std::printf("  qpu %2u: %llu instructions\n", q, static_cast<unsigned long long>(per_qpu[q]));
		for (double mhz : {250.0, 300.0, 400.0})
			std::printf("  estimated (uncalibrated) %.3f ms at %.0f MHz\n",
			            static_cast<double>(cycles) / (mhz * 1000.0), mhz);
		return 0;
	} catch (const std::exception &e) {
		std::fprintf(stderr, "vc4-run: %s\n", e.what());
		return 1;
	}
}
