// SPDX-License-Identifier: MIT
// Typed builders for the setup words written to the VPM/VCD and TMU registers, so that
// kernels contain no magic numbers. Reference guide section 7 (Tables 32-37) and
// section 4 (texture config parameters, Tables 15-18); bit layouts as tabulated in
// ../shared/design/vc4-research.md sections 1.4 (the team's folder beside the checkout).
#pragma once

#include <cstdint>

namespace frappe::vc4::isa {

enum class VpmSize : uint8_t { Bits8 = 0, Bits16 = 1, Bits32 = 2 };

// Table 32 "VPM generic block write setup format".
struct VpmWriteSetup {
	uint8_t stride = 1;     // 6 bits, added to addr after each vector (0 means 64)
	bool horizontal = true;
	bool laned = false;
	VpmSize size = VpmSize::Bits32;
	uint8_t addr = 0;

	constexpr uint32_t word() const
	{
		return (uint32_t{stride & 63u} << 12) | (uint32_t{horizontal} << 11) |
		       (uint32_t{laned} << 10) | (uint32_t{static_cast<uint8_t>(size)} << 8) | addr;
	}
	static constexpr VpmWriteSetup fromWord(uint32_t w)
	{
		return {static_cast<uint8_t>((w >> 12) & 63), ((w >> 11) & 1) != 0,
		        ((w >> 10) & 1) != 0, static_cast<VpmSize>((w >> 8) & 3),
		        static_cast<uint8_t>(w & 255)};
	}
};

// Table 33 "VPM generic block read setup format".
struct VpmReadSetup {
	uint8_t num = 1;        // vectors to read, 4 bits (0 means 16)
	uint8_t stride = 1;
	bool horizontal = true;
	bool laned = false;
	VpmSize size = VpmSize::Bits32;
	uint8_t addr = 0;

	constexpr uint32_t word() const
	{
		return (uint32_t{num & 15u} << 20) | (uint32_t{stride & 63u} << 12) |
		       (uint32_t{horizontal} << 11) | (uint32_t{laned} << 10) |
		       (uint32_t{static_cast<uint8_t>(size)} << 8) | addr;
	}
	static constexpr VpmReadSetup fromWord(uint32_t w)
	{
		return {static_cast<uint8_t>((w >> 20) & 15), static_cast<uint8_t>((w >> 12) & 63),
		        ((w >> 11) & 1) != 0, ((w >> 10) & 1) != 0, static_cast<VpmSize>((w >> 8) & 3),
		        static_cast<uint8_t>(w & 255)};
	}
};

// Table 34 "VCD DMA write (VDW) basic setup format": ID = 2 in bits 31:30.
struct VdwSetup {
	uint8_t units = 1;      // 7 bits: rows (horizontal) or columns (vertical); 0 means 128
	uint8_t depth = 16;     // 7 bits: words per row (horizontal); 0 means 128
	bool horizontal = true;
	uint16_t vpm_base = 0;  // 11 bits; 32-bit horizontal: Y << 4 | X
	uint8_t modew = 0;      // 0: 32-bit, 2/3: 16-bit half offset, 4..7: 8-bit byte offset

	constexpr uint32_t word() const
	{
		return (2u << 30) | (uint32_t{units & 127u} << 23) | (uint32_t{depth & 127u} << 16) |
		       (uint32_t{horizontal} << 14) | (uint32_t{vpm_base & 0x7ffu} << 3) | (modew & 7u);
	}
	static constexpr VdwSetup fromWord(uint32_t w)
	{
		return {static_cast<uint8_t>((w >> 23) & 127), static_cast<uint8_t>((w >> 16) & 127),
		        ((w >> 14) & 1) != 0, static_cast<uint16_t>((w >> 3) & 0x7ff),
		        static_cast<uint8_t>(w & 7)};
	}
	static constexpr uint16_t base32(unsigned y, unsigned x) { return static_cast<uint16_t>(y << 4 | x); }
};

// Table 35 "VDW stride setup format": ID = 3 in bits 31:30. STRIDE is 16 bits wide
// (vc4asm addendum; the guide's 13-bit width is a typo).
struct VdwStride {
	uint16_t stride = 0;    // bytes added after each row
	bool block_mode = false;

