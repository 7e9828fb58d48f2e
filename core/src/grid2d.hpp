// A sparse 2-D grid over points for fixed-radius neighbour queries (private
// to the core). Cells are `cell` wide and only occupied cells are stored (a
// hash table from cell key to the cell's points), so memory is O(n) and a
// query costs O(1) probes plus the points of the 3x3 cells around it, however
// far apart the points are: one outlier a kilometre away adds one cell, not a
// coarser grid (issue 14 item 3). The points are also copied in cell order
// with each cell's bounding box, so that a query streams through memory and
// skips, without a distance test per point, the cells that its disc misses
// (issue 17).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"

namespace sogmm::detail {

class Grid2d {
 public:
  /// Largest number of (possibly empty) cells the key space may span: keys
  /// are gy * nx + gx in int64.
  static constexpr double kMaxKeys = 4.0e18;
  /// Indexes n points (x, y interleaved) with square cells of side `cell`.
  Grid2d(const double* xy, std::size_t n, double cell) : cell_(cell) {
    min_x_ = min_y_ = INFINITY;
    double max_x = -INFINITY, max_y = -INFINITY;
    for (std::size_t i = 0; i < n; ++i) {
      min_x_ = std::min(min_x_, xy[2 * i]);
      min_y_ = std::min(min_y_, xy[2 * i + 1]);
      max_x = std::max(max_x, xy[2 * i]);
      max_y = std::max(max_y, xy[2 * i + 1]);
    }
    require(n > 0 && std::isfinite(min_x_) && std::isfinite(min_y_) && std::isfinite(max_x) &&
                std::isfinite(max_y) && cell > 0,
            ErrorCode::InvalidData, "neighbour grid: points or cell size are not finite");
    require(n <= 0xFFFFFFFFu, ErrorCode::Limit, "neighbour grid: more than 2^32 - 1 points");
    // The per-axis counts are bounded before they are converted to integers.
    const double fx = std::floor((max_x - min_x_) / cell) + 1, fy = std::floor((max_y - min_y_) / cell) + 1;
    require(fx * fy <= kMaxKeys, ErrorCode::Limit,
            "cell size " + checked::exact(cell) + " is too small for the extent of the data (" +
                checked::exact(fx * fy) + " grid cells, limit " + checked::exact(kMaxKeys) + ")");
    nx_ = checked::to_int<std::int64_t>(fx, "grid cells along x");
    ny_ = checked::to_int<std::int64_t>(fy, "grid cells along y");
    // Points sorted by (cell key, index): a cell's points are contiguous and
    // in index order, the order in which a dense grid visited them.
    std::vector<std::pair<std::int64_t, std::uint32_t>> keyed(n);
    for (std::size_t i = 0; i < n; ++i)
      keyed[i] = {cell_index(cx(xy[2 * i]), cy(xy[2 * i + 1])), static_cast<std::uint32_t>(i)};
    std::sort(keyed.begin(), keyed.end());
    order_.resize(n);
    sorted_.resize(2 * n);
    std::vector<std::int64_t> keys;  // occupied cells, ascending
    std::vector<std::size_t> start;  // cell c holds order_[start[c], start[c+1])
    for (std::size_t i = 0; i < n; ++i) {
      order_[i] = keyed[i].second;
      const double px = xy[2 * order_[i]], py = xy[2 * order_[i] + 1];
      sorted_[2 * i] = px;
      sorted_[2 * i + 1] = py;
      if (i == 0 || keyed[i].first != keyed[i - 1].first) {
        keys.push_back(keyed[i].first);
        start.push_back(i);
        boxes_.push_back(Box{px, px, py, py});
      }
      Box& b = boxes_.back();
      b.lo_x = std::min(b.lo_x, px);
      b.hi_x = std::max(b.hi_x, px);
      b.lo_y = std::min(b.lo_y, py);
      b.hi_y = std::max(b.hi_y, py);
    }
    start.push_back(n);
    // Open addressing, load factor <= 1/4 (at 1/2 linear probing's chains
    // cost 15% of a frame's mode count); a slot holds the cell's key and its
    // range of order_, so a probe touches one cache line.
    std::size_t capacity = 1;
    shift_ = 64;
    while (capacity < 4 * keys.size()) capacity *= 2, --shift_;
    slots_.assign(capacity, Slot{});
    for (std::size_t c = 0; c < keys.size(); ++c) {
      std::size_t s = slot_of(keys[c]);
      while (slots_[s].end != 0) s = (s + 1) & (capacity - 1);
      slots_[s] = Slot{keys[c], static_cast<std::uint32_t>(start[c]), static_cast<std::uint32_t>(start[c + 1]),
                       static_cast<std::uint32_t>(c)};
    }
  }

