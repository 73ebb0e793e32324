// SPDX-License-Identifier: MIT
#include "runtime/os.hpp"

#include <cerrno>
#include <cstring>
#include <dirent.h>
#include <fcntl.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

namespace frappe::vc4::runtime {

namespace {

class SystemOs final : public Os {
public:
	int open(const std::string &path, int flags) override
	{
		const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
		return fd < 0 ? -errno : fd;
	}
	int close(int fd) override { return ::close(fd) < 0 ? -errno : 0; }
	int dup(int fd) override
	{
		const int r = ::fcntl(fd, F_DUPFD_CLOEXEC, 0);
		return r < 0 ? -errno : r;
	}
	int fileId(int fd, FileId &out) override
	{
		struct stat st;
		if (::fstat(fd, &st) < 0)
			return -errno;
		out.device = st.st_dev;
		out.inode = st.st_ino;
		out.size = static_cast<uint64_t>(st.st_size);
		return 0;
	}
	int ioctl(int fd, unsigned long request, void *arg) override
	{
		int r;
		do
			r = ::ioctl(fd, request, arg);
		while (r < 0 && errno == EINTR);
		return r < 0 ? -errno : r;
	}
	void *mmap(size_t length, int fd, uint64_t offset, int &error) override
	{
		void *p = ::mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd,
		                 static_cast<off_t>(offset));
		if (p == MAP_FAILED) {
			error = -errno;
			return nullptr;
		}
		error = 0;
		return p;
	}
	int munmap(void *address, size_t length) override
	{
		return ::munmap(address, length) < 0 ? -errno : 0;
	}
	std::optional<std::string> readFile(const std::string &path) override
	{
		/* Opened without waiting (a FIFO in the file's place), checked
		 * on the descriptor, read up to a bound (/dev/zero): device-tree
		 * and sysfs files are small regular files. */
		const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
		if (fd < 0)
			return std::nullopt;
		struct stat st;
		std::optional<std::string> text;
		if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) {
			std::string buf(kMaxReadFileBytes + 1, '\0');
			std::size_t got = 0;
			for (;;) {
				const ssize_t r = ::read(fd, buf.data() + got, buf.size() - got);
				if (r < 0 && errno == EINTR)
					continue;
				if (r <= 0 || (got += static_cast<std::size_t>(r)) == buf.size())
					break;
			}
			if (got <= kMaxReadFileBytes) {
				buf.resize(got);
				text = std::move(buf);
			}
		}
		::close(fd);
		return text;
	}
	std::vector<std::string> listDir(const std::string &path) override
	{
		std::vector<std::string> out;
		DIR *d = ::opendir(path.c_str());
		if (!d)
			return out;
		while (const dirent *e = ::readdir(d)) {
			const std::string name = e->d_name;
			if (name != "." && name != "..")
				out.push_back(name);
		}
		::closedir(d);
		return out;
	}
};

} // namespace

Os &systemOs()
{
	static SystemOs os;
	return os;
}

std::string errorText(int negative_errno)
{
	return std::strerror(-negative_errno);
}

} // namespace frappe::vc4::runtime
