// SPDX-License-Identifier: MIT
// The region map's two QPU launches (kernels/pass_region.cpp) for the VC4 front end: its
// device buffers, sized with the frame, its uniform streams, and the map read back into
// EdgeMap::regions, byte for byte frappe-core's (front_end_cpu.cpp).
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "frappe/edge_map.h"
#include "frontend/vc4_front_end.hpp"
#include "isa/setup_words.hpp"
#include "kernels/kernels.hpp"

namespace frappe::vc4 {

/// Where the QPUs read the frame (4-aligned rows) and how it is scaled, as pass 1 does.
struct RegionSource {
	uint32_t bus = 0;    ///< row 0
	uint32_t stride = 0; ///< bytes, a multiple of 4
	int width = 0, height = 0;
	uint32_t step_x = 0, step_y = 0; ///< scaleNearest's 16.16 steps
};

template <class Device>
class RegionPass {
public:
	using Buffer = typename Device::Buffer;
	static constexpr unsigned kPrograms = 12;

	RegionPass()
	{
		programs_[0] = kernels::regionMeansPass().program;
		programs_[1] = kernels::regionDarkPass().program;
	}

	/// Whether a scaled w x h frame has a region map (frappe-core's makesRegionMap).
	static bool makesMap(int width, int height, int contrast)
	{
		return contrast > 0 && width / 2 >= 3 && height / 2 >= 3;
	}

	/// Buffers for a scaled width x height frame (the code is uploaded once: the
	/// detector's device lives as long as the front end).
	void allocate(Device &device, int width, int height)
	{
		for (int pass = 0; pass < 2; ++pass)
			if (!code_[pass].bus)
				code_[pass] = device.upload(programs_[pass].code);
		layout_ = Layout(width, height);
		if (!makesMap(width, height, 1))
			return;
		buffer_ = device.alloc(layout_.bufferBytes());
		out_ = device.alloc(layout_.outBytes());
		mask_ = device.alloc(layout_.maskBytes());
		for (int pass = 0; pass < 2; ++pass)
			for (auto &u : unif_[pass])
				u = device.alloc(layout_.unifBytes(pass), 64);
	}

	/// Gives the data buffers back before the geometry changes.
	void release(Device &device)
	{
		for (Buffer *b : {&buffer_, &out_, &mask_})
			if (b->bus)
				device.release(*b);
		for (auto &pass : unif_)
			for (Buffer &b : pass)
				if (b.bus)
					device.release(b);
		buffer_ = out_ = mask_ = {};
		for (auto &pass : unif_)
			std::fill(std::begin(pass), std::end(pass), Buffer{});
	}

