// Sums over the points within a fixed radius of a query (private to the
// core): the flat mean shift's one question, asked ~80,000 times per d = 1
// frame with ~1,000 points in each disc (issue 35). Grid2d answers it by
// testing every point of the 3 x 3 cells of side `radius` around the query
// (~1,800 tests each); this index cuts the plane into cells `radius / split`
// wide, so that most of a disc is whole cells, and keeps per row of cells
// the running sums of its cells, so that a run of whole cells costs one
// subtraction. Only the cells the disc's edge may cross are tested point by
// point. Only occupied cells and rows are stored, so memory is O(n) however
// far apart the points are (issue 14 item 3).
//
// Exactness: a point counts when dx * dx + dy * dy <= r2 as computed (dx =
// px - x), as in Grid2d. A cell is taken whole or skipped on bounds built
// from its points' own coordinates (its box in x, its row's box in y), and a
// cell index floor((v - min) / cell) never decreases as v grows, so a row's
// cells are ordered in x and the rows in y without overlap; rounding is
// monotone, so the computed gap to a box is never larger, and the computed
// distance to its far side never smaller, than a member point's. So the set
// of points counted is exactly Grid2d's; only the order of the additions
// differs (whole runs of cells enter as differences of running sums of the
// coordinates less their row's first point, plus their count times it, so a
// mean's rounding follows the scene's extent, not its distance from the
// origin).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <tuple>
#include <vector>

#include "sogmm/error.hpp"
#include "z_order.hpp"

namespace sogmm::detail {

class RowSumGrid {
 public:
  /// Largest number of cells along an axis (cell indices are 32-bit).
  static constexpr double kMaxCellsPerAxis = 2147483647.0;
  /// Indexes n points (x, y interleaved, finite) for queries of radius
  /// `radius` with cells of side radius / split. Throws Error(Limit) when an
  /// axis spans more than kMaxCellsPerAxis cells.
  RowSumGrid(const double* xy, std::size_t n, double radius, int split) {
    require(n > 0 && n <= 0xFFFFFFFFu && radius > 0 && split >= 1, ErrorCode::InvalidData,
            "row-sum grid: no points, more than 2^32 - 1, or a radius that is not positive");
    double max_x = -INFINITY, max_y = -INFINITY;
    min_x_ = min_y_ = INFINITY;
    for (std::size_t i = 0; i < n; ++i) {
      min_x_ = std::min(min_x_, xy[2 * i]);
      min_y_ = std::min(min_y_, xy[2 * i + 1]);
      max_x = std::max(max_x, xy[2 * i]);
      max_y = std::max(max_y, xy[2 * i + 1]);
    }
    cell_ = radius / split;
    require(std::floor((max_x - min_x_) / cell_) <= kMaxCellsPerAxis &&
                std::floor((max_y - min_y_) / cell_) <= kMaxCellsPerAxis,
            ErrorCode::Limit, "row-sum grid: more than 2^31 - 1 cells along an axis");
    // Points sorted by (row, cell, index): a cell's points are contiguous and
    // in index order. sort_by_key gives std::sort's order of these pairs in a
    // few radix passes (std::sort was a fifth of the mode count's serial time
    // at d = 1).
    std::vector<std::pair<std::uint64_t, std::size_t>> keyed(n);
    for (std::size_t i = 0; i < n; ++i)
      keyed[i] = {(static_cast<std::uint64_t>(index_of(xy[2 * i + 1], min_y_)) << 32) |
                      static_cast<std::uint64_t>(index_of(xy[2 * i], min_x_)),
                  i};
    sort_by_key(keyed);
    // The gather first, in a loop of its own: its reads are cache misses
    // (the order is by cell, not by index), and in the loop below, whose
    // iterations are long, few of them were in flight at once (half of the
    // constructor's time waited on them).
    points_.resize(2 * n);
    for (std::size_t k = 0; k < n; ++k) {
      points_[2 * k] = xy[2 * keyed[k].second];
      points_[2 * k + 1] = xy[2 * keyed[k].second + 1];
    }
    for (std::size_t k = 0; k < n; ++k) {
      const double px = points_[2 * k], py = points_[2 * k + 1];
      const auto gy = static_cast<std::uint32_t>(keyed[k].first >> 32);
      const auto gx = static_cast<std::uint32_t>(keyed[k].first);
      const bool new_row = k == 0 || gy != static_cast<std::uint32_t>(keyed[k - 1].first >> 32);
      if (new_row) {
        rows_.push_back(Row{py, py, static_cast<std::uint32_t>(cells_.size()), 0, kNoTable, px, py});
        row_gy_.push_back(gy);
      }
      if (new_row || keyed[k].first != keyed[k - 1].first) {
        cells_.push_back(Cell{px, px, static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(k)});
        cell_gx_.push_back(gx);
      }
      Row& row = rows_.back();
      Cell& c = cells_.back();
      row.lo_y = std::min(row.lo_y, py);
      row.hi_y = std::max(row.hi_y, py);
      row.cell_end = static_cast<std::uint32_t>(cells_.size());
      c.lo_x = std::min(c.lo_x, px);
      c.hi_x = std::max(c.hi_x, px);
      c.end = static_cast<std::uint32_t>(k + 1);
    }
    // Running sums of the cells within each row, from the row's first cell,
    // of the coordinates less the row's first point: a run's sum is then a
    // difference of sums as large as the scene's extent times the row's
    // points, not its distance from the origin times them (at an offset of
    // 1e9 the plain sums' rounding would move a mean by ~1e-3), and a run of
    // one point, or of equal points, adds their coordinates exactly.
    sums_.resize(cells_.size());
    for (const Row& row : rows_) {
      Sum run{};
      for (std::uint32_t c = row.cell_begin; c < row.cell_end; ++c) {
        for (std::uint32_t k = cells_[c].begin; k < cells_[c].end; ++k) {
          run.x += points_[2 * k] - row.origin_x;
          run.y += points_[2 * k + 1] - row.origin_y;
        }
        run.count += cells_[c].end - cells_[c].begin;
        sums_[c] = run;
      }
    }
    // Tables from a cell index to the first occupied cell (row) at or after
    // it, where they are short: a lookup instead of a binary search per row.
    // Sparse rows (far outliers) keep the search, so memory stays O(n).
    row_table_ = tabulate(row_gy_, 0, static_cast<std::uint32_t>(rows_.size()));
    for (Row& row : rows_) row.table = tabulate(cell_gx_, row.cell_begin, row.cell_end);
  }

