// SPDX-License-Identifier: MIT
// libFuzzer target: the settings a user types. A dictionary name (any bytes)
// and every Config field from the input, then a Detector and a Pipeline on
// them and a frame of a fuzzed size; and the public helpers (rotateCode,
// markerImage) on fuzzed arguments. The library's promise: a bad setting or
// frame is a std::invalid_argument, nothing else; a good one detects.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "frappe/frappe.h"

namespace {

/* Reads values off the input, zeros once it runs out. */
class Reader
{
public:
	Reader(const std::uint8_t *data, std::size_t size) : data_(data), size_(size) {}
	template<typename T>
	T get()
	{
		T v{};
		const std::size_t n = std::min(sizeof(T), size_ - at_);
		std::memcpy(&v, data_ + at_, n);
		at_ += n;
		return v;
	}
	std::string_view text(std::size_t most)
	{
		const std::size_t n = std::min<std::size_t>(get<std::uint8_t>() % (most + 1), size_ - at_);
		std::string_view s(reinterpret_cast<const char *>(data_ + at_), n);
		at_ += n;
		return s;
	}

private:
	const std::uint8_t *data_;
	std::size_t size_;
	std::size_t at_ = 0;
};

/* A float that is often in a sensible range and sometimes anything. */
float number(Reader &in, float typical)
{
	const std::uint8_t how = in.get<std::uint8_t>();
	const float raw = in.get<float>();
	switch (how % 4) {
	case 0: return typical;
	case 1: return typical * static_cast<float>(how) / 64.0f;
	default: return raw; /* NaN, infinities, negatives, huge */
	}
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size)
{
	Reader in(data, size);
	frappe::Config c;
	const std::string_view name = in.text(40);
	const auto dicts = frappe::dictionaries();
	/* Half the time a real name, so the other fields get fuzzed past it. */
	if ((in.get<std::uint8_t>() & 1) != 0)
		c.dictionary = std::string(dicts[in.get<std::uint8_t>() % dicts.size()].name);
	else
		c.dictionary = std::string(name);
	const frappe::Dictionary *found = frappe::findDictionary(name);
	if (found && frappe::findDictionary(found->name) != found)
		std::abort(); /* a dictionary's own name finds it */

	static constexpr frappe::Mode kModes[] = { frappe::Mode::Normal, frappe::Mode::AScale, frappe::Mode::Track };
	c.mode = kModes[in.get<std::uint8_t>() % 3];
	/* Every number of the settings table, from its default (Config{}'s):
	 * a new setting is fuzzed without a line here. */
	for (const frappe::Setting &s : frappe::settings()) {
		if (s.isChoice())
			continue;
		const double typical = s.number(c);
		if (!s.isInteger()) {
			s.setNumber(c, number(in, static_cast<float>(typical)));
			continue;
		}
		const std::uint8_t how = in.get<std::uint8_t>();
		const std::int32_t raw = in.get<std::int32_t>();
		switch (how % 4) {
		case 0: s.setNumber(c, typical); break;
		case 1: s.setNumber(c, typical + static_cast<std::int8_t>(how) / 8); break;
		case 2: s.setNumber(c, raw % 8); break;
		default: s.setNumber(c, raw); break; /* negatives, huge */
		}
	}

	/* Geometry: sizes, strides and the pixel count around the limits. */
	const int w = in.get<std::int16_t>() % 300;
	const int h = in.get<std::int16_t>() % 300;
	const int stride = w + in.get<std::int8_t>() % 8;
	std::vector<std::uint8_t> pixels(static_cast<std::size_t>(std::max(0, stride)) *
					 static_cast<std::size_t>(std::max(0, h)) + 1, 128);
	const frappe::ImageView view(pixels.data(), w, h, stride);

	const std::uint8_t pipelineMode = in.get<std::uint8_t>();

	/* The public helpers: a bad argument is std::invalid_argument (or
	 * std::out_of_range for an id), never undefined behaviour. Cells stay
	 * small: a 32768 px marker image is legal, and a gigabyte. */
	try {
		const frappe::Dictionary &d = dicts[in.get<std::uint8_t>() % dicts.size()];
		frappe::rotateCode(in.get<std::uint64_t>(), in.get<std::int8_t>());
		int side = 0;
		frappe::markerImage(d, in.get<std::int16_t>(), in.get<std::int8_t>() % 24, in.get<std::int8_t>() % 8,
				    side);
	} catch (const std::invalid_argument &) {
	} catch (const std::out_of_range &) {
	}

	try {
		frappe::Detector det(c);
		try {
			det.detect(view);
		} catch (const std::invalid_argument &) {
		}
		/* Overlap::Stages at latency 2 or 1 (the element's staged overlap). */
		const bool staged = (pipelineMode & 1) != 0;
		frappe::Pipeline pipeline(
			c, staged ? frappe::Pipeline::Overlap::Stages : frappe::Pipeline::Overlap::Frames,
			staged ? 2 - ((pipelineMode >> 1) & 1) : frappe::Pipeline::kDefaultLatency);
		try {
			pipeline.push(view);
		} catch (const std::invalid_argument &) {
		}
		while (pipeline.flush()) {
		}
	} catch (const std::invalid_argument &) {
		/* a refused setting: the documented answer */
	}
	return 0;
}
