// Row-major 4 x 4 poses as Eigen matrices, built from a rotation and a
// translation, and the error of an estimate against the truth.
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

namespace sogmm_test {

inline Eigen::Matrix4d pose_matrix(const std::array<double, 16>& p) {
  Eigen::Matrix4d m;
  for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = p[i];
  return m;
}

/// The pose [r t; 0 1].
inline std::array<double, 16> pose_of(const Eigen::Matrix3d& r, const Eigen::Vector3d& t) {
  std::array<double, 16> p{};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) p[4 * i + j] = r(i, j);
    p[4 * i + 3] = t(i);
  }
  p[15] = 1.0;
  return p;
}

inline std::array<double, 16> pose_array(const Eigen::Matrix4d& m) {
  std::array<double, 16> p;
  for (int i = 0; i < 16; ++i) p[i] = m(i / 4, i % 4);
  return p;
}

/// (translation metres, rotation degrees) of `est` against `truth`.
inline std::pair<double, double> pose_error(const std::array<double, 16>& est, const Eigen::Matrix4d& truth) {
  const Eigen::Matrix4d e = pose_matrix(est);
  const Eigen::Matrix4d d = truth.inverse() * e;
  const double c = std::clamp((d.topLeftCorner<3, 3>().trace() - 1) / 2, -1.0, 1.0);
  return {(e.topRightCorner<3, 1>() - truth.topRightCorner<3, 1>()).norm(), std::acos(c) * 180 / M_PI};
}

}  // namespace sogmm_test
