// SPDX-License-Identifier: MIT
// python/src/pose.cpp: frappe.Camera, frappe.read_calibration(),
// frappe.Pose and frappe.estimate_pose(), with project_points() and
// undistort_points() to use them.
#include "module.h"
#include "nogil.h"

#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

#include <pybind11/stl.h>

#include <frappe/bundle.h>
#include <frappe/camera.h>
#include <frappe/pose.h>

namespace frappe::python {

namespace {

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;

Doubles doublesArg(py::handle obj, const char *what)
{
	try {
		Doubles a = Doubles::ensure(obj);
		if (a)
			return a;
	} catch (const py::error_already_set &) {
	}
	throw py::type_error(std::string(what) + " must be an array of numbers, got " + std::string(py::repr(obj)));
}

Camera cameraFromArrays(py::handle matrix, py::handle distortion, int width, int height)
{
	const Doubles k = doublesArg(matrix, "camera_matrix");
	if (k.ndim() != 2 || k.shape(0) != 3 || k.shape(1) != 3)
		throw py::value_error("camera_matrix must be 3 x 3, got shape " +
				      std::string(py::str(k.attr("shape"))));
	Camera camera;
	std::copy(k.data(), k.data() + 9, camera.matrix.begin());
	if (!distortion.is_none()) {
		/* Any shape: OpenCV's calibrateCamera gives (1, 5). */
		const Doubles d = doublesArg(distortion, "dist_coeffs");
		camera.distortion.assign(d.data(), d.data() + d.size());
	}
	camera.width = width;
	camera.height = height;
	camera.validate();
	return camera;
}

/// A Camera, or a matrix and distortion coefficients as OpenCV takes them.
Camera cameraArg(py::handle matrix, py::handle distortion)
{
	if (py::isinstance<Camera>(matrix)) {
		if (!distortion.is_none())
			throw py::value_error("dist_coeffs goes with a camera matrix; a frappe.Camera has its own");
		return matrix.cast<Camera>();
	}
	return cameraFromArrays(matrix, distortion, 0, 0);
}

py::array_t<double> vector3(const std::array<double, 3> &v)
{
	py::array_t<double> a(3);
	std::copy(v.begin(), v.end(), a.mutable_data());
	return a;
}

/// cv::Rodrigues: the rotation matrix of an axis-angle vector.
std::array<double, 9> rotationMatrix(const std::array<double, 3> &r)
{
	const double theta = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
	if (theta < 1e-12)
		return { 1, -r[2], r[1], r[2], 1, -r[0], -r[1], r[0], 1 };
	const double x = r[0] / theta, y = r[1] / theta, z = r[2] / theta;
	const double c = std::cos(theta), s = std::sin(theta), t = 1.0 - c;
	return { t * x * x + c,     t * x * y - s * z, t * x * z + s * y,
		 t * x * y + s * z, t * y * y + c,     t * y * z - s * x,
		 t * x * z - s * y, t * y * z + s * x, t * z * z + c };
}

/// One pose of a marker and, for the better of the two, the other.
struct PyPose {
	Pose pose;
	std::shared_ptr<PyPose> alternative;
	double ambiguity = INFINITY;
};

std::string poseRepr(const PyPose &p)
{
	char buf[256];
	std::snprintf(buf, sizeof(buf),
		      "frappe.Pose(rvec=[%.4f, %.4f, %.4f], tvec=[%.4f, %.4f, %.4f], error=%.3f, ambiguity=%.2f)",
		      p.pose.rvec[0], p.pose.rvec[1], p.pose.rvec[2], p.pose.tvec[0], p.pose.tvec[1],
		      p.pose.tvec[2], p.pose.error, p.ambiguity);
	return buf;
}

std::string cameraRepr(const Camera &c)
{
	char buf[256];
	std::snprintf(buf, sizeof(buf), "frappe.Camera(fx=%.2f, fy=%.2f, cx=%.2f, cy=%.2f, distortion=%zu, %dx%d)",
		      c.matrix[0], c.matrix[4], c.matrix[2], c.matrix[5], c.distortion.size(), c.width, c.height);
	return buf;
}

std::optional<PyPose> estimate(py::handle corners, double size, py::handle matrix, py::handle distortion)
{
	const std::array<Point2f, 4> c = cornersArg(corners);
	const Camera camera = cameraArg(matrix, distortion);
	const std::optional<MarkerPose> mp = estimatePose(c, size, camera);
	if (!mp)
		return std::nullopt;
	PyPose out{ mp->pose, nullptr, mp->ambiguity() };
	if (std::isfinite(mp->alternative.error))
		out.alternative = std::make_shared<PyPose>(PyPose{ mp->alternative, nullptr, INFINITY });
	return out;
}

py::array_t<float> pointsOut(const std::vector<Point2f> &points)
{
	py::array_t<float> out = newFloatArray(static_cast<py::ssize_t>(points.size()), 2);
	float *o = out.mutable_data();
	for (const Point2f &p : points) {
		*o++ = p.x;
		*o++ = p.y;
	}
	return out;
}

py::array_t<float> project(py::handle points, const PyPose &pose, py::handle matrix, py::handle distortion)
{
	const Doubles p = doublesArg(points, "points");
	if (p.ndim() != 2 || p.shape(1) != 3)
		throw py::value_error("points must be an (N, 3) array of marker-frame points, got shape " +
				      std::string(py::str(p.attr("shape"))));
	const Camera camera = cameraArg(matrix, distortion);
	std::vector<std::array<double, 3>> in(static_cast<std::size_t>(p.shape(0)));
	std::copy(p.data(), p.data() + p.size(), in.empty() ? nullptr : in[0].data());
	return pointsOut(projectPoints(in, pose.pose, camera));
}

py::array_t<float> undistort(py::handle points, py::handle matrix, py::handle distortion)
{
	const Doubles p = doublesArg(points, "points");
	if (p.size() % 2 != 0 || (p.size() > 0 && p.shape(p.ndim() - 1) != 2))
		throw py::value_error("points must be an (N, 2) array, got shape " +
				      std::string(py::str(p.attr("shape"))));
	const Camera camera = cameraArg(matrix, distortion);
	std::vector<Point2f> in(static_cast<std::size_t>(p.size() / 2));
	for (std::size_t i = 0; i < in.size(); ++i)
		in[i] = { static_cast<float>(p.data()[2 * i]), static_cast<float>(p.data()[2 * i + 1]) };
	return pointsOut(undistortPoints(in, camera));
}

/// A bundle's pose: the pose, the ids used and rejected.
struct PyBundlePose {
	PyPose pose;
	std::vector<int> used, rejected;
};

std::optional<PyBundlePose> estimateBundle(const Bundle &bundle, py::iterable markers, py::handle matrix,
					   py::handle distortion)
{
	std::vector<frappe::Marker> seen;
	for (py::handle obj : markers) {
		const Marker &m = obj.cast<const Marker &>();
		frappe::Marker f;
		f.id = m.id;
		f.corners = cornersArg(obj);
		seen.push_back(f);
	}
	const Camera camera = cameraArg(matrix, distortion);
	const auto bp = estimateBundlePose(bundle, seen, camera);
	if (!bp)
		return std::nullopt;
	return PyBundlePose{ PyPose{ bp->pose, nullptr, INFINITY }, bp->used, bp->rejected };
}

} // namespace

void bindPose(py::module_ &m)
{
	py::class_<Camera>(m, "Camera", R"doc(
A calibrated pinhole camera with OpenCV's distortion model: Camera(matrix,
distortion=None, width=0, height=0) with matrix the 3 x 3 camera matrix and
distortion OpenCV's k1 k2 p1 p2 [k3 [k4 k5 k6]] (0, 4, 5 or 8 values), or
frappe.read_calibration(path). width and height are the frame size it was
calibrated at (0: unknown). Raises ValueError saying what is wrong.)doc")
		.def(py::init(&cameraFromArrays), py::arg("matrix"), py::arg("distortion") = py::none(),
		     py::arg("width") = 0, py::arg("height") = 0)
		.def_static("pinhole", &Camera::pinhole, py::arg("fx"), py::arg("fy"), py::arg("cx"), py::arg("cy"),
			    py::arg("width") = 0, py::arg("height") = 0, "A camera from fx, fy, cx, cy, no distortion.")
		.def_property_readonly(
			"matrix",
			[](const Camera &c) {
				py::array_t<double> k({ 3, 3 });
				std::copy(c.matrix.begin(), c.matrix.end(), k.mutable_data());
				return k;
			},
			"The 3 x 3 camera matrix (float64).")
		.def_property_readonly(
			"distortion",
			[](const Camera &c) {
				py::array_t<double> d(static_cast<py::ssize_t>(c.distortion.size()));
				std::copy(c.distortion.begin(), c.distortion.end(), d.mutable_data());
				return d;
			},
			"The distortion coefficients, OpenCV's order (float64, 0, 4, 5 or 8 of them).")
		.def_readonly("width", &Camera::width)
		.def_readonly("height", &Camera::height)
		.def_property_readonly("fx", [](const Camera &c) { return c.matrix[0]; })
		.def_property_readonly("fy", [](const Camera &c) { return c.matrix[4]; })
		.def_property_readonly("cx", [](const Camera &c) { return c.matrix[2]; })
		.def_property_readonly("cy", [](const Camera &c) { return c.matrix[5]; })
		.def("fits", &Camera::fits, py::arg("width"), py::arg("height"),
		     "Whether frames of this size can use it (same size or aspect ratio, or size unknown).")
		.def("scaled_to", &Camera::scaledTo, py::arg("width"), py::arg("height"),
		     "This camera for frames of another size of the same aspect ratio.")
		.def("__repr__", &cameraRepr);

