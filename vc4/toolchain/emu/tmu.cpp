// SPDX-License-Identifier: MIT
#include "emu/tmu.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace frappe::vc4::emu {

TextureConfig TextureConfig::fromUniforms(uint32_t p0, uint32_t p1)
{
	TextureConfig c;
	c.base = p0 & 0xfffff000u;
	c.type = ((p0 >> 4) & 15) | (((p1 >> 31) & 1) << 4);
	c.height = (p1 >> 20) & 0x7ff;
	c.width = (p1 >> 8) & 0x7ff;
	if (c.height == 0)
		c.height = 2048;
	if (c.width == 0)
		c.width = 2048;
	c.mag_nearest = (p1 >> 7) & 1;
	c.wrap_t = (p1 >> 2) & 3;
	c.wrap_s = p1 & 3;
	return c;
}

namespace {

// Wrap modes of P1 (vc4_packet.h: 0 repeat, 1 clamp, 2 mirror, 3 border).
int wrap(int i, int size, unsigned mode, bool &border)
{
	switch (mode) {
	case 0:
		return ((i % size) + size) % size;
	case 2: {
		const int period = 2 * size;
		int m = ((i % period) + period) % period;
		return m < size ? m : period - 1 - m;
	}
	case 3:
		if (i < 0 || i >= size)
			border = true;
		return std::clamp(i, 0, size - 1);
	default:
		return std::clamp(i, 0, size - 1);
	}
}

unsigned bytesPerTexel(unsigned type)
{
	switch (type) {
	case 0: case 1: case 16: return 4; // RGBA8888, RGBX8888, RGBA32R
	case 5: case 6: return 1;          // LUMINANCE, ALPHA
	default:
		throw std::runtime_error("texture type " + std::to_string(type) + " is not modelled");
	}
}

uint32_t texel(const Memory &memory, const TextureConfig &tex, int x, int y)
{
	bool border = false;
	const int wx = wrap(x, static_cast<int>(tex.width), tex.wrap_s, border);
	const int wy = wrap(y, static_cast<int>(tex.height), tex.wrap_t, border);
	if (border)
		return 0; // border colour (P3) is not modelled: transparent black
	const uint32_t address = tex.base + texelOffset(tex, static_cast<unsigned>(wx), static_cast<unsigned>(wy));
	switch (tex.type) {
	case 1: return memory.read32(address) | 0xff000000u;
	case 5: return (memory.read32(address & ~3u) >> (8 * (address & 3)) & 255) * 0x010101u | 0xff000000u;
	case 6: return (memory.read32(address & ~3u) >> (8 * (address & 3)) & 255) << 24;
	default: return memory.read32(address);
	}
}

} // namespace

uint32_t texelOffset(const TextureConfig &tex, unsigned x, unsigned y)
{
	const unsigned cpp = bytesPerTexel(tex.type);
	if (tex.type == 16)
		return (y * tex.width + x) * 4;
	const unsigned utile_w = cpp == 1 ? 8 : 4, utile_h = cpp == 1 ? 8 : 4;
	const unsigned ux = x / utile_w, uy = y / utile_h;
	const unsigned inside = (y % utile_h) * utile_w * cpp + (x % utile_w) * cpp;
	unsigned utiles_per_row = (tex.width + utile_w - 1) / utile_w;
	if (tex.width <= 4 * utile_w || tex.height <= 4 * utile_h) // LT
		return (uy * utiles_per_row + ux) * 64 + inside;
	utiles_per_row = (utiles_per_row + 7) / 8 * 8;
	const unsigned tiles_per_row = utiles_per_row / 8;
	const unsigned tile_y = uy / 8;
	unsigned tile_x = ux / 8;
	const bool odd = tile_y & 1;
	if (odd)
		tile_x = tiles_per_row - 1 - tile_x; // odd tile rows run right to left
	const unsigned subtile = ((uy / 4) & 1) * 2 + ((ux / 4) & 1);
	static constexpr unsigned even_order[4] = {0, 3, 1, 2};
	static constexpr unsigned odd_order[4] = {2, 1, 3, 0};
	return 4096 * (tile_y * tiles_per_row + tile_x) +
	       1024 * (odd ? odd_order[subtile] : even_order[subtile]) +
	       64 * ((uy & 3) * 4 + (ux & 3)) + inside;
}

uint32_t sampleTexture(const Memory &memory, const TextureConfig &tex, float s, float t,
                       unsigned fraction_bits)
{
	bytesPerTexel(tex.type); // rejects types that are not modelled
	const float u = s * static_cast<float>(tex.width);
	const float v = t * static_cast<float>(tex.height);
	if (tex.mag_nearest)
		return texel(memory, tex, static_cast<int>(std::floor(u)), static_cast<int>(std::floor(v)));
	const float uc = u - 0.5f, vc = v - 0.5f;
	const int x0 = static_cast<int>(std::floor(uc)), y0 = static_cast<int>(std::floor(vc));
	const uint32_t one = 1u << fraction_bits;
	const auto fx = static_cast<uint32_t>((uc - static_cast<float>(x0)) * static_cast<float>(one));
	const auto fy = static_cast<uint32_t>((vc - static_cast<float>(y0)) * static_cast<float>(one));
	const uint32_t c00 = texel(memory, tex, x0, y0), c10 = texel(memory, tex, x0 + 1, y0);
	const uint32_t c01 = texel(memory, tex, x0, y0 + 1), c11 = texel(memory, tex, x0 + 1, y0 + 1);
	uint32_t out = 0;
	for (unsigned ch = 0; ch < 32; ch += 8) {
		auto c = [ch](uint32_t p) { return uint64_t{(p >> ch) & 255}; };
		const uint64_t top = c(c00) * (one - fx) + c(c10) * fx;
		const uint64_t bottom = c(c01) * (one - fx) + c(c11) * fx;
		const uint64_t sum = top * (one - fy) + bottom * fy;
		const uint64_t rounded = (sum + (uint64_t{1} << (2 * fraction_bits - 1))) >> (2 * fraction_bits);
		out |= static_cast<uint32_t>(std::min<uint64_t>(rounded, 255)) << ch;
	}
	return out;
}

} // namespace frappe::vc4::emu
