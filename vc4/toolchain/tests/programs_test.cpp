// SPDX-License-Identifier: MIT
// Small programs on the emulator compared with plain C++: TMU direct loads (section 4,
// "general memory lookups"), VPM generic blocks (section 7, Tables 32/33), VDR/VDW with
// strides (Tables 34-37), texture fetch with bilinear filtering (section 4), the mutex
// and semaphores (section 3), 12 QPUs under round-robin and seeded random schedules.
#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <cmath>
#include <numeric>

#include "asm/assembler.hpp"
#include "emu/device.hpp"
#include "emu/tmu.hpp"
#include "emu/v3d.hpp"
#include "isa/setup_words.hpp"
#include "samples/samples.hpp"

using namespace frappe::vc4;

namespace {

struct Machine {
	explicit Machine(emu::Config c = {}) : v3d(memory, c) {}
	emu::Memory memory;
	emu::V3d v3d;
};

std::vector<uint32_t> readWords(emu::Memory &m, uint32_t address, size_t n)
{
	std::vector<uint32_t> out(n);
	for (size_t i = 0; i < n; ++i)
		out[i] = m.read32(address + static_cast<uint32_t>(4 * i));
	return out;
}

} // namespace

TEST(Programs, VectorSumOnOneQpu)
{
	Machine m;
	const auto program = samples::vectorSum();
	std::vector<uint32_t> a(64), b(64);
	for (uint32_t i = 0; i < 64; ++i) {
		a[i] = i * 7 + 3;
		b[i] = 1000 - i * i;
	}
	const uint32_t pa = m.memory.load(a), pb = m.memory.load(b), out = m.memory.alloc(256);
	const uint32_t code = m.memory.load(program.code);
	const emu::Job job{m.memory.load(std::vector<uint32_t>{pa, pb, out, 4}), code};
	const auto stats = m.v3d.launch(std::span(&job, 1));
	const auto result = readWords(m.memory, out, 64);
	for (size_t i = 0; i < 64; ++i)
		EXPECT_EQ(result[i], a[i] + b[i]) << i;
	// Issue model: 4 cycles per instruction plus the modelled TMU and DMA stalls.
	EXPECT_EQ(stats.qpus[0].cycles, 4 * stats.qpus[0].instructions + stats.qpus[0].stall_cycles);
	EXPECT_GT(stats.qpus[0].stall_cycles, 0u);
}

TEST(Programs, LaneReductionSumsSixteenLanes)
{
	Machine m;
	std::vector<uint32_t> in(16);
	for (uint32_t i = 0; i < 16; ++i)
		in[i] = i * i + 5;
	const uint32_t pin = m.memory.load(in), out = m.memory.alloc(64);
	const uint32_t code = m.memory.load(samples::laneReduction().code);
	const emu::Job job{m.memory.load(std::vector<uint32_t>{pin, out}), code};
	m.v3d.launch(std::span(&job, 1));
	const uint32_t expected = std::accumulate(in.begin(), in.end(), 0u);
	for (uint32_t v : readWords(m.memory, out, 16))
		EXPECT_EQ(v, expected);
}

TEST(Programs, TileCopyThroughVdrVpmVdw)
{
	// A 128x32 8-bit image; the 64x16 tile at (32, 8) goes to a 96-byte-pitch image at (16, 4).
	Machine m;
	const uint32_t src_pitch = 128, dst_pitch = 96;
	const uint32_t src = m.memory.alloc(src_pitch * 32), dst = m.memory.alloc(dst_pitch * 24);
	auto s = m.memory.bytes(src, src_pitch * 32);
	for (uint32_t i = 0; i < s.size(); ++i)
		s[i] = static_cast<uint8_t>((i * 37 + i / 128) & 255);
	const uint32_t tile_src = src + 8 * src_pitch + 32, tile_dst = dst + 4 * dst_pitch + 16;
	const uint32_t code = m.memory.load(samples::tileCopy().code);
	const emu::Job job{m.memory.load(std::vector<uint32_t>{tile_src, tile_dst, src_pitch, dst_pitch}), code};
	m.v3d.launch(std::span(&job, 1));
	auto d = m.memory.bytes(dst, dst_pitch * 24);
	for (uint32_t y = 0; y < 24; ++y)
		for (uint32_t x = 0; x < dst_pitch; ++x) {
			const bool inside = y >= 4 && y < 20 && x >= 16 && x < 80;
			const uint8_t want = inside ? static_cast<uint8_t>(std::min(
			                                  255, s[(y - 4 + 8) * src_pitch + (x - 16 + 32)] + 1))
			                            : 0;
			ASSERT_EQ(d[y * dst_pitch + x], want) << x << "," << y;
		}
}

