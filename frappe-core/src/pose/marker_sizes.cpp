// SPDX-License-Identifier: MIT
// frappe::MarkerSizes: the side of each marker id, from "id:size,...".
#include "frappe/pose.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace frappe {

namespace {

std::string_view trim(std::string_view s)
{
	while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
		s.remove_prefix(1);
	while (!s.empty() && (s.back() == ' ' || s.back() == '\t'))
		s.remove_suffix(1);
	return s;
}

[[noreturn]] void fail(std::string_view entry, const std::string &why)
{
	throw std::invalid_argument("marker sizes: \"" + std::string(entry) + "\": " + why);
}

/* The whole of `s` as a number, or false. */
template<typename T>
bool parseWhole(std::string_view s, T &value)
{
	if (s.empty())
		return false;
	const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
	return ec == std::errc() && end == s.data() + s.size();
}

} // namespace

MarkerSizes MarkerSizes::parse(std::string_view spec, double default_size)
{
	if (!std::isfinite(default_size) || default_size < 0.0)
		throw std::invalid_argument("marker sizes: the default size must be 0 (none) or positive, got " +
					    std::to_string(default_size));
	/* Every surface (the element under its lock, the CLI, Python) parses
	 * at most this much: a few milliseconds. */
	if (spec.size() > kMaxSpecBytes)
		throw std::invalid_argument("marker sizes: " + std::to_string(spec.size()) + " bytes, more than the " +
					    std::to_string(kMaxSpecBytes) + " a list of sizes may have");
	MarkerSizes sizes(default_size);
	if (trim(spec).empty())
		return sizes;
	/* Where each entry is in `spec`, to name the second of a repeated id
	 * once all are sorted: appending then sorting is n log n where
	 * inserting in order was quadratic. */
	std::vector<std::size_t> at;
	const std::string_view whole = spec;
	while (true) {
		const std::size_t comma = spec.find(',');
		const std::string_view entry = trim(spec.substr(0, comma));
		if (entry.empty())
			fail(entry, "an empty entry (a stray comma?)");
		const std::size_t colon = entry.find(':');
		if (colon == std::string_view::npos)
			fail(entry, "expected id:size (e.g. 7:0.05)");
		const std::string_view id_text = trim(entry.substr(0, colon));
		const std::string_view size_text = trim(entry.substr(colon + 1));
		int id;
		double size;
		if (!parseWhole(id_text, id))
			fail(entry, "the id is not an integer");
		if (id < 0)
			fail(entry, "the id is negative");
		if (!parseWhole(size_text, size))
			fail(entry, "the size is not a number");
		if (!std::isfinite(size) || !(size > 0.0))
			fail(entry, "the size must be positive and finite (metres)");
		sizes.sizes_.push_back({ id, size });
		at.push_back(static_cast<std::size_t>(entry.data() - whole.data()));
		if (comma == std::string_view::npos)
			break;
		spec.remove_prefix(comma + 1);
	}
	std::vector<std::size_t> order(at.size());
	for (std::size_t i = 0; i < order.size(); ++i)
		order[i] = i;
	const auto &s = sizes.sizes_;
	std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return s[a].first < s[b].first; });
	/* The repeat met first in the text, as a scan in order would. */
	std::size_t repeat = order.size();
	for (std::size_t k = 1; k < order.size(); ++k)
		if (s[order[k]].first == s[order[k - 1]].first && (repeat == order.size() || order[k] < repeat))
			repeat = order[k];
	if (repeat != order.size()) {
		const std::string_view rest = whole.substr(at[repeat]);
		fail(trim(rest.substr(0, rest.find(','))), "id " + std::to_string(s[repeat].first) + " is given twice");
	}
	std::vector<std::pair<int, double>> sorted;
	sorted.reserve(order.size());
	for (std::size_t i : order)
		sorted.push_back(s[i]);
	sizes.sizes_ = std::move(sorted);
	return sizes;
}

double MarkerSizes::operator()(int id) const
{
	const auto at = std::lower_bound(sizes_.begin(), sizes_.end(), id,
					 [](const auto &e, int i) { return e.first < i; });
	return at != sizes_.end() && at->first == id ? at->second : default_;
}

bool MarkerSizes::any() const
{
	return default_ > 0.0 || !sizes_.empty();
}

std::string MarkerSizes::toString() const
{
	std::string out;
	for (const auto &[id, size] : sizes_) {
		char buf[32];
		/* The shortest text that reads back as the same double. */
		const auto end = std::to_chars(buf, buf + sizeof(buf), size).ptr;
		if (!out.empty())
			out += ',';
		out += std::to_string(id) + ':' + std::string(buf, end);
	}
	return out;
}

} // namespace frappe
