// SPDX-License-Identifier: MIT
// The zero-copy camera path (issue 14): a frame in a dma-buf is read by the QPUs in place,
// imported once per buffer into the one device a detector's front end and warper share;
// anything else is copied once, with the reason. On the emulator (memfd frames, as
// allocateFrameMemory("vc4-emu") hands out) the markers match a plain copy's; on the real
// GPU's code path, against a fake kernel, the imports, cache syncs and the bytes copied
// per frame are counted.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>
#include <string>

#include <sys/mman.h>
#include <unistd.h>

#include "frappe/frappe.h"
#include "frappe/render.h"
#include "frontend/backend.hpp"
#include "emu/v3d.hpp"
#include "frontend/qpu_context.hpp"
#include "frontend/vc4_warper.hpp"
#include "runtime_fake_os.hpp"

using namespace frappe;

namespace {

std::vector<std::uint8_t> scene(unsigned seed, int width, int height, int markers)
{
	std::vector<std::uint8_t> pixels(static_cast<std::size_t>(width) * height, 120);
	std::mt19937 rng(seed);
	std::uniform_real_distribution<float> u(0, 1);
	const Dictionary &dict = *findDictionary("aruco_mip_36h12");
	MutableImageView m{ pixels.data(), width, height, width };
	for (int k = 0; k < markers; ++k) {
		const float side = 28 + 10 * u(rng);
		const float cx = side + 4 + (width - 2 * side - 8) * (static_cast<float>(k) + 0.5f) / static_cast<float>(markers);
		renderMarker(m, dict, static_cast<int>(seed % 50) + 3 * k, perspectiveSquare(cx, height / 2.0f, side, 90 * u(rng), 20 * u(rng)));
	}
	return pixels;
}

/* A frame in frame memory of the vc4-emu backend (a memfd), rows `stride` bytes apart. */
struct DmabufFrame {
	int fd = -1;
	std::uint8_t *map = nullptr;
	std::size_t bytes = 0;
	ImageView view;

	DmabufFrame(const std::vector<std::uint8_t> &pixels, int width, int height, int stride, std::size_t bytes_ = 0)
	{
		bytes = bytes_ ? bytes_ : static_cast<std::size_t>(stride) * height;
		std::string why;
		fd = vc4::allocateFrameMemory("vc4-emu", bytes, why);
		EXPECT_GE(fd, 0) << why;
		map = static_cast<std::uint8_t *>(::mmap(nullptr, std::max(bytes, static_cast<std::size_t>(stride) * height),
							 PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0));
		if (bytes < static_cast<std::size_t>(stride) * height) { /* the CPU's view must hold the frame */
			EXPECT_EQ(ftruncate(fd, static_cast<off_t>(static_cast<std::size_t>(stride) * height)), 0);
		}
		for (int y = 0; y < height; ++y)
			std::memcpy(map + static_cast<std::size_t>(y) * stride, pixels.data() + static_cast<std::size_t>(y) * width,
				    static_cast<std::size_t>(width));
		if (bytes < static_cast<std::size_t>(stride) * height) { /* ... and the dma-buf says it is smaller */
			EXPECT_EQ(ftruncate(fd, static_cast<off_t>(bytes)), 0);
		}
		view = ImageView{ map, width, height, stride };
		view.dmabuf_fd = fd;
	}
	~DmabufFrame()
	{
		::munmap(map, static_cast<std::size_t>(view.stride) * view.height);
		::close(fd);
	}
};

struct QpuDetector {
	Detector detector{ Config{} };
	const FrontEnd *frontEnd = nullptr;
	const CandidateWarper *warper = nullptr;

