// SPDX-License-Identifier: MIT
#include "nogil.h"

#include <condition_variable>
#include <mutex>

namespace frappe::python {

namespace {

/* The one interpreter's calls into the library: how many are without the
 * GIL, and whether it is exiting. Process-wide because the interpreter is. */
struct Calls {
	std::mutex mutex;
	std::condition_variable done;
	int inFlight = 0;
	bool exiting = false;
};

Calls &calls()
{
	static Calls *c = new Calls; /* never destroyed: threads may still wait on it at exit */
	return *c;
}

/* atexit: runs with the GIL before finalization begins. */
void waitForCalls()
{
	Calls &c = calls();
	{
		std::lock_guard<std::mutex> lock(c.mutex);
		c.exiting = true;
	}
	pybind11::gil_scoped_release nogil;
	std::unique_lock<std::mutex> lock(c.mutex);
	c.done.wait(lock, [&] { return c.inFlight == 0; });
}

} // namespace

WithoutGil::WithoutGil()
{
	Calls &c = calls();
	bool exiting;
	{
		std::lock_guard<std::mutex> lock(c.mutex);
		exiting = c.exiting;
		if (!exiting)
			++c.inFlight;
	}
	state_ = PyEval_SaveThread();
	if (exiting) {
		/* Too late to come back: wait, without the GIL, for the end. */
		std::unique_lock<std::mutex> lock(c.mutex);
		c.done.wait(lock, [] { return false; });
	}
}

WithoutGil::~WithoutGil()
{
	/* The GIL first: the exit hook lets finalization begin only once no
	 * call is left to take it back. */
	PyEval_RestoreThread(state_);
	Calls &c = calls();
	std::lock_guard<std::mutex> lock(c.mutex);
	if (--c.inFlight == 0)
		c.done.notify_all();
}

void registerExitHook()
{
	pybind11::module_::import("atexit").attr("register")(pybind11::cpp_function(&waitForCalls));
}

} // namespace frappe::python
