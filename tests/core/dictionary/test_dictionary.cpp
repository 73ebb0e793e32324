// SPDX-License-Identifier: MIT
// Dictionaries and the Hamming decoder: every code of every dictionary in
// all four rotations, with up to h_thr bits flipped, and h_thr + 1 rejected.
#include <bit>
#include <filesystem>
#include <random>
#include <set>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "decode.h"
#include "frappe/dictionary.h"

using namespace frappe;

TEST(Dictionary, AllSharedDictionariesAreBuiltIn)
{
	const std::set<std::string_view> expected = {
		"4x4_50", "4x4_100", "4x4_250", "4x4_1000", "5x5_50", "5x5_100", "5x5_250", "5x5_1000",
		"6x6_50", "6x6_100", "6x6_250", "6x6_1000", "7x7_50", "7x7_100", "7x7_250", "7x7_1000",
		"apriltag_16h5", "apriltag_25h9", "apriltag_36h10", "apriltag_36h11", "aruco_mip_36h12",
		"aruco_original",
		/* AprilTag 3's layout families (issue 32) */
		"apriltag_standard41h12", "apriltag_standard52h13", "apriltag_circle21h7", "apriltag_circle49h12",
		"apriltag_custom48h12",
	};
	std::set<std::string_view> got;
	for (const Dictionary &d : dictionaries())
		got.insert(d.name);
	EXPECT_EQ(got, expected);
}

/* Every file of frappe-core/dictionaries is compiled in, and every
 * built-in dictionary has its file: a new file missing from
 * frappe-core/meson.build fails here, not in a user's hands. */
TEST(Dictionary, EveryDictionaryFileIsCompiledIn)
{
	const std::filesystem::path dir = std::filesystem::path(FRAPPE_SOURCE_ROOT) / "frappe-core" / "dictionaries";
	std::set<std::string> files, builtIn;
	for (const auto &entry : std::filesystem::directory_iterator(dir)) {
		if (entry.path().extension() == ".txt")
			files.insert(entry.path().stem().string());
	}
	for (const Dictionary &d : dictionaries())
		builtIn.insert(std::string(d.name));
	EXPECT_FALSE(files.empty());
	EXPECT_EQ(files, builtIn);
}

TEST(Dictionary, KnownCodesAndSizes)
{
	const Dictionary *d = findDictionary("aruco_mip_36h12");
	ASSERT_NE(d, nullptr);
	EXPECT_EQ(d->bits, 6);
	EXPECT_EQ(d->size(), 250);
	EXPECT_EQ(d->min_hamming, 12);
	EXPECT_EQ(d->codes[0], 0xd2b63a09dull); /* id 0, from the dictionary README */
	EXPECT_EQ(d->defaultMaxHamming(), 2);
	EXPECT_EQ(findDictionary("apriltag_36h11")->size(), 587);
	EXPECT_EQ(findDictionary("apriltag_36h11")->defaultMaxHamming(), 1);
	EXPECT_EQ(findDictionary("4x4_50")->defaultMaxHamming(), 0);
	EXPECT_EQ(findDictionary("aruco_original")->defaultMaxHamming(), 0);
}

TEST(Dictionary, AliasesAndUnknownNames)
{
	EXPECT_EQ(findDictionary("opencv_6x6_250"), findDictionary("6x6_250"));
	EXPECT_EQ(findDictionary("DICT_6X6_250"), findDictionary("6x6_250"));
	EXPECT_EQ(findDictionary("DICT_APRILTAG_36h11"), findDictionary("apriltag_36h11"));
	EXPECT_EQ(findDictionary("tag36h11"), findDictionary("apriltag_36h11"));
	EXPECT_EQ(findDictionary("ARUCO_MIP_36h12"), findDictionary("aruco_mip_36h12"));
	/* The element's dashed spelling, on every surface now. */
	EXPECT_EQ(findDictionary("apriltag-36h11"), findDictionary("apriltag_36h11"));
	EXPECT_EQ(findDictionary("6x6-250"), findDictionary("6x6_250"));
	EXPECT_EQ(findDictionary("6x6_251"), nullptr);
	EXPECT_EQ(findDictionary(""), nullptr);
	EXPECT_NE(dictionaryNames().find("apriltag_16h5"), std::string::npos);
}

