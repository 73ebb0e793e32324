// SPDX-License-Identifier: MIT
// One pose from many markers (frappe/bundle.h): bundles read from
// apriltag_ros's YAML or a grid board's description, and their pose from
// every marker seen of them.
#include "frappe/bundle.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "lens.h"
#include "markup.h"
#include "rigid_fit.h"
#include "rodrigues.h"
#include "small_file.h"
#include "utf8.h"

namespace frappe {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using detail::Lens;
using detail::MarkupNode;

const BundleMarker *Bundle::find(int id) const
{
	for (const BundleMarker &m : markers)
		if (m.id == id)
			return &m;
	return nullptr;
}

BundleMarker Bundle::placed(int id, double size, std::array<double, 3> position, std::array<double, 4> q)
{
	const Matrix3d R = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
	const Vector3d c(position[0], position[1], position[2]);
	/* frappe/pose.h's marker frame: TL (-s/2, s/2), TR, BR, BL. */
	const double h = size / 2.0, square[4][2] = { { -h, h }, { h, h }, { h, -h }, { -h, -h } };
	BundleMarker m;
	m.id = id;
	m.size = size;
	for (int i = 0; i < 4; ++i) {
		const Vector3d p = R * Vector3d(square[i][0], square[i][1], 0.0) + c;
		m.corners[static_cast<std::size_t>(i)] = { p.x(), p.y(), p.z() };
	}
	return m;
}

Bundle Bundle::grid(int rows, int cols, double size, double gap, int first_id)
{
	if (rows < 1 || cols < 1 || static_cast<long long>(rows) * cols > (1 << 20))
		throw std::invalid_argument("Bundle::grid: rows and cols must be at least 1 (and at most 2^20 markers)");
	if (!(size > 0.0) || !std::isfinite(size) || !(gap >= 0.0) || !std::isfinite(gap))
		throw std::invalid_argument("Bundle::grid: size must be positive and gap not negative");
	if (first_id < 0)
		throw std::invalid_argument("Bundle::grid: first_id must not be negative");
	Bundle b;
	b.name = "grid";
	const double pitch = size + gap, top = rows * size + (rows - 1) * gap;
	for (int r = 0; r < rows; ++r) {
		for (int c = 0; c < cols; ++c) {
			BundleMarker m;
			m.id = first_id + r * cols + c;
			m.size = size;
			const double x = c * pitch, y = top - r * pitch;
			m.corners = { { { x, y, 0.0 }, { x + size, y, 0.0 }, { x + size, y - size, 0.0 }, { x, y - size, 0.0 } } };
			b.markers.push_back(m);
		}
	}
	return b;
}

namespace {

/* 'text', built by appending (GCC 12 warns falsely, its bug 105329, on
 * "'" + std::string). */
std::string quoted(std::string_view text)
{
	std::string q(1, '\'');
	q.append(text);
	q += '\'';
	return q;
}

/* The bundle file's keys, each a number or an integer, with errors that
 * name the origin and line. */
class Reader
{
public:
	explicit Reader(std::string_view origin) : origin_(origin) {}

