// Depth quantisation of a camera-frame cloud (see depth_quantisation.hpp).
#include "sogmm/depth_quantisation.hpp"

#include <algorithm>
#include <cmath>

namespace sogmm {

DepthQuantisation DepthQuantisation::detect(const PointsView& points) {
  DepthQuantisation q;
  std::vector<double> z(points.size);
  for (std::size_t i = 0; i < points.size; ++i) {
    z[i] = points[i][2];
    if (!(z[i] > 0.0)) return q;  // not a camera-frame cloud in front of the camera
  }
  std::sort(z.begin(), z.end());
  z.erase(std::unique(z.begin(), z.end()), z.end());
  if (z.size() < 2 || z.size() * kMinPointsPerLevel > points.size) return q;
  q.levels_ = std::move(z);
  return q;
}

void DepthQuantisation::floor_covariance_at(const double mean[4], double covariance[16]) const {
  if (empty() || !(mean[2] > 0.0)) return;
  // The bin containing mean z: between levels j - 1 and j.
  const std::size_t last = levels_.size() - 1;
  const std::size_t j = std::clamp<std::size_t>(
      static_cast<std::size_t>(std::upper_bound(levels_.begin(), levels_.end(), mean[2]) - levels_.begin()), 1, last);
  const double w = levels_[j] - levels_[j - 1];
  const double v[3] = {mean[0] / mean[2], mean[1] / mean[2], 1.0};
  const double norm2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
  const double u[3] = {v[0] / std::sqrt(norm2), v[1] / std::sqrt(norm2), v[2] / std::sqrt(norm2)};
  // Variance of the bin along the unit ray u, and the component's own.
  const double bin = w * w / 12.0 * norm2;
  double own = 0.0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) own += u[a] * covariance[4 * a + b] * u[b];
  if (!(own < bin)) return;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) covariance[4 * a + b] += (bin - own) * u[a] * u[b];
}

}  // namespace sogmm
