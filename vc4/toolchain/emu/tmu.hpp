// SPDX-License-Identifier: MIT
// Texture fetch of the TMU (reference guide section 4): raster RGBA32 and T/LT-tiled
// RGBA8888, RGBX8888, LUMINANCE and ALPHA textures, wrap modes, nearest and bilinear
// filtering with a parameterised weight precision.
#pragma once

#include <cstdint>

#include "emu/memory.hpp"

namespace frappe::vc4::emu {

struct TextureConfig {
	uint32_t base = 0;
	unsigned type = 16;
	unsigned width = 1;
	unsigned height = 1;
	bool mag_nearest = false;
	unsigned wrap_s = 1;
	unsigned wrap_t = 1;

	// From texture config parameters P0 and P1 (section 4, "Texture Config Parameter 0/1").
	static TextureConfig fromUniforms(uint32_t p0, uint32_t p1);
};

// Byte offset of texel (x, y) from the texture base. Raster for RGBA32R; otherwise 64-byte
// microtiles (4x4 texels at 32 bpp, 8x8 at 8 bpp) laid out LT (raster order of microtiles)
// when the image is at most 4 microtiles wide or high, T (4 KiB tiles of 2x2 1 KiB
// subtiles, boustrophedon rows) otherwise.
uint32_t texelOffset(const TextureConfig &tex, unsigned x, unsigned y);

// Returns the filtered RGBA8888 texel at normalised coordinates (s, t). Bilinear weights
// are truncated to `fraction_bits` bits; the guide does not document the hardware's.
uint32_t sampleTexture(const Memory &memory, const TextureConfig &tex, float s, float t,
                       unsigned fraction_bits);

} // namespace frappe::vc4::emu
