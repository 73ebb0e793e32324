// SPDX-License-Identifier: MIT
// A pretend Raspberry Pi kernel for the runtime tests: files and directories, device
// nodes that open or fail with a chosen errno, a firmware answering mailbox property
// messages, a dma-heap, vcsm-cma and /dev/mem. Every call is logged so that tests can
// check ordering (cache syncs around launches) as well as bytes.
#pragma once

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <functional>
#include <list>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "runtime/os.hpp"
#include "runtime/uapi.hpp"

namespace frappe::vc4::runtime::test {

inline std::string hex32(uint64_t v)
{
	char b[24];
	std::snprintf(b, sizeof b, "0x%08llx", static_cast<unsigned long long>(v));
	return b;
}

class FakeOs final : public Os {
public:
	// What exists.
	std::map<std::string, std::string> files;
	std::map<std::string, std::vector<std::string>> dirs;
	std::set<std::string> devices;
	std::map<std::string, int> open_errors; // path -> -errno

	// Firmware behaviour.
	uint32_t enable_status = 0;  // set_enable_qpu answer
	uint32_t execute_status = 0; // execute_qpu answer
	int execute_errno = 0;       // ioctl result for execute_qpu (e.g. -ETIMEDOUT)
	// When set, runs execute_qpu's programs (count, control block bus address) over the
	// fake's memory (bus_to_cpu) and returns its status.
	std::function<uint32_t(uint32_t, uint32_t)> execute;
	uint32_t parse_code = uapi::kResponseSuccess;
	uint32_t v3d_hz = 300'000'000;
	uint32_t next_handle = 7;
	uint32_t locked_bus = 0xDE000000; // bus address of the first locked handle
	uint64_t next_dma_addr = 0x1F000000;

	// What happened.
	std::vector<std::string> log;
	std::vector<std::vector<uint32_t>> messages; // property messages as sent
	std::vector<std::vector<uint32_t>> control_blocks; // execute_qpu control blocks, read at launch
	std::map<int, std::string> open_fds;

	void pi(const std::string &model = "Raspberry Pi Zero W Rev 1.1", const std::string &soc = "bcm2835")
	{
		files["/proc/device-tree/model"] = model + std::string(1, '\0');
		files["/proc/device-tree/compatible"] = "raspberrypi,model-zero-w" + std::string(1, '\0') + "brcm," + soc +
		                                        std::string(1, '\0');
		devices.insert("/dev/vcio");
	}
	void dmaHeap()
	{
		devices.insert("/dev/dma_heap/vidbuf_cached");
		devices.insert("/dev/vcsm-cma");
	}

	int open(const std::string &path, int) override
	{
		log.push_back("open " + path);
		if (auto it = open_errors.find(path); it != open_errors.end())
			return it->second;
		if (!devices.count(path))
			return -ENOENT;
		const int fd = next_fd_++;
		open_fds[fd] = path;
		return fd;
	}
	int close(int fd) override
	{
		auto it = open_fds.find(fd);
		if (it == open_fds.end())
			return -EBADF;
		log.push_back("close " + it->second);
		open_fds.erase(it);
		return 0;
	}
	// A dma-buf made elsewhere (a camera's): `inode` names the buffer, `fd` its number
	// (-1: the next free one), backed by zeroed memory the test fills (cpu()).
	int cameraBuffer(const std::string &name, size_t bytes, uint64_t inode, int fd = -1)
	{
		if (fd < 0)
			fd = next_fd_++;
		open_fds[fd] = name;
		sizes_[fd] = bytes;
		inodes_[name] = inode;
		auto &m = maps_.emplace_back(bytes, uint8_t{0});
		dmabuf_map_[name] = m.data();
		return fd;
	}
	uint8_t *cpu(const std::string &name) { return dmabuf_map_[name]; }
	std::set<std::string> refuse_import; // dma-bufs vcsm-cma will not import (-EINVAL)

