/* SPDX-License-Identifier: MIT
 *
 * gstfrappemeta-export.h: what libgstfrappemeta-1.0 exports. The library is
 * built with hidden visibility, so only the declarations marked
 * GST_FRAPPE_META_API are its ABI (soname major.minor until 1.0:
 * docs/install.md).
 */
#pragma once

#if defined(_WIN32)
#define GST_FRAPPE_META_API
#else
#define GST_FRAPPE_META_API __attribute__((visibility("default")))
#endif
