// The tracking target (tracking_target.hpp).
#include "tracking_target.hpp"

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <map>

namespace sogmm::detail {

namespace {
struct CellSums {
  std::size_t n = 0;
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  Eigen::Matrix4d outer = Eigen::Matrix4d::Zero();  // about the cell's first point (no cancellation far out)
  Eigen::Vector4d ref = Eigen::Vector4d::Zero();
};
}  // namespace

Gmm cell_gaussians(const PointsView& points, double cell, std::size_t min_points) {
  // Keys in double (floor of coordinate / cell): exact integers for any
  // float32 coordinate, as the pending voxels.
  std::map<std::array<double, 3>, CellSums> cells;
  for (std::size_t i = 0; i < points.size; ++i) {
    const float* p = points[i];
    const std::array<double, 3> key = {std::floor(p[0] / cell), std::floor(p[1] / cell), std::floor(p[2] / cell)};
    CellSums& c = cells[key];
    const Eigen::Vector4d x(p[0], p[1], p[2], p[3]);
    if (c.n == 0) c.ref = x;
    const Eigen::Vector4d d = x - c.ref;
    ++c.n;
    c.sum += d;
    c.outer.noalias() += d * d.transpose();
  }
  Gmm out;
  std::size_t kept = 0;
  for (const auto& [key, c] : cells) {
    if (c.n < min_points) continue;
    const Eigen::Vector4d mean_d = c.sum / double(c.n);
    Eigen::Matrix4d cov = c.outer / double(c.n) - mean_d * mean_d.transpose();
    for (int k = 0; k < 3; ++k) cov(k, k) += kPendingCellSpatialFloor;
    cov(3, 3) += kPendingCellGrayFloor;
    std::array<double, 16> stored{};
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) stored[4 * i + j] = double(static_cast<float>(0.5 * (cov(i, j) + cov(j, i))));
    if (!stored_cholesky(stored.data())) continue;  // cannot happen with the floors; never hand out a bad one
    const Eigen::Vector4d mean = c.ref + mean_d;
    out.weights.push_back(static_cast<float>(c.n));
    for (int i = 0; i < 4; ++i) out.means.push_back(static_cast<float>(mean(i)));
    for (double v : stored) out.covariances.push_back(static_cast<float>(v));
    kept += c.n;
  }
  for (float& w : out.weights) w = static_cast<float>(w / double(kept));
  out.support_size = kept;
  return out;
}

Gmm tracking_target(const Map& map) {
  const Gmm& components = map.model().gmm;
  if (map.pending() == 0) return components;
  const PointCloud pending = map.pending_points();
  const Gmm cells = cell_gaussians(pending.view(), kPendingCell, kPendingCellMin);
  if (cells.size() == 0) return components;
  const double s = double(components.support_size), p = double(cells.support_size), total = s + p;
  Gmm out = components;
  for (float& w : out.weights) w = static_cast<float>(w * s / total);
  for (std::size_t k = 0; k < cells.size(); ++k) out.weights.push_back(static_cast<float>(cells.weights[k] * p / total));
  out.means.insert(out.means.end(), cells.means.begin(), cells.means.end());
  out.covariances.insert(out.covariances.end(), cells.covariances.begin(), cells.covariances.end());
  out.support_size = components.support_size + cells.support_size;
  return out;
}

}  // namespace sogmm::detail
