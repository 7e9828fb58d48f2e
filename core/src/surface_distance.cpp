// Distance to the surface as the union of the components' discs
// (sogmm/surface_distance.hpp).
#include "sogmm/surface_distance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>

#include "finite_rows.hpp"
#include "gmm_eigen.hpp"
#include "parallel.hpp"
#include "progress.hpp"
#include "sogmm/error.hpp"
#include "sogmm/options.hpp"
#include "z_order.hpp"

namespace sogmm {

namespace {

constexpr std::size_t kBlock = 64;

struct Disc {
  Eigen::Vector3d mu, e1, e2, normal;
  double a, b;    // semi-axes, a >= b > 0
  double radius;  // a: every point of the disc is within it of mu
};

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
  }
  return out;
}

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

// Distance of x to disc d; `from` receives x minus the nearest disc point.
double disc_distance(const Disc& d, const Eigen::Vector3d& x, Eigen::Vector3d& from) {
  const Eigen::Vector3d r = x - d.mu;
  const double s = r.dot(d.e1), t = r.dot(d.e2), c = r.dot(d.normal);
  if ((s / d.a) * (s / d.a) + (t / d.b) * (t / d.b) <= 1.0) {
    from = c * d.normal;
    return std::abs(c);
  }
  const auto [ps, pt] = nearest_on_ellipse(d.a, d.b, std::abs(s), std::abs(t));
  const double ds = std::abs(s) - ps, dt = std::abs(t) - pt;
  from = std::copysign(ds, s) * d.e1 + std::copysign(dt, t) * d.e2 + c * d.normal;
  return std::sqrt(ds * ds + dt * dt + c * c);
}

// A spatially compact order of the points (Z-order of 5 cm cells, or coarser
// when the points span more than 2^21 cells).
std::vector<std::size_t> z_order(const float* xyz, std::size_t n, int team) {
  double lo[3], hi[3];
  for (int k = 0; k < 3; ++k) lo[k] = hi[k] = xyz[k];
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], static_cast<double>(xyz[3 * i + k]));
      hi[k] = std::max(hi[k], static_cast<double>(xyz[3 * i + k]));
    }
  double cell = 0.05;
  for (int k = 0; k < 3; ++k) cell = std::max(cell, (hi[k] - lo[k]) / double(1 << 20));
  std::vector<std::pair<std::uint64_t, std::size_t>> keyed(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::uint64_t c[3];
    for (int k = 0; k < 3; ++k) c[k] = static_cast<std::uint64_t>((xyz[3 * i + k] - lo[k]) / cell);
    keyed[i] = {detail::z_order_key(c[0], c[1], c[2]), i};
  }
  detail::parallel_sort(keyed, team);
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = keyed[i].second;
  return order;
}

}  // namespace

void validate(const SurfaceDistanceOptions& options) {
  require_option(OptionKey::SURFACE_DISC_SIGMAS, options.disc_sigmas, "surface disc_sigmas");
}

void surface_distance(const Gmm& gmm, const float* xyz, std::size_t n, double* distance, double* gradient,
                      const SurfaceDistanceOptions& options, int threads, const ProgressSink& progress) {
  validate(options);
  require(gmm.size() > 0, ErrorCode::InvalidData, "surface distance: the model has no component");
  if (n == 0) return;
  require(xyz != nullptr && distance != nullptr, ErrorCode::InvalidArgument, "surface distance: null input or output");
  detail::require_finite_rows(xyz, n, 3, "points for surface distance");
  const ProgressScope scope(progress);
  const int team = detail::team_size(threads);
  const std::vector<Disc> discs = discs_of(gmm, options.disc_sigmas);
  const std::vector<std::size_t> order = z_order(xyz, n, team);
  const std::size_t blocks = (n + kBlock - 1) / kBlock;

  detail::progress_begin(Stage::Scoring, n);
  std::vector<std::vector<std::pair<double, std::uint32_t>>> scratch(static_cast<std::size_t>(team));
  detail::parallel_for(blocks, team, 1, [&](std::size_t blk, int thread) {
    const std::size_t first = blk * kBlock, last = std::min(n, first + kBlock);
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (std::size_t j = first; j < last; ++j)
      for (int k = 0; k < 3; ++k) {
        lo(k) = std::min(lo(k), static_cast<double>(xyz[3 * order[j] + k]));
        hi(k) = std::max(hi(k), static_cast<double>(xyz[3 * order[j] + k]));
      }
    // Bounds over the block's box: near(m) <= distance to disc m <= far(m).
    double best_far = std::numeric_limits<double>::infinity();
    auto& cand = scratch[static_cast<std::size_t>(thread)];
    cand.clear();
    for (std::size_t m = 0; m < discs.size(); ++m) {
      const Eigen::Vector3d& mu = discs[m].mu;
      const Eigen::Vector3d gap = (lo - mu).cwiseMax(mu - hi).cwiseMax(0.0);
      const Eigen::Vector3d span = (mu - lo).cwiseAbs().cwiseMax((hi - mu).cwiseAbs());
      best_far = std::min(best_far, span.norm());
      const double near = gap.norm() - discs[m].radius;
      if (near <= best_far) cand.emplace_back(near, static_cast<std::uint32_t>(m));
    }
    std::sort(cand.begin(), cand.end());
    for (std::size_t j = first; j < last; ++j) {
      const std::size_t i = order[j];
      const Eigen::Vector3d x(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
      double best = std::numeric_limits<double>::infinity();
      Eigen::Vector3d best_from = Eigen::Vector3d::Zero(), from;
      std::uint32_t best_m = 0;
      for (const auto& [near, m] : cand) {
        if (near > best) break;  // sorted: no later candidate can be nearer
        const Disc& d = discs[m];
        if ((x - d.mu).norm() - d.radius > best) continue;
        const double dist = disc_distance(d, x, from);
        if (dist < best) {
          best = dist;
          best_from = from;
          best_m = m;
        }
      }
      distance[i] = best;
      if (gradient != nullptr) {
        const double len = best_from.norm();
        const Eigen::Vector3d g = len > 0 ? Eigen::Vector3d(best_from / len) : discs[best_m].normal;
        for (int k = 0; k < 3; ++k) gradient[3 * i + k] = g(k);
      }
    }
  });
}

void surface_distance(const Map& map, const float* xyz, std::size_t n, double* distance, double* gradient,
                      const SurfaceDistanceOptions& options, int threads, const ProgressSink& progress) {
  surface_distance(map.model().gmm, xyz, n, distance, gradient, options, threads, progress);
}

}  // namespace sogmm