TEST(Programs, TextureFetchBilinearAndNearest)
{
	for (bool nearest : {false, true}) {
		Machine m;
		const uint32_t tex = m.memory.alloc(4 * 4 * 4);
		for (uint32_t i = 0; i < 16; ++i)
			m.memory.write32(tex + 4 * i, 0x01010101u * (i * 16) | 0xff000000u);
		std::vector<uint32_t> s(16), t(16);
		for (uint32_t i = 0; i < 16; ++i) {
			s[i] = std::bit_cast<uint32_t>(0.1f + 0.05f * static_cast<float>(i));
			t[i] = std::bit_cast<uint32_t>(0.9f - 0.04f * static_cast<float>(i));
		}
		const uint32_t ps = m.memory.load(s), pt = m.memory.load(t), out = m.memory.alloc(64);
		const isa::TexP1 p1{.type = isa::TextureType::Rgba32Raster, .height = 4, .width = 4,
		                    .mag_nearest = nearest, .min_filter = 0,
		                    .wrap_t = isa::TextureWrap::Clamp, .wrap_s = isa::TextureWrap::Clamp};
		const isa::TexP0 p0{.base = tex, .type = isa::TextureType::Rgba32Raster};
		const uint32_t code = m.memory.load(samples::textureFetch().code);
		const emu::Job job{m.memory.load(std::vector<uint32_t>{ps, pt, p0.word(), p1.word(), out}), code};
		m.v3d.launch(std::span(&job, 1));
		const auto result = readWords(m.memory, out, 16);
		for (uint32_t i = 0; i < 16; ++i) {
			// Plain C++ reference: texel centres at (i + 0.5) / 4, 8-bit weights.
			const float u = std::bit_cast<float>(s[i]) * 4, v = std::bit_cast<float>(t[i]) * 4;
			auto texel = [&](int x, int y) {
				x = std::clamp(x, 0, 3);
				y = std::clamp(y, 0, 3);
				return static_cast<uint32_t>(y * 4 + x) * 16;
			};
			uint32_t grey;
			if (nearest) {
				grey = texel(static_cast<int>(u), static_cast<int>(v));
			} else {
				const float uc = u - 0.5f, vc = v - 0.5f;
				const int x0 = static_cast<int>(std::floor(uc)), y0 = static_cast<int>(std::floor(vc));
				const auto fx = static_cast<uint32_t>((uc - static_cast<float>(x0)) * 256);
				const auto fy = static_cast<uint32_t>((vc - static_cast<float>(y0)) * 256);
				const uint32_t top = texel(x0, y0) * (256 - fx) + texel(x0 + 1, y0) * fx;
				const uint32_t bottom = texel(x0, y0 + 1) * (256 - fx) + texel(x0 + 1, y0 + 1) * fx;
				grey = (top * (256 - fy) + bottom * fy + 32768) >> 16;
			}
			EXPECT_EQ(result[i] & 0xffffffu, 0x010101u * grey) << i << (nearest ? " nearest" : " bilinear");
			EXPECT_EQ(result[i] >> 24, 0xffu);
		}
	}
}