	int dup(int fd) override
	{
		auto it = open_fds.find(fd);
		if (it == open_fds.end())
			return -EBADF;
		const int d = next_fd_++;
		open_fds[d] = it->second;
		sizes_[d] = sizes_[fd];
		log.push_back("dup " + it->second);
		return d;
	}
	int fileId(int fd, FileId &out) override
	{
		auto it = open_fds.find(fd);
		if (it == open_fds.end())
			return -EBADF;
		auto ino = inodes_.find(it->second);
		out.device = 9;
		out.inode = ino == inodes_.end() ? 1000 + static_cast<uint64_t>(fd) : ino->second;
		out.size = sizes_[fd];
		return 0;
	}
	int ioctl(int fd, unsigned long request, void *arg) override
	{
		auto it = open_fds.find(fd);
		if (it == open_fds.end())
			return -EBADF;
		const std::string path = it->second;
		log.push_back("ioctl " + path + " " + hex32(request));
		if (path == "/dev/vcio" && request == uapi::kIoctlMboxProperty)
			return firmware(static_cast<uint32_t *>(arg));
		if (path.rfind("/dev/dma_heap/", 0) == 0 && request == uapi::kIoctlDmaHeapAlloc) {
			auto *a = static_cast<uapi::DmaHeapAllocationData *>(arg);
			const int buf = next_fd_++;
			open_fds[buf] = "dmabuf" + std::to_string(++dmabufs_);
			sizes_[buf] = a->len;
			a->fd = static_cast<uint32_t>(buf);
			log.back() += " len=" + std::to_string(a->len) + " -> " + open_fds[buf];
			return 0;
		}
		if (path == "/dev/vcsm-cma" && request == uapi::kIoctlVcsmImportDmabuf) {
			auto *im = static_cast<uapi::VcsmImportDmabuf *>(arg);
			auto src = open_fds.find(im->dmabuf_fd);
			if (src == open_fds.end())
				return -EBADF;
			if (refuse_import.count(src->second)) {
				log.back() += " " + src->second + " refused";
				return -EINVAL;
			}
			const int h = next_fd_++;
			open_fds[h] = "import-of-" + src->second;
			im->handle = h;
			im->vc_handle = 0x100 + static_cast<uint32_t>(h);
			im->size = static_cast<uint32_t>(sizes_[im->dmabuf_fd]);
			im->dma_addr = next_dma_addr;
			bus_to_cpu[(static_cast<uint32_t>(next_dma_addr) & 0x3fffffffu) | 0xC0000000u] = dmabuf_map_[src->second];
			bus_size[(static_cast<uint32_t>(next_dma_addr) & 0x3fffffffu) | 0xC0000000u] = sizes_[im->dmabuf_fd];
			next_dma_addr += (sizes_[im->dmabuf_fd] + 0xffff) & ~uint64_t{0xffff};
			log.back() += " " + src->second + " cached=" + std::to_string(im->cached) + " name=" +
			              reinterpret_cast<const char *>(im->name);
			return 0;
		}
		if ((path.rfind("dmabuf", 0) == 0 || inodes_.count(path)) && request == uapi::kIoctlDmaBufSync) {
			log.back() = "sync " + path + " " + hex32(static_cast<uapi::DmaBufSync *>(arg)->flags);
			return 0;
		}
		return -ENOTTY;
	}
	void *mmap(size_t length, int fd, uint64_t offset, int &error) override
	{
		auto it = open_fds.find(fd);
		if (it == open_fds.end()) {
			error = -EBADF;
			return nullptr;
		}
		log.push_back("mmap " + it->second + " " + std::to_string(length) + " @" + hex32(offset));
		auto &m = maps_.emplace_back(length, uint8_t{0xA5}); // garbage: alloc must zero
		mapped_[m.data()] = {it->second, offset};
		if (it->second == "/dev/mem") {
			bus_to_cpu[static_cast<uint32_t>(offset) | 0xC0000000u] = m.data();
			bus_size[static_cast<uint32_t>(offset) | 0xC0000000u] = length;
		}
		else
			dmabuf_map_[it->second] = m.data();
		error = 0;
		return m.data();
	}
	int munmap(void *address, size_t length) override
	{
		log.push_back("munmap " + mapped_[address].first + " " + std::to_string(length));
		mapped_.erase(address);
		return 0;
	}
	std::optional<std::string> readFile(const std::string &path) override
	{
		auto it = files.find(path);
		if (it == files.end())
			return std::nullopt;
		return it->second;
	}
	std::vector<std::string> listDir(const std::string &path) override
	{
		auto it = dirs.find(path);
		return it == dirs.end() ? std::vector<std::string>{} : it->second;
	}

	// The CPU view of bus address `bus` (in any mapped buffer), for reading control blocks.
	const uint8_t *cpuOf(uint32_t bus) const
	{
		for (const auto &[bus0, ptr] : bus_to_cpu)
			if (bus >= bus0 && bus - bus0 < bus_size.at(bus0))
				return ptr + (bus - bus0);
		return nullptr;
	}
	std::map<uint32_t, uint8_t *> bus_to_cpu; // from /dev/mem offsets and vcsm imports
	std::map<uint32_t, uint64_t> bus_size;

	std::vector<std::string> entries(const std::string &prefix) const
	{
		std::vector<std::string> out;
		for (const auto &l : log)
			if (l.rfind(prefix, 0) == 0)
				out.push_back(l);
		return out;
	}

private:
	int firmware(uint32_t *m)
	{
		const uint32_t bytes = m[0];
		messages.emplace_back(m, m + bytes / 4);
		const uint32_t tag = m[2];
		log.back() += " tag=" + hex32(tag);
		uint32_t *v = m + 5;
		unsigned words = 1;
		switch (tag) {
		case uapi::tag::set_enable_qpu: v[0] = enable_status; break;
		case uapi::tag::execute_qpu:
			if (const uint8_t *c = cpuOf(v[1])) {
				std::vector<uint32_t> block(2 * v[0]);
				std::memcpy(block.data(), c, 8 * v[0]);
				control_blocks.push_back(block);
			}
			if (execute_errno)
				return execute_errno;
			v[0] = execute ? execute(v[0], v[1]) : execute_status;
			break;
		case uapi::tag::clock_rate: v[1] = v3d_hz; words = 2; break;
		case uapi::tag::firmware_revision: v[0] = 0x5f5e1000; break;
		case uapi::tag::allocate_memory: v[0] = next_handle++; break;
		case uapi::tag::lock_memory: v[0] = locked_bus + 0x100000 * (v[0] - 7); break;
		case uapi::tag::unlock_memory:
		case uapi::tag::release_memory: v[0] = 0; break;
		default: return 0; // unknown: no response bit
		}
		m[1] = parse_code;
		m[4] = uapi::kTagResponse | (4 * words);
		return 0;
	}

	int next_fd_ = 3;
	int dmabufs_ = 0;
	std::map<int, uint64_t> sizes_;
	std::list<std::vector<uint8_t>> maps_;
	std::map<void *, std::pair<std::string, uint64_t>> mapped_;
	std::map<std::string, uint8_t *> dmabuf_map_;
	std::map<std::string, uint64_t> inodes_;
};

} // namespace frappe::vc4::runtime::test
