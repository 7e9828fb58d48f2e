// Collision probability of ellipsoidal robots (sogmm/collision.hpp, issue
// 31) against independent truth: a sphere and an ellipsoid above one flat
// component in closed form (Phi(-clearance / sigma)), monotone in distance,
// >= 0.99 overlapping and <= 0.01 more than 3 sigma clear, a fitted plane,
// and bad shapes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "sogmm/collision.hpp"
#include "sogmm/map.hpp"
#include "plane_scene.hpp"
#include "test_util.hpp"

namespace {

double phi(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// One flat component at the origin: standard deviations 0.1, 0.08 (disc of
// semi-axes 0.2, 0.16) and sigma = 0.005 along z.
sogmm::Gmm flat_component() {
  sogmm::Gmm g;
  g.resize(1);
  g.weights[0] = 1.0f;
  for (int i = 0; i < 4; ++i) g.means[i] = 0.0f;
  for (float& c : g.covariances) c = 0.0f;
  g.covariances[0] = 0.01f;
  g.covariances[5] = 0.0064f;
  g.covariances[10] = 0.000025f;
  g.covariances[15] = 0.01f;
  return g;
}

std::vector<double> probabilities(const sogmm::Gmm& g, const std::vector<double>& centers, const std::vector<double>& shape) {
  const std::size_t n = centers.size() / 3;
  std::vector<double> shapes, out(n, -1.0);
  for (std::size_t i = 0; i < n; ++i) shapes.insert(shapes.end(), shape.begin(), shape.end());
  sogmm::collision_probability(g, centers.data(), shapes.data(), n, out.data());
  return out;
}

TEST(Collision, SphereAndEllipsoidAboveADiscClosedForm) {
  const sogmm::Gmm g = flat_component();
  const double sigma = 0.005;
  const std::vector<double> heights = {0.0, 0.05, 0.09, 0.1, 0.105, 0.11, 0.115, 0.13, 0.2};
  std::vector<double> centers;
  for (double h : heights) centers.insert(centers.end(), {0.03, -0.02, h});
  const std::vector<double> sphere = {0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01};     // radius 0.1
  const std::vector<double> ellipsoid = {0.04, 0, 0, 0, 0.0025, 0, 0, 0, 0.01};  // semi-axes 0.2, 0.05, 0.1
  for (const auto& shape : {sphere, ellipsoid}) {
    const std::vector<double> p = probabilities(g, centers, shape);
    for (std::size_t i = 0; i < heights.size(); ++i) {
      // Above the disc's interior the clearance is h - 0.1 (the z semi-axis).
      EXPECT_NEAR(p[i], phi(-(heights[i] - 0.1) / sigma), 1e-6) << "h = " << heights[i];
      if (i > 0) {
        EXPECT_LE(p[i], p[i - 1]);
      }
    }
    EXPECT_GE(p[0], 0.99);   // the robot's centre on the surface
    EXPECT_NEAR(p[3], 0.5, 1e-6);  // touching
    EXPECT_LE(p[7], 0.01);   // 3 cm = 6 sigma clear
  }
}

TEST(Collision, BesideTheDiscTheRimCounts) {
  // Sphere of radius 0.1 in the disc's plane, its centre 0.35 m along x: the
  // rim is at x = 0.2, clearance 0.05 m -> essentially 0; at 0.29, 0.01 short.
  const sogmm::Gmm g = flat_component();
  const std::vector<double> sphere = {0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01};
  const std::vector<double> p = probabilities(g, {0.35, 0, 0, 0.29, 0, 0}, sphere);
  EXPECT_NEAR(p[0], phi(-0.05 / 0.005), 1e-9);
  EXPECT_NEAR(p[1], phi(0.01 / 0.005), 1e-6);
}

TEST(Collision, FittedPlaneOverlapAndClearance) {
  const sogmm::Map map = sogmm_test::plane_map();
  const std::vector<double> sphere = {0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01};
  std::vector<double> centers;
  for (int i = 0; i <= 10; ++i) centers.insert(centers.end(), {0.1, 0.05, 2.0 - 0.02 * i});
  const std::vector<double> p = probabilities(map.model().gmm, centers, sphere);
  EXPECT_GE(p[0], 0.99);
  for (std::size_t i = 1; i < p.size(); ++i) EXPECT_LE(p[i], p[i - 1] + 1e-12) << i;
  EXPECT_LE(p.back(), 0.01);  // 10 cm clear of a plane fitted to exact depths
}

TEST(Collision, BadShapesAreRefused) {
  const sogmm::Gmm g = flat_component();
  const double c[3] = {0, 0, 1};
  double out = -1.0;
  const double negative[9] = {-0.01, 0, 0, 0, -0.01, 0, 0, 0, -0.01};  // a negative radius
  const double asymmetric[9] = {0.01, 0.005, 0, 0, 0.01, 0, 0, 0, 0.01};
  const double singular[9] = {0.01, 0, 0, 0, 0.01, 0, 0, 0, 0};
  for (const double* s : {negative, asymmetric, singular})
    sogmm_test::expect_error([&] { sogmm::collision_probability(g, c, s, 1, &out); },
                             sogmm::ErrorCode::InvalidArgument, {"robot 0"}, "a bad shape");
  EXPECT_EQ(out, -1.0);
  const double nan_c[3] = {0, std::numeric_limits<double>::quiet_NaN(), 1};
  const double sphere[9] = {0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01};
  sogmm_test::expect_error([&] { sogmm::collision_probability(g, nan_c, sphere, 1, &out); },
                           sogmm::ErrorCode::InvalidData, {"robot 0"}, "a NaN centre");
}

}  // namespace
