// SPDX-License-Identifier: MIT
// floor and ceil to int by conversions only: ARMv6's VFPv2 has no rounding
// instruction, and Debian armel's libm floorf/ceilf are calls into soft-float
// code. For finite x within int's range (image coordinates).
#pragma once

namespace frappe::detail {

inline int floorInt(float x)
{
	const int i = static_cast<int>(x);
	return static_cast<float>(i) > x ? i - 1 : i;
}

inline int ceilInt(float x)
{
	const int i = static_cast<int>(x);
	return static_cast<float>(i) < x ? i + 1 : i;
}

} // namespace frappe::detail
