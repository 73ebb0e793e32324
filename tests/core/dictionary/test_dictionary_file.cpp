// SPDX-License-Identifier: MIT
// Dictionaries from files (loadDictionary, parseDictionary): the built-in
// files and OpenCV's own YAML/XML load equal to the built-ins, a custom
// dictionary detects, and malformed or unreadable files are refused with
// the file and line named.
#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "blocking_read.h"
#include "frappe/frappe.h"
#include "scene.h"

using namespace frappe;
using namespace frappe::test;

namespace {

const std::string kSource = FRAPPE_SOURCE_ROOT;

void expectSame(const Dictionary &got, const Dictionary &want)
{
	EXPECT_EQ(got.name, want.name);
	EXPECT_EQ(got.bits, want.bits) << want.name;
	EXPECT_EQ(got.min_hamming, want.min_hamming) << want.name;
	EXPECT_EQ(got.opencv_max_correction, want.opencv_max_correction) << want.name;
	ASSERT_EQ(got.layout != nullptr, want.layout != nullptr) << want.name;
	if (want.layout) {
		EXPECT_EQ(got.layout->cells, want.layout->cells) << want.name;
	}
	ASSERT_EQ(got.size(), want.size()) << want.name;
	for (int id = 0; id < want.size(); ++id)
		ASSERT_EQ(got.codes[id], want.codes[id]) << want.name << " id " << id;
}

/* A file of its own under the test's temporary directory. */
std::string writeFile(const std::string &name, const std::string &text)
{
	const auto dir = std::filesystem::temp_directory_path() / ("frappe-dictfile-" + std::to_string(::getpid()));
	std::filesystem::create_directories(dir);
	const std::string path = (dir / name).string();
	std::ofstream(path, std::ios::binary) << text;
	return path;
}

/* The message of the invalid_argument that parsing `text` throws. */
std::string parseError(const std::string &text)
{
	try {
		parseDictionary(text, "bad.txt");
	} catch (const std::invalid_argument &e) {
		return e.what();
	}
	return "(no error)";
}

} // namespace

TEST(DictionaryFile, EveryBuiltInFileLoadsAsTheBuiltIn)
{
	for (const Dictionary &d : dictionaries()) {
		const auto loaded = loadDictionary(kSource + "/frappe-core/dictionaries/" + std::string(d.name) + ".txt");
		expectSame(*loaded, d);
	}
}

/* Written by OpenCV 4.6's cv::aruco::Dictionary::writeDictionary. */
TEST(DictionaryFile, OpenCvYamlAndXmlOf4x4_50LoadAsTheBuiltIn)
{
	const Dictionary &want = *findDictionary("4x4_50");
	for (const char *ext : { ".yml", ".xml" }) {
		const auto got = loadDictionary(kSource + "/tests/core/dictionaries/opencv_4x4_50" + ext);
		EXPECT_EQ(got->name, "opencv_4x4_50") << ext; /* the file's stem */
		EXPECT_EQ(got->opencv_max_correction, 1) << ext;
		ASSERT_EQ(got->size(), 50) << ext;
		EXPECT_EQ(got->bits, 4);
		EXPECT_EQ(got->min_hamming, want.min_hamming);
		for (int id = 0; id < 50; ++id)
			ASSERT_EQ(got->codes[id], want.codes[id]) << ext << " id " << id;
	}
}

/* No header: the side from the digits; CRLF, a byte-order mark, blank
 * lines and trailing comments are fine; a code that is its own rotation is
 * accepted with min_hamming 0 (as aruco_original). */
