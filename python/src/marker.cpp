// SPDX-License-Identifier: MIT
// python/src/marker.cpp: frappe.Marker, what Detector.detect() returns, and
// the corners that estimate_pose() and draw_marker() take.
#include "module.h"

#include <frappe/marker_record.h>

#include <cstdio>
#include <string>

namespace frappe::python {

std::array<Point2f, 4> cornersArg(py::handle obj)
{
	if (py::isinstance<Marker>(obj))
		obj = obj.cast<const Marker &>().corners;
	using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;
	Doubles a;
	try {
		a = Doubles::ensure(obj);
	} catch (const py::error_already_set &) {
	}
	if (!a || a.size() != 8 || a.ndim() < 1 || a.shape(a.ndim() - 1) != 2)
		throw py::value_error("corners must be 4 (x, y) points: a Marker or an array of shape (4, 2), got " +
				      std::string(py::repr(obj)));
	std::array<Point2f, 4> corners;
	const double *p = a.data();
	for (int i = 0; i < 4; ++i)
		corners[i] = { static_cast<float>(p[2 * i]), static_cast<float>(p[2 * i + 1]) };
	return corners;
}

namespace {

Marker makeMarker(int id, py::handle corners, int hamming, float margin, std::string dictionary, bool tracked)
{
	const std::array<Point2f, 4> c = cornersArg(corners);
	Marker m{ id, newFloatArray(4, 2), hamming, margin, std::move(dictionary), tracked };
	float *out = m.corners.mutable_data();
	for (int i = 0; i < 4; ++i) {
		out[2 * i] = c[i].x;
		out[2 * i + 1] = c[i].y;
	}
	return m;
}

/* frappe.Marker(...): made by hand, never tracked. */
Marker newMarker(int id, py::handle corners, int hamming, float margin, std::string dictionary)
{
	return makeMarker(id, corners, hamming, margin, std::move(dictionary), false);
}

std::string repr(const Marker &m)
{
	std::string s = "frappe.Marker(id=" + std::to_string(m.id) +
			(m.dictionary.empty() ? "" : ", dictionary='" + m.dictionary + "'") + ", corners=[";
	const float *c = m.corners.data();
	char buf[64];
	for (int i = 0; i < 4; ++i) {
		std::snprintf(buf, sizeof(buf), "%s[%.2f, %.2f]", i ? ", " : "", c[2 * i], c[2 * i + 1]);
		s += buf;
	}
	std::snprintf(buf, sizeof(buf), "], hamming=%d, margin=%.3f)", m.hamming, m.margin);
	return s + buf;
}

} // namespace

void bindMarker(py::module_ &m)
{
	py::class_<Marker>(m, "Marker", R"doc(
One detected marker.

id          its id in the detector's dictionary
dictionary  the dictionary's name (the library's spelling)
corners     (4, 2) float32 array, pixels: the outer corners of the black
            border, top-left, top-right, bottom-right, bottom-left of the marker
            in its upright orientation (clockwise on screen), as cv2.aruco
            orders them; (0, 0) is the centre of the top-left pixel
hamming     bits corrected to reach the code
margin      how clearly the code was read, 0..1: filter on it to trade misses
            for certainty
tracked     mode='track': found where the last frames predicted it (its corners
            measured on this frame all the same); False when found afresh

The fields are frappe::forEachMarkerField()'s (frappe.MARKER_FIELDS, the pose's
aside: frappe.estimate_pose), as frappe-detect's and frappejson's JSON.)doc")
		.def(py::init(&newMarker), py::arg("id"), py::arg("corners"), py::arg("hamming") = 0,
		     py::arg("margin") = 0.0f, py::arg("dictionary") = "")
		.def_readonly("id", &Marker::id)
		.def_readonly("corners", &Marker::corners)
		.def_readonly("hamming", &Marker::hamming)
		.def_readonly("margin", &Marker::margin)
		.def_readonly("dictionary", &Marker::dictionary)
		.def_readonly("tracked", &Marker::tracked)
		.def_property_readonly(
			"center",
			[](const Marker &mk) {
				const float *c = mk.corners.data();
				py::array_t<double> centre(2);
				double *out = centre.mutable_data();
				out[0] = (double(c[0]) + c[2] + c[4] + c[6]) / 4.0;
				out[1] = (double(c[1]) + c[3] + c[5] + c[7]) / 4.0;
				return centre;
			},
			"The mean of the corners, (2,) float64.")
		.def("__repr__", &repr)
		.def(py::pickle(
			[](const Marker &mk) {
				return py::make_tuple(mk.id, mk.corners, mk.hamming, mk.margin, mk.dictionary,
						      mk.tracked);
			},
			[](const py::tuple &t) {
				/* 4: pickled before the dictionary was a field, 5: before tracked */
				if (t.size() < 4 || t.size() > 6)
					throw py::value_error("a pickled frappe.Marker has 6 fields");
				return makeMarker(t[0].cast<int>(), t[1], t[2].cast<int>(), t[3].cast<float>(),
						  t.size() >= 5 ? t[4].cast<std::string>() : std::string(),
						  t.size() == 6 && t[5].cast<bool>());
			}));
	/* The library's one list of a marker's output fields (pose ones last). */
	py::tuple fields(markerFieldNames().size());
	for (std::size_t i = 0; i < markerFieldNames().size(); ++i)
		fields[i] = py::str(std::string(markerFieldNames()[i]));
	m.attr("MARKER_FIELDS") = fields;
}

} // namespace frappe::python
