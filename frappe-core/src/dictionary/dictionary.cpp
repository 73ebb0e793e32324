// SPDX-License-Identifier: MIT
#include "frappe/dictionary.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <stdexcept>
#include <string>

#include "dictionary_table.h"

namespace frappe {

namespace {

/* The most bits up to `limit` whose chance stays below `chance`. */
int mostWithin(const Dictionary &d, int limit, double chance)
{
	int t = 0;
	while (t < limit && d.randomDecodeChance(t + 1) < chance)
		++t;
	return t;
}

} // namespace

std::uint64_t Dictionary::rotate(std::uint64_t code) const
{
	return layout ? layout->rotate(code) : rotateCode(code, bits);
}

/* A union bound: 4 n C(bits^2, <= t) / 2^bits^2. */
double Dictionary::randomDecodeChance(int t) const
{
	const int cells = codeBits();
	double within = 0.0, choose = 1.0;
	for (int i = 0; i <= t && i <= cells; ++i) {
		within += choose;
		choose = choose * (cells - i) / (i + 1);
	}
	return 4.0 * size() * within / std::ldexp(1.0, cells);
}

int Dictionary::defaultMaxHamming() const
{
	return mostWithin(*this, std::clamp((min_hamming - 1) / 2, 0, 5), 1e-5);
}

int Dictionary::weakMaxHamming() const
{
	return std::max(defaultMaxHamming(), mostWithin(*this, std::clamp((min_hamming - 1) / 2, 0, 5), 2e-2));
}

std::span<const Dictionary> dictionaries()
{
	return { detail::kDictionaries, detail::kDictionaryCount };
}

namespace {

std::string lower(std::string_view s)
{
	std::string out(s);
	for (char &c : out)
		c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
	return out;
}

/* Maps the names other libraries use onto ours: 6x6-250, opencv_6x6_250 and
 * DICT_6X6_250 -> 6x6_250, DICT_APRILTAG_36h11 and tag36h11 ->
 * apriltag_36h11, DICT_ARUCO_ORIGINAL -> aruco_original. */
std::string canonicalName(std::string_view name)
{
	std::string n = lower(name);
	/* The element's dashed spelling ("apriltag-36h11") too. */
	std::replace(n.begin(), n.end(), '-', '_');
	for (std::string_view prefix : { "opencv_", "dict_", "cv2.aruco.dict_" }) {
		if (n.starts_with(prefix))
			n.erase(0, prefix.size());
	}
	if (n.starts_with("tag") && n.size() > 3 && std::isdigit(static_cast<unsigned char>(n[3])))
		n = "apriltag_" + n.substr(3);
	/* AprilTag 3's own names: tagStandard41h12 -> apriltag_standard41h12. */
	for (std::string_view kind : { "standard", "circle", "custom" }) {
		if (n.starts_with("tag") && n.substr(3).starts_with(kind))
			n = "apriltag_" + n.substr(3);
	}
	if (n == "aruco_mip_36h12" || n == "mip_36h12" || n == "arucomip36h12")
		n = "aruco_mip_36h12";
	return n;
}

} // namespace

const Dictionary *findDictionary(std::string_view name)
{
	const std::string wanted = canonicalName(name);
	for (const Dictionary &d : dictionaries()) {
		if (d.name == wanted)
			return &d;
	}
	return nullptr;
}

std::string dictionaryNames(std::string_view separator)
{
	std::string out;
	for (const Dictionary &d : dictionaries()) {
		if (!out.empty())
			out += separator;
		out += d.name;
	}
	return out;
}

std::uint64_t rotateCode(std::uint64_t code, int bits)
{
	/* bits^2 cells must fit the 64 bits of a code: shifting by 64 or more,
	 * or by a negative count, is undefined. */
	if (bits < 1 || bits > 8)
		throw std::invalid_argument("rotateCode: bits must be in [1, 8] (bits^2 cells in a 64-bit code), got " +
					    std::to_string(bits));
	/* Bit index of cell (row r, col c) is n*n-1 - (r*n + c). After a
	 * quarter turn clockwise, the cell at (r, c) comes from (n-1-c, r). */
	const int n = bits;
	const int top = n * n - 1;
	std::uint64_t out = 0;
	for (int r = 0; r < n; ++r) {
		for (int c = 0; c < n; ++c) {
			const int sr = n - 1 - c, sc = r;
			const std::uint64_t bit = (code >> (top - (sr * n + sc))) & 1u;
			out |= bit << (top - (r * n + c));
		}
	}
	return out;
}

} // namespace frappe
