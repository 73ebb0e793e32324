// SPDX-License-Identifier: MIT
#include "frontend/vc4_warper.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "emu/device.hpp"
#include "frontend/emulator.hpp"
#include "frontend/qpu_context.hpp"
#include "kernels/warp.hpp"
#include "kernels/warp_reference.hpp"
#if FRAPPE_VC4_HAVE_RUNTIME
#include "runtime/gpu_device.hpp"
#endif

namespace frappe::vc4 {

namespace {

constexpr unsigned kPrograms = 12;
/* Per program: 7 words, then 12 a candidate for up to ceil(32 / 12) = 3 candidates. */
constexpr uint32_t kUniformBytes = 4 * (kernels::kWarpProgramUniforms + 3 * kernels::kWarpCandidateUniforms);
constexpr uint32_t kOutputBytes = kernels::kWarpOutputBytes * kernels::kWarpMaxCandidates;

/* The detector's shared context: the front end's device, and the frame it staged. */
template <class Dev>
struct SharedTarget {
	using Device = Dev;
	using Job = std::conditional_t<QpuContext<Dev>::kEmulated, emu::Job,
#if FRAPPE_VC4_HAVE_RUNTIME
				       runtime::Job
#else
				       emu::Job
#endif
				       >;
	std::shared_ptr<QpuContext<Device>> context;

	static const char *name() { return QpuContext<Device>::kEmulated ? "vc4-emu" : "vc4"; }
	/* The slowest QPU's cycles on the emulator, 0 on the GPU. */
	uint64_t run(std::span<const Job> jobs)
	{
		if constexpr (QpuContext<Device>::kEmulated) {
			return runOnEmulator(context->device(), jobs, context->options()).cycles;
		} else {
			context->device().wait(context->device().launch(jobs));
			return 0;
		}
	}
};
using EmuTarget = SharedTarget<emu::Device>;
#if FRAPPE_VC4_HAVE_RUNTIME
using GpuTarget = SharedTarget<runtime::GpuDevice>;
#endif

template <class Target>
class QpuWarper final : public CandidateWarper {
public:
	using Device = typename Target::Device;
	using Job = typename Target::Job;

	explicit QpuWarper(Target target) : target_(std::move(target)), program_(kernels::warpKernel()),
					    cpu_(makeCpuWarper())
	{
	}
	const char *name() const override { return Target::name(); }

	void warp(const ImageView &image, std::span<const std::array<Point2f, 4>> quads, int side,
		  std::span<CandidateSamples> out, std::span<std::uint8_t> ok) override
	{
		counts_ = {};
		const std::size_t n = quads.size();
		if (n == 0)
			return;
		if (side > kernels::kWarpSide || image.width < 2 || image.height < 2) {
			cpu_->warp(image, quads, side, out, ok);
			counts_.on_cpu = static_cast<unsigned>(n);
			return;
		}
		prepare();
		/* The frame the front end staged (imported or copied), else staged now. */
		const FrameSource src = target_.context->frame(image, false);
		const kernels::WarpImage qpuImage{ src.bus, src.stride, image.width, image.height };

		/* Quantise every candidate; the ones the fixed point refuses go to the CPU. */
		onQpu_.clear();
		params_.clear();
		for (std::size_t k = 0; k < n; ++k) {
			if (auto p = kernels::warpParams(quads[k], side)) {
				onQpu_.push_back(k);
				params_.push_back(*p);
			} else {
				cpu_->warp(image, quads.subspan(k, 1), side, out.subspan(k, 1), ok.subspan(k, 1));
				++counts_.on_cpu;
			}
		}
		for (std::size_t first = 0; first < params_.size(); first += kernels::kWarpMaxCandidates) {
			const std::size_t count = std::min<std::size_t>(kernels::kWarpMaxCandidates, params_.size() - first);
			/* Uniforms straight into the device buffers: a launch allocates nothing. */
			uint32_t *streams[kPrograms];
			for (unsigned p = 0; p < kPrograms; ++p)
				streams[p] = reinterpret_cast<uint32_t *>(unif_[p].cpu.data());
			const unsigned programs = kernels::writeWarpUniforms(
				qpuImage, std::span<const kernels::WarpParams>(params_).subspan(first, count), out_.bus, kPrograms,
				streams);
			Job jobs[kPrograms];
			for (unsigned p = 0; p < programs; ++p)
				jobs[p] = { unif_[p].bus, code_.bus };
			counts_.slowest_cycles += target_.run(std::span<const Job>(jobs, programs));
			++counts_.launches;
			for (std::size_t c = 0; c < count; ++c) {
				const std::size_t k = onQpu_[first + c];
				const std::uint8_t *s = out_.cpu.data() + kernels::kWarpOutputBytes * c;
				out[k].side = side;
				for (int j = 0; j < side; ++j)
					for (int i = 0; i < side; ++i)
						out[k].samples[static_cast<std::size_t>(j * side + i)] =
							static_cast<float>(s[j * kernels::kWarpSide + i]);
				ok[k] = 1;
			}
			counts_.on_qpus += static_cast<unsigned>(count);
		}
	}

