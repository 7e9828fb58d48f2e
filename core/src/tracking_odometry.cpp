// Tracking's odometry pieces (tracking_odometry.hpp).
#include "tracking_odometry.hpp"

#include <cmath>

#include "tracking_target.hpp"

namespace sogmm::detail {

Gmm odometry_target(const PointsView& points) { return cell_gaussians(points, kOdometryCell, kOdometryCellMin); }

double rms_displacement(const PointsView& points, const Pose& a, const Pose& b) {
  if (points.size == 0) return 0.0;
  double d[12];
  for (int i = 0; i < 12; ++i) d[i] = a[i] - b[i];
  double sum = 0.0;
  for (std::size_t i = 0; i < points.size; ++i) {
    const float* p = points[i];
    for (int r = 0; r < 3; ++r) {
      const double e = d[4 * r] * p[0] + d[4 * r + 1] * p[1] + d[4 * r + 2] * p[2] + d[4 * r + 3];
      sum += e * e;
    }
  }
  return std::sqrt(sum / double(points.size));
}

}  // namespace sogmm::detail