	m.def(
		"read_calibration",
		[](py::handle path) {
			const std::string file = pathArg(path);
			try {
				WithoutGil nogil; /* a slow disk stops no other thread */
				return readCalibration(file);
			} catch (const std::invalid_argument &) {
				throw;
			} catch (const std::runtime_error &e) {
				raiseOSError(e);
			}
		},
		py::arg("path"), R"doc(
The camera a calibration file describes: ROS camera_info YAML or OpenCV
FileStorage YAML / XML (camera_matrix or K, distortion_coefficients or D, the
image size). Raises OSError when the file cannot be read, ValueError naming
the file and key when it is not a calibration.)doc");

	py::class_<PyPose>(m, "Pose", R"doc(
Where a marker is: the motion from the marker's frame to the camera's, as
cv2.solvePnP gives it (x right, y down, z forward; the marker's origin at its
centre, x right, y up, z towards the viewer). Units are those of the marker
size given to estimate_pose(). The better of the two poses a square's corners
allow, with the other as .alternative: C++'s frappe::MarkerPose in one.)doc")
		.def_property_readonly("rvec", [](const PyPose &p) { return vector3(p.pose.rvec); },
				       "Rotation vector (axis times angle, radians), (3,) float64, as cv2.Rodrigues.")
		.def_property_readonly("tvec", [](const PyPose &p) { return vector3(p.pose.tvec); },
				       "The marker's centre in the camera frame, (3,) float64.")
		.def_property_readonly(
			"rotation_matrix",
			[](const PyPose &p) {
				py::array_t<double> r({ 3, 3 });
				const auto rm = rotationMatrix(p.pose.rvec);
				std::copy(rm.begin(), rm.end(), r.mutable_data());
				return r;
			},
			"The rotation as a 3 x 3 matrix (pupil-apriltags' pose_R; tvec is its pose_t).")
		.def_property_readonly(
			"transform",
			[](const PyPose &p) {
				py::array_t<double> t({ 4, 4 });
				double *o = t.mutable_data();
				const auto rm = rotationMatrix(p.pose.rvec);
				for (int r = 0; r < 3; ++r) {
					for (int c = 0; c < 3; ++c)
						o[4 * r + c] = rm[3 * r + c];
					o[4 * r + 3] = p.pose.tvec[r];
				}
				o[12] = o[13] = o[14] = 0.0;
				o[15] = 1.0;
				return t;
			},
			"The 4 x 4 homogeneous transform from marker to camera coordinates.")
		.def_property_readonly("error", [](const PyPose &p) { return p.pose.error; },
				       "RMS reprojection error of the four corners, pixels.")
		.def_property_readonly(
			"alternative",
			[](const PyPose &p) { return p.alternative ? py::cast(*p.alternative) : py::none(); },
			"The other pose the corners allow (a planar square is ambiguous), unrefined,\n"
			"or None.")
		.def_readonly("ambiguity", &PyPose::ambiguity, R"doc(
alternative.error / error: near 1 the two poses explain the corners alike
and the pose may flip between frames; infinity when there is no alternative.)doc")
		.def("__repr__", &poseRepr);

	m.def("estimate_pose", &estimate, py::arg("corners"), py::arg("marker_size"), py::arg("camera_matrix"),
	      py::arg("dist_coeffs") = py::none(), R"doc(
The pose of a square marker of side `marker_size` (> 0, in the unit you want
tvec in) whose corners the camera saw at `corners` (a Marker, or (4, 2)
pixels as the detector reports them: distorted, top-left first, clockwise).
camera_matrix is a 3 x 3 array with dist_coeffs (0, 4, 5 or 8 values, None
for none), or a frappe.Camera. IPPE refined by Levenberg-Marquardt; returns a
frappe.Pose, or None when the corners are degenerate (collinear, not finite).
Raises ValueError for a size not positive or a bad camera.)doc");

	m.def("project_points", &project, py::arg("points"), py::arg("pose"), py::arg("camera_matrix"),
	      py::arg("dist_coeffs") = py::none(), R"doc(
Projects (N, 3) points of the marker's frame into the image through `pose`
and the camera (distortion applied): (N, 2) float32 pixels; a point behind
the camera gives NaN. E.g. the axes to draw.)doc");

	m.def("undistort_points", &undistort, py::arg("points"), py::arg("camera_matrix"),
	      py::arg("dist_coeffs") = py::none(), R"doc(
Where (N, 2) pixel points would be under the same camera matrix without
distortion (cv2.undistortPoints with P = K): (N, 2) float32.)doc");

	py::class_<Bundle>(m, "Bundle", R"doc(
A rigid set of markers with known corners (a board, apriltag_ros's bundle):
frappe.load_bundle(path) or frappe.Bundle.grid(rows, cols, size, gap,
first_id=0), for estimate_bundle_pose().)doc")
		.def_static("grid", &Bundle::grid, py::arg("rows"), py::arg("cols"), py::arg("size"), py::arg("gap"),
			    py::arg("first_id") = 0, R"doc(
OpenCV's GridBoard: ids row-major from first_id at the top-left, the origin at
the board's bottom-left corner, x right, y up, z out of the board.)doc")
		.def_readonly("name", &Bundle::name)
		.def_property_readonly(
			"ids",
			[](const Bundle &b) {
				std::vector<int> ids;
				for (const BundleMarker &mk : b.markers)
					ids.push_back(mk.id);
				return ids;
			},
			"The ids of its markers.")
		.def(
			"corners",
			[](const Bundle &b, int id) {
				const BundleMarker *mk = b.find(id);
				if (!mk)
					throw py::key_error("id " + std::to_string(id) + " is not in the bundle");
				py::array_t<double> c({ 4, 3 });
				for (int i = 0; i < 4; ++i)
					std::copy(mk->corners[static_cast<std::size_t>(i)].begin(),
						  mk->corners[static_cast<std::size_t>(i)].end(), c.mutable_data() + 3 * i);
				return c;
			},
			py::arg("id"), "Marker id's four corners in the bundle's frame, (4, 3) float64.")
		.def("__len__", [](const Bundle &b) { return b.markers.size(); });

	m.def(
		"load_bundle",
		[](py::handle path) {
			const std::string file = pathArg(path);
			try {
				return loadBundle(file);
			} catch (const std::invalid_argument &) {
				throw;
			} catch (const std::runtime_error &e) {
				raiseOSError(e);
			}
		},
		py::arg("path"), R"doc(
A bundle from apriltag_ros's tags.yaml (its first tag_bundles entry: id, size,
x, y, z, qw, qx, qy, qz) or a grid board's file (board: grid, rows, cols,
size, gap, first_id). Raises OSError when the file cannot be read, ValueError
naming the file and line when it is no bundle.)doc");

	py::class_<PyBundlePose>(m, "BundlePose", "One pose from every marker of a bundle seen.")
		.def_property_readonly("pose", [](const PyBundlePose &p) { return p.pose; },
				       "The bundle frame's pose (frappe.Pose; error: RMS over the corners used).")
		.def_readonly("used", &PyBundlePose::used, "Ids whose corners made the pose.")
		.def_readonly("rejected", &PyBundlePose::rejected,
			      "Ids seen but left out: corners that disagree (a marker moved, a wrong read).");

	m.def("estimate_bundle_pose", &estimateBundle, py::arg("bundle"), py::arg("markers"), py::arg("camera_matrix"),
	      py::arg("dist_coeffs") = py::none(), R"doc(
One pose from every marker of `bundle` among `markers` (frappe.Marker, as
detect() gives them): each marker's poses as starting points, the one most
agree with refined over every agreeing corner with the lens model, markers
that still disagree rejected. A frappe.BundlePose, or None when no marker of
the bundle gives a pose.)doc");
}

} // namespace frappe::python
