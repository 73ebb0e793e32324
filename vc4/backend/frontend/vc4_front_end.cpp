// SPDX-License-Identifier: MIT
#include "frontend/vc4_front_end.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "emu/device.hpp"
#include "frontend/emulator.hpp"
#include "frontend/qpu_context.hpp"
#include "frontend/region_pass.hpp"
#include "isa/setup_words.hpp"
#include "kernels/kernels.hpp"

static_assert(frappe::vc4::kMaxQpuWidth == frappe::vc4::kernels::kMaxWidth);
#if FRAPPE_VC4_HAVE_RUNTIME
#include "runtime/gpu_device.hpp"
#endif

namespace frappe::vc4 {

namespace {

using kernels::kTileH;
using kernels::kTileW;

constexpr unsigned kPrograms = 12;

uint32_t roundUp(uint32_t v, uint32_t m) { return (v + m - 1) / m * m; }

// What a frame needs from the device, sized once per frame geometry.
struct Geometry {
	int src_w = 0, src_h = 0, w = 0, h = 0;
	bool operator==(const Geometry &) const = default;
	uint32_t paddedW() const { return roundUp(static_cast<uint32_t>(w), kTileW); }
	uint32_t paddedH() const { return roundUp(static_cast<uint32_t>(h), kTileH); }
	uint32_t tilesX() const { return paddedW() / kTileW; }
	uint32_t tilesY() const { return paddedH() / kTileH; }
	uint32_t tiles() const { return tilesX() * tilesY(); }
	uint32_t gradPitch() const { return 16 * paddedW(); }
	uint32_t gradBytes() const { return gradPitch() * paddedH(); }
	/// Pass 2 reads border pixels' neighbours unclamped: a margin of a row and more.
	uint32_t gradMargin() const { return kernels::gradMargin(gradPitch()); }
	uint32_t edgeBytes() const { return paddedW() * paddedH(); }
	uint32_t maskBytes() const { return 128 * tiles(); }

	/// Pass 1: four strips a 64-pixel group, over the bands that balance the QPUs best
	/// (a band pays 6 rows to fill the window and about one for its setup).
	uint32_t strips() const { return 4 * tilesX(); }
	uint32_t bands() const
	{
		uint32_t best = 1;
		uint64_t best_cost = ~uint64_t{0};
		const uint32_t most = static_cast<uint32_t>(std::max(1, h / 16));
		for (uint32_t nb = 1; nb <= most; ++nb) {
			const uint64_t per = (uint64_t{strips()} * nb + kPrograms - 1) / kPrograms;
			const uint64_t cost = per * ((static_cast<uint32_t>(h) + nb - 1) / nb + 7);
			if (cost < best_cost) {
				best_cost = cost;
				best = nb;
			}
		}
		return best;
	}
	uint32_t gradientUnits() const { return strips() * bands(); }
	/// Pass 2: half tiles.
	uint32_t edgeUnits() const { return tilesX() * (paddedH() / kernels::kEdgeRows); }
	uint32_t gradientUniformBytes() const
	{
		const uint32_t rows = (static_cast<uint32_t>(h) + bands() - 1) / bands();
		const uint32_t per = kernels::kGradientUnitUniforms + kernels::gradientRowUniformCount(static_cast<int>(rows)) + 1;
		return 4 * (kernels::kGradientUniforms + per * ((gradientUnits() + kPrograms - 1) / kPrograms));
	}
	uint32_t edgeUniformBytes() const
	{
		const uint32_t per = kernels::kEdgeUnitUniforms + kernels::kEdgeRows + 1;
		return 4 * (kernels::kEdgeUniforms + per * ((edgeUnits() + kPrograms - 1) / kPrograms));
	}
};

template <class Device>
struct Buffers {
	typename Device::Buffer grad, edge, mask, code[2];
	typename Device::Buffer unif[2][kPrograms];
};

// The device adapter: the detector's shared QpuContext (one device, never re-created);
// buffers of an old geometry are released one by one.
template <class Dev>
struct SharedBackend {
	using Device = Dev;
	std::shared_ptr<QpuContext<Device>> context;

