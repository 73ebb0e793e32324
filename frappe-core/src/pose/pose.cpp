// SPDX-License-Identifier: MIT
// A square marker's pose from its four corners: IPPE (Collins and Bartoli,
// "Infinitesimal Plane-based Pose Estimation", IJCV 2014) gives both poses
// the corners allow in closed form; the better one is refined by
// Levenberg-Marquardt on the reprojection error in distorted pixels.
#include "frappe/pose.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "lens.h"
#include "rigid_fit.h"
#include "rodrigues.h"

namespace frappe {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using detail::Lens;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/* The corners in the marker frame for a side of 2 (Marker::corners' order). */
constexpr double kSquare[4][2] = { { -1.0, 1.0 }, { 1.0, 1.0 }, { 1.0, -1.0 }, { -1.0, -1.0 } };

struct Rigid {
	Matrix3d R;
	Vector3d t;
	double error = kInf;
};

/* The corners in the marker frame for a side of 2 * half. */
std::array<Vector3d, 4> squareCorners(double half)
{
	std::array<Vector3d, 4> m;
	for (int i = 0; i < 4; ++i)
		m[static_cast<std::size_t>(i)] = Vector3d(half * kSquare[i][0], half * kSquare[i][1], 0.0);
	return m;
}

/* RMS over the corners of the distance between projection and observation,
 * pixels; infinity when a corner is behind the camera. */
double reprojectionError(const Matrix3d &R, const Vector3d &t, double half, const Lens &lens,
			 const std::array<Point2f, 4> &corners)
{
	return std::sqrt(detail::squaredReprojection(R, t, squareCorners(half), corners, lens) / 4.0);
}

/* A convex quadrilateral with some area: no three corners collinear or
 * coincident, which a view of a square in front of the camera always is. */
bool properQuadrilateral(const std::array<Eigen::Vector2d, 4> &q)
{
	double scale = 0.0;
	for (int i = 0; i < 4; ++i)
		scale = std::max(scale, (q[i] - q[(i + 2) % 4]).squaredNorm());
	int positive = 0, negative = 0;
	for (int i = 0; i < 4; ++i) {
		const Eigen::Vector2d a = q[(i + 1) % 4] - q[i], b = q[(i + 2) % 4] - q[(i + 1) % 4];
		const double cross = a.x() * b.y() - a.y() * b.x();
		if (cross > 1e-9 * scale)
			++positive;
		else if (cross < -1e-9 * scale)
			++negative;
	}
	return positive == 4 || negative == 4;
}

/* The homography taking the side-2 square to `q`, normalised so that
 * H(2, 2) = 1 (the square's centre is in front of the camera). */
bool squareHomography(const std::array<Eigen::Vector2d, 4> &q, Matrix3d &H)
{
	Eigen::Matrix<double, 8, 8> A;
	Eigen::Matrix<double, 8, 1> b;
	for (int i = 0; i < 4; ++i) {
		const double X = kSquare[i][0], Y = kSquare[i][1], u = q[i].x(), v = q[i].y();
		A.row(2 * i) << X, Y, 1.0, 0.0, 0.0, 0.0, -u * X, -u * Y;
		A.row(2 * i + 1) << 0.0, 0.0, 0.0, X, Y, 1.0, -v * X, -v * Y;
		b(2 * i) = u;
		b(2 * i + 1) = v;
	}
	const Eigen::FullPivLU<Eigen::Matrix<double, 8, 8>> lu(A);
	if (!lu.isInvertible())
		return false;
	const Eigen::Matrix<double, 8, 1> h = lu.solve(b);
	H << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), 1.0;
	return H.allFinite();
}

/* The translation that, with rotation R, best explains the normalised
 * points: each gives two equations linear in t (the projection's equations
 * multiplied by depth); least squares. */
