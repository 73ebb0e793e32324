// SPDX-License-Identifier: MIT
#include "rigid_fit.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

#include "rodrigues.h"

namespace frappe::detail {

using Eigen::Matrix3d;
using Eigen::Vector3d;

bool projectPoint(const Vector3d &p, const Lens &lens, double &u, double &v)
{
	if (!(p.z() > 0.0))
		return false;
	double xd, yd;
	lens.distort(p.x() / p.z(), p.y() / p.z(), xd, yd);
	lens.toPixel(xd, yd, u, v);
	return std::isfinite(u) && std::isfinite(v);
}

double squaredReprojection(const Matrix3d &R, const Vector3d &t, std::span<const Vector3d> model,
			   std::span<const Point2f> observed, const Lens &lens)
{
	double sum = 0.0;
	for (std::size_t i = 0; i < model.size(); ++i) {
		double u, v;
		if (!projectPoint(R * model[i] + t, lens, u, v))
			return std::numeric_limits<double>::infinity();
		const double du = u - observed[i].x, dv = v - observed[i].y;
		sum += du * du + dv * dv;
	}
	return sum;
}

double refineRigid(Matrix3d &R, Vector3d &t, std::span<const Vector3d> model, std::span<const Point2f> observed,
		   const Lens &lens, int iterations)
{
	double lambda = 1e-3, err = squaredReprojection(R, t, model, observed, lens);
	const Eigen::Matrix2d K =
		Eigen::Map<const Eigen::Matrix<double, 2, 2, Eigen::RowMajor>>(lens.pixelJacobian().data());
	for (int it = 0; it < iterations && std::isfinite(err); ++it) {
		Eigen::Matrix<double, 6, 6> JtJ = Eigen::Matrix<double, 6, 6>::Zero();
		Eigen::Matrix<double, 6, 1> Jtr = Eigen::Matrix<double, 6, 1>::Zero();
		for (std::size_t i = 0; i < model.size(); ++i) {
			const Vector3d q = R * model[i];
			const Vector3d p = q + t;
			if (!(p.z() > 0.0))
				return err;
			const double x = p.x() / p.z(), y = p.y() / p.z();
			double xd, yd, u, v;
			Jacobian2 jd;
			lens.distort(x, y, xd, yd, &jd);
			lens.toPixel(xd, yd, u, v);
			Eigen::Matrix<double, 2, 3> dpi;
			dpi << 1.0, 0.0, -x, 0.0, 1.0, -y;
			dpi /= p.z();
			const Eigen::Matrix<double, 2, 3> D =
				K * Eigen::Map<const Eigen::Matrix<double, 2, 2, Eigen::RowMajor>>(jd.data()) * dpi;
			Matrix3d qx;
			qx << 0.0, -q.z(), q.y(), q.z(), 0.0, -q.x(), -q.y(), q.x(), 0.0;
			Eigen::Matrix<double, 2, 6> J;
			J.leftCols<3>() = -D * qx;
			J.rightCols<3>() = D;
			const Eigen::Vector2d r(u - observed[i].x, v - observed[i].y);
			JtJ += J.transpose() * J;
			Jtr += J.transpose() * r;
		}
		bool improved = false;
		for (int tries = 0; tries < 8 && !improved; ++tries) {
			Eigen::Matrix<double, 6, 6> A = JtJ;
			A.diagonal() += lambda * JtJ.diagonal();
			const Eigen::Matrix<double, 6, 1> step = -A.ldlt().solve(Jtr);
			if (!step.allFinite())
				return err;
			const Matrix3d nextR = rotationMatrix(step.head<3>()) * R;
			const Vector3d nextT = t + step.tail<3>();
			const double e = squaredReprojection(nextR, nextT, model, observed, lens);
			if (e < err) {
				const bool converged = step.norm() < 1e-12 * (1.0 + t.norm());
				R = nextR;
				t = nextT;
				err = e;
				lambda = std::max(lambda * 0.1, 1e-9);
				improved = true;
				if (converged)
					return err;
			} else {
				lambda *= 10.0;
			}
		}
		if (!improved)
			return err;
	}
	return err;
}

} // namespace frappe::detail
