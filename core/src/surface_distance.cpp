// Distance to the surface as the union of the components' discs
// (sogmm/surface_distance.hpp).
#include "sogmm/surface_distance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "finite_rows.hpp"
#include "parallel.hpp"
#include "progress.hpp"
#include "surface_discs.hpp"
#include "sogmm/error.hpp"
#include "sogmm/options.hpp"
#include "z_order.hpp"

namespace sogmm {

namespace {

using detail::Disc;
using detail::disc_distance;
using detail::discs_of;

constexpr std::size_t kBlock = 64;

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
  std::vector<std::vector<double>> bounds(static_cast<std::size_t>(team));
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
    // Two passes: the block's best upper bound first, so that the second
    // keeps only the components that can beat it.
    for (const Disc& d : discs) {
      const Eigen::Vector3d span = (d.mu - lo).cwiseAbs().cwiseMax((hi - d.mu).cwiseAbs());
      best_far = std::min(best_far, span.squaredNorm());
    }
    best_far = std::sqrt(best_far);
    for (std::size_t m = 0; m < discs.size(); ++m) {
      const Eigen::Vector3d& mu = discs[m].mu;
      const Eigen::Vector3d gap = (lo - mu).cwiseMax(mu - hi).cwiseMax(0.0);
      const double near = gap.norm() - discs[m].radius;
      if (near <= best_far) cand.emplace_back(near, static_cast<std::uint32_t>(m));
    }
    std::sort(cand.begin(), cand.end());
    for (std::size_t j = first; j < last; ++j) {
      const std::size_t i = order[j];
      const Eigen::Vector3d x(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
      // A lower bound per candidate: the disc lies in its plane within
      // `radius` of mu, so with c the offset along the normal and rho the
      // in-plane distance from mu, distance >= sqrt(c^2 + max(0, rho -
      // radius)^2). The candidate with the smallest bound is usually the
      // nearest disc: measured first, its distance bounds the rest, and a
      // candidate whose bound is not below it is skipped (it cannot be
      // strictly nearer), so only a few rim solves run per point. The
      // block's candidates are sorted by their block-wide bound, which ends
      // the scan once no later one can be nearer.
      auto& lb = bounds[static_cast<std::size_t>(thread)];
      lb.clear();
      std::size_t first_pick = 0;
      for (const auto& [near, m] : cand) {
        const Disc& d = discs[m];
        const Eigen::Vector3d r = x - d.mu;
        const double c = r.dot(d.normal);
        const double rim = std::max(0.0, std::sqrt(std::max(0.0, r.squaredNorm() - c * c)) - d.radius);
        const double b = std::sqrt(c * c + rim * rim);
        if (!lb.empty() && b < lb[first_pick]) first_pick = lb.size();
        lb.push_back(b);
      }
      Eigen::Vector3d from;
      std::uint32_t best_m = cand[first_pick].second;
      Eigen::Vector3d best_from;
      double best = disc_distance(discs[best_m], x, best_from);
      for (std::size_t c = 0; c < cand.size(); ++c) {
        if (cand[c].first > best) break;  // sorted: no later candidate can be nearer
        if (lb[c] > best || c == first_pick) continue;
        const std::uint32_t m = cand[c].second;
        const double dist = disc_distance(discs[m], x, from);
        if (dist < best || (dist == best && m < best_m)) {  // ties: the lowest id, whatever the order
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
