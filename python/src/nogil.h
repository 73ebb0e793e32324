// SPDX-License-Identifier: MIT
// python/src/nogil.h: the GIL released around calls into the library, so
// that an interpreter shutting down never meets a thread coming back.
//
// A daemon thread that comes back from C++ after the interpreter began to
// finalize is ended by Python inside PyEval_RestoreThread (pthread_exit);
// unwinding through C++ frames that may not throw aborts the process (exit
// 134, as OpenCV does). So: at exit (an atexit hook, before finalization)
// the interpreter waits for the calls in flight to come back, and a call
// begun after that never returns to Python: the thread waits, without the
// GIL, for the process to end.
#pragma once

#include <Python.h>

#include <pybind11/pybind11.h>

namespace frappe::python {

/// Releases the GIL for its lifetime, as py::gil_scoped_release; made with
/// the GIL held. After the exit hook ran, blocks for good instead.
class WithoutGil
{
public:
	WithoutGil();
	~WithoutGil();
	WithoutGil(const WithoutGil &) = delete;
	WithoutGil &operator=(const WithoutGil &) = delete;

private:
	PyThreadState *state_;
};

/// Registers the exit hook that waits for the calls in flight.
void registerExitHook();

} // namespace frappe::python
