// SPDX-License-Identifier: MIT
// libFuzzer target: detect() on frames of any size, stride, dictionary and
// content. The first bytes choose the geometry and the settings; the rest are
// the pixels, repeated to fill the frame. Any crash, sanitizer report or
// exception other than the documented std::invalid_argument is a finding.
//
// Frames stay at most 192 x 192 so that thousands run a second; sizes that
// matter for overflow (the 2^15 side, max_pixels) are the config target's.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <vector>

#include "frappe/frappe.h"

namespace {

/* One detector per dictionary and mode, made on first use: a detector's
 * state across frames (AScale, buffers sized for the largest frame) is part
 * of what is fuzzed. */
frappe::Detector &detectorFor(std::size_t dict, bool ascale, float regionContrast)
{
	static std::vector<std::unique_ptr<frappe::Detector>> cache;
	const auto dicts = frappe::dictionaries();
	const std::size_t slots = dicts.size() * 2 * 2;
	if (cache.empty())
		cache.resize(slots);
	const std::size_t d = dict % dicts.size();
	const std::size_t i = (d * 2 + (ascale ? 1 : 0)) * 2 + (regionContrast > 0.0f ? 1 : 0);
	if (!cache[i]) {
		frappe::Config c;
		c.dictionary = std::string(dicts[d].name);
		c.mode = ascale ? frappe::Mode::AScale : frappe::Mode::Normal;
		c.region_contrast = regionContrast;
		cache[i] = std::make_unique<frappe::Detector>(c);
	}
	return *cache[i];
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size)
{
	if (size < 6)
		return 0;
	const int w = 1 + data[0] % 192;
	const int h = 1 + data[1] % 192;
	const int pad = data[2] % 17;
	const bool ascale = (data[3] & 1) != 0;
	const float regionContrast = (data[3] & 2) != 0 ? 0.16f : 0.0f;
	const std::size_t dict = data[4];
	const int frames = 1 + data[5] % 2;
	const std::uint8_t *pixels = data + 6;
	const std::size_t n = size - 6;

	const int stride = w + pad;
	std::vector<std::uint8_t> frame(static_cast<std::size_t>(stride) * static_cast<std::size_t>(h));
	for (std::size_t i = 0; i < frame.size(); ++i)
		frame[i] = n ? pixels[i % n] : 0;

	frappe::Detector &det = detectorFor(dict, ascale, regionContrast);
	for (int f = 0; f < frames; ++f) {
		const frappe::Result &r = det.detect(frappe::ImageView(frame.data(), w, h, stride));
		for (const frappe::Marker &m : r.markers) {
			/* Every corner a finite point near the frame; a marker a known id. */
			for (const auto &p : m.corners)
				if (!(p.x > -w && p.x < 2.0f * w && p.y > -h && p.y < 2.0f * h))
					std::abort();
			if (m.id < 0 || m.id >= det.dictionary().size())
				std::abort();
		}
	}
	return 0;
}
