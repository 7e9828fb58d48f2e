// Hand-made registration scenes shared by the registration tests: planes
// tiled by flat components, rigid poses, and points sampled from a scene.
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <utility>
#include <vector>

#include "sogmm/gmm.hpp"
#include "sogmm/inference.hpp"
#include "test_util.hpp"

namespace sogmm_test {

// Flat components tiling the unit square of each listed plane through the
// origin (0: x = 0, 1: y = 0, 2: z = 0): in-plane sigma 4 cm, normal 3 mm,
// gray varying across the plane.
inline sogmm::Gmm planes(std::initializer_list<int> normals, Eigen::Vector3d shift = Eigen::Vector3d::Zero()) {
  std::vector<std::pair<Eigen::Vector4d, Eigen::Matrix4d>> comps;
  for (int axis : normals)
    for (int a = 0; a < 10; ++a)
      for (int b = 0; b < 10; ++b) {
        Eigen::Vector4d mu = Eigen::Vector4d::Zero();
        Eigen::Matrix4d cov = Eigen::Matrix4d::Zero();
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        mu(u) = 0.05 + 0.1 * a;
        mu(v) = 0.05 + 0.1 * b;
        mu.head<3>() += shift;
        mu(3) = 0.2 + 0.06 * a + 0.01 * b;
        cov(u, u) = cov(v, v) = 0.04 * 0.04;
        cov(axis, axis) = 0.003 * 0.003;
        cov(3, 3) = 0.01 * 0.01;
        comps.emplace_back(mu, cov);
      }
  sogmm::Gmm g;
  g.resize(comps.size());
  for (std::size_t k = 0; k < comps.size(); ++k)
    sogmm_test::set_component(g, k, 1.0 / double(comps.size()), comps[k].first, comps[k].second);
  g.support_size = 1;
  return g;
}

// The pose rotating by `deg` about `axis` and then translating by `t`.
inline Eigen::Matrix4d rigid(double deg, Eigen::Vector3d axis, Eigen::Vector3d t) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = Eigen::AngleAxisd(deg * M_PI / 180, axis.normalized()).toRotationMatrix();
  m.topRightCorner<3, 1>() = t;
  return m;
}

// `n` points of `g` (sampled with `seed`), moved by `move`: rows x, y, z, gray.
inline std::vector<float> samples(const sogmm::Gmm& g, std::size_t n, const Eigen::Matrix4d& move,
                                  std::uint64_t seed = 7) {
  std::vector<float> pts(4 * n);
  sogmm::sample(g, n, seed, 4, pts.data());
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector4d y = move * Eigen::Vector4d(pts[4 * i], pts[4 * i + 1], pts[4 * i + 2], 1.0);
    for (int k = 0; k < 3; ++k) pts[4 * i + k] = static_cast<float>(y(k));
  }
  return pts;
}

}  // namespace sogmm_test