  /// Adds the coordinates of the points within distance sqrt(r2) of (x, y)
  /// (any r2 >= 0; fastest near the radius squared the grid was built for)
  /// to sx and sy and their number to count. The order of the
  /// additions is fixed by the points and the query (rows upwards; in a row,
  /// the edge cells' points, then the whole cells' running sums), so the
  /// result does not depend on the thread that asks. Returns the query's
  /// cost: the points tested one by one plus the runs of whole cells.
  std::size_t sum_within(double x, double y, double r2, double& sx, double& sy, std::size_t& count) const {
    // First row whose points reach y: rows below it lie wholly below y. A
    // row before the first at or after y's row index holds only points below
    // y (the index never decreases as y grows), and so does that row when its
    // highest point is below y, while a later row's are all above y.
    std::size_t m = first_at_or_after(row_gy_, row_table_, 0, static_cast<std::uint32_t>(rows_.size()), y, min_y_);
    if (m < rows_.size() && rows_[m].hi_y < y) ++m;
    std::size_t first = m;
    while (first > 0 && sq(y - rows_[first - 1].hi_y) <= r2) --first;
    std::size_t cost = 0;
    for (std::size_t r = first; r < rows_.size(); ++r) {
      const Row& row = rows_[r];
      const double near_y = row.lo_y > y ? sq(row.lo_y - y) : (row.hi_y < y ? sq(y - row.hi_y) : 0.0);
      if (near_y > r2) break;  // this and every later row lie wholly above the disc
      const double far_y = std::max(sq(row.lo_y - y), sq(row.hi_y - y));
      cost += sum_row(row, x, y, r2, near_y, far_y, sx, sy, count);
    }
    return cost;
  }