	static const char *name() { return QpuContext<Device>::kEmulated ? "vc4-emu" : "vc4"; }
	Device &open(Buffers<Device> &old)
	{
		Device &device = context->device();
		for (auto *b : {&old.grad, &old.edge, &old.mask}) {
			if (b->bus)
				device.release(*b);
			*b = {};
		}
		for (auto &pass : old.unif)
			for (auto &b : pass) {
				if (b.bus)
					device.release(b);
				b = {};
			}
		return device;
	}
	template <class Job>
	void run(std::span<const Job> jobs, PassCounts &c)
	{
		if constexpr (QpuContext<Device>::kEmulated) {
			const emu::LaunchStats s = runOnEmulator(context->device(), jobs, context->options());
			c.instructions = s.instructions;
			c.slowest_cycles = s.cycles;
			c.dram_read = s.traffic.read();
			c.dram_written = s.traffic.vdw_written;
		} else {
			context->device().wait(context->device().launch(jobs));
		}
		c.programs = static_cast<unsigned>(jobs.size());
	}
};
using EmuBackend = SharedBackend<emu::Device>;
#if FRAPPE_VC4_HAVE_RUNTIME
using GpuBackend = SharedBackend<runtime::GpuDevice>;
#endif

template <class Backend>
class Vc4FrontEnd final : public FrontEnd {
public:
	using Device = typename Backend::Device;

	explicit Vc4FrontEnd(Backend backend) : backend_(std::move(backend))
	{
		programs_[0] = kernels::gradientPass().program;
		programs_[1] = kernels::edgePass().program;
	}
	const char *name() const override { return Backend::name(); }
	bool makesRegionMap() const override { return true; }
	const Backend &backend() const { return backend_; }

	std::size_t lastCopyBytes() const override { return backend_.context->copyBytes(); }
	const QpuContext<Device> &context() const { return *backend_.context; }

