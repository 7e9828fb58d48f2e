// Collision probability of ellipsoidal robots (sogmm/collision.hpp).
#include "sogmm/collision.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

#include "parallel.hpp"
#include "progress.hpp"
#include "sogmm/error.hpp"
#include "surface_discs.hpp"

namespace sogmm {

namespace {

// A robot's frame: S^-1/2, S^1/2 and its bounding radius sqrt(lambda_max(S)).
struct Robot {
  Eigen::Vector3d c;
  Eigen::Matrix3d inv_sqrt, sqrt;
  double radius;
};

Robot robot_at(const double* center, const double* shape, std::size_t i) {
  Robot r;
  Eigen::Matrix3d s;
  for (int k = 0; k < 3; ++k) r.c(k) = center[k];
  require(r.c.allFinite(), ErrorCode::InvalidData, "collision: centre of robot " + std::to_string(i) + " is not finite");
  for (int k = 0; k < 9; ++k) s(k / 3, k % 3) = shape[k];
  const double scale = s.cwiseAbs().maxCoeff();
  const bool symmetric = s.allFinite() && (s - s.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * scale;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(s);
  require(symmetric && eig.info() == Eigen::Success && eig.eigenvalues()(0) > 0 &&
              std::isfinite(1.0 / eig.eigenvalues()(0)),
          ErrorCode::InvalidArgument,
          "collision: shape of robot " + std::to_string(i) + " is not a finite symmetric positive definite matrix");
  const Eigen::Vector3d l = eig.eigenvalues();
  const Eigen::Matrix3d& q = eig.eigenvectors();
  r.inv_sqrt = q * l.cwiseSqrt().cwiseInverse().asDiagonal() * q.transpose();
  r.sqrt = q * l.cwiseSqrt().asDiagonal() * q.transpose();
  r.radius = std::sqrt(l(2));
  return r;
}

double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// P_k of the header: disc d seen from robot r.
double contact_probability(const Robot& r, const detail::Disc& d) {
  detail::Disc y;
  y.mu = r.inv_sqrt * (d.mu - r.c);
  Eigen::Matrix<double, 3, 2> axes;
  axes.col(0) = d.a * (r.inv_sqrt * d.e1);
  axes.col(1) = d.b * (r.inv_sqrt * d.e2);
  const Eigen::JacobiSVD<Eigen::Matrix<double, 3, 2>> svd(axes, Eigen::ComputeThinU);
  y.e1 = svd.matrixU().col(0);
  y.e2 = svd.matrixU().col(1);
  y.normal = y.e1.cross(y.e2);
  y.a = svd.singularValues()(0);
  y.b = std::max(svd.singularValues()(1), 1e-300);
  Eigen::Vector3d from;
  const double dist = detail::disc_distance(y, Eigen::Vector3d::Zero(), from);
  // The nearest point is -from; at distance 0 the disc passes through the
  // centre: the clearance is minus the robot's radius along the disc's normal.
  const Eigen::Vector3d u = dist > 0 ? Eigen::Vector3d(-from / dist) : y.normal;
  const double gap = (dist - 1.0) * (r.sqrt * u).norm();
  return normal_cdf(-gap / d.sigma);
}

}  // namespace

void collision_probability(const Gmm& gmm, const double* centers, const double* shapes, std::size_t n, double* out,
                           const SurfaceDistanceOptions& options, int threads, const ProgressSink& progress) {
  validate(options);
  require(gmm.size() > 0, ErrorCode::InvalidData, "collision: the model has no component");
  if (n == 0) return;
  require(centers != nullptr && shapes != nullptr && out != nullptr, ErrorCode::InvalidArgument,
          "collision: null input or output");
  std::vector<Robot> robots;
  robots.reserve(n);
  for (std::size_t i = 0; i < n; ++i) robots.push_back(robot_at(centers + 3 * i, shapes + 9 * i, i));
  const ProgressScope scope(progress);
  const std::vector<detail::Disc> discs = detail::discs_of(gmm, options.disc_sigmas);
  detail::progress_begin(Stage::Scoring, n);
  detail::parallel_for(n, detail::team_size(threads), 16, [&](std::size_t i, int) {
    const Robot& r = robots[i];
    double best = 0.0;
    for (const detail::Disc& d : discs) {
      // Beyond the bounding spheres by 8 sigma: P_k < Phi(-8).
      if ((d.mu - r.c).norm() - r.radius - d.radius > 8.0 * d.sigma) continue;
      best = std::max(best, contact_probability(r, d));
    }
    out[i] = best;
  });
}

}  // namespace sogmm
