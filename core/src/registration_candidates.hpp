// The candidate components of each source point of a registration, kept
// between the evaluations of one coarse-to-fine level (private to
// registration.cpp).
//
// Why: an evaluation asks, for every point at the current pose, which
// components' boxes hold it (ComponentIndex::query_point: a hash lookup and a
// scan of the cell's entries). Between two Gauss-Newton steps a point moves
// little (millimetres once the level is under way), so each point keeps the
// components whose box meets the cube of half-width `margin` about where it
// was last queried (its anchor). While the point stays within `margin` of its
// anchor (per axis), every box that holds it meets that cube, so filtering
// the kept list by the exact box test gives exactly query_point's answer
// (the same ids, ascending); a point that moves further is queried again.
//
// One cache serves every level: it is built on the coarsest level's index,
// whose boxes hold the finer levels' boxes of the same components (same
// means, larger variances: component_box is monotone in the variance), and
// each level filters by its own boxes.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "sogmm/component_index.hpp"

namespace sogmm::detail {

class CandidateCache {
 public:
  /// For `n` points against `index` (which must outlive the cache and not
  /// change), re-querying a point once it moves more than `margin` metres
  /// from its anchor along some axis.
  CandidateCache(const ComponentIndex& index, std::size_t n, double margin)
      : index_(&index), margin_(margin), anchor_(n), near_(n), valid_(n, 0) {}

  /// Sets `out` to the ids, ascending, of the components whose box in
  /// `boxes` holds `x` (point i at the current pose): boxes.query_point's
  /// answer. Every box of `boxes` must lie in the same component's box of
  /// the cache's index. Calls for different i may run concurrently.
  void query(std::size_t i, const Eigen::Vector3d& x, const ComponentIndex& boxes, std::vector<std::uint32_t>& out) {
    out.clear();
    if (!x.allFinite()) return;  // as query_point: no component
    if (!valid_[i] || ((x - anchor_[i]).cwiseAbs().array() > margin_).any()) {
      // The cube is widened by a relative 1e-9 so that rounding in x - anchor
      // or in its bounds never drops a box that holds a point within margin.
      const double m = margin_ * (1.0 + 1e-9) + 1e-12;
      Box3 cube;
      for (int d = 0; d < 3; ++d) {
        cube.lo[d] = x(d) - m;
        cube.hi[d] = x(d) + m;
      }
      // Queried into `out` and copied: one allocation of the exact size
      // instead of a vector grown entry by entry for every new point.
      index_->query_box(cube, out);
      near_[i].assign(out.begin(), out.end());
      out.clear();
      anchor_[i] = x;
      valid_[i] = 1;
    }
    const double xyz[3] = {x(0), x(1), x(2)};
    for (std::uint32_t id : near_[i])
      if (boxes.box(id).contains(xyz)) out.push_back(id);
  }

 private:
  const ComponentIndex* index_;
  double margin_;
  std::vector<Eigen::Vector3d> anchor_;
  std::vector<std::vector<std::uint32_t>> near_;
  std::vector<std::uint8_t> valid_;  // bytes, not vector<bool>: threads write their own points
};

}  // namespace sogmm::detail