TEST(DictionaryFile, TextWithoutHeaderCrlfAndSymmetricCode)
{
	const auto d = parseDictionary("\xEF\xBB\xBF# mine\r\n0x1ff\r\n\r\n0x0a8  # a comment\r\n", "mine");
	EXPECT_EQ(d->name, "mine");
	EXPECT_EQ(d->bits, 3);
	ASSERT_EQ(d->size(), 2);
	EXPECT_EQ(d->codes[0], 0x1ffu);
	EXPECT_EQ(d->codes[1], 0x0a8u);
	EXPECT_EQ(d->min_hamming, 0); /* all-white is the same in every rotation */

	/* 0x0a8 = 010 101 000; its rotations are 2 to 4 bits away, 0x1ff 6. */
	const auto e = parseDictionary("# dictionary: named\n0x0a8\n", "fallback");
	EXPECT_EQ(e->name, "named");
	EXPECT_EQ(e->min_hamming, 2);

	/* A name from the caller is cut, never refused; YAML's name key wins. */
	EXPECT_EQ(parseDictionary("0x0a8\n", "")->name, "custom");
	EXPECT_EQ(parseDictionary("0x0a8\n", std::string(300, 'n'))->name, std::string(128, 'n'));
	EXPECT_EQ(parseDictionary("nmarkers: 1\nname: yml\nmarkersize: 3\nmarker_0: '010101000'\n", "x")->name, "yml");
}

/* The detector reads a dictionary of the user's own, of the smallest and
 * largest sides it supports, with exact ids; it reports the dictionary's
 * name and keeps it alive on its own. */
TEST(DictionaryFile, CustomDictionaryDetectsRenderedMarkers)
{
	const char *const files[] = {
		"# dictionary: three\n# marker_side_bits: 3\n0x00f\n0x033\n0x065\n",
		"# dictionary: eight\n0x8d3a5c71e29b46f0\n0x3c6e91a7d05b28f4\n0xe41f7b2c9a63d085\n",
	};
	for (const char *text : files) {
		std::unique_ptr<Detector> det;
		std::string name;
		{
			Config cfg;
			cfg.custom_dictionary = parseDictionary(text, "unused");
			name = std::string(cfg.custom_dictionary->name);
			ASSERT_EQ(cfg.custom_dictionary->size(), 3);
			if (cfg.custom_dictionary->bits == 3) {
				EXPECT_EQ(cfg.custom_dictionary->min_hamming, 4); /* the best 3 codes of 3x3 have */
			}
			det = std::make_unique<Detector>(cfg);
		}
		const Dictionary &dict = det->dictionary();
		EXPECT_EQ(dict.name, name);
		ASSERT_EQ(dict.size(), 3);
		Image img(600, 240, 200);
		RenderOptions opt;
		opt.black = 20;
		opt.white = 230;
		std::array<std::array<Point2f, 4>, 3> truth;
		for (int id = 0; id < 3; ++id) {
			truth[id] = squarePose(110.0f + 190.0f * id + 0.3f, 120.0f - 0.2f, 100.0f, 25.0f * id - 20.0f,
					       15.0f * id);
			renderMarker(img.mut(), dict, id, truth[id], opt);
		}
		const Result &res = det->detect(img.view());
		ASSERT_EQ(res.markers.size(), 3u) << name;
		for (int id = 0; id < 3; ++id) {
			const Marker *m = findMarker(res.markers, id);
			ASSERT_NE(m, nullptr) << name << " id " << id;
			EXPECT_LT(meanCornerError(m->corners, truth[id]), 0.3f) << name << " id " << id;
		}
	}
}