	void run(const ImageView &image, float scale, const FrontEndParams &params, EdgeMap &out) override
	{
		backend_.context->beginFrame();
		Geometry g;
		g.src_w = image.width;
		g.src_h = image.height;
		g.w = scale < 1.0f ? scaledLength(image.width, scale) : image.width;
		g.h = scale < 1.0f ? scaledLength(image.height, scale) : image.height;
		if (g.w < 3 || g.h < 3 || g.w > kMaxQpuWidth || params.light_floor < 0) {
			// Nothing for the QPUs (an all-zero map), wider than the VDW stride allows, or a
			// negative light floor (q < 0: the kernels' mul24 and v8adds take it unsigned).
			counted_ = false;
			backend_.context->forget(image);
			if (!cpu_)
				cpu_ = makeCpuFrontEnd(1);
			cpu_->run(image, scale, params, out);
			return;
		}
		prepare(g);
		out.resize(g.w, g.h);
		out.scale = scale < 1.0f ? scale : 1.0f;

		// The source frame: its dma-buf in place, else a copy (the shared context decides).
		const FrameSource src = backend_.context->frame(image, true);
		const uint32_t stride = src.stride;

		const uint32_t stepX = static_cast<uint32_t>((static_cast<uint64_t>(g.src_w) * 65536u + g.w / 2) / g.w);
		const uint32_t stepY = static_cast<uint32_t>((static_cast<uint64_t>(g.src_h) * 65536u + g.h / 2) / g.h);
		// E' and T as the contract clamps them (E' = -1 acts as 0: an edge has m > m(prev) >= 0),
		// the floor at 128 (q = min(p + floor, 128) either way).
		const auto edgeThr = static_cast<uint32_t>(std::clamp<int64_t>(params.edge_threshold_sq, 0, int64_t{1} << 22));
		const auto cornerT = static_cast<uint32_t>(std::clamp<int64_t>(params.corner_threshold, 0, (int64_t{1} << 23) - 1));
		const auto floor = static_cast<uint32_t>(std::min(params.light_floor, FrontEndParams::kLightReference));
		const uint32_t pitch = g.gradPitch(), pw = g.paddedW();
		const uint32_t grad = buf_.grad.bus + g.gradMargin();
		const unsigned tiles = g.tiles();

		// Uniform streams straight into the device buffers (no allocation per frame).
		// Pass 1: strip k of band b is unit b * strips + k, on program unit % 12.
		const unsigned units[2] = {g.gradientUnits(), g.edgeUnits()};
		const unsigned programs[2] = {std::min(kPrograms, units[0]), std::min(kPrograms, units[1])};
		const uint32_t bands = g.bands(), strips = g.strips();
		for (unsigned p = 0; p < programs[0]; ++p) {
			const kernels::GradientUniforms head{static_cast<uint32_t>(g.src_w - 1), stepX,
				static_cast<uint32_t>(g.w - 1), pitch,
				isa::VdwStride{.stride = static_cast<uint16_t>(pitch / 4 - 64)}.word(), floor};
			uint8_t *at = put(buf_.unif[0][p].cpu.data(), &head, sizeof(head));
			for (unsigned u = p; u < units[0]; u += kPrograms) {
				const uint32_t band = u / strips, strip = u % strips;
				const int y0 = static_cast<int>(band * static_cast<uint32_t>(g.h) / bands);
				const int y1 = static_cast<int>((band + 1) * static_cast<uint32_t>(g.h) / bands);
				const uint32_t x = strip / 4 * kTileW + strip % 4;
				const kernels::GradientUnit unit{x, grad + static_cast<uint32_t>(y0) * pitch + 4 * kernels::gradWord(x),
				                                 static_cast<uint32_t>(y1 - y0)};
				at = put(at, &unit, sizeof(unit));
				at = reinterpret_cast<uint8_t *>(kernels::gradientRowUniforms(reinterpret_cast<uint32_t *>(at),
					src.bus, stride, g.src_h, stepY, g.h, y0, y1 - y0));
				at = more(at, u + kPrograms < units[0]);
			}
		}
		// Pass 2: half tiles in raster order, unit u on program u % 12.
		for (unsigned p = 0; p < programs[1]; ++p) {
			const kernels::EdgeUniforms head{pitch, edgeThr, cornerT,
				isa::VdwStride{.stride = static_cast<uint16_t>(pw - 64)}.word(), 4 * pw};
			uint8_t *at = put(buf_.unif[1][p].cpu.data(), &head, sizeof(head));
			for (unsigned u = p; u < units[1]; u += kPrograms) {
				const uint32_t x0 = (u % g.tilesX()) * kTileW, y0 = (u / g.tilesX()) * kernels::kEdgeRows;
				const uint32_t t = (u / g.tilesX() / 2) * g.tilesX() + u % g.tilesX();
				const kernels::EdgeUnit unit{x0, static_cast<uint32_t>(g.w - 2), grad + (y0 - 1) * pitch + 4 * x0,
				                             pitch / 4, buf_.edge.bus + y0 * pw + x0,
				                             buf_.mask.bus + 128 * t + 64 * (u / g.tilesX() % 2)};
				at = put(at, &unit, sizeof(unit));
				for (int r = 0; r < kernels::kEdgeRows; ++r) {
					const int y = static_cast<int>(y0) + r;
					const uint32_t m = y >= 1 && y <= g.h - 2 ? 0xffffffffu : 0u;
					at = put(at, &m, 4);
				}
				at = more(at, u + kPrograms < units[1]);
			}
		}
		for (int pass = 0; pass < 2; ++pass) {
			std::array<JobType, kPrograms> jobs;
			for (unsigned p = 0; p < programs[pass]; ++p)
				jobs[p] = {buf_.unif[pass][p].bus, buf_.code[pass].bus};
			counts_.pass[pass].tiles = tiles;
			counts_.pass[pass].units = units[pass];
			backend_.template run<JobType>(std::span<const JobType>(jobs.data(), programs[pass]), counts_.pass[pass]);
		}
		runRegions(RegionSource{src.bus, stride, g.src_w, g.src_h, stepX, stepY}, params, out);
		counted_ = true;

		for (int y = 0; y < g.h; ++y)
			std::memcpy(out.pixels.data() + static_cast<size_t>(y) * g.w,
			            buf_.edge.cpu.data() + static_cast<size_t>(y) * pw, static_cast<size_t>(g.w));
		std::fill(out.tiles.begin(), out.tiles.end(), 0);
		for (unsigned t = 0; t < tiles; ++t) {
			uint32_t words[32];
			std::memcpy(words, buf_.mask.cpu.data() + 128 * t, sizeof(words));
			const int tx = static_cast<int>(t % g.tilesX()), ty = static_cast<int>(t / g.tilesX());
			for (int half = 0; half < 2; ++half)
				for (int b = 0; b < 4; ++b) {
					const int bx = 4 * tx + b, by = 2 * ty + half;
					if (bx >= out.tiles_x || by >= out.tiles_y)
						continue;
					if (words[16 * half + 4 * b + 3])
						out.tiles[static_cast<size_t>(by) * out.tiles_x + bx] = 1;
				}
		}
	}

	bool gradient(std::vector<uint32_t> &words, int &pitch_words) const
	{
		if (!counted_)
			return false;
		words.resize(geometry_.gradBytes() / 4);
		std::memcpy(words.data(), buf_.grad.cpu.data() + geometry_.gradMargin(), geometry_.gradBytes());
		pitch_words = static_cast<int>(geometry_.gradPitch() / 4);
		return true;
	}

	bool counts(FrameCounts &out) const
	{
		if (!counted_)
			return false;
		out = counts_;
		return true;
	}

private:
	using JobType = std::conditional_t<std::is_same_v<Device, emu::Device>, emu::Job,
#if FRAPPE_VC4_HAVE_RUNTIME
	                                   runtime::Job
#else
	                                   emu::Job
#endif
	                                   >;