  /// Calls visit(index) for every point within distance `radius` (<= cell) of
  /// (x, y), cells in row-major order and points in index order within a
  /// cell. Returns the number of points whose distance it evaluated (the
  /// query's cost, for cost accounting that does not depend on a clock):
  /// those of the cells whose bounding box the disc reaches.
  template <typename Visit>
  std::size_t for_each_within(double x, double y, double radius, Visit&& visit) const {
    const double r2 = radius * radius;
    return for_each_cell(x, y, r2, [&](const Slot& c) {
      for (std::uint32_t k = c.begin; k < c.end; ++k) {
        const double dx = sorted_[2 * k] - x, dy = sorted_[2 * k + 1] - y;
        if (dx * dx + dy * dy <= r2) visit(order_[k]);
      }
    });
  }

 private:
  // A cell's points are order_[begin, end); end = 0 marks an empty slot (an
  // occupied cell has end >= 1).
  struct Slot {
    std::int64_t key = 0;
    std::uint32_t begin = 0, end = 0;
    std::uint32_t cell = 0;  // index into boxes_
  };
  // The smallest box holding a cell's points.
  struct Box {
    double lo_x, hi_x, lo_y, hi_y;
  };

  // Calls on_cell(slot) for the occupied cells among the 3 x 3 around
  // (x, y), in row-major order, except those whose box is farther than
  // sqrt(r2) from (x, y). The test is exact for the per-point test dx * dx +
  // dy * dy <= r2 with dx = px - x: rounding is monotone, so the gap to the
  // box as computed is never larger than a member point's distance as
  // computed. Returns the number of points in the cells visited.
  template <typename OnCell>
  std::size_t for_each_cell(double x, double y, double r2, OnCell&& on_cell) const {
    const std::int64_t ix = cx(x), iy = cy(y);
    std::size_t examined = 0;
    for (std::int64_t gy = std::max<std::int64_t>(iy - 1, 0); gy <= std::min(iy + 1, ny_ - 1); ++gy) {
      for (std::int64_t gx = std::max<std::int64_t>(ix - 1, 0); gx <= std::min(ix + 1, nx_ - 1); ++gx) {
        const Slot& c = find(cell_index(gx, gy));
        if (c.end == 0) continue;
        const Box& b = boxes_[c.cell];
        const double lx = b.lo_x - x, hx = b.hi_x - x, ly = b.lo_y - y, hy = b.hi_y - y;
        const double gap_x = lx > 0 ? lx : (hx < 0 ? hx : 0.0), gap_y = ly > 0 ? ly : (hy < 0 ? hy : 0.0);
        if (gap_x * gap_x + gap_y * gap_y > r2) continue;
        examined += c.end - c.begin;
        on_cell(c);
      }
    }
    return examined;
  }

  // Cell index of a coordinate, clamped to [-1, n] before the conversion so
  // that it is defined for any query (NaN maps to -1: no cell is visited).
  static std::int64_t clamped_cell(double t, std::int64_t n) {
    if (!(t >= -1.0)) t = -1.0;
    if (t > static_cast<double>(n)) t = static_cast<double>(n);
    return static_cast<std::int64_t>(std::floor(t));
  }
  std::int64_t cx(double x) const { return clamped_cell((x - min_x_) / cell_, nx_); }
  std::int64_t cy(double y) const { return clamped_cell((y - min_y_) / cell_, ny_); }
  std::int64_t cell_index(std::int64_t gx, std::int64_t gy) const { return gy * nx_ + gx; }
  // Fibonacci hashing: the top bits of key * 2^64 / golden ratio.
  std::size_t slot_of(std::int64_t key) const {
    return shift_ >= 64 ? 0 : static_cast<std::size_t>((static_cast<std::uint64_t>(key) * 0x9E3779B97F4A7C15ull) >> shift_);
  }
  // The slot of the occupied cell with this key, or an empty one (end 0).
  const Slot& find(std::int64_t key) const {
    for (std::size_t s = slot_of(key);; s = (s + 1) & (slots_.size() - 1)) {
      const Slot& v = slots_[s];
      if (v.end == 0 || v.key == key) return v;
    }
  }

  double cell_;
  double min_x_, min_y_;
  std::int64_t nx_ = 1, ny_ = 1;
  int shift_ = 64;
  std::vector<std::uint32_t> order_;  // point indices sorted by (cell, index)
  std::vector<double> sorted_;        // the points in that order, x and y interleaved
  std::vector<Box> boxes_;            // per occupied cell, ascending key
  std::vector<Slot> slots_;           // hash table of the occupied cells
};

}  // namespace sogmm::detail
