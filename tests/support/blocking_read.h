// SPDX-License-Identifier: MIT
// What a reader of a named file does when the name is a FIFO with no
// writer: the message it throws, or "blocked" when it waited (issue 34: an
// open by name blocked forever). A blocked reader is set free by opening
// the FIFO's write end, so that the test fails rather than hangs.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdio>
#include <exception>
#include <fstream>
#include <functional>
#include <string>
#include <thread>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace frappe::test {

/* Runs `work` on a thread and waits up to `seconds` for it, polling: no
 * std::future, whose timed wait libstdc++ lacks on ARMv6 (no futex
 * atomics there). When it has not finished, `unblock` sets it free. True
 * when it finished in time. */
inline bool finishedWithin(double seconds, const std::function<void()> &work, const std::function<void()> &unblock)
{
	std::atomic<bool> done{ false };
	std::thread worker([&] {
		work();
		done = true;
	});
	const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
	while (!done && std::chrono::steady_clock::now() < end)
		std::this_thread::sleep_for(std::chrono::milliseconds(5));
	const bool finished = done;
	if (!finished)
		unblock();
	worker.join();
	return finished;
}

inline std::string readingFifo(const std::string &fifo, const std::function<void(const std::string &)> &read)
{
	::unlink(fifo.c_str());
	if (::mkfifo(fifo.c_str(), 0600) != 0)
		return "mkfifo failed";
	std::string what;
	const bool finished = finishedWithin(
		3.0,
		[&] {
			try {
				read(fifo);
				what = "read without an error";
			} catch (const std::exception &e) {
				what = e.what();
			}
		},
		[&] {
			const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
			if (fd >= 0)
				::close(fd);
		});
	if (!finished)
		what = "blocked";
	::unlink(fifo.c_str());
	return what;
}

/* The attack itself: `path` swapped (renameat2 RENAME_EXCHANGE) between a
 * regular file of `text` and a FIFO again and again while `read` reads it
 * for `seconds`. True when a read blocked: a check by name passed on the
 * file, then the open met the FIFO. */
inline bool blockedBySwappedFifo(const std::string &path, const std::string &text, double seconds,
				 const std::function<void(const std::string &)> &read)
{
	const std::string other = path + ".fifo";
	::unlink(path.c_str());
	::unlink(other.c_str());
	std::ofstream(path, std::ios::binary) << text;
	if (::mkfifo(other.c_str(), 0600) != 0)
		return true;
	std::atomic<bool> reading{ true }, swapping{ true }, blocked{ false };
	std::atomic<long> reads{ 0 };
	std::thread swapper([&] {
		while (swapping)
			::renameat2(AT_FDCWD, path.c_str(), AT_FDCWD, other.c_str(), RENAME_EXCHANGE);
	});
	std::thread watchdog([&] {
		long seen = -1;
		while (reading) {
			std::this_thread::sleep_for(std::chrono::milliseconds(500));
			if (reads == seen && reading) {
				blocked = true;
				swapping = false;
				/* Set the reader free: a writer on whichever name
				 * the FIFO has now. */
				for (const std::string &name : { path, other }) {
					const int fd = ::open(name.c_str(), O_WRONLY | O_NONBLOCK);
					if (fd >= 0)
						::close(fd);
				}
			}
			seen = reads;
		}
	});
	const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
	while (std::chrono::steady_clock::now() < end && !blocked) {
		try {
			read(path);
		} catch (const std::exception &) {
		}
		++reads;
	}
	reading = false;
	swapping = false;
	swapper.join();
	watchdog.join();
	::unlink(path.c_str());
	::unlink(other.c_str());
	return blocked;
}

} // namespace frappe::test
