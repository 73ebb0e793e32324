// SPDX-License-Identifier: MIT
// Runs a check once per Highway target this CPU has (so that the vector
// kernels of every target are compared, not only the best one's), or once
// in a build without Highway. Tests built with FRAPPE_TEST_HWY_TARGETS link
// libhwy (tests/meson.build).
#pragma once

#include <cstdio>

#include <gtest/gtest.h>

#ifdef FRAPPE_TEST_HWY_TARGETS
#include <hwy/targets.h>
#endif

namespace frappe::test {

/// Calls check(name) with each target selected in turn, then restores
/// Highway's own choice.
template <class F>
void onEveryTarget(F check)
{
#if defined(FRAPPE_TEST_HWY_TARGETS) && defined(HWY_COMPILE_ONLY_STATIC)
	/* Built for one target and called without a run-time check (aarch64:
	 * frappe-core/meson.build): whatever the CPU reports, that one runs. */
	check(hwy::TargetName(HWY_STATIC_TARGET));
	std::printf("compared on %s (the only target built)\n", hwy::TargetName(HWY_STATIC_TARGET));
#elif defined(FRAPPE_TEST_HWY_TARGETS)
	int targets = 0;
	for (const std::int64_t t : hwy::SupportedAndGeneratedTargets()) {
		hwy::SetSupportedTargetsForTest(t);
		check(hwy::TargetName(t));
		std::printf("compared on %s\n", hwy::TargetName(t));
		++targets;
	}
	hwy::SetSupportedTargetsForTest(0);
	EXPECT_GE(targets, 1);
#else
	check("build without Highway");
#endif
}

} // namespace frappe::test
