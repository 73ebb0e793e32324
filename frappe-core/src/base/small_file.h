// SPDX-License-Identifier: MIT
// readSmallFile: the whole of a file a user names (a calibration, a
// dictionary), read without ever waiting on what the name turns out to be.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace frappe::detail {

struct SmallFile {
	enum class Fault { None, NotFound, Directory, NotRegular, TooLarge, Unreadable };
	Fault fault = Fault::None;
	std::string text;        ///< the contents, when no fault
	std::uintmax_t size = 0; ///< TooLarge: the bytes found (at least maxBytes + 1)
	std::string reason;      ///< NotRegular, Unreadable: what it is, or the system's error
};

/// Opens `path` once (O_NONBLOCK: a FIFO or a device put in a file's place
/// does not block the open), checks on that descriptor that it is a regular
/// file of at most `maxBytes`, and reads at most `maxBytes` + 1 bytes of it
/// (a file growing while read is TooLarge, never read without end).
SmallFile readSmallFile(const std::string &path, std::size_t maxBytes);

/// Throws std::runtime_error for f's fault (none: returns), naming the file
/// `where`: "WHERE: no such file", "WHERE: not a regular file (...)",
/// "WHERE: N bytes, over the LIMIT a KIND may have", "WHERE: cannot be
/// read: ...".
void throwFileFault(const SmallFile &f, const std::string &where, std::string_view limit, std::string_view kind);

} // namespace frappe::detail
