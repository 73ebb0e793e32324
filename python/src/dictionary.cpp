// SPDX-License-Identifier: MIT
// python/src/dictionary.cpp: frappe.Dictionary, frappe.dictionaries(),
// frappe.get_dictionary() and frappe.load_dictionary().
#include "module.h"
#include "nogil.h"

#include <stdexcept>
#include <string>

#include <pybind11/stl.h>

#include <frappe/dictionary.h>

namespace frappe::python {

bool DictionaryRef::builtin() const
{
	const auto all = dictionaries();
	return dict && dict.get() >= all.data() && dict.get() < all.data() + all.size();
}

DictionaryRef builtinDictionary(const std::string &name)
{
	const Dictionary *d = findDictionary(name);
	if (!d)
		throw py::value_error("unknown dictionary '" + name + "'; known: " + dictionaryNames() +
				      " (or a frappe.Dictionary from frappe.load_dictionary())");
	/* Built-ins live as long as the library: a shared_ptr that owns nothing. */
	return { std::shared_ptr<const Dictionary>(std::shared_ptr<void>(), d) };
}

DictionaryRef dictionaryArg(py::handle obj)
{
	if (py::isinstance<DictionaryRef>(obj))
		return obj.cast<DictionaryRef>();
	if (py::isinstance<py::str>(obj)) {
		/* A str that is not text (a lone surrogate, as os.fsdecode makes of
		 * a file name's undecodable bytes) converts to no std::string. */
		std::string name;
		try {
			name = obj.cast<std::string>();
		} catch (const py::cast_error &) {
			throw py::value_error("unknown dictionary " + std::string(py::str(py::module_::import("builtins").attr("ascii")(obj))) +
					      ": not valid text (a lone surrogate); known: " + dictionaryNames());
		}
		return builtinDictionary(name);
	}
	throw py::type_error("dictionary must be a name (str) or a frappe.Dictionary, not " +
			     std::string(py::str(obj.get_type().attr("__name__"))));
}

namespace {

std::string repr(const DictionaryRef &d)
{
	return "frappe.Dictionary('" + std::string(d.dict->name) + "', bits=" + std::to_string(d.dict->bits) +
	       ", size=" + std::to_string(d.dict->size()) + ", min_hamming=" +
	       std::to_string(d.dict->min_hamming) + ")";
}

} // namespace

void bindDictionaries(py::module_ &m)
{
	py::class_<DictionaryRef>(m, "Dictionary", R"doc(
A family of square markers: a built-in one (frappe.get_dictionary(name)) or
one of your own (frappe.load_dictionary(path)). Pass it, or a built-in's
name, as a Detector's dictionary.)doc")
		.def_property_readonly("name", [](const DictionaryRef &d) { return std::string(d.dict->name); },
				       "Its name, e.g. 'aruco_mip_36h12'.")
		.def_property_readonly("bits", [](const DictionaryRef &d) { return d.dict->bits; },
				       "Cells per side of the inner code grid (6 for a 36-bit family).")
		.def_property_readonly("size", [](const DictionaryRef &d) { return d.dict->size(); },
				       "How many markers it has: ids are 0 .. size - 1.")
		.def_property_readonly("min_hamming", [](const DictionaryRef &d) { return d.dict->min_hamming; },
				       "Minimum distance in bits between two codes, rotations included.")
		.def_property_readonly("default_max_hamming",
				       [](const DictionaryRef &d) { return d.dict->defaultMaxHamming(); },
				       "The bit errors a Detector corrects with max_hamming=-1.")
		.def_property_readonly("builtin", &DictionaryRef::builtin,
				       "Whether it is compiled into the library.")
		.def_property_readonly(
			"codes",
			[](const DictionaryRef &d) {
				py::array_t<std::uint64_t> codes(static_cast<py::ssize_t>(d.dict->codes.size()));
				std::copy(d.dict->codes.begin(), d.dict->codes.end(), codes.mutable_data());
				return codes;
			},
			"Each id's code (uint64 array): the bits x bits grid row-major from the top-left\n"
			"cell, most significant used bit first, 1 = white.")
		.def("__len__", [](const DictionaryRef &d) { return d.dict->size(); })
		.def("__eq__", [](const DictionaryRef &a, const DictionaryRef &b) { return a.dict == b.dict; })
		.def("__hash__", [](const DictionaryRef &d) { return std::hash<const void *>()(d.dict.get()); })
		.def("__repr__", &repr);

	m.def(
		"dictionaries",
		[]() {
			std::vector<std::string> names;
			for (const Dictionary &d : dictionaries())
				names.emplace_back(d.name);
			return names;
		},
		R"doc(The names of the built-in dictionaries, e.g. ['4x4_50', ..., 'aruco_mip_36h12', ...].)doc");

	m.def("get_dictionary", &builtinDictionary, py::arg("name"), R"doc(
The built-in dictionary `name`: a name from dictionaries(), case-insensitive,
or a common alias ('DICT_6X6_250', 'DICT_APRILTAG_36h11', 'tag36h11').
Raises ValueError for an unknown name.)doc");

	m.def(
		"load_dictionary",
		[](py::handle path) {
			const std::string file = pathArg(path);
			try {
				std::shared_ptr<const Dictionary> d;
				{
					WithoutGil nogil; /* a slow disk stops no other thread */
					d = loadDictionary(file);
				}
				return DictionaryRef{ std::move(d) };
			} catch (const std::invalid_argument &) {
				throw;
			} catch (const std::runtime_error &e) {
				raiseOSError(e);
			}
		},
		py::arg("path"), R"doc(
A dictionary of your own from a file: frappe's text format (one 0x-hex code a
line) or OpenCV's aruco YAML (what cv2.aruco.Dictionary.writeDictionary
writes). Raises OSError when the file cannot be read and ValueError, naming
the file and line, when it is not a dictionary.)doc");
}

} // namespace frappe::python
