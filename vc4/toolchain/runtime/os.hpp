// SPDX-License-Identifier: MIT
// The few system calls the real-GPU runtime makes, behind an interface so that tests can
// replace the kernel with fakes. Calls return >= 0 on success and -errno on failure.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace frappe::vc4::runtime {

// Which file an fd is (fstat): two fds name the same dma-buf when device and inode match,
// whatever their numbers.
struct FileId {
	uint64_t device = 0;
	uint64_t inode = 0;
	uint64_t size = 0; // bytes (a dma-buf's size)
	bool operator==(const FileId &o) const { return device == o.device && inode == o.inode; }
};

class Os {
public:
	virtual ~Os() = default;
	virtual int open(const std::string &path, int flags) = 0;
	virtual int close(int fd) = 0;
	virtual int dup(int fd) = 0;
	virtual int fileId(int fd, FileId &out) = 0;
	virtual int ioctl(int fd, unsigned long request, void *arg) = 0;
	// Shared read-write mapping of `length` bytes of `fd` at `offset`; nullptr on failure
	// with -errno in `error`.
	virtual void *mmap(size_t length, int fd, uint64_t offset, int &error) = 0;
	virtual int munmap(void *address, size_t length) = 0;
	// Whole contents of a (small, sysfs/procfs) file; nullopt when it cannot be read, is not a
	// regular file (a FIFO, a device) or holds more than kMaxReadFileBytes.
	virtual std::optional<std::string> readFile(const std::string &path) = 0;
	static constexpr std::size_t kMaxReadFileBytes = 64 << 10;
	// Names in a directory (without . and ..); empty when it does not exist.
	virtual std::vector<std::string> listDir(const std::string &path) = 0;
};

// The real system calls.
Os &systemOs();

// strerror-style text for a negative errno value.
std::string errorText(int negative_errno);

} // namespace frappe::vc4::runtime
