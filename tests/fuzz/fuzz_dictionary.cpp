// SPDX-License-Identifier: MIT
// libFuzzer target: a dictionary file of the user's own (parseDictionary),
// any bytes. The promise: a file that is not a dictionary is a
// std::invalid_argument; one that is has 1..4096 codes of a side 3..8 that
// fit its cells, no two ids alike in any rotation, and a Detector built on
// it reads a frame.
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "frappe/frappe.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size)
{
	std::shared_ptr<const frappe::Dictionary> d;
	try {
		d = frappe::parseDictionary(std::string_view(reinterpret_cast<const char *>(data), size), "fuzz");
	} catch (const std::invalid_argument &) {
		return 0;
	}
	const int cells = d->bits * d->bits;
	if (d->bits < 3 || d->bits > 8 || d->size() < 1 || d->size() > 4096 || d->name.empty() ||
	    d->min_hamming < 0 || d->min_hamming > cells)
		std::abort();
	int nearest = cells;
	for (int i = 0; i < d->size(); ++i) {
		if (cells < 64 && d->codes[i] >> cells)
			std::abort();
		std::uint64_t turned = d->codes[i];
		for (int r = 0; r < 4; ++r, turned = frappe::rotateCode(turned, d->bits)) {
			if (r > 0)
				nearest = std::min(nearest, std::popcount(turned ^ d->codes[i]));
			for (int j = 0; j < i; ++j) {
				if (turned == d->codes[j])
					std::abort(); /* two ids alike in a rotation */
				nearest = std::min(nearest, std::popcount(turned ^ d->codes[j]));
			}
		}
	}
	if (nearest != d->min_hamming)
		std::abort();

	/* The detector takes it and reads its last marker. */
	frappe::Config c;
	c.custom_dictionary = d;
	frappe::Detector det(c);
	int side = 0;
	const std::vector<std::uint8_t> img = frappe::markerImage(*d, d->size() - 1, 4, 1, side);
	det.detect({ img.data(), side, side, side });
	return 0;
}
