// Surface distance as main answered it at d33d204, before the disc tree of
// issue 31 (core/src/disc_tree.cpp): Z-order blocks of 64 points (5 cm
// cells), each block keeping the discs that may beat its best upper bound,
// each point bounding every kept disc. A frozen copy so that
// sogmm-occupancy-octomap --compare-main times both in one run and counts
// the answers that differ. Bench-only: not a public path.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "parallel.hpp"
#include "sogmm/gmm.hpp"
#include "surface_discs.hpp"
#include "z_order.hpp"

namespace sogmm_bench {

// main's point order: Z-order of 5 cm cells (coarser beyond 2^20 cells).
inline std::vector<std::size_t> main_z_order(const float* xyz, std::size_t n) {
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
    keyed[i] = {sogmm::detail::z_order_key(c[0], c[1], c[2]), i};
  }
  sogmm::detail::sort_by_key(keyed);  // the same order as the std::sort it froze
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = keyed[i].second;
  return order;
}

// main's search (finite points, a model with components, default options).
inline void main_surface_distance(const sogmm::Gmm& gmm, const float* xyz, std::size_t n, double* distance,
                                  double* gradient, int threads, double disc_sigmas = 2.0) {
  using sogmm::detail::Disc;
  using sogmm::detail::disc_distance;
  constexpr std::size_t kBlock = 64;
  const int team = sogmm::detail::team_size(threads);
  const std::vector<Disc> discs = sogmm::detail::discs_of(gmm, disc_sigmas);
  const std::vector<std::size_t> order = main_z_order(xyz, n);
  const std::size_t blocks = (n + kBlock - 1) / kBlock;
  std::vector<std::vector<std::pair<double, std::uint32_t>>> scratch(static_cast<std::size_t>(team));
  std::vector<std::vector<double>> bounds(static_cast<std::size_t>(team));
  sogmm::detail::parallel_for(blocks, team, 1, [&](std::size_t blk, int thread) {
    const std::size_t first = blk * kBlock, last = std::min(n, first + kBlock);
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (std::size_t j = first; j < last; ++j)
      for (int k = 0; k < 3; ++k) {
        lo(k) = std::min(lo(k), static_cast<double>(xyz[3 * order[j] + k]));
        hi(k) = std::max(hi(k), static_cast<double>(xyz[3 * order[j] + k]));
      }
    double best_far = std::numeric_limits<double>::infinity();
    auto& cand = scratch[static_cast<std::size_t>(thread)];
    cand.clear();
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
        if (cand[c].first > best) break;
        if (lb[c] > best || c == first_pick) continue;
        const std::uint32_t m = cand[c].second;
        const double dist = disc_distance(discs[m], x, from);
        if (dist < best || (dist == best && m < best_m)) {
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

}  // namespace sogmm_bench