Vector3d translationFor(const Matrix3d &R, double half, const std::array<Eigen::Vector2d, 4> &q)
{
	Matrix3d AtA = Matrix3d::Zero();
	Vector3d Atb = Vector3d::Zero();
	for (int i = 0; i < 4; ++i) {
		const Vector3d p = R * Vector3d(half * kSquare[i][0], half * kSquare[i][1], 0.0);
		const double u = q[i].x(), v = q[i].y();
		const Vector3d r1(1.0, 0.0, -u), r2(0.0, 1.0, -v);
		AtA += r1 * r1.transpose() + r2 * r2.transpose();
		Atb += r1 * (u * p.z() - p.x()) + r2 * (v * p.z() - p.y());
	}
	return AtA.partialPivLu().solve(Atb);
}

/* IPPE's two rotations. The square's centre (the plane's origin) is seen
 * along the ray t ~ (vx, vy, 1). Rv turns the optical axis onto that ray;
 * in its frame the projection's derivative at the centre is [I 0] / depth,
 * so the homography's Jacobian J there equals (1 / depth) B R' where B is
 * ([I | -v] Rv) restricted to two columns and R' = Rv^T R. Its upper-left
 * 2x2 block is then A = B^-1 J up to a positive scale: the scale is the
 * largest singular value of A (the block's columns must complete to
 * orthonormal ones), and the completing third row is fixed up to its sign:
 * the two solutions. */
bool ippeRotations(const Matrix3d &H, Matrix3d &R1, Matrix3d &R2)
{
	const double vx = H(0, 2), vy = H(1, 2);
	Eigen::Matrix2d J;
	J << H(0, 0) - H(2, 0) * vx, H(0, 1) - H(2, 1) * vx, H(1, 0) - H(2, 0) * vy, H(1, 1) - H(2, 1) * vy;

	const Vector3d ray = Vector3d(vx, vy, 1.0).normalized();
	const Vector3d axis = Vector3d::UnitZ().cross(ray);
	const double s = axis.norm();
	const Matrix3d Rv = s > 1e-15 ? detail::rotationMatrix(axis / s * std::atan2(s, ray.z()))
				      : Matrix3d::Identity();
	Eigen::Matrix<double, 2, 3> P;
	P << 1.0, 0.0, -vx, 0.0, 1.0, -vy;
	const Eigen::Matrix2d B = (P * Rv).leftCols<2>();
	const double detB = B.determinant();
	if (!std::isfinite(detB) || std::abs(detB) < 1e-12)
		return false;
	const Eigen::Matrix2d A = B.inverse() * J;

	/* The largest singular value: the square root of AtA's larger eigenvalue. */
	const Eigen::Matrix2d S = A.transpose() * A;
	const double half_tr = 0.5 * (S(0, 0) + S(1, 1));
	const double d = 0.5 * (S(0, 0) - S(1, 1));
	const double gamma = std::sqrt(half_tr + std::sqrt(d * d + S(0, 1) * S(0, 1)));
	if (!std::isfinite(gamma) || gamma < 1e-12)
		return false;
	const Eigen::Matrix2d R22 = A / gamma;
	const Eigen::Matrix2d M = Eigen::Matrix2d::Identity() - R22.transpose() * R22;
	const double b0 = std::sqrt(std::max(M(0, 0), 0.0));
	const double b1 = std::copysign(std::sqrt(std::max(M(1, 1), 0.0)), M(0, 1) < 0.0 ? -1.0 : 1.0);

	const auto rotation = [&](double sign) {
		Vector3d c1(R22(0, 0), R22(1, 0), sign * b0);
		Vector3d c2(R22(0, 1), R22(1, 1), sign * b1);
		/* Orthonormal to the last bit (rounding leaves ~1e-16). */
		c1.normalize();
		c2 = (c2 - c1.dot(c2) * c1).normalized();
		Matrix3d Rp;
		Rp.col(0) = c1;
		Rp.col(1) = c2;
		Rp.col(2) = c1.cross(c2);
		return Matrix3d(Rv * Rp);
	};
	R1 = rotation(1.0);
	R2 = rotation(-1.0);
	return R1.allFinite() && R2.allFinite();
}

/* Levenberg-Marquardt on the pose, minimising the corners' reprojection
 * error in distorted pixels (rigid_fit.h). */
void refine(Rigid &pose, double half, const Lens &lens, const std::array<Point2f, 4> &corners)
{
	pose.error = std::sqrt(detail::refineRigid(pose.R, pose.t, squareCorners(half), corners, lens, 20) / 4.0);
}

