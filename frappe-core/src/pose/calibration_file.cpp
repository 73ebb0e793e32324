// SPDX-License-Identifier: MIT
// readCalibration: a Camera from a ROS camera_info YAML file or an OpenCV
// FileStorage YAML or XML file.
#include "frappe/camera.h"

#include <algorithm>
#include <charconv>
#include <initializer_list>
#include <stdexcept>
#include <string>

#include "markup.h"
#include "small_file.h"
#include "utf8.h"

namespace frappe {

using detail::MarkupNode;

namespace {

/* "text" (built by appending: GCC 12 warns falsely on "\"" + string). */
std::string inQuotes(std::string_view text)
{
	std::string q(1, '"');
	q.append(text);
	q += '"';
	return q;
}

class Calibration
{
public:
	Calibration(const MarkupNode &root, std::string_view origin) : root_(root), origin_(origin) {}

	Camera camera() const
	{
		Camera cam;
		const auto [k_key, k] = find({ "camera_matrix", "cameraMatrix", "K" });
		if (!k)
			fail("no camera matrix (camera_matrix, cameraMatrix or K)");
		const std::vector<double> m = matrix(k_key, *k, 3, 3);
		std::copy(m.begin(), m.end(), cam.matrix.begin());
		cam.distortion = distortion();
		size(cam);
		try {
			cam.validate();
		} catch (const std::invalid_argument &e) {
			fail(e.what());
		}
		return cam;
	}

private:
	const MarkupNode &root_;
	std::string_view origin_;

	[[noreturn]] void fail(const std::string &what) const
	{
		throw std::invalid_argument(std::string(origin_) + ": " + what);
	}
	[[noreturn]] void fail(std::string_view key, const std::string &what) const
	{
		fail(std::string(key) + ": " + what);
	}

	/* The first of `keys` the file has, and its value. */
	std::pair<std::string_view, const MarkupNode *> find(std::initializer_list<std::string_view> keys) const
	{
		for (std::string_view key : keys)
			if (const MarkupNode *n = root_.find(key))
				return { key, n };
		return { {}, nullptr };
	}

	double number(std::string_view key, std::string_view text) const
	{
		std::string_view t = text;
		if (!t.empty() && t[0] == '+')
			t.remove_prefix(1);
		double v = 0.0;
		const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
		if (t.empty() || r.ec != std::errc() || r.ptr != t.data() + t.size())
			fail(key, inQuotes(text) + " is not a number");
		return v;
	}

	int integer(std::string_view key, const MarkupNode &n) const
	{
		int v = 0;
		const std::string &t = n.text;
		const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
		if (n.kind != MarkupNode::Kind::Scalar || t.empty() || r.ec != std::errc() ||
		    r.ptr != t.data() + t.size())
			fail(key, inQuotes(t) + " is not an integer");
		return v;
	}

	/* A list of numbers: [a, b, ...] in YAML, "a b ..." in XML (OpenCV
	 * writes them space-separated), or <_> items. */
	std::vector<double> numbers(std::string_view key, const MarkupNode &n) const
	{
		std::vector<double> out;
		if (n.kind == MarkupNode::Kind::Seq) {
			for (const MarkupNode &item : n.items) {
				if (item.kind != MarkupNode::Kind::Scalar)
					fail(key, "a list inside the list of numbers");
				out.push_back(number(key, item.text));
			}
		} else if (n.kind == MarkupNode::Kind::Scalar) {
			std::string_view t = n.text;
			while (true) {
				const std::size_t a = t.find_first_not_of(" \t\r\n");
				if (a == std::string_view::npos)
					break;
				t.remove_prefix(a);
				const std::size_t b = std::min(t.find_first_of(" \t\r\n"), t.size());
				out.push_back(number(key, t.substr(0, b)));
				t.remove_prefix(b);
			}
		} else {
			fail(key, "expected numbers, got a mapping");
		}
		return out;
	}

	/* A matrix: {rows, cols, dt, data} (ROS, !!opencv-matrix) or a plain
	 * list. rows or cols -1: a vector of any length. */
	std::vector<double> matrix(std::string_view key, const MarkupNode &n, int rows, int cols) const
	{
		if (n.kind != MarkupNode::Kind::Map) {
			std::vector<double> v = numbers(key, n);
			if (rows > 0 && v.size() != static_cast<std::size_t>(rows * cols))
				fail(key, std::to_string(v.size()) + " numbers, expected " + std::to_string(rows * cols));
			return v;
		}
		if (!n.tag.empty() && n.tag != "opencv-matrix")
			fail(key, "type " + n.tag + ", expected opencv-matrix");
		const MarkupNode *data = n.find("data");
		if (!data)
			fail(key, "no data");
		if (const MarkupNode *dt = n.find("dt"); dt && dt->text != "d" && dt->text != "f")
			fail(key, "dt " + inQuotes(dt->text) + ", expected d or f (double or float)");
		std::vector<double> v = numbers(key, *data);
		const MarkupNode *r = n.find("rows"), *c = n.find("cols");
		if (!r || !c)
			fail(key, std::string("no ") + (r ? "cols" : "rows"));
		const int nr = integer(std::string(key) + ": rows", *r);
		const int nc = integer(std::string(key) + ": cols", *c);
		if (nr < 0 || nc < 0 || static_cast<long long>(nr) * nc != static_cast<long long>(v.size()))
			fail(key, std::to_string(v.size()) + " numbers for " + std::to_string(nr) + " rows and " +
					  std::to_string(nc) + " cols");
		if (rows > 0 && (nr != rows || nc != cols))
			fail(key, std::to_string(v.size()) + " numbers (" + std::to_string(nr) + "x" +
					  std::to_string(nc) + "), expected " + std::to_string(rows * cols) + " (" +
					  std::to_string(rows) + "x" + std::to_string(cols) + ")");
		if (rows < 0 && nr > 1 && nc > 1)
			fail(key, "a " + std::to_string(nr) + "x" + std::to_string(nc) + " matrix, expected a vector");
		return v;
	}

