// The EM's covariance regulariser relative to the data's scales (see
// sogmm/reg_covar.hpp).
#include "sogmm/reg_covar.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

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
// median; when that is 0, the largest side of their bounding box.
double spatial_size(const PointsView& pts) {
  std::vector<double> v(pts.size);
  double centre[3], extent = 0.0;
  for (int j = 0; j < 3; ++j) {
    for (std::size_t i = 0; i < pts.size; ++i) v[i] = pts[i][j];
    const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
    extent = std::max(extent, *hi - *lo);
    centre[j] = lower_median(v);
  }
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
double gray_range(const PointsView& pts) {
  std::vector<float> g(pts.size);
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
  const double spatial = spatial_size(points);
  f.spatial = floor_for_decade(spatial > 0.0 ? nearest_decade(spatial) : 0);
  const double gray = gray_range(points);
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