Pose toPose(const Rigid &r)
{
	Pose p;
	const Vector3d rv = detail::rotationVector(r.R);
	p.rvec = { rv.x(), rv.y(), rv.z() };
	p.tvec = { r.t.x(), r.t.y(), r.t.z() };
	p.error = r.error;
	return p;
}

} // namespace

double MarkerPose::ambiguity() const
{
	if (pose.error > 0.0)
		return alternative.error / pose.error;
	return alternative.error > 0.0 ? kInf : 1.0;
}

std::optional<MarkerPose> estimatePose(const std::array<Point2f, 4> &corners, double marker_size,
				       const Camera &camera)
{
	if (!std::isfinite(marker_size) || !(marker_size > 0.0))
		throw std::invalid_argument("estimatePose: marker size must be positive and finite, got " +
					    std::to_string(marker_size));
	camera.validate();
	const Lens lens(camera);
	const double half = marker_size / 2.0;

	std::array<Eigen::Vector2d, 4> q;
	for (int i = 0; i < 4; ++i) {
		if (!std::isfinite(corners[i].x) || !std::isfinite(corners[i].y))
			return std::nullopt;
		double xd, yd, x, y;
		lens.fromPixel(corners[i].x, corners[i].y, xd, yd);
		if (!lens.undistort(xd, yd, x, y))
			return std::nullopt;
		q[i] = { x, y };
	}
	Matrix3d H, R1, R2;
	if (!properQuadrilateral(q) || !squareHomography(q, H) || !ippeRotations(H, R1, R2))
		return std::nullopt;

	Rigid a{ R1, translationFor(R1, half, q) };
	Rigid b{ R2, translationFor(R2, half, q) };
	a.error = reprojectionError(a.R, a.t, half, lens, corners);
	b.error = reprojectionError(b.R, b.t, half, lens, corners);
	if (b.error < a.error)
		std::swap(a, b);
	if (!std::isfinite(a.error))
		return std::nullopt;
	refine(a, half, lens, corners);

	MarkerPose result;
	result.pose = toPose(a);
	result.alternative = toPose(b);
	if (!std::isfinite(b.error))
		result.alternative.error = kInf;
	return result;
}

void projectPoints(std::span<const std::array<double, 3>> points, const Pose &pose, const Camera &camera,
		   std::span<Point2f> out)
{
	if (out.size() != points.size())
		throw std::invalid_argument("frappe::projectPoints: " + std::to_string(points.size()) + " points but room for " +
					    std::to_string(out.size()));
	camera.validate();
	const Lens lens(camera);
	const Matrix3d R = detail::rotationMatrix(Vector3d(pose.rvec[0], pose.rvec[1], pose.rvec[2]));
	const Vector3d t(pose.tvec[0], pose.tvec[1], pose.tvec[2]);
	for (std::size_t i = 0; i < points.size(); ++i) {
		const auto &m = points[i];
		double u, v;
		if (detail::projectPoint(R * Vector3d(m[0], m[1], m[2]) + t, lens, u, v))
			out[i] = { static_cast<float>(u), static_cast<float>(v) };
		else
			out[i] = { std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::quiet_NaN() };
	}
}

std::vector<Point2f> projectPoints(std::span<const std::array<double, 3>> points, const Pose &pose,
				  const Camera &camera)
{
	std::vector<Point2f> out(points.size());
	projectPoints(points, pose, camera, out);
	return out;
}

std::vector<Point2f> undistortPoints(std::span<const Point2f> points, const Camera &camera)
{
	camera.validate();
	const Lens lens(camera);
	std::vector<Point2f> out;
	out.reserve(points.size());
	for (const Point2f &p : points) {
		double xd, yd, x, y, u, v;
		lens.fromPixel(p.x, p.y, xd, yd);
		if (lens.undistort(xd, yd, x, y)) {
			lens.toPixel(x, y, u, v);
			out.push_back({ static_cast<float>(u), static_cast<float>(v) });
		} else {
			out.push_back({ std::numeric_limits<float>::quiet_NaN(),
					std::numeric_limits<float>::quiet_NaN() });
		}
	}
	return out;
}

} // namespace frappe