TEST(DictionaryFile, ConfigChecksAgainstTheCustomDictionary)
{
	Config cfg;
	cfg.dictionary = "no-such-name"; /* ignored when a custom one is set */
	cfg.custom_dictionary = parseDictionary("0x0ba\n0x1c6\n", "three");
	cfg.max_hamming = 4; /* 3 x 3 / 2 */
	EXPECT_NO_THROW(Detector{ cfg });
	cfg.max_hamming = 5;
	EXPECT_THROW(Detector{ cfg }, std::invalid_argument);

	/* One made by hand: a side the sample grid has no room for, none at
	 * all, codes beyond the cells. */
	static const std::uint64_t codes[] = { 0x1, 0x200 };
	for (int bits : { 9, 2 }) {
		auto bad = std::make_shared<Dictionary>(Dictionary{ "bad", bits, 1, 0, codes });
		cfg.custom_dictionary = bad;
		cfg.max_hamming = -1;
		EXPECT_THROW(Detector{ cfg }, std::invalid_argument) << bits;
	}
	cfg.custom_dictionary = std::make_shared<Dictionary>(Dictionary{ "bad", 3, 1, 0, codes });
	try {
		Detector det(cfg);
		ADD_FAILURE() << "0x200 has a bit beyond 9 cells";
	} catch (const std::invalid_argument &e) {
		EXPECT_NE(std::string(e.what()).find("beyond the 9 cells"), std::string::npos) << e.what();
	}
}

/* Issue 34: a name that is not UTF-8 (Latin-1 in a file's header) was
 * taken as it was, and every JSON line, GStreamer message and Python str
 * carrying it broke. Refused at load naming the file, the line and the
 * byte; a file name's stem (any bytes) becomes UTF-8; a hand-made
 * dictionary with such a name is refused by the Detector; messages quoting
 * a file's bytes are UTF-8 too. */
TEST(DictionaryFile, NamesThatAreNotUtf8AreRefused)
{
	EXPECT_EQ(parseError("# dictionary: caf\xe9\n0x1234\n0xff00\n"),
		  "frappe::parseDictionary: bad.txt:1: the dictionary name is not UTF-8 text (byte 0xe9 at its byte 4); "
		  "save the file as UTF-8");
	EXPECT_EQ(parseError("%YAML:1.0\nnmarkers: 1\nmarkersize: 3\nname: \xff\xfe\nmarker_0: \"010101010\"\n"),
		  "frappe::parseDictionary: bad.txt:4: the dictionary name is not UTF-8 text (byte 0xff at its byte 1); "
		  "save the file as UTF-8");
	/* Overlong forms and surrogates are not UTF-8 either. */
	EXPECT_NE(parseError("# dictionary: \xc0\xae\n0x1234\n").find("not UTF-8"), std::string::npos);
	EXPECT_NE(parseError("# dictionary: \xed\xa0\x80\n0x1234\n").find("not UTF-8"), std::string::npos);
	/* UTF-8 is kept as it is. */
	EXPECT_EQ(parseDictionary("# dictionary: caf\xc3\xa9-\xe6\x97\xa5\n0x1234\n0xff00\n", "ok")->name,
		  "caf\xc3\xa9-\xe6\x97\xa5");

	/* The stem of a Latin-1 file name: its bytes read as Latin-1, cut at
	 * 128 bytes on a character's start. */
	const std::string latin1 = writeFile("caf\xe9.txt", "0x1234\n0xff00\n");
	EXPECT_EQ(loadDictionary(latin1)->name, "caf\xc3\xa9");
	const std::string longName = std::string(127, 'a') + "\xc3\xa9";
	EXPECT_EQ(parseDictionary("0x1234\n", longName)->name, std::string(127, 'a'));
	/* A message quoting a line of Latin-1 text is UTF-8. */
	EXPECT_EQ(parseError("0x1234\n0x12\xe9\n"), "frappe::parseDictionary: bad.txt:2: a codeword must be a 0x hex "
						    "number of at most 64 bits, got '0x12\xc3\xa9'");

	static const std::uint64_t codes[] = { 0x1, 0x2 };
	Config cfg;
	cfg.custom_dictionary = std::make_shared<Dictionary>(Dictionary{ "caf\xe9", 3, 1, 0, codes });
	try {
		Detector det(cfg);
		ADD_FAILURE() << "a name that is not UTF-8 was taken";
	} catch (const std::invalid_argument &e) {
		EXPECT_EQ(std::string(e.what()), "frappe::Config: custom_dictionary: the name is not UTF-8 text");
	}
}

