// A uniform 2-D grid over points for fixed-radius neighbour queries (private
// to the core). Cells are `cell` wide; a query of radius <= cell visits the
// 3x3 cells around the query point.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"

namespace sogmm::detail {

class Grid2d {
 public:
  /// Largest grid accepted (cells), about 1 GiB of cell offsets.
  static constexpr double kMaxCells = 1.0e8;
  /// Indexes n points (x, y interleaved) with square cells of side `cell`.
  Grid2d(const double* xy, std::size_t n, double cell) : xy_(xy), cell_(cell) {
    min_x_ = min_y_ = INFINITY;
    double max_x = -INFINITY, max_y = -INFINITY;
    for (std::size_t i = 0; i < n; ++i) {
      min_x_ = std::min(min_x_, xy[2 * i]);
      min_y_ = std::min(min_y_, xy[2 * i + 1]);
      max_x = std::max(max_x, xy[2 * i]);
      max_y = std::max(max_y, xy[2 * i + 1]);
    }
    nx_ = static_cast<std::int64_t>((max_x - min_x_) / cell) + 1;
    ny_ = static_cast<std::int64_t>((max_y - min_y_) / cell) + 1;
    // A dense grid is fastest; refuse sizes that would exhaust memory.
    const double cells = static_cast<double>(nx_) * static_cast<double>(ny_);
    require(cells <= kMaxCells, ErrorCode::Limit,
            "bandwidth " + checked::exact(cell) + " is too small for the extent of the data (" +
                checked::exact(cells) + " grid cells, limit " + std::to_string(kMaxCells) + ")");
    // Counting sort of points by cell: cell c holds order_[start_[c], start_[c+1]).
    start_.assign(static_cast<std::size_t>(nx_ * ny_ + 1), 0);
    std::vector<std::int64_t> cell_of(n);
    for (std::size_t i = 0; i < n; ++i) {
      cell_of[i] = cell_index(cx(xy[2 * i]), cy(xy[2 * i + 1]));
      ++start_[cell_of[i] + 1];
    }
    std::partial_sum(start_.begin(), start_.end(), start_.begin());
    order_.resize(n);
    std::vector<std::size_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < n; ++i) order_[fill[cell_of[i]]++] = static_cast<std::uint32_t>(i);
  }

  /// Calls visit(index) for every point within distance `radius` (<= cell) of (x, y).
  template <typename Visit>
  void for_each_within(double x, double y, double radius, Visit&& visit) const {
    const double r2 = radius * radius;
    const std::int64_t ix = cx(x), iy = cy(y);
    for (std::int64_t gy = std::max<std::int64_t>(iy - 1, 0); gy <= std::min(iy + 1, ny_ - 1); ++gy) {
      for (std::int64_t gx = std::max<std::int64_t>(ix - 1, 0); gx <= std::min(ix + 1, nx_ - 1); ++gx) {
        const std::int64_t c = cell_index(gx, gy);
        for (std::size_t k = start_[c]; k < start_[c + 1]; ++k) {
          const std::uint32_t i = order_[k];
          const double dx = xy_[2 * i] - x, dy = xy_[2 * i + 1] - y;
          if (dx * dx + dy * dy <= r2) visit(i);
        }
      }
    }
  }

 private:
  std::int64_t cx(double x) const { return static_cast<std::int64_t>(std::floor((x - min_x_) / cell_)); }
  std::int64_t cy(double y) const { return static_cast<std::int64_t>(std::floor((y - min_y_) / cell_)); }
  std::int64_t cell_index(std::int64_t gx, std::int64_t gy) const { return gy * nx_ + gx; }

  const double* xy_;
  double cell_;
  double min_x_, min_y_;
  std::int64_t nx_ = 1, ny_ = 1;
  std::vector<std::size_t> start_;
  std::vector<std::uint32_t> order_;
};

}  // namespace sogmm::detail
