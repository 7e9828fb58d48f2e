// The one rigid-pose check (kPoseTolerance) shared by the C API, the core
// transform, the .sogmm writer and reader, and the tools.
#include <cmath>
#include <string>

#include "sogmm/checked.hpp"
#include "sogmm/model.hpp"

namespace sogmm {

std::string rigid_pose_error(const std::array<double, 16>& p) {
  for (int i = 0; i < 16; ++i) {
    if (!std::isfinite(p[i])) {
      return "entry " + std::to_string(i) + " (row " + std::to_string(i / 4) + ", column " + std::to_string(i % 4) +
             ") is " + checked::exact(p[i]) + ", not finite";
    }
  }
  // Exactly (0, 0, 0, 1): a rigid transform's last row is not a measurement,
  // and products of rigid transforms keep it exact.
  if (p[12] != 0.0 || p[13] != 0.0 || p[14] != 0.0 || p[15] != 1.0) {
    return "last row is (" + checked::exact(p[12]) + ", " + checked::exact(p[13]) + ", " + checked::exact(p[14]) +
           ", " + checked::exact(p[15]) + "), not (0, 0, 0, 1)";
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      double dot = 0.0;
      for (int k = 0; k < 3; ++k) dot += p[k * 4 + i] * p[k * 4 + j];
      const double expected = i == j ? 1.0 : 0.0;
      if (!(std::fabs(dot - expected) <= kPoseTolerance)) {
        return "rotation block is not orthonormal: (R^T R)[" + std::to_string(i) + "][" + std::to_string(j) +
               "] = " + checked::exact(dot) + ", more than " + checked::exact(kPoseTolerance) + " from " +
               (i == j ? "1" : "0");
      }
    }
  }
  const double det = p[0] * (p[5] * p[10] - p[6] * p[9]) - p[1] * (p[4] * p[10] - p[6] * p[8]) +
                     p[2] * (p[4] * p[9] - p[5] * p[8]);
  if (!(det > 0.0)) return "rotation block has determinant " + checked::exact(det) + " (a reflection), not 1";
  return {};
}

std::array<double, 16> compose_poses(const std::array<double, 16>& a, const std::array<double, 16>& b) {
  std::array<double, 16> c{};
  for (int r = 0; r < 4; ++r)
    for (int k = 0; k < 4; ++k) {
      double v = 0.0;
      for (int j = 0; j < 4; ++j) v += a[4 * r + j] * b[4 * j + k];
      c[4 * r + k] = v;
    }
  return c;
}

std::array<double, 16> inverse_rigid(const std::array<double, 16>& p) {
  std::array<double, 16> q{};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) q[4 * r + c] = p[4 * c + r];
    q[4 * r + 3] = -(p[r] * p[3] + p[4 + r] * p[7] + p[8 + r] * p[11]);
  }
  q[15] = 1.0;
  return q;
}

}  // namespace sogmm
