// A 3-D spatial index over the components of a Gmm: which components may
// matter at a point or inside a box (the incremental map's novelty test and
// box export; query culling).
//
// Each component is keyed by the axis-aligned box of its r-sigma ellipsoid
// {x : (x - mu)^T Sigma_xx^-1 (x - mu) <= r^2} in x, y, z. The box half-width
// along axis i is r sqrt(Sigma_ii): the exact extent of that ellipsoid in every
// rotation (max of e_i^T (x - mu) over the ellipsoid). So a component within
// Mahalanobis distance r of a point always has the point in its box, and the
// queries below have 100 % recall for it; they may also return components
// whose box, but not ellipsoid, holds the point (callers evaluate those
// exactly anyway).
//
// Why a uniform hash grid and not nanoflann (a k-d tree over points): the
// question is "which boxes contain this point", not "which centres are
// near". A k-d tree over centres needs the largest half-width as its search
// radius, so one wide component slows every query; a grid with a cell of the
// typical box size answers a point with one hash lookup and a few box tests,
// whatever the map size, and takes new components without a rebuild.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "sogmm/gmm.hpp"

namespace sogmm {

/// An axis-aligned box [lo, hi] in x, y, z (metres), bounds included.
struct Box3 {
  std::array<double, 3> lo{};
  std::array<double, 3> hi{};
  /// True when the point lies in the box (bounds included).
  bool contains(const double p[3]) const {
    return p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1] && p[2] >= lo[2] && p[2] <= hi[2];
  }
  /// True when the boxes share a point (bounds included).
  bool intersects(const Box3& b) const {
    return lo[0] <= b.hi[0] && b.lo[0] <= hi[0] && lo[1] <= b.hi[1] && b.lo[1] <= hi[1] && lo[2] <= b.hi[2] &&
           b.lo[2] <= hi[2];
  }
};

/// The box of component m's `sigmas`-sigma ellipsoid in x, y, z: mu_i -/+
/// sigmas sqrt(Sigma_ii), computed in double from the float32 model and
/// widened by a relative 1e-6 so that float rounding never loses recall.
/// Requires m < gmm.size() and sigmas > 0 (not checked: callers are the index
/// and the map).
Box3 component_box(const Gmm& gmm, std::size_t m, double sigmas);

/// Uniform hash grid over component boxes. Component ids are the indices of
/// the Gmm given to build()/add()/update(); the index keeps no reference to
/// the Gmm. Not thread-safe for writes; const queries may run concurrently.
class ComponentIndex {
 public:
  /// Default radius of the index: 3 sigma (the novelty test's and the issue's).
  static constexpr double kDefaultSigmas = 3.0;
  /// A component whose box spans more than this many cells is kept in a
  /// separate list that every query tests, so memory stays linear in M.
  static constexpr std::size_t kMaxCellsPerComponent = 64;

  /// An empty index of `sigmas`-sigma boxes. Throws Error(InvalidArgument)
  /// unless sigmas is finite and in (0, 100].
  explicit ComponentIndex(double sigmas = kDefaultSigmas);

  /// Indexes every component of `gmm` (replacing what was indexed). The cell
  /// size is the median of the boxes' largest side, so a typical box covers
  /// at most 8 cells. Throws Error(Limit) for more than 2^32 - 1 components.
  void build(const Gmm& gmm);
  /// Indexes components [first, gmm.size()) of `gmm`, which must extend the
  /// indexed model (first == size()). Rebuilds with a fresh cell size when
  /// the index has doubled since its last build (amortised O(1) per
  /// component), so the cell size follows the data.
  void add(const Gmm& gmm, std::size_t first);
  /// Re-keys component m (< size()) after its mean or covariance changed.
  void update(const Gmm& gmm, std::size_t m);
  /// Removes everything.
  void clear();

  /// Number of indexed components.
  std::size_t size() const { return boxes_.size(); }
  /// The radius r of the boxes, in standard deviations.
  double sigmas() const { return sigmas_; }
  /// Side of a grid cell in metres (0 while empty).
  double cell_size() const { return cell_; }
  /// The box of component m (m < size()).
  const Box3& box(std::size_t m) const { return boxes_[m]; }

  /// Sets `out` to the ids, ascending, of every component whose box contains
  /// `xyz` (3 coordinates). Includes every component within Mahalanobis
  /// distance sigmas() of the point (3-D marginal). Non-finite input gives no
  /// component.
  void query_point(const double xyz[3], std::vector<std::uint32_t>& out) const;

  /// Remembers the grid cell of the previous query_point, so that a run of
  /// nearby points (a depth image row by row) pays one hash lookup per cell,
  /// not per point. One per thread; valid until the index is next modified.
  class Cursor {
    friend class ComponentIndex;
    std::uint64_t key_ = ~std::uint64_t{0};
    const void* cell_ = nullptr;
    bool valid_ = false;
  };
  /// query_point with a cursor: the same result, faster for coherent points.
  void query_point(const double xyz[3], std::vector<std::uint32_t>& out, Cursor& cursor) const;
  /// Sets `out` to the ids, ascending, of every component whose box
  /// intersects `box`: every component whose sigmas()-ellipsoid meets the box.
  void query_box(const Box3& box, std::vector<std::uint32_t>& out) const;

 private:
  using CellKey = std::uint64_t;
  /// A cell's entry: the component's box rounded outward to float (a
  /// superset, tested first from contiguous memory; hits are confirmed on the
  /// double box) and its id.
  struct Entry {
    float lo[3];
    float hi[3];
    std::uint32_t id;
  };
  bool cell_range(const Box3& b, std::array<std::int64_t, 3>& lo, std::array<std::int64_t, 3>& hi) const;
  std::int64_t cell_coord(double v, int axis) const;
  void insert(std::uint32_t id);
  void erase(std::uint32_t id);

  double sigmas_;
  double cell_ = 0.0;
  std::array<double, 3> origin_{};
  std::size_t built_size_ = 0;  ///< size() at the last rebuild
  std::vector<Box3> boxes_;
  std::vector<std::uint8_t> large_flag_;  ///< 1: the component is in large_, not in cells
  std::vector<std::uint32_t> large_;
  std::unordered_map<CellKey, std::vector<Entry>> cells_;
};

}  // namespace sogmm