	explicit QpuDetector(const char *backend)
	{
		vc4::BackendChoice c = vc4::selectFrontEnd(backend, 1);
		frontEnd = c.frontEnd.get();
		warper = c.warper.get();
		detector.setFrontEnd(std::move(c.frontEnd));
		detector.setWarper(std::move(c.warper));
	}
	vc4::ContextInfo info() const
	{
		vc4::ContextInfo a, b;
		EXPECT_TRUE(vc4::contextInfo(*frontEnd, a));
		EXPECT_TRUE(vc4::contextInfo(*warper, b));
		EXPECT_EQ(a.context, b.context) << "front end and warper must share one device";
		return a;
	}
};

void expectSameMarkers(const Result &got, const Result &want, const std::string &what)
{
	ASSERT_EQ(got.markers.size(), want.markers.size()) << what;
	for (std::size_t i = 0; i < want.markers.size(); ++i) {
		EXPECT_EQ(got.markers[i].id, want.markers[i].id) << what;
		for (int c = 0; c < 4; ++c) {
			EXPECT_EQ(got.markers[i].corners[c].x, want.markers[i].corners[c].x) << what;
			EXPECT_EQ(got.markers[i].corners[c].y, want.markers[i].corners[c].y) << what;
		}
	}
}

constexpr int kW = 320, kH = 240;

} // namespace

TEST(ZeroCopyEmu, DmabufFramesGiveTheMarkersOfACopyWithNothingCopied)
{
	QpuDetector inPlace("vc4-emu"), copied("vc4-emu");
	const vc4::ContextInfo first = inPlace.info();
	std::size_t found = 0;
	/* Frames in their own buffers, a larger one among them (the device grows without being
	 * re-created), then buffers seen again. */
	const int sizes[][2] = { { kW, kH }, { kW, kH }, { 400, 300 }, { kW, kH } };
	std::vector<std::unique_ptr<DmabufFrame>> pool;
	for (unsigned f = 0; f < 4; ++f) {
		const int w = sizes[f][0], h = sizes[f][1];
		const auto pixels = scene(11 + f, w, h, 4);
		std::unique_ptr<DmabufFrame> frame = std::make_unique<DmabufFrame>(pixels, w, h, w);
		const Result want = copied.detector.detect(ImageView{ pixels.data(), w, h, w });
		const Result got = inPlace.detector.detect(frame->view);
		const std::string what = "frame " + std::to_string(f);
		expectSameMarkers(got, want, what);
		found += got.markers.size();
		EXPECT_EQ(inPlace.frontEnd->lastCopyBytes(), 0u) << what;
		EXPECT_EQ(vc4::copyReason(*inPlace.frontEnd), "") << what;
		/* System memory: copied once for the front end and the warp together. */
		EXPECT_EQ(copied.frontEnd->lastCopyBytes(), static_cast<std::size_t>(w) * h) << what;
		EXPECT_NE(vc4::copyReason(*copied.frontEnd).find("system memory"), std::string_view::npos) << what;
		EXPECT_EQ(inPlace.info().context, first.context) << what;
		pool.push_back(std::move(frame));
	}
	EXPECT_GE(found, 12u);
	EXPECT_EQ(inPlace.info().imports, 4u); /* one import a buffer */
	/* Frames seen again are not imported again. */
	for (int again : { 0, 1 }) {
		inPlace.detector.detect(pool[static_cast<std::size_t>(again)]->view);
		EXPECT_EQ(inPlace.frontEnd->lastCopyBytes(), 0u);
	}
	EXPECT_EQ(inPlace.info().imports, 4u);
	EXPECT_EQ(copied.info().imports, 0u);
}

TEST(ZeroCopyEmu, RecycledFdNumberReadsTheNewBuffer)
{
	QpuDetector qpu("vc4-emu");
	Detector cpu{ Config{} };
	const auto a = scene(21, kW, kH, 4), b = scene(22, kW, kH, 4);
	auto first = std::make_unique<DmabufFrame>(a, kW, kH, kW);
	const int number = first->fd;
	expectSameMarkers(qpu.detector.detect(first->view), cpu.detect(ImageView{ a.data(), kW, kH }), "first buffer");
	first.reset(); /* its fd number is free again */
	DmabufFrame second(b, kW, kH, kW);
	if (second.fd != number) {
		ASSERT_EQ(::dup2(second.fd, number), number);
		::close(second.fd);
		second.fd = second.view.dmabuf_fd = number;
	}
	const Result want = cpu.detect(ImageView{ b.data(), kW, kH });
	ASSERT_GE(want.markers.size(), 3u);
	expectSameMarkers(qpu.detector.detect(second.view), want, "same fd number, another buffer");
	EXPECT_EQ(qpu.frontEnd->lastCopyBytes(), 0u);
	EXPECT_EQ(qpu.info().imports, 2u);
}

