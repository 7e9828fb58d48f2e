// render_expected_surface (tools/sogmm/render.cpp) on a hand-built model with
// two surfaces along the same rays (issue 14 item 9): the rendered depth is
// the first surface a camera would see, not the densest.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include "render.hpp"
#include "sogmm/gmm.hpp"
#include "sogmm/inference.hpp"

namespace {

void set_component(sogmm::Gmm& g, std::size_t k, double w, const Eigen::Vector4d& mu, const Eigen::Vector4d& var) {
  g.weights[k] = static_cast<float>(w);
  for (int i = 0; i < 4; ++i) g.means[4 * k + i] = static_cast<float>(mu(i));
  for (int i = 0; i < 16; ++i) g.covariances[16 * k + i] = i % 5 == 0 ? static_cast<float>(var(i / 5)) : 0.0f;
}

// A small sparse patch at z = 1 m (one component, weight 0.01, gray 0.2) in
// front of a dense wall at z = 2 m (3 x 3 components, weight 0.99, thinner,
// gray 0.9): along the central ray the wall's density peak is about 16x the
// patch's (checked below with score_samples).
sogmm::Gmm two_surfaces() {
  sogmm::Gmm g;
  g.resize(10);
  set_component(g, 0, 0.01, Eigen::Vector4d(0, 0, 1.0, 0.2), Eigen::Vector4d(0.03 * 0.03, 0.03 * 0.03, 0.02 * 0.02, 0.001));
  for (int k = 0; k < 9; ++k)
    set_component(g, 1 + k, 0.99 / 9, Eigen::Vector4d(0.2 * (k % 3) - 0.2, 0.2 * (k / 3) - 0.2, 2.0, 0.9),
                  Eigen::Vector4d(0.1 * 0.1, 0.1 * 0.1, 0.002 * 0.002, 0.001));
  return g;
}

}  // namespace

TEST(RenderExpectedSurface, FirstSurfaceAlongTheRayNotTheDensest) {
  const sogmm::Gmm g = two_surfaces();
  // The densest point of the central ray is on the wall, by a factor > 10.
  const float on_ray[6] = {0, 0, 1.0f, 0, 0, 2.0f};
  double log_p[2];
  sogmm::score_samples(g, on_ray, 2, 3, log_p);
  ASSERT_GT(log_p[1], log_p[0] + std::log(10.0));
  const sogmm::Camera cam{9, 9, 20.0, 20.0, 4.0, 4.0};  // pixel u looks along x / z = (u - 4) / 20
  const sogmm::tools::RenderedView r = sogmm::tools::render_expected_surface(g, cam, 0.1, 3.0, 3.0);
  // Centre pixel: the ray meets the patch at 1 m, then the wall at 2 m.
  const std::size_t centre = 4 * 9 + 4;
  EXPECT_NEAR(r.depth[centre], 1.0, 1e-3);
  EXPECT_NEAR(r.gray[centre], 0.2, 1e-3);
  // Corner pixel: x / z = 0.2, 6.7 sigma beside the patch at 1 m: only the wall.
  const std::size_t corner = 8 * 9 + 8;
  EXPECT_NEAR(r.depth[corner], 2.0, 1e-3);
  EXPECT_NEAR(r.gray[corner], 0.9, 1e-3);
}

TEST(RenderExpectedSurface, RemovingTheFrontSurfaceShowsTheOneBehind) {
  sogmm::Gmm g = two_surfaces();
  g.weights[0] = 0.0f;  // the patch no longer exists (and its peak is no surface)
  for (int k = 1; k < 10; ++k) g.weights[k] = 1.0f / 9.0f;
  const sogmm::Camera cam{9, 9, 20.0, 20.0, 4.0, 4.0};
  const sogmm::tools::RenderedView r = sogmm::tools::render_expected_surface(g, cam, 0.1, 3.0, 3.0);
  EXPECT_NEAR(r.depth[4 * 9 + 4], 2.0, 1e-3);
  EXPECT_NEAR(r.gray[4 * 9 + 4], 0.9, 1e-3);
}
