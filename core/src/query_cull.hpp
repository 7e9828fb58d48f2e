// Which components a block of query points must evaluate (private): the
// culled score_samples and regress_gray (QueryOptions::truncation_nats > 0).
//
// The guarantee is the truncated E-step's: a component is skipped for a point
// only when its term is provably more than `nats` below the point's largest
// evaluated term. The proof for one block of points with 3-D bounding box B:
// - the index holds every component's R-sigma box in x, y, z (R below);
//   a component whose box misses B has Mahalanobis distance > R (3-D
//   marginal) from every point of B, and the joint (4-D) distance is at least
//   the marginal one, so its term is below c_k - R^2 / 2, with c_k its log
//   weight minus log det L minus D/2 log 2 pi;
// - every component has an upper bound on its term over B, the truncated
//   E-step's (em.cpp): interval arithmetic of the whitened coordinates
//   y = L^-1 (x - mu) over B (in D dimensions, gray included for scores)
//   bounds |y|^2 below by the squared distance of each y_j's interval from 0;
// - the block first evaluates, among the components whose box meets B, the
//   few that best explain a few probe points of the block (and the
//   regression's background); with `worst` the
//   lowest per-point maximum found, and cut = worst - nats, every other
//   component whose term can reach the cut is evaluated too: first the
//   remaining candidates with bound >= cut, then (with the cut raised by
//   what they found) the components outside the index's answer with
//   c_k - R^2 / 2 >= cut (a prefix of the components sorted by c_k, so this
//   costs nothing when there are none) and bound >= cut. All other terms are
//   below cut = worst - nats <= best - nats.
// R only trades index work against that fallback, never the guarantee: it is
// chosen so that the fallback is rare (R^2 / 2 = nats + the spread of c_k
// between its median and 90th percentile + 8 nats of a point's own distance).
//
// Points are visited in Z-order so that each block is spatially compact.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "query_kernel.hpp"
#include "sogmm/component_index.hpp"
#include "sogmm/gmm.hpp"

namespace sogmm::detail {

/// Per-thread lists of one block's components.
struct CullScratch {
  std::vector<std::uint32_t> candidates;  ///< the index's answer, ascending
  std::vector<double> upper;              ///< their bounds
  std::vector<std::uint32_t> first;       ///< evaluated first
  std::vector<std::uint32_t> extra;       ///< evaluated once the cut is known
  std::vector<std::pair<double, std::uint32_t>> ranked;
  double lo[4], hi[4];                    ///< the block's box
};

class QueryCuller {
 public:
  /// `params`: the packed model (query_kernel.hpp) in `dims` (3 or 4)
  /// dimensions, with the background at entry gmm.size() when `background`.
  /// `points`: the n query points, rows of `width` floats. `team`: threads
  /// for the set-up (the order does not depend on it).
  QueryCuller(const Gmm& gmm, const std::vector<double>& params, int dims, bool background, double nats,
              const float* points, std::size_t n, int width, int team);

  /// The order in which points are visited (a permutation of [0, n)).
  const std::vector<std::size_t>& order() const { return order_; }

  /// Calls eval(list, count) with the components `block` must evaluate, in
  /// one or two lists; `max` is the block's running per-point maximum (read
  /// after the first call).
  template <class Eval>
  void evaluate(const QueryBlock& block, CullScratch& s, const Eval& eval, const double* max) const {
    choose_first(block, s);
    eval(s.first.data(), s.first.size());
    // Each step can only raise the worst maximum, so a later cut is higher.
    choose_candidates(cut(block, max), s);
    if (!s.extra.empty()) eval(s.extra.data(), s.extra.size());
    choose_others(cut(block, max), s);
    if (!s.extra.empty()) eval(s.extra.data(), s.extra.size());
  }

 private:
  /// Points of a block probed, and components kept per probe, for the
  /// first evaluation.
  static constexpr int kProbes = 4;
  static constexpr std::size_t kPerProbe = 8;
  void choose_first(const QueryBlock& block, CullScratch& s) const;
  void choose_candidates(double cut, CullScratch& s) const;
  void choose_others(double cut, CullScratch& s) const;
  /// The lowest per-point maximum of the block minus nats.
  double cut(const QueryBlock& block, const double* max) const {
    double worst = max[0];
    for (int p = 1; p < block.count; ++p) worst = worst < max[p] ? worst : max[p];
    return worst - nats_;
  }
  double upper_bound(std::uint32_t k, const double* lo, const double* hi) const;
  /// Component k's term at point p of the block.
  double term_at(std::uint32_t k, const QueryBlock& block, int p) const;

  const std::vector<double>& params_;
  int dims_;
  double nats_;
  double half_r2_ = 0.0;                 ///< R^2 / 2
  bool background_;
  std::uint32_t m_;
  ComponentIndex index_;
  std::vector<std::uint32_t> by_const_;  ///< components by c_k, descending
  std::vector<double> const_;            ///< c_k in that order
  std::vector<std::size_t> order_;
};

}  // namespace sogmm::detail
