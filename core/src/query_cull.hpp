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
// - the block first evaluates the components whose box meets B (and the
//   regression's background); with `worst` the lowest per-point maximum found,
//   and cut = worst - nats, every other component whose term can reach the
//   cut is evaluated too: those with c_k - R^2 / 2 >= cut (a prefix of the
//   components sorted by c_k, so this costs nothing when there are none)
//   whose bound over B is >= cut as well. That bound is the truncated
//   E-step's (em.cpp): interval arithmetic of the whitened coordinates
//   y = L^-1 (x - mu) over B (in D dimensions, gray included for scores)
//   bounds |y|^2 below by the squared distance of each y_j's interval from 0.
//   All other terms are below cut = worst - nats <= best - nats.
// R only trades index work against that fallback, never the guarantee: it is
// chosen so that the fallback is rare (R^2 / 2 = nats + the spread of c_k
// between its median and 90th percentile + 8 nats of a point's own distance).
//
// Points are visited in Z-order so that each block is spatially compact.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "query_kernel.hpp"
#include "sogmm/component_index.hpp"
#include "sogmm/gmm.hpp"

namespace sogmm::detail {

/// Per-thread lists of one block's components.
struct CullScratch {
  std::vector<std::uint32_t> list;
  std::vector<std::uint32_t> extra;
};

class QueryCuller {
 public:
  /// `params`: the packed model (query_kernel.hpp) in `dims` (3 or 4)
  /// dimensions, with the background at entry gmm.size() when `background`.
  /// `points`: the n query points, rows of `width` floats.
  QueryCuller(const Gmm& gmm, const std::vector<double>& params, int dims, bool background, double nats,
              const float* points, std::size_t n, int width);

  /// The order in which points are visited (a permutation of [0, n)).
  const std::vector<std::uint32_t>& order() const { return order_; }

  /// Calls eval(list, count) with the components `block` must evaluate, in
  /// one or two lists; `max` is the block's running per-point maximum (read
  /// after the first call).
  template <class Eval>
  void evaluate(const QueryBlock& block, CullScratch& s, const Eval& eval, const double* max) const {
    candidates(block, s.list);
    eval(s.list.data(), s.list.size());
    double worst = max[0];
    for (int p = 1; p < block.count; ++p) worst = worst < max[p] ? worst : max[p];
    fallback(block, worst - nats_, s.list, s.extra);
    if (!s.extra.empty()) eval(s.extra.data(), s.extra.size());
  }

 private:
  void candidates(const QueryBlock& block, std::vector<std::uint32_t>& out) const;
  void fallback(const QueryBlock& block, double cut, const std::vector<std::uint32_t>& taken,
                std::vector<std::uint32_t>& out) const;
  double upper_bound(std::uint32_t k, const double* lo, const double* hi) const;

  const std::vector<double>& params_;
  int dims_;
  double nats_;
  double half_r2_ = 0.0;                 ///< R^2 / 2
  bool background_;
  std::uint32_t m_;
  ComponentIndex index_;
  std::vector<std::uint32_t> by_const_;  ///< components by c_k, descending
  std::vector<double> const_;            ///< c_k in that order
  std::vector<std::uint32_t> order_;
};

}  // namespace sogmm::detail
