// Components as surface discs (surface_discs.hpp).
#include "surface_discs.hpp"

#include <cmath>
#include <string>
#include <utility>

#include <Eigen/Eigenvalues>

#include "gmm_eigen.hpp"
#include "sogmm/error.hpp"

namespace sogmm::detail {

namespace {

// The point of the ellipse (s/a)^2 + (t/b)^2 = 1 nearest to (s, t), which
// lies outside it, with s, t >= 0: (a^2 s / (tau + a^2), b^2 t / (tau + b^2))
// for the root tau > 0 of F(tau) = (a s / (tau + a^2))^2 + (b t / (tau + b^2))^2 - 1.
// F is convex and decreasing for tau > -b^2, so Newton from 0 climbs to the
// root from below without overshooting.
std::pair<double, double> nearest_on_ellipse(double a, double b, double s, double t) {
  double tau = 0.0;
  for (int it = 0; it < 64; ++it) {
    const double p = a * s / (tau + a * a), q = b * t / (tau + b * b);
    const double f = p * p + q * q - 1.0;
    if (f <= 1e-15) break;
    const double df = -2.0 * (p * p / (tau + a * a) + q * q / (tau + b * b));
    const double next = tau - f / df;
    if (!(next > tau)) break;
    tau = next;
  }
  return {a * a * s / (tau + a * a), b * b * t / (tau + b * b)};
}

}  // namespace

std::vector<Disc> discs_of(const Gmm& gmm, double k) {
  std::vector<Disc> out(gmm.size());
  for (std::size_t m = 0; m < gmm.size(); ++m) {
    const Eigen::Matrix3d s = detail::covariance_of(gmm, m).topLeftCorner<3, 3>();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(s);
    const Eigen::Vector3d l = eig.eigenvalues();
    require(eig.info() == Eigen::Success && l(0) > 0 && std::isfinite(l(2)), ErrorCode::Numeric,
            "surface distance: component " + std::to_string(m) + "'s spatial covariance is not positive definite");
    Disc& d = out[m];
    d.mu = detail::mean_of(gmm, m).head<3>();
    d.normal = eig.eigenvectors().col(0);
    d.e2 = eig.eigenvectors().col(1);
    d.e1 = eig.eigenvectors().col(2);
    d.a = k * std::sqrt(l(2));
    d.b = k * std::sqrt(l(1));
    d.radius = d.a;
    d.sigma = std::sqrt(l(0));
  }
  return out;
}

namespace {
bool inside_ellipse(const Disc& d, double s, double t) { return (s / d.a) * (s / d.a) + (t / d.b) * (t / d.b) <= 1.0; }
}  // namespace

bool over_face(const Disc& d, const Eigen::Vector3d& x) {
  const Eigen::Vector3d r = x - d.mu;
  return inside_ellipse(d, r.dot(d.e1), r.dot(d.e2));
}

// Distance of x to disc d; `from` receives x minus the nearest disc point.
double disc_distance(const Disc& d, const Eigen::Vector3d& x, Eigen::Vector3d& from) {
  const Eigen::Vector3d r = x - d.mu;
  const double s = r.dot(d.e1), t = r.dot(d.e2), c = r.dot(d.normal);
  if (inside_ellipse(d, s, t)) {
    from = c * d.normal;
    return std::abs(c);
  }
  const auto [ps, pt] = nearest_on_ellipse(d.a, d.b, std::abs(s), std::abs(t));
  const double ds = std::abs(s) - ps, dt = std::abs(t) - pt;
  from = std::copysign(ds, s) * d.e1 + std::copysign(dt, t) * d.e2 + c * d.normal;
  return std::sqrt(ds * ds + dt * dt + c * c);
}

}  // namespace sogmm::detail