TEST(Programs, BilinearPrecisionIsAParameter)
{
	emu::Memory mem;
	const uint32_t tex = mem.alloc(16);
	mem.write32(tex, 0);
	mem.write32(tex + 4, 255);
	emu::TextureConfig c;
	c.base = tex;
	c.width = 2;
	c.height = 1;
	// s = 0.5 + 1/3 texel: weight 1/3 truncated to 2 bits (1/4) or 8 bits (85/256).
	const float s = (0.5f + 1.0f / 3.0f) / 2.0f;
	EXPECT_EQ(emu::sampleTexture(mem, c, s, 0.5f, 2), 64u);
	EXPECT_EQ(emu::sampleTexture(mem, c, s, 0.5f, 8), 85u);
}

TEST(Programs, TwelveQpusVectorSumUnderEverySchedule)
{
	const auto program = samples::vectorSum();
	for (int seed = -1; seed < 8; ++seed) {
		Machine m;
		std::vector<uint32_t> a(12 * 32), b(12 * 32);
		for (uint32_t i = 0; i < a.size(); ++i) {
			a[i] = i * 3;
			b[i] = 0x10000 + i;
		}
		const uint32_t pa = m.memory.load(a), pb = m.memory.load(b), out = m.memory.alloc(12 * 128);
		const uint32_t code = m.memory.load(program.code);
		std::vector<emu::Job> jobs;
		for (uint32_t q = 0; q < 12; ++q)
			jobs.push_back({m.memory.load(std::vector<uint32_t>{pa + 128 * q, pb + 128 * q, out + 128 * q, 2}), code});
		emu::LaunchOptions options;
		if (seed >= 0)
			options = {emu::Schedule::Random, static_cast<uint64_t>(seed)};
		const auto stats = m.v3d.launch(jobs, options);
		const auto result = readWords(m.memory, out, a.size());
		for (size_t i = 0; i < a.size(); ++i)
			ASSERT_EQ(result[i], a[i] + b[i]) << "seed " << seed << " word " << i;
		ASSERT_EQ(stats.qpus.size(), 12u);
		for (const auto &q : stats.qpus)
			EXPECT_EQ(q.instructions, stats.qpus[0].instructions);
		EXPECT_EQ(stats.instructions, 12 * stats.qpus[0].instructions);
	}
}

TEST(Programs, SemaphoreGatherWaitsForEveryWorker)
{
	for (int seed = -1; seed < 16; ++seed) {
		Machine m;
		const uint32_t out = m.memory.alloc(12 * 64);
		const uint32_t code = m.memory.load(samples::semaphoreGather().code);
		const uint32_t unif = m.memory.load(std::vector<uint32_t>{out, 12});
		std::vector<emu::Job> jobs(12, emu::Job{unif, code});
		emu::LaunchOptions options;
		if (seed >= 0)
			options = {emu::Schedule::Random, static_cast<uint64_t>(seed)};
		m.v3d.launch(jobs, options);
		uint32_t expected = 0;
		for (uint32_t q = 1; q < 12; ++q)
			expected += 100 + q;
		ASSERT_EQ(m.memory.read32(out), expected) << "seed " << seed;
		EXPECT_EQ(m.v3d.semaphore(0), 0u);
	}
}

TEST(Programs, RoundRobinIsDeterministicAndRandomIsSeeded)
{
	auto cycles = [](emu::LaunchOptions o) {
		Machine m;
		const uint32_t out = m.memory.alloc(12 * 64);
		const uint32_t code = m.memory.load(samples::semaphoreGather().code);
		const uint32_t unif = m.memory.load(std::vector<uint32_t>{out, 12});
		std::vector<emu::Job> jobs(12, emu::Job{unif, code});
		const auto s = m.v3d.launch(jobs, o);
		std::vector<uint64_t> per;
		for (const auto &q : s.qpus)
			per.push_back(q.cycles);
		return per;
	};
	EXPECT_EQ(cycles({}), cycles({}));
	EXPECT_EQ(cycles({emu::Schedule::Random, 3}), cycles({emu::Schedule::Random, 3}));
}

TEST(Programs, DeadlockIsReported)
{
	// A lone QPU acquiring a semaphore nobody releases.
	Machine m;
	qasm::Assembler a;
	a.semaphoreAcquire(2);
	a.thrend();
	const uint32_t code = m.memory.load(a.finish().code);
	const emu::Job job{m.memory.load(std::vector<uint32_t>{}), code};
	EXPECT_THROW(m.v3d.launch(std::span(&job, 1)), emu::Fault);
}