	[[noreturn]] void fail(int line, const std::string &what) const
	{
		throw std::invalid_argument(std::string(origin_) + ":" + std::to_string(line) + ": " + what);
	}
	const MarkupNode &need(const MarkupNode &map, std::string_view key) const
	{
		const MarkupNode *n = map.find(key);
		if (!n)
			fail(map.line, "no " + quoted(key));
		if (n->kind != MarkupNode::Kind::Scalar)
			fail(n->line, quoted(key) + " must be a number");
		return *n;
	}
	double number(const MarkupNode &map, std::string_view key) const
	{
		const MarkupNode &n = need(map, key);
		double v = 0.0;
		const auto [end, ec] = std::from_chars(n.text.data(), n.text.data() + n.text.size(), v);
		if (ec != std::errc() || end != n.text.data() + n.text.size() || !std::isfinite(v))
			fail(n.line, quoted(key) + " is not a number: " + quoted(detail::toUtf8(n.text, 40)));
		return v;
	}
	int integer(const MarkupNode &map, std::string_view key) const
	{
		const MarkupNode &n = need(map, key);
		int v = 0;
		const auto [end, ec] = std::from_chars(n.text.data(), n.text.data() + n.text.size(), v);
		if (ec != std::errc() || end != n.text.data() + n.text.size() || v < 0)
			fail(n.line, quoted(key) + " must be a whole number, 0 or more: " + quoted(detail::toUtf8(n.text, 40)));
		return v;
	}
	/* Only these keys. */
	void only(const MarkupNode &map, std::initializer_list<std::string_view> keys) const
	{
		for (std::size_t k = 0; k < map.keys.size(); ++k)
			if (std::find(keys.begin(), keys.end(), map.keys[k]) == keys.end())
				fail(map.items[k].line, "unknown key " + quoted(detail::toUtf8(map.keys[k], 40)));
	}

private:
	std::string_view origin_;
};

Bundle apriltagRos(const Reader &rd, const MarkupNode &bundles)
{
	if (bundles.kind != MarkupNode::Kind::Seq || bundles.items.empty())
		rd.fail(bundles.line, "tag_bundles must be a list of bundles");
	const MarkupNode &first = bundles.items[0];
	if (first.kind != MarkupNode::Kind::Map)
		rd.fail(first.line, "a bundle must be {name: ..., layout: [...]}");
	Bundle b;
	if (const MarkupNode *name = first.find("name"))
		b.name = name->text;
	const MarkupNode *layout = first.find("layout");
	if (!layout || layout->kind != MarkupNode::Kind::Seq || layout->items.empty())
		rd.fail(first.line, "the bundle has no layout: [{id: ..., size: ..., x: ..., ...}, ...]");
	for (const MarkupNode &t : layout->items) {
		if (t.kind != MarkupNode::Kind::Map)
			rd.fail(t.line, "a layout entry must be {id: ..., size: ..., x: ..., y: ..., z: ..., qw: ..., ...}");
		rd.only(t, { "id", "size", "x", "y", "z", "qw", "qx", "qy", "qz" });
		const int id = rd.integer(t, "id");
		const double size = rd.number(t, "size");
		if (!(size > 0.0))
			rd.fail(t.line, "id " + std::to_string(id) + ": size must be positive");
		auto opt = [&](std::string_view key, double dflt) { return t.find(key) ? rd.number(t, key) : dflt; };
		const std::array<double, 4> q = { opt("qw", 1.0), opt("qx", 0.0), opt("qy", 0.0), opt("qz", 0.0) };
		const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
		if (std::abs(norm - 1.0) > 1e-3)
			rd.fail(t.line, "id " + std::to_string(id) + ": the quaternion's length is " + std::to_string(norm) +
						", not 1");
		if (b.find(id))
			rd.fail(t.line, "id " + std::to_string(id) + " given twice");
		b.markers.push_back(Bundle::placed(id, size, { opt("x", 0.0), opt("y", 0.0), opt("z", 0.0) }, q));
	}
	return b;
}

Bundle parseAny(std::string_view text, std::string_view origin)
{
	const Reader rd(origin);
	const MarkupNode root = detail::parseYamlSubset(text, origin);
	if (root.kind != MarkupNode::Kind::Map)
		rd.fail(root.line, "not a bundle (expected tag_bundles: or board: grid)");
	if (const MarkupNode *bundles = root.find("tag_bundles"))
		return apriltagRos(rd, *bundles);
	if (const MarkupNode *board = root.find("board")) {
		if (board->text != "grid")
			rd.fail(board->line, "board: " + quoted(detail::toUtf8(board->text, 40)) + " is not a known board (grid)");
		rd.only(root, { "board", "rows", "cols", "size", "gap", "first_id", "name" });
		try {
			Bundle b = Bundle::grid(rd.integer(root, "rows"), rd.integer(root, "cols"), rd.number(root, "size"),
						rd.number(root, "gap"), root.find("first_id") ? rd.integer(root, "first_id") : 0);
			if (const MarkupNode *name = root.find("name"))
				b.name = name->text;
			return b;
		} catch (const std::invalid_argument &e) {
			const std::string what = e.what();
			if (what.starts_with("Bundle::grid"))
				rd.fail(board->line, what);
			throw;
		}
	}
	rd.fail(root.line, "not a bundle: no tag_bundles (apriltag_ros) nor board: grid");
}

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Rigid {
	Matrix3d R = Matrix3d::Identity();
	Vector3d t = Vector3d::Zero();
};

/* A marker seen: its corners in the bundle frame and in the image. */
struct Seen {
	const BundleMarker *marker = nullptr;
	std::array<Vector3d, 4> model;
	std::array<Point2f, 4> image;
	double sidePx = 0.0;
	double rms = kInf;
};

/* Sum of squared corner distances, pixels^2; infinity behind the camera. */
double squaredError(const Rigid &T, const Seen &s, const Lens &lens)
{
	return detail::squaredReprojection(T.R, T.t, s.model, s.image, lens);
}

} // namespace

/* What a pose needs besides its result, kept by BundleScratch. */
struct BundleScratch::Impl {
	std::vector<Seen> seen;
	std::vector<Seen *> used;
	std::vector<Vector3d> model; /* refine()'s corners */
	std::vector<Point2f> image;
};

namespace {

/* Every corner of `seen` refined together (rigid_fit.h), gathered into
 * `model` and `image`. */
void refine(Rigid &T, std::span<Seen *const> seen, const Lens &lens, std::vector<Vector3d> &model,
	    std::vector<Point2f> &image)
{
	model.clear();
	image.clear();
	for (const Seen *s : seen) {
		model.insert(model.end(), s->model.begin(), s->model.end());
		image.insert(image.end(), s->image.begin(), s->image.end());
	}
	detail::refineRigid(T.R, T.t, model, image, lens, 30);
}

double totalError(const Rigid &T, std::span<Seen *const> seen, const Lens &lens)
{
	double sum = 0.0;
	for (const Seen *s : seen)
		sum += squaredError(T, *s, lens);
	return sum;
}

/* The marker's own frame in the bundle's: x along its top side, y up its
 * left side. */
Rigid markerInBundle(const Seen &s)
{
	const Vector3d c = 0.25 * (s.model[0] + s.model[1] + s.model[2] + s.model[3]);
	const Vector3d x = (s.model[1] - s.model[0] + s.model[2] - s.model[3]).normalized();
	Vector3d y = s.model[0] - s.model[3] + s.model[1] - s.model[2];
	y = (y - x * x.dot(y)).normalized();
	Rigid T;
	T.R.col(0) = x;
	T.R.col(1) = y;
	T.R.col(2) = x.cross(y);
	T.t = c;
	return T;
}

/* Markers whose corners lie within max(2 px, 4% of their side) RMS. */
double threshold(const Seen &s)
{
	return std::max(2.0, 0.04 * s.sidePx);
}

} // namespace

Bundle parseBundle(std::string_view text, std::string_view origin)
{
	try {
		Bundle b = parseAny(text, origin);
		if (b.markers.empty())
			throw std::invalid_argument(std::string(origin) + ": no markers");
		return b;
	} catch (const std::invalid_argument &e) {
		const std::string_view what = e.what();
		if (detail::invalidUtf8At(what) == std::string_view::npos)
			throw;
		throw std::invalid_argument(detail::toUtf8(what, std::string::npos));
	}
}

Bundle loadBundle(const std::string &path)
{
	const detail::SmallFile f = detail::readSmallFile(path, detail::kMarkupMaxBytes);
	detail::throwFileFault(f, detail::toUtf8(path, std::string::npos), "1 MiB", "bundle file");
	return parseBundle(f.text, path);
}

BundleScratch::BundleScratch() : impl_(std::make_unique<Impl>())
{}
BundleScratch::~BundleScratch() = default;
BundleScratch::BundleScratch(BundleScratch &&) noexcept = default;
BundleScratch &BundleScratch::operator=(BundleScratch &&) noexcept = default;

std::optional<BundlePose> estimateBundlePose(const Bundle &bundle, std::span<const Marker> markers,
					     const Camera &camera)
{
	BundleScratch scratch;
	BundlePose out;
	if (!estimateBundlePose(bundle, markers, camera, out, scratch))
		return std::nullopt;
	return out;
}

bool estimateBundlePose(const Bundle &bundle, std::span<const Marker> markers, const Camera &camera, BundlePose &out,
			BundleScratch &scratch)
{
	camera.validate();
	const Lens lens(camera);
	out.pose = {};
	out.used.clear();
	out.rejected.clear();
	std::vector<Seen> &seen = scratch.impl().seen;
	seen.clear();
	for (const Marker &m : markers) {
		const BundleMarker *b = bundle.find(m.id);
		if (!b)
			continue;
		/* An id seen twice: which is the bundle's is unknown. */
		const auto twice = [&](const Seen &s) { return s.marker == b; };
		if (std::any_of(seen.begin(), seen.end(), twice)) {
			seen.erase(std::remove_if(seen.begin(), seen.end(), twice), seen.end());
			if (std::find(out.rejected.begin(), out.rejected.end(), m.id) == out.rejected.end())
				out.rejected.push_back(m.id);
			continue;
		}
		if (std::find(out.rejected.begin(), out.rejected.end(), m.id) != out.rejected.end())
			continue;
		Seen s;
		s.marker = b;
		double side = 0.0;
		for (int i = 0; i < 4; ++i) {
			const auto &c = b->corners[static_cast<std::size_t>(i)];
			s.model[static_cast<std::size_t>(i)] = Vector3d(c[0], c[1], c[2]);
			s.image[static_cast<std::size_t>(i)] = m.corners[static_cast<std::size_t>(i)];
			const Point2f a = m.corners[static_cast<std::size_t>(i)], n = m.corners[static_cast<std::size_t>((i + 1) & 3)];
			side += std::hypot(a.x - n.x, a.y - n.y) / 4.0;
		}
		s.sidePx = side;
		seen.push_back(s);
	}
	if (seen.empty())
		return false;

	/* Starting points: each marker's two poses, carried to the bundle's
	 * frame; the one most markers agree with (then the smallest error over
	 * them) is kept. */
	Rigid best;
	int bestCount = 0;
	double bestErr = kInf;
	for (const Seen &s : seen) {
		const auto mp = estimatePose(s.image, s.marker->size, camera);
		if (!mp)
			continue;
		const Rigid inBundle = markerInBundle(s);
		for (const Pose *p : { &mp->pose, &mp->alternative }) {
			if (!std::isfinite(p->error))
				continue;
			const Matrix3d Rcm = detail::rotationMatrix(Vector3d(p->rvec[0], p->rvec[1], p->rvec[2]));
			Rigid T;
			T.R = Rcm * inBundle.R.transpose();
			T.t = Vector3d(p->tvec[0], p->tvec[1], p->tvec[2]) - T.R * inBundle.t;
			int count = 0;
			double err = 0.0;
			for (const Seen &o : seen) {
				const double e = squaredError(T, o, lens);
				if (std::sqrt(e / 4.0) < threshold(o)) {
					++count;
					err += e;
				}
			}
			if (count > bestCount || (count == bestCount && err < bestErr)) {
				best = T;
				bestCount = count;
				bestErr = err;
			}
		}
	}
	if (bestCount == 0)
		return false;

	/* Refined over the agreeing markers, then once more without those
	 * that still disagree. */
	std::vector<Seen *> &used = scratch.impl().used;
	for (int pass = 0; pass < 2; ++pass) {
		used.clear();
		for (Seen &s : seen) {
			s.rms = std::sqrt(squaredError(best, s, lens) / 4.0);
			if (s.rms < threshold(s))
				used.push_back(&s);
		}
		if (used.empty())
			return false;
		refine(best, used, lens, scratch.impl().model, scratch.impl().image);
	}
	for (Seen &s : seen) {
		s.rms = std::sqrt(squaredError(best, s, lens) / 4.0);
		if (std::find(used.begin(), used.end(), &s) != used.end())
			out.used.push_back(s.marker->id);
		else
			out.rejected.push_back(s.marker->id);
	}
	const double err = totalError(best, used, lens);
	const Vector3d rv = detail::rotationVector(best.R);
	out.pose.rvec = { rv.x(), rv.y(), rv.z() };
	out.pose.tvec = { best.t.x(), best.t.y(), best.t.z() };
	out.pose.error = std::sqrt(err / (4.0 * static_cast<double>(used.size())));
	std::sort(out.used.begin(), out.used.end());
	std::sort(out.rejected.begin(), out.rejected.end());
	return true;
}

} // namespace frappe
