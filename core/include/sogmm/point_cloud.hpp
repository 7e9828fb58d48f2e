// Point clouds as the core consumes them: N x 4 float32, row-major (x, y, z, gray).
#pragma once

#include <cstddef>
#include <vector>

namespace sogmm {

/// N points of (x, y, z, gray), row-major, metres and [0, 1] gray. A view:
/// the memory belongs to the caller and must outlive the view.
struct PointsView {
  const float* data = nullptr;  ///< 4 * size floats
  std::size_t size = 0;         ///< number of points N
  /// True for camera-frame points back-projected from a depth image
  /// (backproject()): the automatic depth floor (FitOptions::dequantise_depth)
  /// applies to them and to no other points.
  bool from_depth_image = false;

  const float* operator[](std::size_t i) const { return data + 4 * i; }
};

/// Owning cloud: 4 floats per point.
struct PointCloud {
  std::vector<float> xyzg;
  bool from_depth_image = false;  ///< as PointsView::from_depth_image
  std::size_t size() const { return xyzg.size() / 4; }
  PointsView view() const { return {xyzg.data(), size(), from_depth_image}; }
};

/// Throws Error(InvalidData) when the view is empty or holds NaN/Inf, naming
/// the first bad point; `what` names the input in the message.
void require_finite_points(const PointsView& points, const char* what = "point cloud");

}  // namespace sogmm
