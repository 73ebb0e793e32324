// SPDX-License-Identifier: MIT
// The benchmarks' percentile: linear between the two nearest samples.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace frappe::bench {

inline double percentile(std::vector<double> v, double p)
{
	if (v.empty())
		return 0;
	std::sort(v.begin(), v.end());
	const double idx = p * static_cast<double>(v.size() - 1);
	const std::size_t lo = static_cast<std::size_t>(idx);
	const std::size_t hi = std::min(lo + 1, v.size() - 1);
	return v[lo] + (idx - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

} // namespace frappe::bench