TEST(Programs, VpmReadSetupsCannotBeQueued)
{
	// Addendum, section 7: a second read setup while more than one read is outstanding
	// is ignored by the hardware; strict mode reports it.
	Machine m;
	qasm::Assembler a;
	const uint32_t two = isa::VpmReadSetup{.num = 2, .stride = 1, .horizontal = true, .laned = false,
	                                       .size = isa::VpmSize::Bits32, .addr = 0}.word();
	a.ldi(qasm::reg::vr_setup, two);
	a.ldi(qasm::reg::vr_setup, two);
	a.thrend();
	const uint32_t code = m.memory.load(a.finish().code);
	const emu::Job job{m.memory.load(std::vector<uint32_t>{}), code};
	EXPECT_THROW(m.v3d.launch(std::span(&job, 1)), emu::Fault);
}

TEST(Device, LaunchAndWaitLikeTheRuntime)
{
	emu::Device dev;
	const auto code = dev.upload(samples::laneReduction().code);
	auto in = dev.alloc(64), out = dev.alloc(64);
	for (uint32_t i = 0; i < 16; ++i)
		std::memcpy(&in.cpu[4 * i], &i, 4);
	const auto unif = dev.upload(std::vector<uint32_t>{in.bus, out.bus});
	const emu::Job job{unif.bus, code.bus};
	const auto fence = dev.launch(std::span(&job, 1));
	const auto stats = dev.wait(fence);
	EXPECT_EQ(stats.qpus.size(), 1u);
	uint32_t first;
	std::memcpy(&first, out.cpu.data(), 4);
	EXPECT_EQ(first, 120u); // 0 + 1 + ... + 15
	EXPECT_THROW(dev.wait(fence), std::invalid_argument);
}

TEST(Texture, TFormatAddressing)
{
	// 64x64 RGBA8888: 4x4-texel microtiles, 1 KiB subtiles ordered (0, 3, 1, 2) on even
	// 4 KiB tile rows and (2, 1, 3, 0) on odd ones, odd tile rows right to left.
	emu::TextureConfig t;
	t.type = 0;
	t.width = t.height = 64;
	EXPECT_EQ(emu::texelOffset(t, 0, 0), 0u);
	EXPECT_EQ(emu::texelOffset(t, 1, 0), 4u);
	EXPECT_EQ(emu::texelOffset(t, 0, 1), 16u);
	EXPECT_EQ(emu::texelOffset(t, 4, 0), 64u);
	EXPECT_EQ(emu::texelOffset(t, 0, 4), 256u);
	EXPECT_EQ(emu::texelOffset(t, 16, 0), 3072u);
	EXPECT_EQ(emu::texelOffset(t, 0, 16), 1024u);
	EXPECT_EQ(emu::texelOffset(t, 16, 16), 2048u);
	EXPECT_EQ(emu::texelOffset(t, 32, 0), 4096u);
	EXPECT_EQ(emu::texelOffset(t, 0, 32), 12288u + 2048u);
	EXPECT_EQ(emu::texelOffset(t, 32, 32), 8192u + 2048u);
}

TEST(Texture, LtFormatAndLuminance)
{
	// 16x16 LUMINANCE is LT (not wider than 4 microtiles of 8x8): microtiles in raster order.
	emu::TextureConfig t;
	t.type = 5;
	t.width = t.height = 16;
	EXPECT_EQ(emu::texelOffset(t, 9, 0), 64u + 1u);
	EXPECT_EQ(emu::texelOffset(t, 0, 9), 128u + 8u);
	emu::Memory mem;
	t.base = mem.alloc(256);
	mem.bytes(t.base + 129, 1)[0] = 200; // texel (1, 8)
	t.mag_nearest = true;
	EXPECT_EQ(emu::sampleTexture(mem, t, 1.5f / 16, 8.5f / 16, 8), 0xffc8c8c8u);
}
