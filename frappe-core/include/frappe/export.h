// SPDX-License-Identifier: MIT
// frappe/export.h: what libfrappe-core exports. The library is built with
// hidden visibility (-fvisibility=hidden), so only what is marked here is
// part of its ABI; frappe::detail and the stages' internals stay inside.
#pragma once

#if defined(_WIN32)
#define FRAPPE_EXPORT
#else
#define FRAPPE_EXPORT __attribute__((visibility("default")))
#endif

/* For the private parts of exported classes (their Impl), defined in the
 * library's sources: nested classes take their enclosing class's
 * visibility otherwise. */
#if defined(_WIN32)
#define FRAPPE_HIDDEN
#else
#define FRAPPE_HIDDEN __attribute__((visibility("hidden")))
#endif