	std::vector<double> distortion() const
	{
		const auto [key, d] = find({ "distortion_coefficients", "dist_coeffs", "distCoeffs", "D" });
		if (!d)
			fail("no distortion coefficients (distortion_coefficients, dist_coeffs, distCoeffs or D)");
		std::vector<double> v = matrix(key, *d, -1, -1);
		/* OpenCV's 12 and 14 coefficients add the thin prism and tilt
		 * terms: usable here when those are zero. */
		if (v.size() > 8 && std::all_of(v.begin() + 8, v.end(), [](double x) { return x == 0.0; }))
			v.resize(8);
		const std::size_t n = v.size();
		if (n != 0 && n != 4 && n != 5 && n != 8)
			fail(key, std::to_string(n) + " coefficients, expected 4, 5 or 8 (k1 k2 p1 p2 [k3 [k4 k5 k6]])");
		if (const MarkupNode *model = root_.find("distortion_model")) {
			const std::string &name = model->text;
			if (name == "equidistant" || name == "fisheye" || name == "kannala_brandt")
				fail("distortion_model", name + " (fisheye) is not supported: only plumb_bob and "
								 "rational_polynomial (OpenCV's 5 and 8 coefficients)");
			const std::size_t expected = name == "plumb_bob" ? 5 : name == "rational_polynomial" ? 8 : 0;
			if (expected == 0)
				fail("distortion_model", inQuotes(name) + " is unknown: expected plumb_bob or "
								   "rational_polynomial");
			if (n != 0 && n != expected)
				fail(key, std::to_string(n) + " coefficients, but " + name + " has " +
						  std::to_string(expected));
		}
		return v;
	}

	void size(Camera &cam) const
	{
		for (const auto &[wk, hk] : { std::pair{ "image_width", "image_height" }, std::pair{ "width", "height" } }) {
			const MarkupNode *w = root_.find(wk), *h = root_.find(hk);
			if (!w && !h)
				continue;
			if (!w || !h)
				fail(w ? wk : hk, std::string("given without ") + (w ? hk : wk));
			cam.width = integer(wk, *w);
			cam.height = integer(hk, *h);
			if (cam.width <= 0 || cam.height <= 0)
				fail(cam.width <= 0 ? wk : hk, "must be positive");
			return;
		}
		const auto [key, s] = find({ "imageSize", "image_size" });
		if (!s)
			return;
		const std::vector<double> v = numbers(key, *s);
		if (v.size() != 2)
			fail(key, std::to_string(v.size()) + " numbers, expected 2 (width height)");
		if (!(v[0] >= 1 && v[0] <= 1e6 && v[1] >= 1 && v[1] <= 1e6) || v[0] != static_cast<int>(v[0]) ||
		    v[1] != static_cast<int>(v[1]))
			fail(key, "not a size in whole pixels");
		cam.width = static_cast<int>(v[0]);
		cam.height = static_cast<int>(v[1]);
	}
};

} // namespace

namespace {

Camera parse(std::string_view text, std::string_view origin)
{
	const std::string where(origin);
	if (text.size() > detail::kMarkupMaxBytes)
		throw std::invalid_argument(where + ": over 1 MiB, not a calibration file");
	if (text.find('\0') != std::string_view::npos)
		throw std::invalid_argument(where + ": a NUL byte: not a text file");
	if (text.substr(0, 3) == "\xEF\xBB\xBF")
		text.remove_prefix(3);
	const std::size_t first = text.find_first_not_of(" \t\r\n");
	if (first == std::string_view::npos)
		throw std::invalid_argument(where + ": empty");
	MarkupNode root;
	if (text[first] == '<') {
		std::string root_name;
		root = detail::parseXmlSubset(text, origin, root_name);
		if (root_name != "opencv_storage")
			throw std::invalid_argument(where + ": <" + root_name +
						    ">: not an OpenCV FileStorage file (expected <opencv_storage>)");
		if (root.kind != MarkupNode::Kind::Map)
			throw std::invalid_argument(where + ": <opencv_storage> holds no keys");
	} else {
		root = detail::parseYamlSubset(text, origin);
		if (root.kind != MarkupNode::Kind::Map)
			throw std::invalid_argument(where + ": not a calibration file (expected key: value lines)");
	}
	return Calibration(root, origin).camera();
}

} // namespace

Camera parseCalibration(std::string_view text, std::string_view origin)
{
	try {
		return parse(text, origin);
	} catch (const std::invalid_argument &e) {
		/* Messages quote the file's name and text: UTF-8 whatever they are. */
		const std::string_view what = e.what();
		if (detail::invalidUtf8At(what) == std::string_view::npos)
			throw;
		throw std::invalid_argument(detail::toUtf8(what, std::string::npos));
	}
}

Camera readCalibration(const std::string &path)
{
	const detail::SmallFile f = detail::readSmallFile(path, detail::kMarkupMaxBytes);
	detail::throwFileFault(f, detail::toUtf8(path, std::string::npos), "1 MiB", "calibration file");
	return parseCalibration(f.text, path);
}

} // namespace frappe
