// Depth quantisation of a camera-frame cloud (see depth_quantisation.hpp).
#include "sogmm/depth_quantisation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "z_order.hpp"

namespace sogmm {

DepthQuantisation DepthQuantisation::detect(const PointsView& points) {
  DepthQuantisation q;
  // The depths' float32 bit patterns: for values > 0 (+infinity included)
  // they order as the values do, and equal patterns are equal values, so a
  // radix sort of the patterns gives std::sort's distinct levels (a sort of
  // the doubles was ~5 ms of a d = 1 fit, serial between the mode count and
  // the seeding).
  std::vector<std::uint32_t> bits(points.size);
  for (std::size_t i = 0; i < points.size; ++i) {
    const float z = points[i][2];
    if (!(z > 0.0f)) return q;  // not a camera-frame cloud in front of the camera
    std::memcpy(&bits[i], &z, sizeof z);
  }
  detail::radix_sort(bits, 32, 8, [](std::uint32_t b) { return b; });
  bits.erase(std::unique(bits.begin(), bits.end()), bits.end());
  if (bits.size() < 2 || bits.size() * kMinPointsPerLevel > points.size) return q;
  q.levels_.resize(bits.size());
  for (std::size_t i = 0; i < bits.size(); ++i) {
    float z;
    std::memcpy(&z, &bits[i], sizeof z);
    q.levels_[i] = z;
  }
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
