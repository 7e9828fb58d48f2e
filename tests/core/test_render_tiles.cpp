// The renderer's tiles (core/src/render_tiles.hpp) against brute force: every
// component whose ellipsoid a pixel's ray meets at positive depth (the test
// render.cpp applies, from the public ray_components) is in that pixel's
// tile list, in ascending order; components wholly behind the camera or off
// the image are culled. Completeness and order are what make the tiled
// render bitwise the render that tests every component.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>

#include "render_tiles.hpp"
#include "sogmm/render.hpp"

namespace {

// A seeded scene of `m` components: thin random discs in front of the
// camera, some far off to the side, some behind it, some across z = 0.
sogmm::Gmm random_scene(std::size_t m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  sogmm::Gmm g;
  g.resize(m);
  for (std::size_t k = 0; k < m; ++k) {
    const Eigen::Matrix3d R =
        Eigen::Quaterniond(Eigen::Vector4d(u(rng), u(rng), u(rng), u(rng)).normalized()).toRotationMatrix();
    const Eigen::Vector3d s(0.02 + 0.1 * std::abs(u(rng)), 0.02 + 0.1 * std::abs(u(rng)), 0.003);
    Eigen::Matrix4d cov = Eigen::Matrix4d::Zero();
    cov.topLeftCorner<3, 3>() = R * s.cwiseProduct(s).asDiagonal() * R.transpose();
    cov(3, 3) = 0.01;
    const double z = k % 7 == 0 ? 0.05 * u(rng) : k % 11 == 0 ? -1.0 + 0.5 * u(rng) : 1.5 + u(rng);
    const double spread = k % 5 == 0 ? 6.0 : 1.0;  // every 5th far off to the side
    const Eigen::Vector4d mu(spread * u(rng), spread * u(rng), z, 0.5);
    g.weights[k] = static_cast<float>(1.0 / m);
    for (int i = 0; i < 4; ++i) g.means[4 * k + i] = static_cast<float>(mu(i));
    for (int i = 0; i < 16; ++i) g.covariances[16 * k + i] = static_cast<float>(cov(i / 4, i % 4));
  }
  return g;
}

TEST(RenderTiles, EveryComponentARayMeetsIsInItsTileInAscendingOrder) {
  const sogmm::Gmm g = random_scene(300, 7);
  const sogmm::Camera cam{64, 48, 50.0, 52.0, 31.5, 23.5};
  const double r2 = 64.0;
  const sogmm::detail::RayTiles tiles = sogmm::detail::ray_tiles(g, cam, r2);
  const std::vector<sogmm::RayComponent> comps = sogmm::ray_components(g);
  std::size_t met = 0, listed = 0;
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) {
      const auto& ids = tiles.at(u, v);
      ASSERT_TRUE(std::is_sorted(ids.begin(), ids.end()));
      listed += ids.size();
      const double d[3] = {(u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0};
      for (std::size_t m = 0; m < comps.size(); ++m) {
        const sogmm::RayComponent& c = comps[m];
        const double a = c.p[0] * d[0] * d[0] + c.p[3] * d[1] * d[1] + c.p[5] * d[2] * d[2] +
                         2 * (c.p[1] * d[0] * d[1] + c.p[2] * d[0] * d[2] + c.p[4] * d[1] * d[2]);
        const double b = c.pm[0] * d[0] + c.pm[1] * d[1] + c.pm[2] * d[2];
        if (c.mpm - b * b / a > r2 || b / a <= 0) continue;
        ++met;
        ASSERT_TRUE(std::binary_search(ids.begin(), ids.end(), static_cast<std::uint32_t>(m)))
            << "component " << m << " meets the ray of pixel (" << u << ", " << v << ") but is not in its tile";
      }
    }
  ASSERT_GT(met, 1000u);  // the scene is not trivially empty
  // The point of the tiles: far fewer tests than every component at every pixel.
  EXPECT_LT(listed, comps.size() * static_cast<std::size_t>(cam.width * cam.height) / 2);
}

TEST(RenderTiles, BehindAndOffImageComponentsAreCulled) {
  sogmm::Gmm g;
  g.resize(2);
  for (std::size_t k = 0; k < 2; ++k) {
    g.weights[k] = 0.5f;
    for (int i = 0; i < 4; ++i) g.covariances[16 * k + 5 * i] = 1e-4f;
  }
  const float behind[4] = {0, 0, -1, 0.5f}, aside[4] = {5, 0, 1, 0.5f};  // 5 m to the side at 1 m depth
  std::copy(behind, behind + 4, g.means.begin());
  std::copy(aside, aside + 4, g.means.begin() + 4);
  const sogmm::Camera cam{32, 32, 30.0, 30.0, 15.5, 15.5};
  const sogmm::detail::RayTiles tiles = sogmm::detail::ray_tiles(g, cam, 64.0);
  for (const auto& ids : tiles.ids) EXPECT_TRUE(ids.empty());
}

}  // namespace
