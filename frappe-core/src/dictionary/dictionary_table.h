// SPDX-License-Identifier: MIT
// The generated table of built-in dictionaries (see gen_dictionaries.py).
#pragma once

#include <cstddef>

#include "frappe/dictionary.h"

namespace frappe::detail {
extern const Dictionary kDictionaries[];
extern const std::size_t kDictionaryCount;
} // namespace frappe::detail
