// SPDX-License-Identifier: MIT
// python/src/module.h: what the binding's files share: the functions that
// add each concept to the module, and the argument conversions several use.
#pragma once

#include <array>
#include <exception>
#include <memory>
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <frappe/dictionary.h>
#include <frappe/image.h>

namespace frappe::python {

namespace py = pybind11;

/// A dictionary as Python holds it: a built-in one (not owned) or one of
/// the user's own from loadDictionary() (shared with the detectors using it).
struct DictionaryRef {
	std::shared_ptr<const Dictionary> dict;
	/// Whether it is compiled into the library (then its name finds it).
	bool builtin() const;
};

/// A built-in dictionary by name; ValueError naming the known ones if none.
DictionaryRef builtinDictionary(const std::string &name);
/// `obj` as a dictionary: a frappe.Dictionary or a built-in's name;
/// TypeError or ValueError otherwise.
DictionaryRef dictionaryArg(py::handle obj);

/// One detected marker, as Python sees it: the corners an array made once.
struct Marker {
	int id = -1;
	py::array_t<float> corners; ///< (4, 2) float32: top-left, top-right, bottom-right, bottom-left
	int hamming = 0;
	float margin = 0.0f;
	std::string dictionary; ///< the detector's dictionary's name
	bool tracked = false;   ///< mode='track': found where the last frames predicted it
};

/// Four corners from a Marker, or an array-like of 8 numbers shaped (4, 2)
/// (cv2.aruco's (1, 4, 2) too); ValueError otherwise.
std::array<Point2f, 4> cornersArg(py::handle obj);

/// Raises OSError with `error`'s message: what the library's
/// std::runtime_error means for a file (missing, unreadable, too large).
[[noreturn]] void raiseOSError(const std::exception &error);

/// A file name from a str or an os.PathLike (pathlib.Path).
std::string pathArg(py::handle obj);

/// A (rows, cols) float32 array of fresh memory owned by Python.
py::array_t<float> newFloatArray(py::ssize_t rows, py::ssize_t cols);

void bindDictionaries(py::module_ &m);
void bindMarker(py::module_ &m);
void bindRender(py::module_ &m);
void bindDetector(py::module_ &m);
void bindPose(py::module_ &m);

} // namespace frappe::python