 private:
  static constexpr std::uint32_t kNoTable = 0xFFFFFFFFu;
  struct Row {
    double lo_y, hi_y;                  // the box of the row's points in y
    std::uint32_t cell_begin, cell_end;  // its cells, ascending in x
    std::uint32_t table;                // offset of its lookup table in table_, or kNoTable
    double origin_x, origin_y;          // its first point: what its running sums leave out
  };
  struct Cell {
    double lo_x, hi_x;        // the box of the cell's points in x
    std::uint32_t begin, end;  // its points in points_, in index order
  };
  struct Sum {
    double x = 0.0, y = 0.0;
    std::size_t count = 0;
  };

  static double sq(double v) { return v * v; }

  // The cell index of coordinate v along an axis starting at lo: the same
  // rounding for points and queries, so it never decreases as v grows.
  // Queries outside the points' span clamp to -1 or 2^31.
  std::int64_t index_of(double v, double lo) const {
    double t = std::floor((v - lo) / cell_);
    if (!(t >= -1.0)) t = -1.0;
    if (t > kMaxCellsPerAxis) t = kMaxCellsPerAxis + 1.0;
    return static_cast<std::int64_t>(t);
  }

  // A lookup table for the sorted indices keys[begin, end): entry g - keys[begin]
  // is the position of the first key >= g. Returns its offset in table_, or
  // kNoTable when it would have more than 4 entries per key and 16 more (so
  // the tables hold at most 12 entries per point, in a cloud of rows of two
  // cells 22 apart; a frame's rows are mostly occupied, ~1-2 per key).
  std::uint32_t tabulate(const std::vector<std::uint32_t>& keys, std::uint32_t begin, std::uint32_t end) {
    const std::uint64_t span = std::uint64_t{keys[end - 1]} - keys[begin] + 1;
    if (span > 4 * std::uint64_t{end - begin} + 16) return kNoTable;
    // Offsets are 32-bit (kNoTable the largest): past that, past ~3.6e8
    // points, the rest keep the binary search rather than wrap.
    if (table_.size() + span >= kNoTable) return kNoTable;
    const auto offset = static_cast<std::uint32_t>(table_.size());
    std::uint32_t at = begin;
    for (std::uint64_t g = keys[begin]; g <= keys[end - 1]; ++g) {
      while (keys[at] < g) ++at;
      table_.push_back(at);
    }
    return offset;
  }

  // Position of the first of keys[begin, end) at or after v's cell index.
  std::uint32_t first_at_or_after(const std::vector<std::uint32_t>& keys, std::uint32_t table, std::uint32_t begin,
                                  std::uint32_t end, double v, double lo) const {
    const std::int64_t g = index_of(v, lo);
    if (g <= keys[begin]) return begin;
    if (g > keys[end - 1]) return end;
    if (table != kNoTable) return table_[table + static_cast<std::uint32_t>(g - keys[begin])];
    return static_cast<std::uint32_t>(
        std::lower_bound(keys.begin() + begin, keys.begin() + end, static_cast<std::uint32_t>(g)) - keys.begin());
  }

