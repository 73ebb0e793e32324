// SPDX-License-Identifier: MIT
#include "small_file.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace frappe::detail {

namespace {

/* Closes the descriptor however the read ends. */
struct Fd {
	int fd;
	~Fd()
	{
		if (fd >= 0)
			::close(fd);
	}
};

} // namespace

SmallFile readSmallFile(const std::string &path, std::size_t maxBytes)
{
	SmallFile f;
	/* Checked on what was opened, never on the name: the name may be
	 * replaced between a check and an open. */
	const Fd file{ ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY) };
	if (file.fd < 0) {
		f.fault = errno == ENOENT || errno == ENOTDIR ? SmallFile::Fault::NotFound : SmallFile::Fault::Unreadable;
		f.reason = std::strerror(errno);
		return f;
	}
	struct stat st {};
	if (::fstat(file.fd, &st) != 0) {
		f.fault = SmallFile::Fault::Unreadable;
		f.reason = std::strerror(errno);
		return f;
	}
	if (S_ISDIR(st.st_mode)) {
		f.fault = SmallFile::Fault::Directory;
		return f;
	}
	if (!S_ISREG(st.st_mode)) {
		f.fault = SmallFile::Fault::NotRegular;
		f.reason = S_ISFIFO(st.st_mode)	  ? "a FIFO"
			   : S_ISCHR(st.st_mode) ? "a character device"
			   : S_ISBLK(st.st_mode) ? "a block device"
			   : S_ISSOCK(st.st_mode) ? "a socket"
						  : "not a file";
		return f;
	}
	if (static_cast<std::uintmax_t>(st.st_size) > maxBytes) {
		f.fault = SmallFile::Fault::TooLarge;
		f.size = static_cast<std::uintmax_t>(st.st_size);
		return f;
	}
	/* Its size now, and one byte more to see it grow past the limit. */
	const std::size_t want = static_cast<std::size_t>(st.st_size) + 1;
	f.text.resize(std::min(want, maxBytes + 1));
	std::size_t got = 0;
	while (got < f.text.size()) {
		const ssize_t r = ::read(file.fd, f.text.data() + got, f.text.size() - got);
		if (r < 0 && errno == EINTR)
			continue;
		if (r < 0) {
			f.fault = SmallFile::Fault::Unreadable;
			f.reason = std::strerror(errno);
			f.text.clear();
			return f;
		}
		if (r == 0)
			break;
		got += static_cast<std::size_t>(r);
		/* Grown since fstat: read on, up to one byte past the limit. */
		if (got == f.text.size() && got <= maxBytes)
			f.text.resize(std::min(2 * got, maxBytes + 1));
	}
	if (got > maxBytes) {
		f.fault = SmallFile::Fault::TooLarge;
		f.size = got;
		f.text.clear();
		return f;
	}
	f.text.resize(got);
	return f;
}

void throwFileFault(const SmallFile &f, const std::string &where, std::string_view limit, std::string_view kind)
{
	using Fault = SmallFile::Fault;
	switch (f.fault) {
	case Fault::None: return;
	case Fault::NotFound: throw std::runtime_error(where + ": no such file");
	case Fault::Directory: throw std::runtime_error(where + ": not a regular file (a directory)");
	case Fault::NotRegular: throw std::runtime_error(where + ": not a regular file (" + f.reason + ")");
	case Fault::TooLarge:
		throw std::runtime_error(where + ": " + std::to_string(f.size) + " bytes, over the " + std::string(limit) + " a " +
					 std::string(kind) + " may have");
	case Fault::Unreadable: throw std::runtime_error(where + ": cannot be read: " + f.reason);
	}
}

} // namespace frappe::detail