	/// Both launches over the allocated geometry, `launch(code, uniforms, programs, counts)`
	/// running one; then out = the region map at scale / 2 (empty when there is none).
	template <class Launch>
	void run(const RegionSource &src, const FrontEndParams &params, float scale, Launch &&launch,
	         PassCounts counts[2], TraceMap &out)
	{
		const Layout &l = layout_;
		const int contrast = params.region_contrast;
		if (!makesMap(l.width, l.height, contrast)) {
			out.resize(0, 0);
			counts[0] = counts[1] = {};
			return;
		}
		const int w = l.width / 2, h = l.height / 2;
		const uint32_t pitch = l.pitch(), blocks = l.blocks();
		const uint32_t stride = isa::VdwStride{.stride = static_cast<uint16_t>(pitch - 64)}.word();
		const unsigned programs = std::min(kPrograms, blocks);
		for (unsigned p = 0; p < programs; ++p) {
			uint8_t *u1 = unif_[0][p].cpu.data(), *u2 = unif_[1][p].cpu.data();
			for (unsigned b = p; b < blocks; b += kPrograms) {
				const uint32_t x0 = b % l.blocksX() * kernels::kRegionBlockW;
				const uint32_t y0 = b / l.blocksX() * kernels::kRegionBlockH;
				const uint32_t more = b + kPrograms < blocks;
				const kernels::RegionMeansUniforms m{
					static_cast<uint32_t>(src.width - 1), src.step_x, static_cast<uint32_t>(w - 1), x0,
					buffer_.bus + 5 * (y0 / 4) * pitch + x0, stride, 5 * pitch};
				uint32_t rows[kernels::kRegionSourceRows];
				kernels::regionSourceRows(rows, src.bus, src.stride, src.height, src.step_y, h, static_cast<int>(y0));
				u1 = put(put(put(u1, m), rows), more);
				const kernels::RegionDarkUniforms d{
					contrastWord(contrast), floor2(params), x0, static_cast<uint32_t>((w + 3) / 4 - 1),
					static_cast<uint32_t>(w - 2), out_.bus + y0 * pitch + x0, stride, 4 * pitch,
					mask_.bus + 64 * b};
				uint32_t tileRows[kernels::kRegionTileRows];
				kernels::regionTileRows(tileRows, buffer_.bus, pitch, h, static_cast<int>(y0));
				u2 = put(put(put(u2, d), tileRows), more);
			}
		}
		for (int pass = 0; pass < 2; ++pass) {
			uint32_t unif[kPrograms];
			for (unsigned p = 0; p < programs; ++p)
				unif[p] = unif_[pass][p].bus;
			counts[pass].tiles = blocks;
			launch(code_[pass].bus, unif, programs, counts[pass]);
		}

		out.resize(w, h);
		out.scale = scale / 2.0f;
		for (int y = 0; y < h; ++y)
			std::memcpy(out.pixels.data() + static_cast<size_t>(y) * w, out_.cpu.data() + static_cast<size_t>(y) * pitch,
			            static_cast<size_t>(w));
		for (unsigned b = 0; b < blocks; ++b) {
			uint32_t words[16];
			std::memcpy(words, mask_.cpu.data() + 64 * b, sizeof(words));
			const int by = static_cast<int>(b / l.blocksX());
			for (int t = 0; t < 4; ++t) {
				const int bx = static_cast<int>(b % l.blocksX()) * 4 + t;
				if (bx < out.tiles_x)
					out.tiles[static_cast<size_t>(by) * out.tiles_x + bx] =
						(words[4 * t] | words[4 * t + 1] | words[4 * t + 2] | words[4 * t + 3]) != 0;
			}
		}
	}

private:
	// The contrast within the kernel's 24-bit multiply: from 65281 on, any tile with
	// lo + hi + 2 floor > 0 needs hi - lo > 255 either way, and one with 0 needs 0.
	static uint32_t contrastWord(int contrast) { return static_cast<uint32_t>(std::min(contrast, 65536)); }
	// 2 floor, the floor capped at 128 (the sum is capped at 256 either way; >= 0: the
	// front end keeps negative floors on the CPU).
	static uint32_t floor2(const FrontEndParams &params)
	{
		return 2u * static_cast<uint32_t>(std::clamp(params.light_floor, 0, FrontEndParams::kLightReference));
	}

	// Sizes for a scaled width x height frame (map: width / 2 x height / 2).
	struct Layout {
		int width = 0, height = 0;
		Layout() = default;
		Layout(int w, int h) : width(w), height(h) {}
		uint32_t pitch() const { return (static_cast<uint32_t>(width / 2) + 63) / 64 * 64; }
		uint32_t blocksX() const { return pitch() / kernels::kRegionBlockW; }
		uint32_t blocksY() const { return (static_cast<uint32_t>(height / 2) + 15) / 16; }
		uint32_t blocks() const { return blocksX() * blocksY(); }
		uint32_t bufferBytes() const { return 5 * 4 * blocksY() * pitch(); }
		uint32_t outBytes() const { return 16 * blocksY() * pitch(); }
		uint32_t maskBytes() const { return 64 * blocks(); }
		uint32_t unifBytes(int pass) const
		{
			const uint32_t per = pass ? kernels::kRegionDarkUniforms + kernels::kRegionTileRows
			                          : kernels::kRegionMeansUniforms + kernels::kRegionSourceRows;
			return 4 * (per + 1) * ((blocks() + kPrograms - 1) / kPrograms);
		}
	};

	template <class T>
	static uint8_t *put(uint8_t *at, const T &block)
	{
		std::memcpy(at, &block, sizeof(block));
		return at + sizeof(block);
	}

	qasm::Program programs_[2];
	Buffer code_[2]{}, buffer_{}, out_{}, mask_{};
	Buffer unif_[2][kPrograms]{};
	Layout layout_;
};

} // namespace frappe::vc4