/* Each malformed input is refused naming the file, the line and what. */
TEST(DictionaryFile, MalformedInputsNameFileLineAndWhat)
{
	struct Case {
		std::string text;
		std::string where; /* "bad.txt:<line>: " */
		std::string what;  /* part of the message */
	};
	const std::string yaml = "%YAML:1.0\n---\nnmarkers: 2\nmarkersize: 3\nmaxCorrectionBits: 0\n";
	const Case cases[] = {
		{ "", "bad.txt:1: ", "no codes" },
		{ "# only a comment\n", "bad.txt:1: ", "no codes" },
		{ "0x12\n", "bad.txt:1: ", "2 hex digits" },
		{ "0x0ba\n0xzz1\n", "bad.txt:2: ", "0x hex number" },
		{ "0x0ba\n123\n", "bad.txt:2: ", "0x hex number" },
		{ "0x0ba\n0x1c6 0x133\n", "bad.txt:2: ", "one codeword a line" },
		{ "# marker_side_bits: 9\n0x1\n", "bad.txt:1: ", "side of 9 bits" },
		{ "# marker_side_bits: 2\n0x1\n", "bad.txt:1: ", "side of 2 bits" },
		{ "# marker_side_bits: 3\n0x0ba\n0x200\n", "bad.txt:3: ", "beyond the 9 cells" },
		{ "0x0ba\n0x1c6\n0x0ba\n", "bad.txt:3: ", "id 2 has the code of id 0" },
		/* 0x124, the left column white, is 0x1c0, the top row, turned. */
		{ "0x1c0\n0x124\n", "bad.txt:2: ", "id 1 has the code of id 0 turned 90 degrees" },
		{ "# codes: 3\n0x0ba\n0x1c6\n", "bad.txt:1: ", "header says 3 codes, the file has 2" },
		{ "0x0ba\n0x1c6\n0x1\n", "bad.txt:3: ", "3 hex digits, as the first" },
		{ "0x0ba\n\x01\n", "bad.txt:2: ", "control character" },
		{ "0x0ba\n" + std::string(5000, ' ') + "\n", "bad.txt:2: ", "longer than 4096" },
		{ "\x89PNG\r\n", "bad.txt:1: ", "expected 'key: value'" },
		{ yaml + "marker_0: \"010111010\"\n", "bad.txt:3: ", "marker_1 is missing" },
		{ yaml + "marker_0: \"010111010\"\nmarker_1: \"111000110\"\nmarker_2: \"100110011\"\n", "bad.txt:8: ",
		  "beyond nmarkers 2" },
		{ yaml + "marker_0: \"01011101\"\nmarker_1: \"111000110\"\n", "bad.txt:6: ", "has 9 bits, this one 8" },
		{ yaml + "marker_0: \"0101110x0\"\n", "bad.txt:6: ", "'0'/'1'" },
		{ yaml + "marker_0: \"010111010\"\nmarker_0: \"111000110\"\n", "bad.txt:7: ", "marker_0 given twice" },
		{ yaml + "rows: 3\n", "bad.txt:6: ", "unknown key 'rows'" },
		{ "%YAML:1.0\nnmarkers: 1\nmarkersize: 10\n", "bad.txt:3: ", "side of 10 bits" },
		{ "%YAML:1.0\nnmarkers: -1\n", "bad.txt:2: ", "nmarkers must be a number" },
		{ "%YAML:1.0\nnmarkers: 5000\nmarkersize: 3\n", "bad.txt:2: ", "more than 4096 codes" },
		{ "%YAML:1.0\nmarkersize: 3\nmarker_0: \"010111010\"\n", "bad.txt:3: ", "no nmarkers" },
		{ "<?xml version=\"1.0\"?>\n<opencv_storage>\n<nmarkers>1</markersize>\n", "bad.txt:3: ",
		  "expected <nmarkers>value</nmarkers>" },
	};
	for (const Case &c : cases) {
		const std::string msg = parseError(c.text);
		EXPECT_NE(msg.find("frappe::parseDictionary: " + c.where), std::string::npos)
			<< "input: " << c.text.substr(0, 80) << "\nmessage: " << msg;
		EXPECT_NE(msg.find(c.what), std::string::npos)
			<< "input: " << c.text.substr(0, 80) << "\nmessage: " << msg;
	}
	/* Through a file: its path names it. */
	const std::string path = writeFile("bad-side.txt", "# marker_side_bits: 12\n0x1\n");
	try {
		loadDictionary(path);
		ADD_FAILURE() << "side 12 accepted";
	} catch (const std::invalid_argument &e) {
		EXPECT_NE(std::string(e.what()).find(path + ":1: "), std::string::npos) << e.what();
	}
}