TEST(Dictionary, RotateCodeTurnsTheGridClockwise)
{
	/* 2x2 grid: top row a b, bottom row c d -> after a clockwise quarter
	 * turn: top row c a, bottom row d b. Bits: a=3 b=2 c=1 d=0. */
	EXPECT_EQ(rotateCode(0b1000, 2), 0b0100u); /* a moves to top-right */
	EXPECT_EQ(rotateCode(0b0100, 2), 0b0001u); /* b moves to bottom-right */
	EXPECT_EQ(rotateCode(0b0010, 2), 0b1000u); /* c moves to top-left */
	for (const Dictionary &d : dictionaries()) {
		for (int id = 0; id < d.size(); id += 7) {
			std::uint64_t c = d.codes[id];
			for (int r = 0; r < 4; ++r)
				c = d.rotate(c);
			ASSERT_EQ(c, d.codes[id]) << d.name << " id " << id;
			if (!d.layout) {
				ASSERT_EQ(d.rotate(c), rotateCode(c, d.bits)) << d.name;
			}
		}
	}
}

/* n^2 cells must fit 64 bits: n above 8, or below 1, is refused with the
 * argument named, not shifted out of range. */
TEST(Dictionary, RotateCodeRefusesGridsBeyondSixtyFourBits)
{
	for (int bits : { 0, -1, 9, 64 }) {
		try {
			rotateCode(1, bits);
			ADD_FAILURE() << "bits " << bits << " accepted";
		} catch (const std::invalid_argument &e) {
			EXPECT_NE(std::string(e.what()).find("bits must be in [1, 8]"), std::string::npos) << e.what();
			EXPECT_NE(std::string(e.what()).find("got " + std::to_string(bits)), std::string::npos) << e.what();
		}
	}
	/* 8 x 8 uses every bit: the top-left cell (bit 63) turns to the
	 * top-right (bit 56). */
	EXPECT_EQ(rotateCode(1ull << 63, 8), 1ull << 56);
	EXPECT_EQ(rotateCode(1, 1), 1u);
}

namespace {

/* `width`: the code's bits (Dictionary::codeBits()). */
std::uint64_t flipBits(std::uint64_t code, int width, int flips, std::mt19937 &rng)
{
	std::uniform_int_distribution<int> pick(0, width - 1);
	std::uint64_t mask = 0;
	while (std::popcount(mask) < flips)
		mask |= 1ull << pick(rng);
	return code ^ mask;
}

} // namespace

class DictionaryDecode : public ::testing::TestWithParam<int> {};

TEST_P(DictionaryDecode, EveryCodeEveryRotationUpToMaxHamming)
{
	const Dictionary &d = dictionaries()[GetParam()];
	const int h = d.defaultMaxHamming();
	std::mt19937 rng(1234 + GetParam());
	/* The 1000-code dictionaries take every 3rd id to bound the run time;
	 * AprilTag 3's large families (up to 65535 codes, each read a scan) every 500th. */
	const int step = d.size() > 4096 ? 500 : d.size() > 600 ? 3 : 1;
	for (int id = 0; id < d.size(); id += step) {
		/* Seen with the marker turned r quarter turns clockwise, the marker's
		 * top-left corner sits at quad corner r. */
		for (int r = 0; r < 4; ++r) {
			std::uint64_t grid = d.codes[id];
			for (int t = 0; t < r; ++t)
				grid = d.rotate(grid);
			const int flips = (id + r) % (h + 1);
			const std::uint64_t seen = flipBits(grid, d.codeBits(), flips, rng);
			const detail::Decoded got = detail::decode(d, seen, h);
			if (got.id != id && d.min_hamming == 0) {
				/* aruco_original has rotation-symmetric and duplicate
				 * codes; a decode must still be one of them. */
				ASSERT_GE(got.id, 0);
				continue;
			}
			ASSERT_EQ(got.id, id) << d.name << " rotation " << r << " flips " << flips;
			ASSERT_EQ(got.hamming, flips);
			if (d.min_hamming > 0 && flips == 0) {
				ASSERT_EQ(got.rotation, r) << d.name << " id " << id;
			}
		}
	}
}

