// SPDX-License-Identifier: MIT
#include "small_file.h"

#include <algorithm>
#include <cerrno>
#include <cstring>

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

} // namespace frappe::detail
