// SPDX-License-Identifier: MIT
// The firmware mailbox property interface over /dev/vcio: QPU enable, execute_qpu, the
// legacy GPU memory calls, clock and board queries. Messages are built and checked by
// pure functions (tested byte for byte); Mailbox only adds the ioctl.
#pragma once

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "runtime/os.hpp"

namespace frappe::vc4::runtime {

// Anything the runtime cannot do, with a message meant for the user.
class RuntimeError : public std::runtime_error {
public:
	using std::runtime_error::runtime_error;
};

// A QPU launch that did not finish in time (firmware execute_qpu timeout or the kernel's
// one-second mailbox timeout).
class TimeoutError : public RuntimeError {
public:
	using RuntimeError::RuntimeError;
};

// One-tag property message: [size, process-request, tag, value-buffer bytes, 0 (request),
// values padded to the buffer, end tag]. The value buffer is as large as the larger of the
// request and the expected response.
std::vector<uint32_t> propertyMessage(uint32_t tag, std::span<const uint32_t> request,
                                      unsigned response_words);

// Checks a message the firmware answered and returns the tag's response values.
// Throws RuntimeError naming the tag when the firmware did not process it.
std::vector<uint32_t> propertyResponse(std::span<const uint32_t> message, unsigned response_words);

class Mailbox {
public:
	// Opens /dev/vcio; throws RuntimeError with a reason (missing, permissions).
	explicit Mailbox(Os &os, const std::string &path = "/dev/vcio");
	~Mailbox();
	Mailbox(const Mailbox &) = delete;
	Mailbox &operator=(const Mailbox &) = delete;

	// Sends one tag and returns its response values.
	std::vector<uint32_t> property(uint32_t tag, std::span<const uint32_t> request,
	                               unsigned response_words);

	// Returns the firmware's status word: 0 = done.
	uint32_t setEnableQpu(bool enable);
	// Runs `qpus` programs described by (uniforms, code) bus-address pairs at `control`;
	// returns 0 when they all ended, non-zero on the firmware's timeout.
	uint32_t executeQpu(uint32_t qpus, uint32_t control, bool noflush, uint32_t timeout_ms);
	uint32_t clockRate(uint32_t clock_id);
	uint32_t firmwareRevision();
	uint32_t boardRevision();
	// Legacy GPU memory (carved out of gpu_mem): handle, bus address, status 0 = done.
	uint32_t memAllocate(uint32_t bytes, uint32_t align, uint32_t flags);
	uint32_t memLock(uint32_t handle);
	uint32_t memUnlock(uint32_t handle);
	uint32_t memRelease(uint32_t handle);

private:
	Os &os_;
	int fd_ = -1;
};

} // namespace frappe::vc4::runtime
