// SPDX-License-Identifier: MIT
// Code file formats of vc4-dis/vc4-run: vc4asm hex listings (low word first) and raw
// little-endian binaries; PGM round trip.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "isa/instr.hpp"
#include "tools/listing.hpp"
#include "tools/pgm.hpp"

using namespace frappe::vc4;

TEST(Listing, HexListingLowWordFirstWithComments)
{
	const auto code = tools::parseHexListing(
		"0x009e7000, 0x100009e7, // nop\n"
		"  0x00000017,0xe80009e7,\n"
		"\n// only a comment\n"
		"0xFFFFFFC0, 0xF03809E7\n");
	ASSERT_EQ(code.size(), 3u);
	EXPECT_EQ(code[0], isa::kNopWord);
	EXPECT_EQ(code[1], 0xe80009e700000017ull);
	EXPECT_EQ(code[2], 0xf03809e7ffffffc0ull);
}

TEST(Listing, RejectsMalformedInput)
{
	EXPECT_THROW(tools::parseHexListing("0x1, 0x2, 0x3,\n"), tools::ListingError);
	EXPECT_THROW(tools::parseHexListing("0x1, nope,\n"), tools::ListingError);
	EXPECT_THROW(tools::parseBinary(std::string(7, '\0')), tools::ListingError);
}

TEST(Listing, BinaryIsLittleEndian)
{
	const std::string bytes("\x00\x70\x9e\x00\xe7\x09\x00\x10", 8);
	const auto code = tools::parseCode(bytes);
	ASSERT_EQ(code.size(), 1u);
	EXPECT_EQ(code[0], isa::kNopWord);
}

TEST(Listing, HexListingRoundTrip)
{
	const std::vector<uint64_t> code = {isa::kNopWord, 0x100208270c042dc0ull, 0x0123456789abcdefull};
	EXPECT_EQ(tools::hexListing(code).substr(0, 24), "0x009e7000, 0x100009e7,\n");
	EXPECT_EQ(tools::parseCode(tools::hexListing(code)), code);
}

TEST(Pgm, RoundTrip)
{
	const auto path = std::filesystem::temp_directory_path() / "vc4-pgm-test.pgm";
	tools::GreyImage img{3, 2, {1, 2, 3, 250, 251, 252}};
	tools::writePgm(path.string(), img);
	const auto back = tools::readPgm(path.string());
	EXPECT_EQ(back.width, 3u);
	EXPECT_EQ(back.height, 2u);
	EXPECT_EQ(back.pixels, img.pixels);
	std::filesystem::remove(path);
}
