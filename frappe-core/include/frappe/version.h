// SPDX-License-Identifier: MIT
#pragma once

namespace frappe {
/// The library's version, "major.minor.patch".
const char *version();
/// The instruction set the detector's per-pixel kernels run with on this
/// CPU: a Highway target name ("AVX2", "AVX3", "NEON", "EMU128", ...) where
/// the library was built with Highway, else "ARMv6 SIMD32" or "scalar".
/// For logs and bug reports: which code ran.
const char *simdTarget();
} // namespace frappe