	const WarpCounts &counts() const { return counts_; }

	const QpuContext<Device> &context() const { return *target_.context; }

private:
	/* Device buffers of a constant size, allocated once on the shared device. */
	void prepare()
	{
		if (device_)
			return;
		device_ = &target_.context->device();
		out_ = device_->alloc(kOutputBytes);
		for (auto &u : unif_)
			u = device_->alloc(kUniformBytes, 64);
		code_ = device_->upload(program_.code);
	}

	Target target_;
	qasm::Program program_;
	std::unique_ptr<CandidateWarper> cpu_;
	Device *device_ = nullptr;
	typename Device::Buffer out_, code_, unif_[kPrograms];
	std::vector<std::size_t> onQpu_;
	std::vector<kernels::WarpParams> params_;
	WarpCounts counts_;
};

} // namespace

std::unique_ptr<frappe::CandidateWarper> makeWarper(const FrontEndOptions &options)
{
	if (options.emulate)
		return makeWarper(makeEmuContext(options));
#if FRAPPE_VC4_HAVE_RUNTIME
	const std::string reason = probeGpu();
	if (!reason.empty())
		throw std::runtime_error(reason);
	return makeWarper(makeGpuContext(runtime::systemOs(), {}));
#else
	throw std::runtime_error("the VideoCore IV runtime is only built for Linux.");
#endif
}

std::unique_ptr<frappe::CandidateWarper> makeWarper(std::shared_ptr<QpuContext<emu::Device>> context)
{
	return std::make_unique<QpuWarper<EmuTarget>>(EmuTarget{ std::move(context) });
}

#if FRAPPE_VC4_HAVE_RUNTIME
std::unique_ptr<frappe::CandidateWarper> makeWarper(std::shared_ptr<QpuContext<runtime::GpuDevice>> context)
{
	return std::make_unique<QpuWarper<GpuTarget>>(GpuTarget{ std::move(context) });
}
#endif

bool contextInfo(const frappe::CandidateWarper &warper, ContextInfo &out)
{
#if FRAPPE_VC4_HAVE_RUNTIME
	return contextInfoOf<QpuWarper<EmuTarget>, QpuWarper<GpuTarget>>(warper, out);
#else
	return contextInfoOf<QpuWarper<EmuTarget>>(warper, out);
#endif
}

bool lastWarpCounts(const frappe::CandidateWarper &warper, WarpCounts &out)
{
	if (const auto *w = dynamic_cast<const QpuWarper<EmuTarget> *>(&warper)) {
		out = w->counts();
		return true;
	}
#if FRAPPE_VC4_HAVE_RUNTIME
	if (const auto *w = dynamic_cast<const QpuWarper<GpuTarget> *>(&warper)) {
		out = w->counts();
		return true;
	}
#endif
	return false;
}

} // namespace frappe::vc4
