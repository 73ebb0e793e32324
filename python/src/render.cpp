// SPDX-License-Identifier: MIT
// python/src/render.cpp: frappe.render_marker() (an upright marker, to
// print) and frappe.draw_marker() (a marker drawn into an image at four
// corners, for test scenes).
#include "module.h"

#include <algorithm>
#include <climits>
#include <stdexcept>
#include <string>

#include <frappe/render.h>

namespace frappe::python {

namespace {

/* Python's ints are of any size: one beyond C's int is clamped to it,
 * where the library refuses it as it refuses one within, never wrapped. */
long long clampedLong(const py::int_ &v)
{
	int overflow = 0;
	const long long x = PyLong_AsLongLongAndOverflow(v.ptr(), &overflow);
	return overflow > 0 ? LLONG_MAX : overflow < 0 ? LLONG_MIN : x;
}

int narrowed(const py::int_ &v)
{
	return static_cast<int>(std::clamp<long long>(clampedLong(v), INT_MIN, INT_MAX));
}

py::array_t<std::uint8_t> renderMarker(py::handle dictionary, const py::int_ &id, const py::int_ &cell_px,
				       const py::int_ &quiet_cells)
{
	const DictionaryRef d = dictionaryArg(dictionary);
	int side = 0;
	std::vector<std::uint8_t> pixels;
	try {
		pixels = markerImage(*d.dict, narrowed(id), narrowed(cell_px), narrowed(quiet_cells), side);
	} catch (const std::out_of_range &e) {
		throw py::value_error(e.what());
	}
	py::array_t<std::uint8_t> image({ side, side });
	std::copy(pixels.begin(), pixels.end(), image.mutable_data());
	return image;
}

/// `image` as a view the renderer can write: a writable 2-D uint8 array
/// whose rows are contiguous.
MutableImageView writableView(py::handle obj)
{
	if (!py::isinstance<py::array>(obj))
		throw py::type_error("image must be a numpy array, not " +
				     std::string(py::str(obj.get_type().attr("__name__"))));
	auto a = obj.cast<py::array>();
	if (!a.dtype().is(py::dtype::of<std::uint8_t>()))
		throw py::type_error("image must be uint8, not " + std::string(py::str(a.dtype())));
	if (a.ndim() != 2)
		throw py::value_error("image must be 2-D (height, width), got " + std::to_string(a.ndim()) +
				      "-D");
	if (!a.writeable())
		throw py::value_error("image is read-only");
	const py::ssize_t h = a.shape(0), w = a.shape(1);
	const py::ssize_t row = h > 1 ? a.strides(0) : w;
	if ((w > 1 && a.strides(1) != 1) || row < w || h > INT_MAX || w > INT_MAX || row > INT_MAX)
		throw py::value_error("image rows must be contiguous (a C-contiguous array or a slice of rows "
				      "and columns of one)");
	return { static_cast<std::uint8_t *>(a.mutable_data()), static_cast<int>(w), static_cast<int>(h),
		 static_cast<int>(row) };
}

void drawMarker(py::handle image, py::handle dictionary, const py::int_ &id, py::handle corners,
		const py::int_ &quiet_cells, const py::int_ &supersample, const py::int_ &black, const py::int_ &white)
{
	const MutableImageView view = writableView(image);
	const DictionaryRef d = dictionaryArg(dictionary);
	const std::array<Point2f, 4> c = cornersArg(corners);
	for (const auto &[name, level] : { std::pair{ "black", &black }, std::pair{ "white", &white } })
		if (clampedLong(*level) < 0 || clampedLong(*level) > 255)
			throw py::value_error(std::string("renderMarker: ") + name + " must be 0..255, got " +
					      std::string(py::str(py::handle(*level))));
	RenderOptions options;
	options.quiet_cells = narrowed(quiet_cells);
	options.supersample = narrowed(supersample);
	options.black = static_cast<std::uint8_t>(clampedLong(black));
	options.white = static_cast<std::uint8_t>(clampedLong(white));
	try {
		frappe::renderMarker(view, *d.dict, narrowed(id), c, options);
	} catch (const std::out_of_range &e) {
		throw py::value_error(e.what());
	}
}

} // namespace

void bindRender(py::module_ &m)
{
	m.def("render_marker", &renderMarker, py::arg("dictionary"), py::arg("id"), py::arg("cell_px") = 10,
	      py::arg("quiet_cells") = 1, R"doc(
Marker `id` of `dictionary` (a name or a frappe.Dictionary), upright, as a
square uint8 array (0 black, 255 white) of side (cells + 2 * quiet_cells)
* cell_px, cells = bits + 2 (or a layout family's whole size, AprilTag 3's
tagStandard41h12 and its kin): the code, its black border and a white quiet
zone of quiet_cells cells. To print, or to paste into test scenes. Raises ValueError for an id
not in the dictionary, cell_px < 1, quiet_cells outside 0..32768 or a side
over 32768.)doc");

	m.def("draw_marker", &drawMarker, py::arg("image"), py::arg("dictionary"), py::arg("id"),
	      py::arg("corners"), py::kw_only(), py::arg("quiet_cells") = 1, py::arg("supersample") = 4,
	      py::arg("black") = 0, py::arg("white") = 255, R"doc(
Draws marker `id` into `image` (a writable 2-D uint8 array, rows contiguous)
so that the outer corners of its black border land on `corners` ((4, 2):
top-left, top-right, bottom-right, bottom-left; pixel centres at integers),
through the perspective those corners define, its quiet zone around it.
Pixels are area-averaged over supersample x supersample samples, so edges
fall at their exact sub-pixel place: a synthetic view whose true corners are
known. Raises ValueError for corners that are no view of a square (not
convex, collinear, not finite), an id not in the dictionary, quiet_cells
outside 0..32768, supersample outside 1..256, black or white outside
0..255.)doc");
}

} // namespace frappe::python
