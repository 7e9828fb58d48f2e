// A bounding-box tree over surface discs and the exact nearest-disc search
// (private; surface_distance.cpp).
//
// Why: a point metres from every surface is near-equidistant from many
// discs, so a flat scan (even one culled per block of points) bounds most of
// the map's discs for it. The tree lets a point skip whole subtrees: a
// subtree whose box is farther than the best distance found so far holds no
// nearer disc, because every disc lies inside its box. A block of nearby
// points shares one walk of the tree (leaves_near) and each point then
// scans only the listed leaves (nearest_among).
//
// The answer is the brute-force one, bit for bit: the disc with the smallest
// disc_distance(), the lowest id among equal distances, and that disc's
// `from`. Distances are always those of disc_distance() itself (the same
// function, the same arguments); the tree and the bounds only decide which
// discs need not be measured. A disc is skipped only when a lower bound of
// its distance exceeds the best distance by more than `slack`, a margin (1e-9
// of the scene's largest coordinate, plus 1e-9 m) that is many orders of
// magnitude above the rounding of the bounds and of disc_distance() (a few
// ulp of the coordinates), so a disc that rounds to a distance equal to or
// below the best is never skipped.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "surface_discs.hpp"

namespace sogmm::detail {

class DiscTree {
 public:
  /// Builds the tree over `discs` (ids are their positions; at least one).
  explicit DiscTree(const std::vector<Disc>& discs);

  struct Nearest {
    double distance = 0;
    std::uint32_t id = 0;
    Eigen::Vector3d from;  ///< x minus the nearest point of the disc
  };

  /// The nearest disc to x (ties: the lowest id). `hint`: any disc id whose
  /// distance starts the search (a neighbour's answer prunes most of the
  /// tree at once); it never changes the answer. `stack`: scratch.
  Nearest nearest(const Eigen::Vector3d& x, std::uint32_t hint, std::vector<std::pair<double, std::uint32_t>>& stack) const;

  /// An upper bound of x's distance to disc `id` without a rim solve: the
  /// distance to the rim point on the ray from mu through x's projection.
  double upper_bound(std::uint32_t id, const Eigen::Vector3d& x) const;

  /// Replaces `leaves` by the leaves whose box is within `bound` (plus the
  /// slack) of the box [lo, hi]: every disc within `bound` of a point of the
  /// box is in one of them. `stack`: scratch.
  void leaves_near(const double lo[3], const double hi[3], double bound, std::vector<std::uint32_t>& leaves,
                   std::vector<std::uint32_t>& stack) const;

  /// nearest() among the discs of `leaves` only. It is nearest()'s answer
  /// when leaves_near() listed them for a box that holds x and a bound at
  /// least x's distance to some disc: every disc outside them is farther.
  Nearest nearest_among(const Eigen::Vector3d& x, std::uint32_t hint, const std::vector<std::uint32_t>& leaves) const;

  /// Among the discs of `leaves` that x lies over (over_face()) and whose
  /// plane is at most `limit` from x, the nearest (ties: the lowest id) into
  /// `face` (`from`: x minus its foot on that face). False when there is
  /// none. Complete when leaves_near() listed the leaves for a box that holds
  /// x and a bound of at least `limit`: such a disc's foot point is within
  /// `limit` of x, so its box is too.
  bool nearest_face_among(const Eigen::Vector3d& x, double limit, const std::vector<std::uint32_t>& leaves,
                          Nearest& face) const;

 private:
  struct Node {
    double lo[3], hi[3];
    std::uint32_t first = 0;  ///< leaf: first disc (in tree order); inner: the second child
    std::uint32_t count = 0;  ///< leaf: number of discs; inner: 0 (first child = this node + 1)
  };
  std::uint32_t build(std::vector<std::uint32_t>& ids, std::uint32_t begin, std::uint32_t end,
                      const std::vector<Disc>& discs, const std::vector<Eigen::Array3d>& lo,
                      const std::vector<Eigen::Array3d>& hi);
  /// Tries disc `k` (tree order) against the best so far.
  void visit(std::uint32_t k, const Eigen::Vector3d& x, double slack, Nearest& best) const;

  std::vector<Node> nodes_;
  std::vector<Disc> discs_;        ///< in tree order
  std::vector<std::uint32_t> id_;  ///< tree order -> disc id
  std::vector<std::uint32_t> at_;  ///< disc id -> tree order
  double slack_ = 0;               ///< 1e-9 (1 + the boxes' largest |coordinate|)
};

}  // namespace sogmm::detail