	// The region map (EdgeMap::regions): two launches of its own over the same source.
	void runRegions(const RegionSource &src, const FrontEndParams &params, EdgeMap &out)
	{
		auto launch = [&](uint32_t code, const uint32_t *unif, unsigned programs, PassCounts &c) {
			std::array<JobType, kPrograms> jobs;
			for (unsigned p = 0; p < programs; ++p)
				jobs[p] = {unif[p], code};
			backend_.run(std::span<const JobType>(jobs.data(), programs), c);
		};
		region_.run(src, params, out.scale, launch, counts_.region, out.regions);
	}

	static uint8_t *put(uint8_t *at, const void *words, size_t bytes)
	{
		std::memcpy(at, words, bytes);
		return at + bytes;
	}
	static uint8_t *more(uint8_t *at, bool another)
	{
		const uint32_t m = another ? 1u : 0u;
		return put(at, &m, 4);
	}

	// Device buffers for this geometry; kept while the geometry does not change.
	void prepare(const Geometry &g)
	{
		if (device_ && g == geometry_)
			return;
		const uint32_t u1 = g.gradientUniformBytes();
		const uint32_t u2 = g.edgeUniformBytes();
		if (device_)
			region_.release(*device_);
		device_ = &backend_.open(buf_);
		buf_.grad = device_->alloc(g.gradBytes() + 2 * g.gradMargin());
		buf_.edge = device_->alloc(g.edgeBytes());
		buf_.mask = device_->alloc(g.maskBytes());
		for (int pass = 0; pass < 2; ++pass) {
			if (!buf_.code[pass].bus)
				buf_.code[pass] = device_->upload(programs_[pass].code);
			for (unsigned p = 0; p < kPrograms; ++p)
				buf_.unif[pass][p] = device_->alloc(pass ? u2 : u1, 64);
		}
		region_.allocate(*device_, g.w, g.h);
		geometry_ = g;
	}

	Backend backend_;
	qasm::Program programs_[2];
	Device *device_ = nullptr;
	Buffers<Device> buf_;
	Geometry geometry_;
	FrameCounts counts_;
	bool counted_ = false;
	std::unique_ptr<FrontEnd> cpu_;
	RegionPass<Device> region_;
};

} // namespace

std::unique_ptr<frappe::FrontEnd> makeFrontEnd(const FrontEndOptions &options)
{
	if (options.emulate)
		return makeFrontEnd(makeEmuContext(options));
#if FRAPPE_VC4_HAVE_RUNTIME
	const runtime::ProbeReport report = runtime::GpuDevice::probe();
	if (!report.usable)
		throw std::runtime_error(report.reason);
	return makeFrontEnd(makeGpuContext(runtime::systemOs(), {}));
#else
	throw std::runtime_error("the VideoCore IV runtime is only built for Linux.");
#endif
}

std::unique_ptr<frappe::FrontEnd> makeFrontEnd(std::shared_ptr<QpuContext<emu::Device>> context)
{
	return std::make_unique<Vc4FrontEnd<EmuBackend>>(EmuBackend{std::move(context)});
}

#if FRAPPE_VC4_HAVE_RUNTIME
std::unique_ptr<frappe::FrontEnd> makeFrontEnd(std::shared_ptr<QpuContext<runtime::GpuDevice>> context)
{
	return std::make_unique<Vc4FrontEnd<GpuBackend>>(GpuBackend{std::move(context)});
}
#endif

bool contextInfo(const frappe::FrontEnd &front_end, ContextInfo &out)
{
#if FRAPPE_VC4_HAVE_RUNTIME
	return contextInfoOf<Vc4FrontEnd<EmuBackend>, Vc4FrontEnd<GpuBackend>>(front_end, out);
#else
	return contextInfoOf<Vc4FrontEnd<EmuBackend>>(front_end, out);
#endif
}

std::string probeGpu()
{
#if FRAPPE_VC4_HAVE_RUNTIME
	try {
		const runtime::ProbeReport report = runtime::GpuDevice::probe();
		return report.usable ? std::string() : report.reason;
	} catch (const std::exception &e) {
		return e.what();
	}
#else
	return "the VideoCore IV runtime is only built for Linux.";
#endif
}

bool lastFrameCounts(const frappe::FrontEnd &front_end, FrameCounts &out)
{
	if (const auto *fe = dynamic_cast<const Vc4FrontEnd<EmuBackend> *>(&front_end))
		return fe->counts(out);
	return false;
}

bool lastGradientBuffer(const frappe::FrontEnd &front_end, std::vector<uint32_t> &words, int &pitch_words)
{
	if (const auto *fe = dynamic_cast<const Vc4FrontEnd<EmuBackend> *>(&front_end))
		return fe->gradient(words, pitch_words);
	return false;
}

} // namespace frappe::vc4