TEST(ZeroCopyEmu, UnalignedStrideOrShortBufferIsCopiedWithTheReason)
{
	QpuDetector qpu("vc4-emu");
	Detector cpu{ Config{} };
	const auto pixels = scene(31, kW, kH, 4);
	const Result want = cpu.detect(ImageView{ pixels.data(), kW, kH });
	ASSERT_GE(want.markers.size(), 3u);

	DmabufFrame odd(pixels, kW, kH, kW + 2); /* rows 322 bytes apart: not 4-aligned */
	expectSameMarkers(qpu.detector.detect(odd.view), want, "odd stride");
	EXPECT_EQ(qpu.frontEnd->lastCopyBytes(), static_cast<std::size_t>(kW) * kH);
	EXPECT_NE(vc4::copyReason(*qpu.frontEnd).find("stride (322 bytes)"), std::string_view::npos)
		<< vc4::copyReason(*qpu.frontEnd);

	DmabufFrame shortBuffer(pixels, kW, kH, kW, static_cast<std::size_t>(kW) * (kH - 1));
	expectSameMarkers(qpu.detector.detect(shortBuffer.view), want, "dma-buf shorter than the frame");
	EXPECT_EQ(qpu.frontEnd->lastCopyBytes(), static_cast<std::size_t>(kW) * kH);
	EXPECT_NE(vc4::copyReason(*qpu.frontEnd).find("is smaller than the frame"), std::string_view::npos)
		<< vc4::copyReason(*qpu.frontEnd);

	DmabufFrame aligned(pixels, kW, kH, kW);
	expectSameMarkers(qpu.detector.detect(aligned.view), want, "aligned");
	EXPECT_EQ(qpu.frontEnd->lastCopyBytes(), 0u);
	EXPECT_EQ(vc4::copyReason(*qpu.frontEnd), "");
}

/* frappe::Pipeline's stages on the QPUs: the warp of frame N comes after the front end of
 * frame N+1 (and of N+2 at latency 2), and finds its own staged copy: each system-memory
 * frame copied once, into the one context, even when two buffers take turns at the same
 * addresses with new pixels. */
TEST(ZeroCopyEmu, StagedPipelineCopiesEachFrameOnceAndWarpsItsOwnCopy)
{
	Detector cpu{ Config{} };
	for (int latency : { 1, 2 }) {
		Pipeline pipeline(Config{}, Pipeline::Overlap::Stages, latency);
		vc4::BackendChoice c = vc4::selectFrontEnd("vc4-emu", 1);
		const FrontEnd *frontEnd = c.frontEnd.get();
		pipeline.detector().setFrontEnd(std::move(c.frontEnd));
		pipeline.detector().setWarper(std::move(c.warper));
		const int frames = 6, buffers = latency + 1;
		std::vector<std::vector<std::uint8_t>> memory(static_cast<std::size_t>(buffers));
		std::vector<Result> want;
		std::size_t next = 0, found = 0;
		auto check = [&](const Result *r) {
			ASSERT_NE(r, nullptr);
			const std::string what = "latency " + std::to_string(latency) + " frame " + std::to_string(next);
			expectSameMarkers(*r, want[next], what);
			EXPECT_EQ(r->copy_bytes, static_cast<std::size_t>(kW) * kH) << what;
			found += r->markers.size();
			++next;
		};
		for (int f = 0; f < frames; ++f) {
			/* Buffer f % buffers is free again: its frame has come out. */
			std::vector<std::uint8_t> &m = memory[static_cast<std::size_t>(f % buffers)];
			m = scene(41 + static_cast<unsigned>(f), kW, kH, 4);
			want.push_back(cpu.detect(ImageView{ m.data(), kW, kH }));
			if (const Result *r = pipeline.push(ImageView{ m.data(), kW, kH }))
				check(r);
		}
		while (const Result *r = pipeline.flush())
			check(r);
		EXPECT_EQ(next, static_cast<std::size_t>(frames));
		EXPECT_GE(found, 12u);
		vc4::ContextInfo info;
		ASSERT_TRUE(vc4::contextInfo(*frontEnd, info));
		EXPECT_EQ(info.total_copy_bytes, static_cast<std::uint64_t>(frames) * kW * kH) << "latency " << latency;
	}
}

