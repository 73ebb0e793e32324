// SPDX-License-Identifier: MIT
// vc4-probe: says whether this machine's VideoCore IV QPUs can be used, and why not.
//   vc4-probe              probe only (exit 0 when usable, 1 when not)
//   vc4-probe --emulate    the selftests below on the emulator instead
//   vc4-probe --selftest   also run a trivial program on all 12 QPUs, then the warp
//                          kernel on 32 candidates, bit-exact against warpReference()
// First thing to run on a new Pi (vc4/BRINGUP.md).
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "asm/assembler.hpp"
#include "isa/setup_words.hpp"
#include "kernels/warp.hpp"
#include "kernels/warp_reference.hpp"
#include "emu/device.hpp"
#include "runtime/gpu_device.hpp"

using namespace frappe::vc4;

namespace {

// The smallest useful program: each QPU stores 0x1000 + 16 qpu + element at out + 64 qpu
// through its VPM row and a VDW under the mutex, raises the host interrupt the firmware
// waits for, and ends. Uniforms: out.
qasm::Program hello()
{
	using namespace qasm;
	Assembler a("hello");
	a.emit(mov(wa(0), a.uniform("out", UniformKind::Address)));
	a.emit(mov(r0, reg::qpu_num));
	a.emit(shl(r1, r0, imm(6)));
	a.emit(add(wa(0), ra(0), r1));
	a.emit(shl(r2, r0, imm(4)));
	a.ldi(r3, 0x1000);
	a.emit(add(r2, r2, r3));
	a.emit(add(r2, r2, reg::elem_num));
	a.ldi(r1, isa::VpmWriteSetup{.stride = 1, .horizontal = true, .laned = false, .size = isa::VpmSize::Bits32,
	                             .addr = 0}.word());
	a.emit(add(reg::vw_setup, r1, r0));
	a.emit(mov(reg::vpm_write, r2));
	a.emit(shl(r0, r0, imm(7)));
	a.ldi(r1, isa::VdwSetup{.units = 1, .depth = 16, .horizontal = true, .vpm_base = 0, .modew = 0}.word());
	a.emit(mov(reg::nop, reg::mutex_acq));
	a.emit(add(reg::vw_setup, r1, r0));
	a.emit(mov(reg::vw_addr, ra(0)));
	a.emit(mov(reg::nop, reg::vw_wait));
	a.emit(mov(reg::mutex_rel, imm(1)));
	a.emit(mov(reg::host_int, imm(1)));
	a.thrend();
	return a.finish();
}

double ms(const runtime::LaunchResult &r) { return std::chrono::duration<double, std::milli>(r.elapsed).count(); }
double ms(const emu::LaunchStats &s) { return static_cast<double>(s.cycles) / 300e3; } // modelled, 300 MHz

// The selftests run on the real GPU (GpuDevice, runtime::Job) or, with --emulate, on the
// emulator (emu::Device, emu::Job): the two devices have the same shape.
template <class Device, class Job>
int helloTest(Device &gpu)
{
	const auto program = hello();
	const auto code = gpu.upload(program.code);
	const auto out = gpu.alloc(64 * 12);
	const auto unif = gpu.upload(std::vector<uint32_t>{out.bus});
	std::vector<Job> jobs(12, Job{unif.bus, code.bus});
	const auto r = gpu.wait(gpu.launch(jobs));
	unsigned bad = 0;
	for (uint32_t q = 0; q < 12; ++q)
		for (uint32_t e = 0; e < 16; ++e) {
			uint32_t v;
			std::memcpy(&v, out.cpu.data() + 64 * q + 4 * e, 4);
			bad += v != 0x1000 + 16 * q + e;
		}
	std::printf("selftest 1, hello on 12 QPUs: %s (%.3f ms)\n", bad ? "FAILED" : "ok", ms(r));
	return bad ? 2 : 0;
}

template <class Device, class Job>
int warpTest(Device &gpu)
{
	// A synthetic 320 x 240 frame with a stride and 32 quads of all shapes.
	constexpr int W = 320, H = 240, S = 336;
	const auto image = gpu.alloc(S * H);
	for (int y = 0; y < H; ++y)
		for (int x = 0; x < W; ++x)
			image.cpu[static_cast<size_t>(y * S + x)] = static_cast<uint8_t>((x * 7 + y * 13 + (x * y) / 5) & 255);
	std::vector<kernels::WarpParams> cands;
	for (int k = 0; cands.size() < 32; ++k) {
		const float cx = 40.0f + (k * 37) % 240, cy = 40.0f + (k * 53) % 160, r = 10.0f + k % 25;
		const std::array<frappe::Point2f, 4> q = {frappe::Point2f{cx - r, cy - r * 0.8f}, {cx + r * 1.1f, cy - r},
		                                          {cx + r, cy + r * 0.9f + k % 3}, {cx - r * 0.7f, cy + r}};
		if (auto p = kernels::warpParams(q))
			cands.push_back(*p);
	}
	const auto program = kernels::warpKernel();
	const auto code = gpu.upload(program.code);
	const auto out = gpu.alloc(kernels::kWarpOutputBytes * 32);
	std::vector<Job> jobs;
	for (const auto &st : kernels::warpUniforms({image.bus, S, W, H}, cands, out.bus))
		jobs.push_back({gpu.upload(st).bus, code.bus});
	const auto r = gpu.wait(gpu.launch(jobs));
	const frappe::ImageView view(image.cpu.data(), W, H, S);
	unsigned bad = 0;
	for (size_t k = 0; k < cands.size(); ++k) {
		std::array<uint8_t, kernels::kWarpSamples> want;
		kernels::warpReference(view, cands[k], want);
		for (size_t i = 0; i < want.size(); ++i)
			if (out.cpu[k * kernels::kWarpSamples + i] != want[i] && bad++ < 5)
				std::printf("  candidate %zu sample %zu: QPU %u, reference %u\n", k, i,
				            out.cpu[k * kernels::kWarpSamples + i], want[i]);
	}
	std::printf("selftest 2, warp of 32 candidates on 12 QPUs: %s, %u samples differ (%.3f ms)\n",
	            bad ? "FAILED" : "bit-exact", bad, ms(r));
	return bad ? 2 : 0;
}

} // namespace

int main(int argc, char **argv)
{
	const std::string arg = argc == 2 ? argv[1] : "";
	if (argc > 2 || (argc == 2 && arg != "--selftest" && arg != "--emulate")) {
		std::fprintf(stderr, "usage: vc4-probe [--selftest | --emulate]\n");
		return 64;
	}
	try {
		if (arg == "--emulate") { // the selftests on the emulator, strict hazard checks
			emu::Device emulator;
			std::printf("emulator (times modelled at 300 MHz):\n");
			if (const int rc = helloTest<emu::Device, emu::Job>(emulator))
				return rc;
			return warpTest<emu::Device, emu::Job>(emulator);
		}
		const auto report = runtime::GpuDevice::probe();
		std::printf("%s\n", report.summary().c_str());
		if (!report.usable)
			return 1;
		if (arg != "--selftest")
			return 0;
		runtime::GpuDevice gpu;
		if (const int rc = helloTest<runtime::GpuDevice, runtime::Job>(gpu))
			return rc;
		return warpTest<runtime::GpuDevice, runtime::Job>(gpu);
	} catch (const std::exception &e) {
		std::printf("selftest: %s\n", e.what());
		return 2;
	}
}
