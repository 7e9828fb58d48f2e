// The EM's covariance regulariser relative to the data's scales (see
// sogmm/reg_covar.hpp).
#include "sogmm/reg_covar.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "parallel.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"
#include "sogmm/model.hpp"
#include "sogmm/shortest_decimal.hpp"

namespace sogmm {
namespace {

// 10^e, correctly rounded (strtod of the decimal literal), so that the floors
// are the same doubles as the literals 1e-6, 1e-4, ... a user would type.
double power_of_ten(int e) { return std::strtod(("1e" + std::to_string(e)).c_str(), nullptr); }

// The exponent k of the power of ten nearest `size` on a log scale (size > 0).
int nearest_decade(double size) { return static_cast<int>(std::lround(std::log10(size))); }

// The smallest k with 10^k >= size (size > 0); log10 only proposes, the
// comparison with the correctly rounded power decides, so a range of exactly
// 1 or 1000 gives 0 or 3 on every libm.
int covering_decade(double size) {
  int k = static_cast<int>(std::ceil(std::log10(size)));
  while (power_of_ten(k) < size) ++k;
  while (power_of_ten(k - 1) >= size) --k;
  return k;
}

// 1e-6 x 100^k, clamped to normal, finite float32 values.
double floor_for_decade(int k) { return power_of_ten(std::clamp(2 * k - 6, -36, 36)); }

// The lower median of v (reordered).
double lower_median(std::vector<double>& v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>((v.size() - 1) / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// The median distance of the points (x, y, z) from their coordinate-wise
// median; when that is 0, the largest side of their bounding box. `centre`
// and `side` are the coordinates' medians and ranges (coordinate_median);
// `v` is scratch of n doubles.
double spatial_size(const PointsView& pts, std::vector<double>& v, const double* centre, const double* side) {
  const double extent = std::max({side[0], side[1], side[2]});
  for (std::size_t i = 0; i < pts.size; ++i) {
    double d2 = 0.0;
    for (int j = 0; j < 3; ++j) {
      const double d = pts[i][j] - centre[j];
      d2 += d * d;
    }
    v[i] = std::sqrt(d2);
  }
  const double median = lower_median(v);
  return median > 0.0 ? median : extent;
}

// Coordinate j of every point into v (n values), and their lower median and
// range (max - min).
void coordinate_median(const PointsView& pts, int j, double* v, double& median, double& side) {
  for (std::size_t i = 0; i < pts.size; ++i) v[i] = pts[i][j];
  const auto [lo, hi] = std::minmax_element(v, v + pts.size);
  side = *hi - *lo;
  const auto mid = v + (pts.size - 1) / 2;
  std::nth_element(v, mid, v + pts.size);
  median = *mid;
}

// The gray range that sets the gray floor: the spread between the gray
// quantiles kGrayTail and 1 - kGrayTail, so that a few out-of-range pixels
// (one pixel of 1000 in a GRAY_F32 frame in [0, 1]) do not set the floor of
// every component (issue 36: it moved 1e-6 to 1e-2 and the frame's
// log-likelihood from 6.62 to 3.37); when that spread is 0 (more than
// 98% of the points share one gray), the full range max - min. The quantiles
// are order statistics of the float32 values, so gray in [0, 1] gives the
// same floor as before whenever its 1-99% spread is above 0.1, as in every
// room frame.
constexpr double kGrayTail = 0.01;
double gray_range(const PointsView& pts, std::vector<float>& g) {
  for (std::size_t i = 0; i < pts.size; ++i) g[i] = pts[i][3];
  const auto [lo, hi] = std::minmax_element(g.begin(), g.end());
  const double full = static_cast<double>(*hi) - *lo;
  const auto tail = static_cast<std::ptrdiff_t>(kGrayTail * static_cast<double>(pts.size - 1));
  const auto q_lo = g.begin() + tail, q_hi = g.end() - 1 - tail;
  std::nth_element(g.begin(), q_lo, g.end());
  const float low = *q_lo;
  std::nth_element(q_lo, q_hi, g.end());
  const double robust = static_cast<double>(*q_hi) - low;
  return robust > 0.0 ? robust : full;
}

}  // namespace

RegCovarFloors auto_reg_covar(const PointsView& points) {
  require(points.size > 0, ErrorCode::InvalidData, "automatic reg_covar: the point cloud is empty");
  RegCovarFloors f;
  f.automatic = true;
  // The three coordinates' medians and the gray range are order statistics
  // of separate arrays (values, whatever the order of the work): four tasks
  // on the team, each array allocated here on the calling thread (see
  // mean_shift.cpp on a worker's memory). Serial, this was ~7 ms of a d = 1
  // fit with the other thread idle.
  std::vector<double> coordinates(3 * points.size);
  std::vector<float> grays(points.size);
  double centre[3], side[3], gray = 0.0;
  // Below kTeamPoints points a team's start costs more than the tasks.
  constexpr std::size_t kTeamPoints = 16384;
  detail::parallel_for(4, points.size >= kTeamPoints ? detail::team_size(0) : 1, 1, [&](std::size_t task, int) {
    const int j = static_cast<int>(task);
    if (j < 3)
      coordinate_median(points, j, &coordinates[j * points.size], centre[j], side[j]);
    else
      gray = gray_range(points, grays);
  });
  coordinates.resize(points.size);
  const double spatial = spatial_size(points, coordinates, centre, side);
  f.spatial = floor_for_decade(spatial > 0.0 ? nearest_decade(spatial) : 0);
  // A range within float32 rounding above a power of ten counts as that power
  // (gray in [0, 1] computed in float may end at 1.0000001).
  f.gray = floor_for_decade(gray > 0.0 ? covering_decade(gray * (1.0 - 1e-6)) : 0);
  return f;
}

RegCovarFloors resolve_reg_covar(const PointsView& points, const std::optional<double>& reg_covar) {
  if (!reg_covar) return auto_reg_covar(points);
  require(std::isfinite(*reg_covar) && *reg_covar >= 0, ErrorCode::InvalidArgument,
          "EM reg_covar (covariance regulariser) must be finite and >= 0, got " + checked::exact(*reg_covar));
  return {*reg_covar, *reg_covar, false};
}

void record_reg_covar(Model& model, const RegCovarFloors& floors) {
  model.fit.reg_covar = floors.spatial;
  set_value(model, kRegCovarGrayKey, shortest_decimal(floors.gray));
  set_value(model, kRegCovarSourceKey, floors.automatic ? "auto" : "user");
}

}  // namespace sogmm
