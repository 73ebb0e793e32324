// SPDX-License-Identifier: MIT
// python/src/detector.cpp: frappe.Detector: a frappe::Detector built from
// keyword arguments, detecting in numpy arrays without the GIL.
#include "module.h"
#include "nogil.h"

#include <algorithm>
#include <cctype>
#include <climits>
#include <mutex>
#include <string>
#include <vector>

#include <frappe/detector.h>
#include <frappe/settings.h>

namespace frappe::python {

namespace {

/// `obj` as a 2-D uint8 array (a (h, w, 1) one too), or TypeError /
/// ValueError saying what it is instead.
py::array imageArg(py::handle obj)
{
	py::array a;
	if (py::isinstance<py::array>(obj)) {
		a = obj.cast<py::array>();
	} else {
		/* Anything with the array interface (a PIL image, a memoryview). */
		try {
			a = py::array::ensure(obj);
		} catch (const py::error_already_set &) {
		}
		if (!a || a.dtype().kind() == 'O')
			throw py::type_error("image must be a numpy array (2-D, uint8), not " +
					     std::string(py::str(obj.get_type().attr("__name__"))));
	}
	if (a.ndim() == 3 && a.shape(2) != 1)
		throw py::value_error("image has " + std::to_string(a.shape(2)) +
				      " channels; frappe detects on 8-bit grey images: convert it first, "
				      "e.g. cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)");
	if (a.ndim() != 2 && a.ndim() != 3)
		throw py::value_error("image must be 2-D (height, width), got " + std::to_string(a.ndim()) +
				      "-D with shape " + std::string(py::str(a.attr("shape"))));
	if (!a.dtype().is(py::dtype::of<std::uint8_t>()))
		throw py::type_error("image must be uint8 (8-bit grey), not " + std::string(py::str(a.dtype())) +
				     "; convert it first, e.g. image.astype(numpy.uint8)");
	return a;
}

class PyDetector
{
public:
	PyDetector(const Config &config, DictionaryRef dict)
		: config_(config), dict_(std::move(dict)), detector_(config)
	{
	}