	constexpr uint32_t word() const { return (3u << 30) | (uint32_t{block_mode} << 16) | stride; }
	static constexpr VdwStride fromWord(uint32_t w)
	{
		return {static_cast<uint16_t>(w & 0xffff), ((w >> 16) & 1) != 0};
	}
};

// Table 36 "VCD DMA read (VDR) basic setup format": bit 31 set.
struct VdrSetup {
	uint8_t modew = 0;      // 3 bits, as VdwSetup::modew
	uint8_t mpitch = 0;     // memory pitch 8 * 2^mpitch bytes; 0 uses the extended pitch
	uint8_t rowlen = 16;    // 4 bits, words per row; 0 means 16
	uint8_t nrows = 1;      // 4 bits; 0 means 16
	uint8_t vpitch = 1;     // 4 bits, VPM rows between rows; 0 means 16
	bool vertical = false;
	uint16_t addrxy = 0;    // 11 bits; 32-bit horizontal: Y << 4 | X

	constexpr uint32_t word() const
	{
		return (1u << 31) | (uint32_t{modew & 7u} << 28) | (uint32_t{mpitch & 15u} << 24) |
		       (uint32_t{rowlen & 15u} << 20) | (uint32_t{nrows & 15u} << 16) |
		       (uint32_t{vpitch & 15u} << 12) | (uint32_t{vertical} << 11) | (addrxy & 0x7ffu);
	}
	static constexpr VdrSetup fromWord(uint32_t w)
	{
		return {static_cast<uint8_t>((w >> 28) & 7), static_cast<uint8_t>((w >> 24) & 15),
		        static_cast<uint8_t>((w >> 20) & 15), static_cast<uint8_t>((w >> 16) & 15),
		        static_cast<uint8_t>((w >> 12) & 15), ((w >> 11) & 1) != 0,
		        static_cast<uint16_t>(w & 0x7ff)};
	}
};

// Table 37 "VDR extended memory stride setup": bits 31:28 = 9, pitch in bytes in 12:0.
struct VdrStride {
	uint16_t pitch = 0;

	constexpr uint32_t word() const { return (9u << 28) | (pitch & 0x1fffu); }
	static constexpr VdrStride fromWord(uint32_t w) { return {static_cast<uint16_t>(w & 0x1fff)}; }
};

// What kind of setup a word written to vr_setup / vw_setup is (by its ID bits).
enum class SetupKind { VpmGeneric, VdwBasic, VdwStride, VdrBasic, VdrStride, Unknown };
constexpr SetupKind vwSetupKind(uint32_t w)
{
	switch (w >> 30) {
	case 0: return SetupKind::VpmGeneric;
	case 2: return SetupKind::VdwBasic;
	case 3: return SetupKind::VdwStride;
	default: return SetupKind::Unknown;
	}
}
constexpr SetupKind vrSetupKind(uint32_t w)
{
	if (w >> 31)
		return (w >> 28) == 9 ? SetupKind::VdrStride : SetupKind::VdrBasic;
	return (w >> 30) == 0 ? SetupKind::VpmGeneric : SetupKind::Unknown;
}

// Texture types used by the emulator (vc4_packet.h VC4_TEXTURE_TYPE_*).
enum class TextureType : uint8_t { Rgba8888 = 0, Luminance = 5, Rgba32Raster = 16 };
enum class TextureWrap : uint8_t { Repeat = 0, Clamp = 1, Mirror = 2, Border = 3 };

// Texture config parameter 0 (section 4 "Texture Config Parameter 0").
struct TexP0 {
	uint32_t base = 0;      // 4 KiB aligned (bits 31:12)
	TextureType type = TextureType::Rgba32Raster;

	constexpr uint32_t word() const
	{
		return (base & 0xfffff000u) | ((static_cast<uint32_t>(type) & 15u) << 4);
	}
};

// Texture config parameter 1.
struct TexP1 {
	TextureType type = TextureType::Rgba32Raster;
	uint16_t height = 1;    // 11 bits; 0 means 2048
	uint16_t width = 1;
	bool mag_nearest = false;
	uint8_t min_filter = 0; // 0 linear, 1 nearest (and mipmap variants above)
	TextureWrap wrap_t = TextureWrap::Clamp;
	TextureWrap wrap_s = TextureWrap::Clamp;

	constexpr uint32_t word() const
	{
		return (((static_cast<uint32_t>(type) >> 4) & 1u) << 31) | (uint32_t{height & 0x7ffu} << 20) |
		       (uint32_t{width & 0x7ffu} << 8) | (uint32_t{mag_nearest} << 7) |
		       (uint32_t{min_filter & 7u} << 4) | (static_cast<uint32_t>(wrap_t) << 2) |
		       static_cast<uint32_t>(wrap_s);
	}
};

} // namespace frappe::vc4::isa
