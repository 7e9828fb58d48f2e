// Mode counting by mean shift on (range, gray) features.
#include "sogmm/mean_shift.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>
#include <string>
#include <utility>

#include "grid2d.hpp"
#include "row_sum_grid.hpp"
#include "parallel.hpp"
#include "progress.hpp"
#include "z_order.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"

namespace sogmm {

bool bandwidth_is_usable(double bandwidth) {
  if (!(std::isfinite(bandwidth) && bandwidth > 0)) return false;
  const double b2 = bandwidth * bandwidth;
  const double inv = 1.0 / (2.0 * b2);
  // 9 b^2: the blurring kernel's radius is 3 bandwidths.
  return b2 > 0 && std::isfinite(9.0 * b2) && std::isfinite(inv) && inv > 0;
}

void require_usable_bandwidth(double bandwidth) {
  require(bandwidth_is_usable(bandwidth), ErrorCode::InvalidArgument,
          "bandwidth must be a finite positive value whose square and inverse square are finite (about "
          "5.3e-155 to 4.4e153), got " + checked::exact(bandwidth));
}

void require_mode_count_range(const std::vector<double>& points2d, double bandwidth) {
  // Grid and bin indices are (coordinate - origin) / bandwidth and
  // coordinate / bandwidth converted to 64-bit integers: bound both so that the
  // conversions are exact and defined (and the sparse grid's cell keys, at
  // most (1e8 / 0.5 + 1)^2 for the duplicate suppression's half-bandwidth
  // cells, stay far inside int64).
  constexpr double kMaxCellsPerAxis = 1.0e8;
  constexpr double kMaxBinIndex = 1.0e15;
  for (int axis = 0; axis < 2; ++axis) {
    double lo = INFINITY, hi = -INFINITY;
    for (std::size_t i = axis; i < points2d.size(); i += 2) {
      lo = std::min(lo, points2d[i]);
      hi = std::max(hi, points2d[i]);
    }
    const double extent = (hi - lo) / bandwidth;
    const double magnitude = std::max(std::fabs(lo), std::fabs(hi)) / bandwidth;
    require(extent <= kMaxCellsPerAxis && magnitude <= kMaxBinIndex, ErrorCode::Limit,
            std::string("bandwidth ") + checked::exact(bandwidth) + " is too small for the " +
                (axis == 0 ? "range" : "gray") + " values of the data (from " + checked::exact(lo) + " to " +
                checked::exact(hi) + "): use a larger bandwidth");
  }
}

namespace {

void check_inputs(const std::vector<double>& points2d, double bandwidth) {
  require_usable_bandwidth(bandwidth);
  require(!points2d.empty() && points2d.size() % 2 == 0, ErrorCode::InvalidData,
          "mean shift needs a non-empty N x 2 array");
  for (double v : points2d)
    require(std::isfinite(v), ErrorCode::InvalidData, "mean shift input has a non-finite value");
  require_mode_count_range(points2d, bandwidth);
}

// Centres of the occupied cells of the bin-seeding grid.
std::vector<double> bin_seeds(const std::vector<double>& xy, double bandwidth, BinAnchor anchor) {
  // The data's lowest coordinates: the DataMin anchor, and (below) the
  // lowest cell of either anchor.
  double low_x = INFINITY, low_y = INFINITY;
  for (std::size_t i = 0; i < xy.size(); i += 2) low_x = std::min(low_x, xy[i]), low_y = std::min(low_y, xy[i + 1]);
  const double min_x = anchor == BinAnchor::DataMin ? low_x : 0.0;
  const double min_y = anchor == BinAnchor::DataMin ? low_y : 0.0;
  auto cell = [&](double v, double lo) {
    // Zero anchor: numpy's round (half to even) as scikit-learn's get_bin_seeds.
    // check_inputs bounds |v| / bandwidth by 1e15, so these never throw on checked input.
    return anchor == BinAnchor::Zero ? checked::to_int<std::int64_t>(std::nearbyint(v / bandwidth), "bin index")
                                     : checked::floor_to_int<std::int64_t>((v - lo) / bandwidth + 0.5, "bin index");
  };
  // The occupied cells in ascending (x, y) order: seeds in a fixed order.
  // check_inputs bounds each axis's extent by 1e8 bandwidths, so a cell's
  // offset from the lowest cell fits 32 bits, and the key (x offset << 32 |
  // y offset) orders cells as (x, y) pairs: a radix sort of the keys then
  // gives std::sort's order of the cells (std::sort of the pairs was ~10% of
  // the mode count's serial time at d = 1). A cell index never decreases as
  // its coordinate grows (division by a positive bandwidth, subtraction of
  // a constant and rounding are monotone), so the lowest cell is the lowest
  // coordinate's. The key alone gives back the cell, so neither the cells
  // nor the points' indices are kept: at 2 threads this runs beside the
  // row-sum grid's build, and with the two arrays of cells and the (key,
  // index) pairs the mode count's peak memory at d = 1 was ~10 MiB higher
  // (34 against 24 MiB).
  const std::size_t n = xy.size() / 2;
  const std::int64_t lo_x = cell(low_x, min_x), lo_y = cell(low_y, min_y);
  std::vector<std::uint64_t> keys(n);
  for (std::size_t i = 0; i < n; ++i)
    keys[i] = static_cast<std::uint64_t>(cell(xy[2 * i], min_x) - lo_x) << 32 |
              static_cast<std::uint64_t>(cell(xy[2 * i + 1], min_y) - lo_y);
  detail::radix_sort(keys, 64, 8, [](std::uint64_t key) { return key; });
  std::vector<double> seeds;
  for (std::size_t k = 0; k < n; ++k) {
    if (k > 0 && keys[k] == keys[k - 1]) continue;
    const std::int64_t cx = static_cast<std::int64_t>(keys[k] >> 32) + lo_x;
    const std::int64_t cy = static_cast<std::int64_t>(keys[k] & 0xFFFFFFFFu) + lo_y;
    seeds.push_back(cx * bandwidth + min_x);
    seeds.push_back(cy * bandwidth + min_y);
  }
  return seeds;
}

struct Mode {
  double x, y;
  std::size_t strength;
};

// Orders modes strongest first (ties: larger centre first, as scikit-learn's
// sort of (intensity, centre) tuples in reverse), drops exact duplicates and
// every mode within `radius` of a stronger kept one.
// `checks` is the neighbour_checks count of the work before.
MeanShiftResult suppress_near_duplicates(std::vector<Mode> modes, double radius, std::uint64_t checks) {
  std::sort(modes.begin(), modes.end(), [](const Mode& a, const Mode& b) {
    if (a.strength != b.strength) return a.strength > b.strength;
    if (a.x != b.x) return a.x > b.x;
    return a.y > b.y;
  });
  modes.erase(std::unique(modes.begin(), modes.end(),
                          [](const Mode& a, const Mode& b) { return a.x == b.x && a.y == b.y; }),
              modes.end());
  std::vector<double> xy(2 * modes.size());
  for (std::size_t i = 0; i < modes.size(); ++i) {
    xy[2 * i] = modes[i].x;
    xy[2 * i + 1] = modes[i].y;
  }
  MeanShiftResult result;
  result.neighbour_checks = checks;
  if (modes.empty()) return result;
  detail::Grid2d grid(xy.data(), modes.size(), radius);
  std::vector<char> unique(modes.size(), 1);
  for (std::size_t i = 0; i < modes.size(); ++i) {
    if (!unique[i]) continue;
    result.neighbour_checks +=
        grid.for_each_within(modes[i].x, modes[i].y, radius, [&](std::uint32_t j) { unique[j] = 0; });
    unique[i] = 1;
  }
  for (std::size_t i = 0; i < modes.size(); ++i) {
    if (!unique[i]) continue;
    result.centers.push_back(modes[i].x);
    result.centers.push_back(modes[i].y);
    result.strengths.push_back(modes[i].strength);
  }
  return result;
}

}  // namespace

MeanShiftResult mean_shift_flat(const std::vector<double>& xy, double bandwidth, const MeanShiftOptions& options) {
  check_inputs(xy, bandwidth);
  require(options.max_iter >= 0 && options.stop_fraction >= 0, ErrorCode::InvalidArgument,
          "mean shift max_iter and stop_fraction must be >= 0");
  const std::size_t n = xy.size() / 2;
  detail::progress_poll();  // serial set-up: a report (and a cancel) between its steps
  // Cells of a quarter bandwidth: most of a disc is then whole cells, while
  // the rows and cells walked per query stay few (at d = 1 a query tests ~410
  // points one by one instead of Grid2d's ~1,800; halves and eighths were
  // slower).
  // The grid and the seeds are independent serial work (sorts of all the
  // points): one on each of two threads. The grid, the larger and the one
  // that lives through the mean shift, is built by the calling thread
  // whenever it takes part: memory a worker allocates stays in the worker's
  // malloc arena after it is freed (glibc), where the calling thread's next
  // stages cannot reuse it (a grid built on the worker raised the d = 1
  // fit's peak memory at 2 threads by ~7 MiB, 34.8 against 28.3 MiB). Of
  // the loop's two calls, the calling thread's first builds the grid and the
  // workers' first the seeds; a side's second call (the other made none)
  // does the other task. So each task runs once, whoever takes the calls.
  std::optional<detail::RowSumGrid> built;
  std::vector<double> seeds;
  std::atomic<bool> caller_called{false}, worker_called{false};
  detail::parallel_for(2, detail::team_size(0), 1, [&](std::size_t, int thread) {
    const bool grid = thread == 0 ? !caller_called.exchange(true) : worker_called.exchange(true);
    if (grid)
      built.emplace(xy.data(), n, bandwidth, 4);
    else
      seeds = bin_seeds(xy, bandwidth, options.anchor);
  });
  const detail::RowSumGrid& grid = *built;
  detail::progress_poll();
  const std::size_t n_seeds = seeds.size() / 2;
  const double stop = options.stop_fraction * bandwidth;
  std::vector<Mode> modes(n_seeds);
  std::vector<std::uint64_t> checks(n_seeds, 0);  // per seed, summed in seed order after the loop
  detail::progress_begin(Stage::ModeCount, n_seeds);
  detail::parallel_for(n_seeds, detail::team_size(0), 16, [&](std::size_t s, int thread) {
    if (thread == 0) detail::progress_at(s);
    double mx = seeds[2 * s], my = seeds[2 * s + 1];
    std::size_t within = 0;
    for (int it = 0;; ++it) {
      double sx = 0.0, sy = 0.0;
      std::size_t count = 0;
      checks[s] += grid.sum_within(mx, my, bandwidth * bandwidth, sx, sy, count);
      within = count;
      if (count == 0) break;
      const double nx = sx / count, ny = sy / count;
      const double moved = std::hypot(nx - mx, ny - my);
      mx = nx;
      my = ny;
      if (moved <= stop || it == options.max_iter) break;
    }
    modes[s] = {mx, my, within};
  });
  // Seeds that saw no point are not modes.
  modes.erase(std::remove_if(modes.begin(), modes.end(), [](const Mode& m) { return m.strength == 0; }), modes.end());
  std::uint64_t total = 0;
  for (std::uint64_t c : checks) total += c;
  return suppress_near_duplicates(std::move(modes), bandwidth, total);
}

MeanShiftResult mean_shift_gaussian_blurring(const std::vector<double>& xy0, double bandwidth, int max_iter) {
  check_inputs(xy0, bandwidth);
  require(max_iter >= 1, ErrorCode::InvalidArgument, "max_iter must be >= 1");
  const std::size_t n = xy0.size() / 2;
  std::vector<double> xy = xy0, next(xy.size());
  const double radius = 3.0 * bandwidth;
  const double inv2s2 = 1.0 / (2.0 * bandwidth * bandwidth);
  const double stop2 = (1e-3 * bandwidth) * (1e-3 * bandwidth);
  std::vector<std::uint64_t> checks(n, 0);  // per point, summed over iterations
  // Per point, summed in point order after the loop: an OpenMP reduction
  // would add in thread order, and the stop test (so the iteration count and
  // the modes) would depend on the thread count.
  std::vector<double> moved2_of(n);
  detail::progress_begin(Stage::ModeCount, static_cast<std::uint64_t>(max_iter));
  for (int it = 0; it < max_iter; ++it) {
    detail::progress_at(static_cast<std::uint64_t>(it));
    const detail::Grid2d grid(xy.data(), n, radius);
    detail::parallel_for(n, detail::team_size(0), 256, [&](std::size_t i, int) {
      double sw = 0.0, sx = 0.0, sy = 0.0;
      const double x = xy[2 * i], y = xy[2 * i + 1];
      checks[i] += grid.for_each_within(x, y, radius, [&](std::uint32_t j) {
        const double dx = xy[2 * j] - x, dy = xy[2 * j + 1] - y;
        const double w = std::exp(-(dx * dx + dy * dy) * inv2s2);
        sw += w;
        sx += w * xy[2 * j];
        sy += w * xy[2 * j + 1];
      });
      next[2 * i] = sx / sw;
      next[2 * i + 1] = sy / sw;
      moved2_of[i] = (next[2 * i] - x) * (next[2 * i] - x) + (next[2 * i + 1] - y) * (next[2 * i + 1] - y);
    });
    xy.swap(next);
    double moved2 = 0.0;
    for (double m : moved2_of) moved2 += m;
    if (moved2 / n < stop2) break;
  }
  // Collapse the blurred points into modes: greedy assignment to a mode within
  // bandwidth / 2, in point order (deterministic). Its distance evaluations
  // count as neighbour checks too.
  std::vector<Mode> modes;
  std::uint64_t total = 0;
  for (std::size_t i = 0; i < n; ++i) {
    bool assigned = false;
    for (std::size_t m = 0; m < modes.size() && !assigned; ++m) {
      ++total;
      if (std::hypot(modes[m].x - xy[2 * i], modes[m].y - xy[2 * i + 1]) <= 0.5 * bandwidth) {
        ++modes[m].strength;
        assigned = true;
      }
    }
    if (!assigned) modes.push_back({xy[2 * i], xy[2 * i + 1], 1});
  }
  for (std::uint64_t c : checks) total += c;
  return suppress_near_duplicates(std::move(modes), 0.5 * bandwidth, total);
}

std::vector<double> range_gray_features(const PointsView& points) {
  std::vector<double> f(2 * points.size);
  // In spans on the team (each feature written by one span): serial, this
  // was ~2% of a d = 1 mode count's time with the other thread idle.
  constexpr std::size_t kSpan = 16384;
  detail::parallel_for((points.size + kSpan - 1) / kSpan, detail::team_size(0), 1, [&](std::size_t s, int) {
    for (std::size_t i = s * kSpan; i < std::min(points.size, (s + 1) * kSpan); ++i) {
      const float* p = points[i];
      f[2 * i] = std::sqrt(double(p[0]) * p[0] + double(p[1]) * p[1] + double(p[2]) * p[2]);
      f[2 * i + 1] = p[3];
    }
  });
  return f;
}

}  // namespace sogmm
