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
// So a component left out of a point's list has a box that does not hold
// the point: beyond 3 sigma, as the index's culling proves.
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

  /// The ids, ascending, of the components of the cache's index whose box
  /// meets the cube of half-width `margin` about point i's anchor, where x
  /// (point i at the current pose) lies within `margin` of that anchor
  /// (re-anchored at x first when it does not): a superset of the
  /// components whose box holds x, for the cache's index and for any index
  /// whose boxes lie in the same components' boxes of it. Filtering it by
  /// such an index's box test gives exactly that index's query_point answer
  /// (registration.cpp does, listing a block's pairs). A non-finite x has
  /// no component (as query_point). Calls for different i may run
  /// concurrently (each with its own `scratch`); the list is valid until
  /// the next call for i.
  const std::vector<std::uint32_t>& near(std::size_t i, const Eigen::Vector3d& x,
                                         std::vector<std::uint32_t>& scratch) {
    static const std::vector<std::uint32_t> kNone;
    if (!x.allFinite()) return kNone;
    if (!valid_[i] || ((x - anchor_[i]).cwiseAbs().array() > margin_).any()) {
      // The cube is widened by a relative 1e-9 so that rounding in x - anchor
      // or in its bounds never drops a box that holds a point within margin.
      const double m = margin_ * (1.0 + 1e-9) + 1e-12;
      Box3 cube;
      for (int d = 0; d < 3; ++d) {
        cube.lo[d] = x(d) - m;
        cube.hi[d] = x(d) + m;
      }
      // Queried into `scratch` and copied: one allocation of the exact size
      // instead of a vector grown entry by entry for every new point.
      index_->query_box(cube, scratch);
      near_[i].assign(scratch.begin(), scratch.end());
      anchor_[i] = x;
      valid_[i] = 1;
    }
    return near_[i];
  }

 private:
  const ComponentIndex* index_;
  double margin_;
  std::vector<Eigen::Vector3d> anchor_;
  std::vector<std::vector<std::uint32_t>> near_;
  std::vector<std::uint8_t> valid_;  // bytes, not vector<bool>: threads write their own points
};

}  // namespace sogmm::detail
