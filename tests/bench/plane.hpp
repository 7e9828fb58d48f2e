// A synthetic scene with known answers: a 0.595 m square of points on the
// plane z = 1.01 m, 5 mm apart, placed so that no point lies on a 0.02 m or
// 0.05 m voxel boundary. 120 x 120 = 14400 points; at 0.02 m every voxel of
// the 30 x 30 grid holds 4 x 4 points.
#pragma once

#include <functional>
#include <vector>

#include "sogmm/camera.hpp"
#include "sogmm/point_cloud.hpp"

namespace sogmm::bench::test {

inline constexpr int kSide = 120;
inline constexpr double kStep = 0.005;
inline constexpr double kZ = 1.01;

inline PointCloud plane_cloud(const std::function<float(double x, double y)>& gray) {
  PointCloud c;
  for (int j = 0; j < kSide; ++j)
    for (int i = 0; i < kSide; ++i) {
      const double x = -0.2975 + kStep * i, y = -0.2975 + kStep * j;
      c.xyzg.insert(c.xyzg.end(), {static_cast<float>(x), static_cast<float>(y), static_cast<float>(kZ), gray(x, y)});
    }
  return c;
}

/// A 128x96 camera that sees the whole plane (decimated PrimeSense).
inline Camera plane_camera() { return Camera{128, 96, 105.0, 105.0, 63.9, 47.9}; }

}  // namespace sogmm::bench::test