/* The real GPU's code path against a fake kernel. Its firmware does not run the programs,
 * so what is checked is where the QPUs are told to read and what the host does. */
namespace {

using vc4::runtime::test::FakeOs;

constexpr int kGw = 128, kGh = 64;

/* The fake firmware's execute_qpu, made real: the programs run on the emulator over the
 * fake kernel's memory, every buffer (camera imports included) mapped at its bus address. */
uint32_t executeOnEmulator(FakeOs &os, uint32_t programs, uint32_t control)
{
	vc4::emu::Memory memory(4096);
	for (const auto &[bus, cpu] : os.bus_to_cpu)
		memory.mapExternal({ cpu, static_cast<std::size_t>(os.bus_size.at(bus)) }, true, bus);
	vc4::emu::Config config;
	config.tmu_fifo_limit = 4;
	vc4::emu::V3d v3d(memory, config);
	std::vector<vc4::emu::Job> jobs(programs);
	for (uint32_t i = 0; i < programs; ++i)
		jobs[i] = { memory.read32(control + 8 * i), memory.read32(control + 8 * i + 4) };
	return v3d.launch(jobs).host_interrupts == programs ? 0u : 0x80000000u;
}

struct FakeGpu {
	FakeOs os;
	std::shared_ptr<vc4::QpuContext<vc4::runtime::GpuDevice>> context;
	std::unique_ptr<FrontEnd> frontEnd;
	std::unique_ptr<CandidateWarper> warper;
	std::vector<std::array<Point2f, 4>> quads{ { Point2f{ 20, 10 }, { 60, 12 }, { 58, 50 }, { 22, 48 } } };
	std::vector<CandidateSamples> samples = std::vector<CandidateSamples>(1);
	std::vector<std::uint8_t> ok = std::vector<std::uint8_t>(1);
	EdgeMap edges;

	explicit FakeGpu(bool run_programs = false)
	{
		if (run_programs)
			os.execute = [this](uint32_t n, uint32_t control) { return executeOnEmulator(os, n, control); };
		os.pi();
		os.dmaHeap();
		context = vc4::makeGpuContext(os, {});
		frontEnd = vc4::makeFrontEnd(context);
		warper = vc4::makeWarper(context);
	}
	void frame(const ImageView &image)
	{
		frontEnd->run(image, 1.0f, FrontEndParams{}, edges);
		warper->warp(image, quads, 16, samples, ok);
	}
	/* Whether a launch's first program was given `bus` (a frame row) in its uniforms. */
	bool uniformsName(std::size_t launch, uint32_t lo, uint32_t hi, std::size_t words) const
	{
		const uint8_t *u = os.cpuOf(os.control_blocks.at(launch).at(0));
		if (!u)
			return false;
		for (std::size_t i = 0; i < words; ++i) {
			uint32_t w;
			std::memcpy(&w, u + 4 * i, 4);
			if (w >= lo && w < hi)
				return true;
		}
		return false;
	}
	std::size_t count(const std::string &part) const
	{
		return static_cast<std::size_t>(std::count_if(os.log.begin(), os.log.end(),
							       [&](const std::string &l) { return l.find(part) != std::string::npos; }));
	}
};

} // namespace

