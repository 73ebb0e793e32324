// SPDX-License-Identifier: MIT
// frappe/dictionary.h: the marker families compiled into the library.
#pragma once

#include "frappe/export.h"
#include "frappe/layout.h"

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace frappe {

/// One family of square markers: each code is the n x n inner grid read
/// row-major from the top-left cell, most significant used bit first,
/// 1 = white (see frappe-core/dictionaries/README.md); or, for a family
/// with a `layout`, its cells as the layout places them.
struct FRAPPE_EXPORT Dictionary {
	std::string_view name;                ///< e.g. "aruco_mip_36h12"
	/// n: cells per side of the inner grid. With a layout: the detected
	/// square's cells less 2, so that bits + 2 is the square's side in cells.
	int bits = 0;
	int min_hamming = 0;                  ///< minimum distance, rotations included
	int opencv_max_correction = 0;        ///< what OpenCV corrects for it, for reference
	std::span<const std::uint64_t> codes; ///< codes[id]
	/// The cells, when not n x n bits in a one-cell black border (AprilTag
	/// 3's tagStandard41h12 and its kin); nullptr for those.
	const MarkerLayout *layout = nullptr;

	/// Bits of a code: n * n, or the layout's.
	int codeBits() const { return layout ? layout->code_bits : bits * bits; }
	/// The code turned a quarter turn clockwise: rotateCode(), or the layout's.
	std::uint64_t rotate(std::uint64_t code) const;

	/// The bit errors the detector corrects unless told otherwise, among
	/// cells read clearly: the most, up to min(5, (dmin - 1) / 2), for which a
	/// random pattern decodes with a chance below 1e-5, that chance being
	/// 4 rotations x codes x patterns within t bits / 2^(bits^2). 0 for
	/// every 4x4 and 5x5 family (one pattern in 300 to 20,000 is a codeword
	/// already), 1 for apriltag_36h11 and 36h10, 2 for aruco_mip_36h12 and
	/// 6x6_250.
	int defaultMaxHamming() const;
	/// The bits corrected in all when the ones beyond defaultMaxHamming()
	/// were read weakly (a cell's mean near the threshold, where blur and
	/// small cells put them): the most, up to min(5, (dmin - 1) / 2), for
	/// which even a pattern of weak cells only decodes with a chance below
	/// 2e-2; never less than defaultMaxHamming(). 5 for aruco_mip_36h12 and
	/// apriltag_36h11, 0 for every 4x4 family.
	int weakMaxHamming() const;
	/// The chance that a pattern of random bits lies within `bits` bits of
	/// some codeword in some rotation: 4 x codes x patterns within `bits`
	/// / 2^codeBits(). What a read corrected by that much is worth as
	/// evidence on its own.
	double randomDecodeChance(int bits) const;
	int size() const { return static_cast<int>(codes.size()); }
};

/// Every built-in dictionary, in a stable order.
FRAPPE_EXPORT std::span<const Dictionary> dictionaries();

/// Looks a dictionary up by name: the one set of spellings every surface
/// (C++, the element, the CLI, Python) accepts. The file names
/// ("aruco_mip_36h12", "6x6_250", "apriltag_36h11"), case-insensitively,
/// with dashes for underscores ("apriltag-36h11", the element's), and the
/// common aliases "opencv_6x6_250", OpenCV's "DICT_6X6_250" and
/// "DICT_APRILTAG_36h11", AprilTag's "tag36h11". Returns nullptr when
/// unknown. Every surface prints the library's name (Dictionary::name).
FRAPPE_EXPORT const Dictionary *findDictionary(std::string_view name);

/// The names of all built-in dictionaries, for error messages and --help.
FRAPPE_EXPORT std::string dictionaryNames(std::string_view separator = ", ");

/// Rotates an n x n code by 90 degrees clockwise (as the marker would look
/// after turning it a quarter turn clockwise). `bits` is n: throws
/// std::invalid_argument unless it is 1..8 (n^2 cells in 64 bits); bits of
/// `code` above the n^2 cells are ignored.
FRAPPE_EXPORT std::uint64_t rotateCode(std::uint64_t code, int bits);

/// Reads a dictionary of the user's own from a file, in either of two
/// formats, told by the content (the text format when the first line that
/// is neither blank nor a `#` comment starts with `0x`):
/// - the built-in dictionaries' text format (frappe-core/dictionaries/
///   README.md): `#` comments, one 0x-hex codeword a line (a `#` comment
///   may follow it), id = codeword index; the side n is taken from a `#
///   marker_side_bits: n` header, else from the codes' hex digits, which
///   must then all be ceil(n*n/4) (3, 4, 7, 9, 13 or 16 for n = 3..8);
/// - OpenCV's aruco YAML (what cv::aruco::Dictionary::writeDictionary
///   writes), or the same keys as its FileStorage XML: markersize,
///   nmarkers, marker_0 .. marker_{N-1} as strings of n*n '0'/'1'
///   characters, row-major, 1 = white (the same bits), in any order.
/// CRLF line ends and a UTF-8 byte-order mark are accepted; lines are at
/// most 4096 bytes. The dictionary is named after the file (its stem, cut
/// to 128 bytes) unless a `# dictionary:` header or a `name` key gives one
/// (1 to 128 bytes). Its min_hamming is computed over the codes and their
/// rotations; a code that is its own rotation is accepted, making it 0 as
/// for aruco_original (such a marker's orientation is ambiguous).
/// opencv_max_correction is the file's maxCorrectionBits (or `#
/// opencv_*_max_correction_bits` header), or 0.
/// Throws std::runtime_error when the file cannot be read (missing, not a
/// regular file, over 64 MiB) and std::invalid_argument, naming the file
/// and line ("frappe::loadDictionary: FILE:LINE: what"), when its content
/// is not a dictionary: no codes, more than 4096 (every pair is compared
/// in 4 rotations: a fraction of a second on a PC at 4096), a side outside
/// 3..8 (what a 64-bit code and the detector's sample grid hold), a code
/// with bits beyond n*n, a codeword that does not parse, a count that
/// disagrees with nmarkers or a `# codes:` header, an unknown or repeated
/// key, a control character, two ids with the same code in some rotation.
FRAPPE_EXPORT std::shared_ptr<const Dictionary> loadDictionary(const std::string &path);

/// The same from a file's text; `name` is the dictionary's unless the text
/// names one, and names the text in messages
/// ("frappe::parseDictionary: NAME:LINE: what").
FRAPPE_EXPORT std::shared_ptr<const Dictionary> parseDictionary(std::string_view text, std::string_view name);

} // namespace frappe
