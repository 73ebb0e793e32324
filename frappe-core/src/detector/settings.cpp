// SPDX-License-Identifier: MIT
// The settings table (frappe/settings.h): every Config field once, with its
// range and a line of text, and the validation that iterates it.
#include "frappe/settings.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <type_traits>

#include "utf8.h"

namespace frappe {

namespace {

/* How many members an aggregate has: the most brace initialisers it takes. */
struct AnyValue {
	template<typename T>
	operator T() const;
};
template<typename T, typename... A>
constexpr std::size_t memberCount()
{
	if constexpr (requires { T{ A{}..., AnyValue{} }; })
		return memberCount<T, A..., AnyValue>();
	else
		return sizeof...(A);
}

/* A new Config member needs its entry below (or a word here on why no
 * surface can show it, as custom_dictionary, a shared object). */
constexpr std::size_t kFieldsWithoutSetting = 1;
constexpr std::size_t kSettingCount = 17;
static_assert(memberCount<Config>() == kSettingCount + kFieldsWithoutSetting,
	      "a Config field was added or removed: describe it in settings.cpp's table (frappe/settings.h)");

constexpr double kInf = std::numeric_limits<double>::infinity();

int largestMaxHamming()
{
	int most = 0;
	for (const Dictionary &d : dictionaries())
		most = std::max(most, d.codeBits() / 2);
	return most;
}

std::vector<Setting> makeTable()
{
	using C = Config;
	/* name, member, min, max, min_open, metavar, doc, surfaces */
	std::vector<Setting> t = {
		{ "dictionary", &C::dictionary, 0, 0, false, "NAME",
		  "marker family: a built-in dictionary's name, in the library's, dashed, OpenCV or AprilTag spelling",
		  kEverywhere },
		{ "mode", &C::mode, 0, 0, false, "MODE",
		  "normal: every frame at full resolution; ascale: scale frames down from the smallest marker of the "
		  "previous frame (video); track: search around the last frames' markers and a band of the rest "
		  "(video)",
		  kEverywhere },
		{ "edge_threshold", &C::edge_threshold, 0.0, 4.0, true, "E",
		  "Sobel magnitude (intensities in [0, 1]) an edge pixel must exceed; lower finds fainter markers, "
		  "traces more clutter",
		  kEverywhere },
		{ "corner_threshold", &C::corner_threshold, 0.0, 100.0, false, "C",
		  "Shi-Tomasi minimum eigenvalue for a corner; too high loses low-contrast corners, too low splits "
		  "them",
		  kEverywhere },
		{ "max_hamming", &C::max_hamming, -1, static_cast<double>(largestMaxHamming()), false, "H",
		  "bit errors corrected among cells read clearly; -1: the dictionary's careful default; at most half "
		  "its bits",
		  kEverywhere },
		{ "weak_margin", &C::weak_margin, 0.0, 1.0, false, "W",
		  "a cell nearer the threshold than this (of half the contrast) is a weak read, correctable beyond "
		  "max_hamming; 0: off",
		  kEverywhere },
		{ "scaled_size", &C::scaled_size, 8.0, 1000.0, false, "PX",
		  "ascale: side in pixels of the smallest marker after scaling", kEverywhere },
		{ "max_scaled_frames", &C::max_scaled_frames, 0, 1000, false, "N",
		  "ascale: at most this many scaled frames in a row before one at full resolution", kEverywhere },
		{ "track_cover_frames", &C::track_cover_frames, 1, 1000, false, "K",
		  "track: every part of the frame is searched for new markers at least once every K frames "
		  "(by the region map; by every path every 2K)",
		  kEverywhere },
		{ "region_contrast", &C::region_contrast, 0.0, 1.0, false, "R",
		  "contrast (intensities in [0, 1]) of the dark-region candidates that find blurred markers; 0: off "
		  "(faster)",
		  kEverywhere },
		{ "light_floor", &C::light_floor, 0.0, 1.0, false, "L",
		  "below mid-grey the thresholds follow the local brightness plus this; 0.5 or more: absolute "
		  "(the paper's); the ceiling of the floor from the frame's noise",
		  kEverywhere },
		{ "light_floor_noise", &C::light_floor_noise, 0.0, 100.0, false, "K",
		  "each frame's light floor is K times its noise deviation, between light_floor / 2 and "
		  "light_floor; 0: light_floor",
		  kEverywhere },
		{ "corner_cluster_radius", &C::corner_cluster_radius, 1.0, 32.0, false, "PX",
		  "corner pixels closer than this (traced resolution) are one corner", kEverywhere },
		{ "min_marker_side", &C::min_marker_side, 4.0, kInf, false, "PX",
		  "candidates whose sides average less than this (full-resolution pixels) are dropped", kEverywhere },
		{ "max_pixels", &C::max_pixels, 1, static_cast<double>(1LL << 30), false, "N",
		  "the largest frame in pixels accepted: a bound on a frame's memory and time", kEverywhere },
		{ "max_candidates", &C::max_candidates, 1, 1 << 20, false, "N",
		  "the most candidate outlines a frame reads; the rest are dropped and counted", kEverywhere },
		/* The element runs frames on threads as `pipelined` says. */
		{ "threads", &C::threads, 0, 256, false, "T",
		  "threads: whole frames at once in a pipeline, row bands in a lone detector; 0: one per core",
		  kOnCli | kOnPython },
	};
	return t;
}

std::string lower(std::string_view s)
{
	std::string out(s);
	for (char &c : out)
		c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
	return out;
}

template<typename T>
std::string numberText(T v)
{
	if constexpr (std::is_floating_point_v<T>) {
		if (std::isinf(v))
			return v > 0 ? "inf" : "-inf";
		if (std::isnan(v))
			return "nan";
	}
	char buf[40];
	const auto r = std::to_chars(buf, buf + sizeof(buf), v);
	return std::string(buf, r.ptr);
}

/* A bound as the member's type writes it; 2^n from 2^20 up. */
template<typename T>
std::string boundText(double v)
{
	if (v >= (1 << 20) && std::isfinite(v)) {
		const int e = static_cast<int>(std::lround(std::log2(v)));
		if (std::ldexp(1.0, e) == v)
			return "2^" + std::to_string(e);
	}
	if constexpr (std::is_floating_point_v<T>)
		return numberText(static_cast<T>(v));
	else
		return numberText(static_cast<long long>(v));
}

} // namespace

std::string Setting::kebabName() const
{
	std::string out(name);
	std::replace(out.begin(), out.end(), '_', '-');
	return out;
}

bool Setting::isChoice() const
{
	return std::holds_alternative<std::string Config::*>(member) || std::holds_alternative<Mode Config::*>(member);
}

bool Setting::isInteger() const
{
	return std::holds_alternative<int Config::*>(member) || std::holds_alternative<long long Config::*>(member);
}

double Setting::number(const Config &c) const
{
	return std::visit(
		[&](auto m) -> double {
			using T = std::remove_cvref_t<decltype(c.*m)>;
			if constexpr (std::is_arithmetic_v<T>)
				return static_cast<double>(c.*m);
			else
				throw std::logic_error("frappe::Setting::number: " + std::string(name) +
						       " is a choice");
		},
		member);
}

void Setting::setNumber(Config &c, double v) const
{
	std::visit(
		[&](auto m) {
			using T = std::remove_cvref_t<decltype(c.*m)>;
			if constexpr (std::is_floating_point_v<T>) {
				c.*m = static_cast<T>(v);
			} else if constexpr (std::is_integral_v<T>) {
				/* Out of the type's range (or NaN): a value validate() refuses. */
				if (!(v >= static_cast<double>(std::numeric_limits<T>::min()) &&
				      v <= static_cast<double>(std::numeric_limits<T>::max())))
					c.*m = std::numeric_limits<T>::min();
				else
					c.*m = static_cast<T>(v);
			} else {
				throw std::logic_error("frappe::Setting::setNumber: " + std::string(name) +
						       " is a choice");
			}
		},
		member);
}

std::string Setting::text(const Config &c) const
{
	return std::visit(
		[&](auto m) -> std::string {
			using T = std::remove_cvref_t<decltype(c.*m)>;
			if constexpr (std::is_same_v<T, std::string>)
				return c.*m;
			else if constexpr (std::is_same_v<T, Mode>)
				return std::string(modeName(c.*m));
			else
				return numberText(c.*m);
		},
		member);
}

void Setting::parse(Config &c, std::string_view text) const
{
	std::visit(
		[&](auto m) {
			using T = std::remove_cvref_t<decltype(c.*m)>;
			if constexpr (std::is_same_v<T, std::string>) {
				const Dictionary *d = findDictionary(text);
				if (!d)
					throw std::invalid_argument("unknown dictionary '" + std::string(text) +
								    "'; known: " + dictionaryNames() +
								    " (or OpenCV's DICT_6X6_250, AprilTag's tag36h11, "
								    "dashes for underscores)");
				c.*m = std::string(d->name);
			} else if constexpr (std::is_same_v<T, Mode>) {
				if (!parseMode(text, c.*m))
					throw std::invalid_argument("must be " + modeNames(" or ") + ", got '" +
								    std::string(text) + "'");
			} else {
				T v{};
				const char *end = text.data() + text.size();
				const auto r = std::from_chars(text.data(), end, v);
				if (text.empty() || r.ec != std::errc() || r.ptr != end)
					throw std::invalid_argument(std::string(std::is_integral_v<T>
											? "needs an integer"
											: "needs a number") +
								    ", got '" + std::string(text) + "'");
				c.*m = v;
			}
		},
		member);
}

std::vector<std::string> Setting::choices() const
{
	std::vector<std::string> out;
	if (std::holds_alternative<Mode Config::*>(member)) {
		out = { "normal", "ascale", "track" };
	} else if (std::holds_alternative<std::string Config::*>(member)) {
		for (const Dictionary &d : dictionaries())
			out.emplace_back(d.name);
	}
	return out;
}

std::string Setting::rangeText() const
{
	if (isChoice()) {
		std::string out;
		for (const std::string &s : choices())
			out += (out.empty() ? "" : ", ") + s;
		return out;
	}
	return std::visit(
		[&](auto m) -> std::string {
			using T = std::remove_cvref_t<decltype(Config{}.*m)>;
			if constexpr (std::is_arithmetic_v<T>) {
				if (std::isinf(max))
					return "at least " + boundText<T>(min);
				return (min_open ? "(" : "[") + boundText<T>(min) + ", " + boundText<T>(max) + "]";
			} else {
				return "";
			}
		},
		member);
}

bool Setting::inRange(double v) const
{
	return (min_open ? v > min : v >= min) && v <= max;
}

bool Setting::same(const Config &a, const Config &b) const
{
	return std::visit([&](auto m) { return a.*m == b.*m; }, member);
}

std::span<const Setting> settings()
{
	static const std::vector<Setting> table = makeTable();
	return table;
}

const Setting *findSetting(std::string_view name)
{
	std::string snake(name);
	std::replace(snake.begin(), snake.end(), '-', '_');
	for (const Setting &s : settings()) {
		if (s.name == snake)
			return &s;
	}
	return nullptr;
}

std::string_view modeName(Mode mode)
{
	return mode == Mode::AScale ? "ascale" : mode == Mode::Track ? "track" : "normal";
}

bool parseMode(std::string_view name, Mode &mode)
{
	const std::string n = lower(name);
	if (n == "normal")
		mode = Mode::Normal;
	else if (n == "ascale")
		mode = Mode::AScale;
	else if (n == "track")
		mode = Mode::Track;
	else
		return false;
	return true;
}

std::string modeNames(std::string_view separator)
{
	return "normal, ascale" + std::string(separator) + "track";
}

void validate(const Config &c)
{
	auto fail = [](const std::string &what) { throw std::invalid_argument("frappe::Config: " + what); };
	/* A dictionary of the user's own wins over the name. */
	const Dictionary *found = c.custom_dictionary ? c.custom_dictionary.get() : findDictionary(c.dictionary);
	if (!found)
		fail("unknown dictionary '" + c.dictionary + "'; known: " + dictionaryNames() +
		     ", or a file (loadDictionary())");
	const Dictionary &d = *found;
	if (c.custom_dictionary) {
		/* One made by hand rather than by loadDictionary(): what the
		 * decoder and the sample grid rely on. */
		if (!d.layout && (d.bits < 3 || d.bits > 8))
			fail("custom_dictionary: bits must be 3..8, got " + std::to_string(d.bits));
		if (d.layout && (d.layout->size + 2 > 16 || d.bits != d.layout->square_cells - 2))
			fail("custom_dictionary: a layout of at most 14 cells a side, with bits its square's cells "
			     "less 2");
		if (d.codes.empty())
			fail("custom_dictionary: no codes");
		/* Every output carries the name: JSON, GStreamer, Python. */
		if (detail::invalidUtf8At(d.name) != std::string_view::npos)
			fail("custom_dictionary: the name is not UTF-8 text");
		const int cells = d.codeBits();
		for (std::uint64_t code : d.codes) {
			if (cells < 64 && code >> cells)
				fail("custom_dictionary: a code with bits beyond the " + std::to_string(cells) +
				     " cells");
		}
	}
	for (const Setting &s : settings()) {
		if (s.isChoice())
			continue;
		if (!s.inRange(s.number(c)))
			fail(std::string(s.name) + " must be " + (std::isinf(s.max) ? "" : "in ") + s.rangeText() +
			     ", got " + s.text(c));
	}
	if (c.mode != Mode::Normal && c.mode != Mode::AScale && c.mode != Mode::Track)
		fail("mode must be Normal, AScale or Track");
	/* The table's range is the widest over the dictionaries: this one's. */
	if (c.max_hamming > d.codeBits() / 2)
		fail("max_hamming must be -1 (dictionary default) or 0.." + std::to_string(d.codeBits() / 2) + " for " +
		     std::string(d.name) + ", got " + std::to_string(c.max_hamming));
}

} // namespace frappe