TEST(ZeroCopyGpu, CameraBuffersImportedOnceReadInPlaceNothingCopied)
{
	FakeGpu gpu;
	/* One device: the probe's trial and one device's opening of vcsm-cma, not two devices'. */
	EXPECT_EQ(gpu.count("open /dev/vcsm-cma"), 2u);
	EXPECT_EQ(gpu.count("open /dev/vcio"), 1u);
	int fds[3];
	for (int i = 0; i < 3; ++i) {
		fds[i] = gpu.os.cameraBuffer("cam" + std::to_string(i), kGw * kGh, 700 + i);
		std::memset(gpu.os.cpu("cam" + std::to_string(i)), 40 * i, kGw * kGh);
	}
	gpu.os.log.clear();
	for (int f = 0; f < 9; ++f) {
		ImageView image{ gpu.os.cpu("cam" + std::to_string(f % 3)), kGw, kGh, kGw };
		image.dmabuf_fd = fds[f % 3];
		const std::size_t launches = gpu.os.control_blocks.size();
		gpu.frame(image);
		EXPECT_EQ(gpu.frontEnd->lastCopyBytes(), 0u) << "frame " << f;
		EXPECT_EQ(vc4::copyReason(*gpu.frontEnd), "");
		/* Pass 1, pass 2 and the warp: pass 1's row addresses and the warp's image lie in
		 * the camera buffer's import. */
		ASSERT_EQ(gpu.os.control_blocks.size(), launches + 3);
		const uint32_t bus = gpu.context->device().importDmabuf(fds[f % 3]).bus;
		EXPECT_TRUE(gpu.uniformsName(launches, bus, bus + kGw * kGh, 300)) << "frame " << f;
		EXPECT_TRUE(gpu.uniformsName(launches + 2, bus, bus + 1, 8)) << "frame " << f;
	}
	EXPECT_EQ(gpu.count("name=vc4-frame"), 3u); /* one vcsm-cma import a buffer over 9 frames */
	EXPECT_EQ(gpu.count("dup cam"), 3u);
	/* Each of the 3 launches a frame writes back (END) every frame imported so far before
	 * and invalidates it (START) after: 1, 2, then 3 buffers; START once more at import. */
	EXPECT_EQ(gpu.count("sync cam0 0x00000007") + gpu.count("sync cam1 0x00000007") + gpu.count("sync cam2 0x00000007"),
		  3u * (1 + 2 + 3 * 7));
	EXPECT_EQ(gpu.count("sync cam0 0x00000003") + gpu.count("sync cam1 0x00000003") + gpu.count("sync cam2 0x00000003"),
		  3u * (1 + 2 + 3 * 7) + 3);
	gpu.warper.reset();
	gpu.frontEnd.reset();
	gpu.context.reset();
	/* The device gone: its imports and dups closed; the camera's own fds stay open. */
	EXPECT_EQ(gpu.os.open_fds.size(), 3u);
	EXPECT_EQ(gpu.count("close import-of-cam"), 3u);
}

