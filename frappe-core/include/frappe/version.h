// SPDX-License-Identifier: MIT
#pragma once

namespace frappe {
/// The library's version, "major.minor.patch".
const char *version();
} // namespace frappe