/* 4096 codes load (their pairs checked in well under a second); one more
 * is refused. */
TEST(DictionaryFile, AtMost4096Codes)
{
	std::mt19937_64 rng(5);
	std::string text = "# marker_side_bits: 8\n";
	char line[32];
	for (int k = 0; k < 4096; ++k) {
		std::snprintf(line, sizeof line, "0x%016llx\n", static_cast<unsigned long long>(rng()));
		text += line;
	}
	const auto d = parseDictionary(text, "big");
	EXPECT_EQ(d->size(), 4096);
	EXPECT_GT(d->min_hamming, 5); /* random 64-bit codes lie far apart */
	text += "0x0000000000000001\n";
	EXPECT_NE(parseError(text).find("bad.txt:4098: more than 4096 codes"), std::string::npos) << parseError(text);
}

/* Issue 34: a FIFO in a dictionary file's place blocked the open forever,
 * and a device was read without end: what is opened is checked first. */
TEST(DictionaryFile, FifoOrDeviceIsRefusedWithoutWaiting)
{
	const std::string fifo = writeFile("fifo.txt", "");
	EXPECT_EQ(frappe::test::readingFifo(fifo, [](const std::string &p) { loadDictionary(p); }),
		  "frappe::loadDictionary: cannot read dictionary file '" + fifo + "': not a regular file (a FIFO)");
	EXPECT_FALSE(frappe::test::blockedBySwappedFifo(fifo + ".txt", "0x1234\n0xff00\n", 1.0,
							 [](const std::string &p) { loadDictionary(p); }));
	try {
		loadDictionary("/dev/zero");
		ADD_FAILURE() << "/dev/zero loaded";
	} catch (const std::runtime_error &e) {
		EXPECT_EQ(std::string(e.what()), "frappe::loadDictionary: cannot read dictionary file '/dev/zero': "
						 "not a regular file (a character device)");
	}
}

TEST(DictionaryFile, UnreadableFilesAreRuntimeErrors)
{
	const std::string huge = writeFile("huge.txt", "");
	std::filesystem::resize_file(huge, (64u << 20) + 1); /* sparse: nothing written */
	const std::string dir = std::filesystem::path(huge).parent_path().string();
	const std::pair<std::string, std::string> cases[] = {
		{ dir + "/no-such-file.txt", "no such file" },
		{ dir, "a directory" },
		{ huge, "over 64 MiB" },
	};
	for (const auto &[path, what] : cases) {
		try {
			loadDictionary(path);
			ADD_FAILURE() << path << " loaded";
		} catch (const std::invalid_argument &e) {
			ADD_FAILURE() << path << ": invalid_argument, not runtime_error: " << e.what();
		} catch (const std::runtime_error &e) {
			const std::string msg = e.what();
			EXPECT_NE(msg.find("'" + path + "'"), std::string::npos) << msg;
			EXPECT_NE(msg.find(what), std::string::npos) << msg;
		}
	}
	std::filesystem::remove_all(dir);
}
