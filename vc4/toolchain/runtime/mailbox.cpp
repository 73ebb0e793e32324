// SPDX-License-Identifier: MIT
#include "runtime/mailbox.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <fcntl.h>

#include "runtime/uapi.hpp"

namespace frappe::vc4::runtime {

namespace {

std::string hex(uint32_t v)
{
	char buf[16];
	std::snprintf(buf, sizeof buf, "0x%08x", v);
	return buf;
}

} // namespace

std::vector<uint32_t> propertyMessage(uint32_t tag, std::span<const uint32_t> request,
                                      unsigned response_words)
{
	const size_t value_words = std::max<size_t>(request.size(), response_words);
	std::vector<uint32_t> m;
	m.reserve(6 + value_words);
	m.push_back(0); // total size, filled in below
	m.push_back(uapi::kProcessRequest);
	m.push_back(tag);
	m.push_back(static_cast<uint32_t>(4 * value_words));
	m.push_back(0); // request: bit 31 clear
	m.insert(m.end(), request.begin(), request.end());
	m.resize(5 + value_words, 0);
	m.push_back(uapi::kEndTag);
	m[0] = static_cast<uint32_t>(4 * m.size());
	return m;
}

std::vector<uint32_t> propertyResponse(std::span<const uint32_t> m, unsigned response_words)
{
	if (m.size() < 6)
		throw RuntimeError("mailbox: short property message");
	const std::string what = "mailbox tag " + hex(m[2]) + ": ";
	if (m[1] == uapi::kResponseError)
		throw RuntimeError(what + "the firmware could not parse the request (" + hex(m[1]) + ")");
	if (m[1] != uapi::kResponseSuccess)
		throw RuntimeError(what + "the firmware did not answer (code " + hex(m[1]) +
		                   "); is this a Raspberry Pi with the vcio driver?");
	if ((m[4] & uapi::kTagResponse) == 0)
		throw RuntimeError(what + "the firmware does not know this tag (no response bit)");
	const uint32_t bytes = m[4] & ~uapi::kTagResponse;
	if (bytes < 4 * response_words || 5 + response_words > m.size())
		throw RuntimeError(what + "response of " + std::to_string(bytes) + " bytes, expected " +
		                   std::to_string(4 * response_words));
	return {m.begin() + 5, m.begin() + 5 + response_words};
}

Mailbox::Mailbox(Os &os, const std::string &path) : os_(os)
{
	fd_ = os_.open(path, O_RDWR);
	if (fd_ == -ENOENT)
		throw RuntimeError(path + " does not exist: not a Raspberry Pi kernel with the vcio "
		                          "mailbox driver (CONFIG_BCM2835_VCIO)");
	if (fd_ == -EACCES || fd_ == -EPERM)
		throw RuntimeError("permission denied opening " + path +
		                   ": run as root or install the udev rule of vc4/BRINGUP.md "
		                   "(KERNEL==\"vcio\", GROUP=\"video\", MODE=\"0660\") and join group video");
	if (fd_ < 0)
		throw RuntimeError("cannot open " + path + ": " + errorText(fd_));
}

Mailbox::~Mailbox()
{
	if (fd_ >= 0)
		os_.close(fd_);
}

std::vector<uint32_t> Mailbox::property(uint32_t tag, std::span<const uint32_t> request,
                                        unsigned response_words)
{
	std::vector<uint32_t> m = propertyMessage(tag, request, response_words);
	const int r = os_.ioctl(fd_, uapi::kIoctlMboxProperty, m.data());
	if (r == -ETIMEDOUT)
		throw TimeoutError("mailbox tag " + hex(tag) +
		                   ": the kernel gave up waiting for the firmware (1 s mailbox timeout)");
	if (r < 0)
		throw RuntimeError("mailbox tag " + hex(tag) + ": ioctl failed: " + errorText(r));
	return propertyResponse(m, response_words);
}

uint32_t Mailbox::setEnableQpu(bool enable)
{
	const uint32_t v[] = {enable ? 1u : 0u};
	return property(uapi::tag::set_enable_qpu, v, 1)[0];
}

uint32_t Mailbox::executeQpu(uint32_t qpus, uint32_t control, bool noflush, uint32_t timeout_ms)
{
	const uint32_t v[] = {qpus, control, noflush ? 1u : 0u, timeout_ms};
	return property(uapi::tag::execute_qpu, v, 1)[0];
}

uint32_t Mailbox::clockRate(uint32_t clock_id)
{
	const uint32_t v[] = {clock_id};
	return property(uapi::tag::clock_rate, v, 2)[1];
}

uint32_t Mailbox::firmwareRevision() { return property(uapi::tag::firmware_revision, {}, 1)[0]; }
uint32_t Mailbox::boardRevision() { return property(uapi::tag::board_revision, {}, 1)[0]; }

uint32_t Mailbox::memAllocate(uint32_t bytes, uint32_t align, uint32_t flags)
{
	const uint32_t v[] = {bytes, align, flags};
	return property(uapi::tag::allocate_memory, v, 1)[0];
}

uint32_t Mailbox::memLock(uint32_t handle)
{
	const uint32_t v[] = {handle};
	return property(uapi::tag::lock_memory, v, 1)[0];
}

uint32_t Mailbox::memUnlock(uint32_t handle)
{
	const uint32_t v[] = {handle};
	return property(uapi::tag::unlock_memory, v, 1)[0];
}

uint32_t Mailbox::memRelease(uint32_t handle)
{
	const uint32_t v[] = {handle};
	return property(uapi::tag::release_memory, v, 1)[0];
}

} // namespace frappe::vc4::runtime
