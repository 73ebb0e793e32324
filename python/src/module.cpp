// SPDX-License-Identifier: MIT
// python/src/module.cpp: the extension module frappe._frappe, which the
// package frappe re-exports, and the helpers its parts share.
#include "module.h"
#include "nogil.h"

#include <frappe/version.h>

namespace frappe::python {

py::array_t<float> newFloatArray(py::ssize_t rows, py::ssize_t cols)
{
	return py::array_t<float>({ rows, cols });
}

std::string pathArg(py::handle obj)
{
	/* os.fsencode: str, bytes or os.PathLike, as open() takes, as the
	 * bytes the system sees (a name that is not UTF-8 has surrogates as
	 * a str, which no std::string conversion takes). */
	return py::module_::import("os").attr("fsencode")(obj).cast<py::bytes>();
}

void raiseOSError(const std::exception &error)
{
	PyErr_SetString(PyExc_OSError, error.what());
	throw py::error_already_set();
}

} // namespace frappe::python

PYBIND11_MODULE(_frappe, m)
{
	using namespace frappe::python;
	m.doc() = "Frappe: fast square fiducial marker (ArUco, AprilTag) detection.";
	m.attr("__version__") = frappe::version();
	m.def("simd_target", &frappe::simdTarget,
	      "The instruction set the detector's per-pixel kernels run with on this CPU ('AVX2', 'scalar', ...).");
	bindDictionaries(m);
	bindMarker(m);
	bindRender(m);
	bindDetector(m);
	bindPose(m);
	registerExitHook();
}