TEST_P(DictionaryDecode, OneMoreFlipThanMaxHammingIsRejected)
{
	const Dictionary &d = dictionaries()[GetParam()];
	const int h = d.defaultMaxHamming();
	if (d.min_hamming < 2 * h + 2)
		GTEST_SKIP() << d.name << ": h_thr + 1 flips may land within h_thr of another code";
	std::mt19937 rng(99 + GetParam());
	/* A word beyond max_hamming of every code is a scan of the whole
	 * dictionary: every fifth code was quadratic in the AprilTag 3
	 * families' 50,000 (75 G instructions, a minute under qemu); every
	 * 50th of those still tries about a thousand. */
	const int step = d.size() > 4096 ? 50 : 5;
	for (int id = 0; id < d.size(); id += step) {
		const std::uint64_t seen = flipBits(d.codes[id], d.codeBits(), h + 1, rng);
		const detail::Decoded got = detail::decode(d, seen, h);
		ASSERT_EQ(got.id, -1) << d.name << " id " << id << " decoded as " << got.id;
	}
}

/* The code book's exact lookup gives decode()'s answer, field by field:
 * exact reads in every rotation, reads within and beyond max_hamming, random
 * words, and the duplicate and rotation-symmetric codes of aruco_original
 * (two ids at distance 0: ambiguous). */
TEST_P(DictionaryDecode, CodeBookAnswersAsTheScan)
{
	const Dictionary &d = dictionaries()[GetParam()];
	const detail::CodeBook book(d);
	const int h = d.defaultMaxHamming();
	std::mt19937 rng(77 + GetParam());
	auto expectSame = [&](std::uint64_t seen, int maxHamming) {
		const detail::Decoded a = detail::decode(d, seen, maxHamming);
		const detail::Decoded b = book.decode(seen, maxHamming);
		ASSERT_EQ(b.id, a.id) << d.name << " code " << seen << " h " << maxHamming;
		ASSERT_EQ(b.hamming, a.hamming) << d.name << " code " << seen;
		ASSERT_EQ(b.rotation, a.rotation) << d.name << " code " << seen;
	};
	const int step = d.size() > 4096 ? 500 : d.size() > 600 ? 7 : 1;
	int exact = 0;
	for (int id = 0; id < d.size(); id += step) {
		std::uint64_t grid = d.codes[id];
		for (int r = 0; r < 4; ++r, grid = d.rotate(grid)) {
			expectSame(grid, h);
			expectSame(grid, 0);
			exact += detail::decode(d, grid, 0).id >= 0;
			expectSame(flipBits(grid, d.codeBits(), 1 + (id + r) % (h + 1), rng), h);
		}
	}
	EXPECT_GT(exact, d.size() / step);
	const std::uint64_t all = d.codeBits() == 64 ? ~std::uint64_t{ 0 } : (std::uint64_t{ 1 } << d.codeBits()) - 1;
	for (int k = 0; k < 200; ++k) {
		/* One draw a statement, in the order x86 has drawn them: the
		 * operands of | are evaluated in an unspecified order. */
		const std::uint64_t hi = rng();
		const std::uint64_t lo = rng();
		expectSame((hi << 32 | lo) & all, h);
	}
	expectSame(d.codes[0], -1);
}

INSTANTIATE_TEST_SUITE_P(All, DictionaryDecode,
			 ::testing::Range(0, static_cast<int>(dictionaries().size())),
			 [](const auto &info) {
				 std::string n(dictionaries()[info.param].name);
				 return n;
			 });