  // One row: the cells whose points may lie in the disc (near) and those
  // whose points all do (whole). Left of x each set is a suffix of the cells,
  // right of x a prefix (the bounds grow away from x), so each is found by a
  // walk from the cell at x outwards.
  std::size_t sum_row(const Row& row, double x, double y, double r2, double near_y, double far_y, double& sx,
                      double& sy, std::size_t& count) const {
    const Cell* c = cells_.data();
    const std::uint32_t b = row.cell_begin, e = row.cell_end;
    // First cell reaching x: the cells before it lie wholly left of x (as the rows, above).
    std::uint32_t mid = first_at_or_after(cell_gx_, row.table, b, e, x, min_x_);
    if (mid < e && c[mid].hi_x < x) ++mid;
    const auto whole = [&](std::uint32_t i) {
      return std::max(sq(c[i].lo_x - x), sq(c[i].hi_x - x)) + far_y <= r2;
    };
    const auto near = [&](std::uint32_t i) {
      const double gap = c[i].lo_x > x ? c[i].lo_x - x : (c[i].hi_x < x ? x - c[i].hi_x : 0.0);
      return gap * gap + near_y <= r2;
    };
    Sum acc{sx, sy, count};
    std::size_t cost = 0;
    std::uint32_t lw = mid;  // whole cells [lw, mid), edge cells [ln, lw)
    while (lw > b && whole(lw - 1)) --lw;
    std::uint32_t ln = lw;
    while (ln > b && near(ln - 1)) --ln;
    cost += test_points(ln, lw, x, y, r2, acc);
    std::uint32_t rw = mid;  // the run of whole cells so far is [lw, rw)
    if (mid < e && whole(mid)) {
      rw = mid + 1;
    } else {
      cost += add_run(row, lw, mid, acc);
      if (mid < e && near(mid)) cost += test_points(mid, mid + 1, x, y, r2, acc);
      if (mid == e || !near(mid)) {  // the cells right of it are farther still
        sx = acc.x, sy = acc.y, count = acc.count;
        return cost;
      }
      lw = rw = mid + 1;
    }
    while (rw < e && whole(rw)) ++rw;
    cost += add_run(row, lw, rw, acc);
    std::uint32_t rn = rw;  // edge cells [rw, rn)
    while (rn < e && near(rn)) ++rn;
    cost += test_points(rw, rn, x, y, r2, acc);
    sx = acc.x, sy = acc.y, count = acc.count;
    return cost;
  }

  // Adds the points of cells [from, to) within the disc, in order; the tests
  // are gathered before the additions so that their outcome is not a branch
  // per point. Returns the points tested.
  std::size_t test_points(std::uint32_t from, std::uint32_t to, double x, double y, double r2, Sum& acc) const {
    if (to <= from) return 0;
    const double* p = points_.data();
    const std::uint32_t begin = cells_[from].begin, end = cells_[to - 1].end;
    constexpr std::uint32_t kChunk = 64;
    std::uint32_t hit[kChunk];
    for (std::uint32_t k0 = begin; k0 < end; k0 += kChunk) {
      const std::uint32_t k1 = std::min(end, k0 + kChunk);
      std::uint32_t h = 0;
      for (std::uint32_t k = k0; k < k1; ++k) {
        const double dx = p[2 * k] - x, dy = p[2 * k + 1] - y;
        hit[h] = k;
        h += dx * dx + dy * dy <= r2 ? 1u : 0u;
      }
      for (std::uint32_t t = 0; t < h; ++t) {
        acc.x += p[2 * hit[t]];
        acc.y += p[2 * hit[t] + 1];
      }
      acc.count += h;
    }
    return end - begin;
  }

  // Adds the cells [from, to) of `row` whole: their running sums'
  // difference, plus their count times the offset the sums left out.
  // Returns 1 (one run) or 0 (empty).
  std::size_t add_run(const Row& row, std::uint32_t from, std::uint32_t to, Sum& acc) const {
    if (to <= from) return 0;
    const Sum& hi = sums_[to - 1];
    const Sum lo = from == row.cell_begin ? Sum{} : sums_[from - 1];
    const std::size_t count = hi.count - lo.count;
    acc.x += (hi.x - lo.x) + static_cast<double>(count) * row.origin_x;
    acc.y += (hi.y - lo.y) + static_cast<double>(count) * row.origin_y;
    acc.count += count;
    return 1;
  }

  std::vector<double> points_;  // x, y interleaved, by (row, cell, index)
  std::vector<Row> rows_;       // occupied rows, ascending in y
  std::vector<Cell> cells_;     // occupied cells, by row then x
  std::vector<Sum> sums_;       // per cell: the row's cells up to and including it, less the row's origin
  std::vector<std::uint32_t> row_gy_;   // per row: its cell index along y
  std::vector<std::uint32_t> cell_gx_;  // per cell: its cell index along x
  std::vector<std::uint32_t> table_;    // the lookup tables (tabulate)
  std::uint32_t row_table_ = kNoTable;  // the rows' table
  double cell_ = 1.0, min_x_ = 0.0, min_y_ = 0.0;
};

}  // namespace sogmm::detail
