// SPDX-License-Identifier: MIT
// frappe/dictionary.h: the marker families compiled into the library.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace frappe {

/// One family of square markers: each code is the n x n inner grid read
/// row-major from the top-left cell, most significant used bit first,
/// 1 = white (see frappe-core/dictionaries/README.md).
struct Dictionary {
	std::string_view name;                ///< e.g. "aruco_mip_36h12"
	int bits = 0;                         ///< n: cells per side of the inner grid
	int min_hamming = 0;                  ///< minimum distance, rotations included
	int opencv_max_correction = 0;        ///< what OpenCV corrects for it, for reference
	std::span<const std::uint64_t> codes; ///< codes[id]

	/// The correction the detector applies unless told otherwise:
	/// min(5, (dmin - 1) / 2), never negative.
	int defaultMaxHamming() const;
	int size() const { return static_cast<int>(codes.size()); }
};

/// Every built-in dictionary, in a stable order.
std::span<const Dictionary> dictionaries();

/// Looks a dictionary up by name. Accepts the file names
/// ("aruco_mip_36h12", "6x6_250", "apriltag_36h11"), case-insensitively,
/// and the common aliases "opencv_6x6_250", "DICT_6X6_250",
/// "DICT_APRILTAG_36h11", "tag36h11". Returns nullptr when unknown.
const Dictionary *findDictionary(std::string_view name);

/// The names of all built-in dictionaries, for error messages and --help.
std::string dictionaryNames(std::string_view separator = ", ");

/// Rotates an n x n code by 90 degrees clockwise (as the marker would look
/// after turning it a quarter turn clockwise).
std::uint64_t rotateCode(std::uint64_t code, int bits);

} // namespace frappe