	py::list detect(py::handle obj);
	py::dict stats();
	void reset();
	py::dict configDict() const;
	const DictionaryRef &dictionary() const { return dict_; }
	int maxHamming() const { return detector_.maxHamming(); }
	std::string repr() const
	{
		return "frappe.Detector(dictionary='" + std::string(dict_.dict->name) + "', mode='" +
		       std::string(modeName(config_.mode)) + "', threads=" + std::to_string(config_.threads) + ")";
	}

private:
	/* One frame at a time: a second Python thread waits, without the GIL. */
	std::mutex mutex_;
	const Config config_;
	const DictionaryRef dict_;
	Detector detector_;
	/* Where an image whose rows are not contiguous is copied, kept between frames. */
	std::vector<std::uint8_t> buffer_;
	/* What stats reports: the last frame's, without its markers. */
	struct Stats {
		StageTimes times;
		float scale = 1.0f;
		int candidates = 0;
		int candidates_dropped = 0;
		bool copied = false;
		std::size_t bytes_read = 0;
		bool whole_frame = true;
	} last_;
};

py::list PyDetector::detect(py::handle obj)
{
	const py::array a = imageArg(obj);
	const py::ssize_t h = a.shape(0), w = a.shape(1);
	const py::ssize_t rowStride = a.strides(0), colStride = a.strides(1);
	if (h > INT_MAX || w > INT_MAX)
		throw py::value_error("image of " + std::to_string(w) + " x " + std::to_string(h) +
				      " pixels is too large");
	const auto *data = static_cast<const std::uint8_t *>(a.data());
	/* Rows of unit-stride pixels, one after the other in memory, are read in
	 * place: a C-contiguous array, or a slice of rows and columns of one. */
	const bool empty = h == 0 || w == 0;
	const bool direct = empty || ((w == 1 || colStride == 1) &&
				      (h == 1 || (rowStride >= w && rowStride <= INT_MAX)));
	const int stride = empty || h == 1 ? static_cast<int>(w) : static_cast<int>(rowStride);

	std::unique_lock<std::mutex> lock(mutex_, std::defer_lock);
	const Result *result;
	{
		WithoutGil nogil;
		lock.lock();
		ImageView view(data, static_cast<int>(w), static_cast<int>(h), stride);
		if (!direct) {
			/* Refused before the copy, as in place: no buffer for a
			 * huge broadcast view. */
			detector_.checkImage(ImageView(data, view.width, view.height, view.width));
			buffer_.resize(static_cast<std::size_t>(w) * h);
			for (py::ssize_t y = 0; y < h; ++y) {
				const std::uint8_t *src = data + y * rowStride;
				std::uint8_t *dst = buffer_.data() + y * w;
				for (py::ssize_t x = 0; x < w; ++x)
					dst[x] = src[x * colStride];
			}
			view = ImageView(buffer_.data(), view.width, view.height, view.width);
		}
		result = &detector_.detect(view);
		last_ = { result->times,	   result->scale,      result->candidates, result->candidates_dropped,
			  !direct, result->bytes_read, result->whole_frame };
	}

	py::list markers(result->markers.size());
	for (std::size_t i = 0; i < result->markers.size(); ++i) {
		const frappe::Marker &m = result->markers[i];
		Marker out{ m.id, newFloatArray(4, 2), m.hamming, m.margin, std::string(dict_.dict->name), m.tracked };
		float *c = out.corners.mutable_data();
		for (int k = 0; k < 4; ++k) {
			c[2 * k] = m.corners[k].x;
			c[2 * k + 1] = m.corners[k].y;
		}
		markers[i] = py::cast(std::move(out));
	}
	return markers;
}

py::dict PyDetector::stats()
{
	Stats last;
	{
		WithoutGil nogil;
		std::lock_guard<std::mutex> lock(mutex_);
		last = last_;
	}
	py::dict times;
	for (int i = 0; i < kStageCount; ++i)
		times[py::str(std::string(stageName(static_cast<Stage>(i))))] = last.times.ms[i];
	times["total"] = last.times.total_ms;
	py::dict out;
	out["times_ms"] = times;
	out["scale"] = last.scale;
	out["candidates"] = last.candidates;
	out["candidates_dropped"] = last.candidates_dropped;
	out["input_copied"] = last.copied;
	out["bytes_read"] = last.bytes_read;
	out["whole_frame"] = last.whole_frame;
	return out;
}

void PyDetector::reset()
{
	WithoutGil nogil;
	std::lock_guard<std::mutex> lock(mutex_);
	detector_.reset();
}

/* A setting's value for Python: a number of its type, or a choice's name. */
py::object settingValue(const Setting &s, const Config &c)
{
	if (s.isChoice())
		return py::str(s.text(c));
	if (s.isInteger())
		return py::int_(static_cast<long long>(s.number(c)));
	return py::float_(s.number(c));
}

py::dict PyDetector::configDict() const
{
	py::dict d;
	for (const Setting &s : settings()) {
		if (s.surfaces & kOnPython)
			d[py::str(std::string(s.name))] = settingValue(s, config_);
	}
	d["dictionary"] = dict_.builtin() ? py::cast(std::string(dict_.dict->name)) : py::cast(dict_);
	return d;
}

std::string typeName(py::handle value)
{
	return py::str(value.get_type().attr("__name__"));
}

/* frappe.Detector(dictionary, **settings): the keywords are the table's
 * (frappe/settings.h) snake_case names; the stubs and docs list them. */
PyDetector *makeDetector(py::handle dictionary, const py::kwargs &kwargs)
{
	DictionaryRef dict = dictionaryArg(dictionary);
	Config c;
	if (dict.builtin())
		c.dictionary = std::string(dict.dict->name);
	else
		c.custom_dictionary = dict.dict;
	for (const auto &[key, value] : kwargs) {
		const std::string name = py::str(key);
		const Setting *s = name.find('-') == std::string::npos ? findSetting(name) : nullptr;
		if (!s || !(s->surfaces & kOnPython) || s->name == "dictionary")
			throw py::type_error("Detector() got an unexpected keyword argument '" + name + "'");
		if (s->isChoice()) {
			if (!py::isinstance<py::str>(value))
				throw py::type_error(name + " must be a str, not " + typeName(value));
			try {
				s->parse(c, value.cast<std::string>());
			} catch (const std::invalid_argument &e) {
				throw py::value_error(name + " " + e.what());
			}
		} else if (s->isInteger()) {
			if (!py::isinstance<py::int_>(value) || py::isinstance<py::bool_>(value))
				throw py::type_error(name + " must be an int, not " + typeName(value));
			long long v = 0;
			try {
				v = value.cast<long long>();
			} catch (const py::cast_error &) {
				throw py::value_error(name + " is out of range: " + std::string(py::str(value)));
			}
			s->setNumber(c, static_cast<double>(v));
		} else {
			if (!py::isinstance<py::float_>(value) && !py::isinstance<py::int_>(value))
				throw py::type_error(name + " must be a float, not " + typeName(value));
			s->setNumber(c, value.cast<double>());
		}
	}
	/* frappe::Detector's std::invalid_argument says which parameter: ValueError. */
	return new PyDetector(c, std::move(dict));
}

} // namespace

void bindDetector(py::module_ &m)
{
	const Config d;
	m.def(
		"settings",
		[]() {
			const Config defaults;
			py::list out;
			for (const Setting &s : settings()) {
				if (!(s.surfaces & kOnPython))
					continue;
				py::dict e;
				e["name"] = std::string(s.name);
				e["type"] = s.isChoice() ? "str" : s.isInteger() ? "int" : "float";
				e["default"] = settingValue(s, defaults);
				e["range"] = s.rangeText();
				e["doc"] = std::string(s.doc);
				out.append(e);
			}
			return out;
		},
		R"doc(Detector's keyword arguments, in frappe::Config's order: a dict per setting
with its name, type ('float', 'int', 'str'), default, range and doc.)doc");
	py::class_<PyDetector>(m, "Detector", R"doc(
Finds the markers of one dictionary in 8-bit grey images.

    detector = frappe.Detector("apriltag_36h11")
    for marker in detector.detect(grey):
        print(marker.id, marker.corners)

`dictionary` is a name from frappe.dictionaries() (aliases such as
'DICT_6X6_250' or 'tag36h11' too) or a frappe.Dictionary. The keyword
arguments are frappe::Config's fields, by the names frappe.settings() lists
(docs/settings.md says what each trades off); the defaults are the paper's.
An unknown keyword or a value of the wrong type raises TypeError, an unknown
dictionary or a value out of range ValueError saying which.

One detector detects one frame at a time: calls from several threads take
turns (the GIL is released while detecting). Use one detector per thread to
detect in parallel; with mode='ascale' or 'track' one detector per video
stream, its frames in order.)doc")
		.def(py::init(&makeDetector), py::arg("dictionary") = d.dictionary)
		.def("detect", &PyDetector::detect, py::arg("image"), R"doc(
The markers in `image`, a 2-D uint8 numpy array (height, width) of grey
levels, as a list of frappe.Marker. Any strides: an array whose rows are
contiguous (C order, or a slice of one) is read in place, others are copied
into a buffer the detector keeps. A colour image raises ValueError (convert
it to grey first: cv2.cvtColor(image, cv2.COLOR_BGR2GRAY), or read it with
cv2.IMREAD_GRAYSCALE as frappe-detect does), another dtype TypeError, an image
over max_pixels ValueError.)doc")
		.def("reset", &PyDetector::reset, "Forgets what mode='ascale' or 'track' learned from earlier frames.")
		.def_property_readonly("stats", &PyDetector::stats, R"doc(
The last detect() call: {'times_ms': {stage: ms, ..., 'total': ms},
'scale': the resolution traced at, 'candidates': outlines decoded,
'candidates_dropped': outlines beyond max_candidates left unread,
'input_copied': whether the image was copied (its rows not contiguous),
'bytes_read': bytes of the frame the front end read (width x height, less
in mode='track' on a frame read in regions), 'whole_frame': whether all of
the frame was searched}.)doc")
		.def_property_readonly("config", &PyDetector::configDict,
				       "The keyword arguments it was made with: Detector(**d.config) makes another.")
		.def_property_readonly("dictionary", &PyDetector::dictionary, "Its frappe.Dictionary.")
		.def_property_readonly("max_hamming", &PyDetector::maxHamming,
				       "The bit errors it corrects among cells read clearly (max_hamming=-1 resolved).")
		.def("__repr__", &PyDetector::repr);
}

} // namespace frappe::python