TEST(ZeroCopyGpu, SystemMemoryUnalignedStrideAndRefusedImportAreCopiedOnce)
{
	FakeGpu gpu;
	std::vector<std::uint8_t> pixels(static_cast<std::size_t>(kGw + 2) * kGh, 90);
	gpu.frame(ImageView{ pixels.data(), kGw, kGh, kGw });
	EXPECT_EQ(gpu.frontEnd->lastCopyBytes(), static_cast<std::size_t>(kGw) * kGh); /* front end and warp: one copy */
	EXPECT_NE(vc4::copyReason(*gpu.frontEnd).find("system memory"), std::string_view::npos);

	const int odd = gpu.os.cameraBuffer("odd", (kGw + 2) * kGh, 800);
	ImageView image{ pixels.data(), kGw, kGh, kGw + 2 };
	image.dmabuf_fd = odd;
	gpu.frame(image);
	EXPECT_EQ(gpu.frontEnd->lastCopyBytes(), static_cast<std::size_t>(kGw) * kGh);
	EXPECT_NE(vc4::copyReason(*gpu.frontEnd).find("stride (130 bytes)"), std::string_view::npos);

	const int refused = gpu.os.cameraBuffer("scattered", kGw * kGh, 801);
	gpu.os.refuse_import.insert("scattered");
	image = ImageView{ pixels.data(), kGw, kGh, kGw };
	image.dmabuf_fd = refused;
	gpu.frame(image);
	EXPECT_EQ(gpu.frontEnd->lastCopyBytes(), static_cast<std::size_t>(kGw) * kGh);
	const std::string_view why = vc4::copyReason(*gpu.frontEnd);
	EXPECT_NE(why.find("could not be imported"), std::string_view::npos) << why;
	EXPECT_NE(why.find("refused to import"), std::string_view::npos) << why;
	EXPECT_EQ(gpu.context->imports(), 0u);
	gpu.frame(image); /* the refusal is remembered: no second import ioctl */
	EXPECT_EQ(gpu.frontEnd->lastCopyBytes(), static_cast<std::size_t>(kGw) * kGh);
	EXPECT_EQ(gpu.count("scattered refused"), 1u);
	/* The warper alone (the front end ran on the CPU or not at all) copies the frame itself. */
	gpu.warper->warp(ImageView{ pixels.data(), kGw, kGh, kGw }, gpu.quads, 16, gpu.samples, gpu.ok);
	EXPECT_EQ(gpu.frontEnd->lastCopyBytes(), 2u * kGw * kGh);
}

TEST(ZeroCopyGpu, ProgramsOnTheFakeFirmwareReadTheCameraBufferInPlace)
{
	FakeGpu gpu(true);
	const int fd = gpu.os.cameraBuffer("cam", kGw * kGh, 900);
	uint8_t *pixels = gpu.os.cpu("cam");
	ImageView image{ pixels, kGw, kGh, kGw };
	image.dmabuf_fd = fd;
	const FrontEndParams params = Detector(Config{}).frontEndParams();
	auto cpu = makeCpuFrontEnd(1);
	auto emuWarper = vc4::makeWarper(vc4::FrontEndOptions{ .emulate = true });
	for (unsigned f = 0; f < 2; ++f) {
		/* The camera writes a new frame into the same buffer: the cached import reads it. */
		const auto frame = scene(40 + f, kGw, kGh, 1);
		std::memcpy(pixels, frame.data(), frame.size());
		EdgeMap want;
		cpu->run(image, 1.0f, params, want);
		gpu.frontEnd->run(image, 1.0f, params, gpu.edges);
		EXPECT_EQ(gpu.frontEnd->lastCopyBytes(), 0u);
		ASSERT_EQ(gpu.edges.pixels.size(), want.pixels.size());
		EXPECT_TRUE(gpu.edges.pixels == want.pixels) << "frame " << f << ": edge bytes differ from the CPU's";
		EXPECT_TRUE(gpu.edges.tiles == want.tiles) << "frame " << f << ": tile mask differs from the CPU's";
		EXPECT_GT(std::count(want.pixels.begin(), want.pixels.end(), 0), 0);
		EXPECT_LT(std::count(want.pixels.begin(), want.pixels.end(), 0), static_cast<long>(want.pixels.size()));

		std::vector<CandidateSamples> ref(1);
		std::vector<std::uint8_t> refOk(1);
		emuWarper->warp(image, gpu.quads, 16, ref, refOk);
		gpu.warper->warp(image, gpu.quads, 16, gpu.samples, gpu.ok);
		ASSERT_TRUE(gpu.ok[0] && refOk[0]);
		EXPECT_TRUE(gpu.samples[0].samples == ref[0].samples) << "frame " << f << ": warp samples differ";
		EXPECT_EQ(gpu.frontEnd->lastCopyBytes(), 0u);
	}
	EXPECT_EQ(gpu.count("name=vc4-frame"), 1u);
	gpu.os.close(fd);
}
