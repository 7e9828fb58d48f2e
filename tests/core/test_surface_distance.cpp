// Distance to the surface (sogmm/surface_distance.hpp, issue 31) against
// independent truth: the closed form above and beside one flat component's
// disc, a rotated disc against a dense sampling of its rim, the exact search
// of many components against a brute-force minimum over each alone, a fitted
// plane against |z - 2|, threads, and bad input.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "sogmm/map.hpp"
#include "sogmm/surface_distance.hpp"
#include "plane_scene.hpp"
#include "test_util.hpp"

namespace {

void set_component(sogmm::Gmm& g, std::size_t k, double w, const Eigen::Vector3d& mu, const Eigen::Matrix3d& cov) {
  g.weights[k] = static_cast<float>(w);
  for (int i = 0; i < 3; ++i) g.means[4 * k + i] = static_cast<float>(mu(i));
  g.means[4 * k + 3] = 0.5f;
  for (int i = 0; i < 16; ++i) g.covariances[16 * k + i] = 0.0f;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) g.covariances[16 * k + 4 * i + j] = static_cast<float>(cov(i, j));
  g.covariances[16 * k + 15] = 0.01f;
}

struct Result {
  std::vector<double> d, g;
};

Result distance(const sogmm::Gmm& gmm, const std::vector<float>& xyz, int threads = 0) {
  Result r;
  r.d.assign(xyz.size() / 3, -1.0);
  r.g.assign(xyz.size(), 0.0);
  sogmm::surface_distance(gmm, xyz.data(), r.d.size(), r.d.data(), r.g.data(), {}, threads);
  return r;
}

// The distance to a disc (centre mu, unit axes e1, e2, semi-axes a, b) by a
// dense sampling of the filled ellipse: an independent reference.
double sampled_distance(const Eigen::Vector3d& x, const Eigen::Vector3d& mu, const Eigen::Vector3d& e1,
                        const Eigen::Vector3d& e2, double a, double b) {
  double best = std::numeric_limits<double>::infinity();
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const double t = 2 * M_PI * i / n;
    for (double r : {1.0}) best = std::min(best, (x - mu - r * a * std::cos(t) * e1 - r * b * std::sin(t) * e2).norm());
  }
  // Inside the rim: the normal offset when the projection falls in the disc.
  const Eigen::Vector3d q = x - mu;
  const double s = q.dot(e1) / a, t = q.dot(e2) / b;
  if (s * s + t * t <= 1) best = std::min(best, std::abs(q.dot(e1.cross(e2))));
  return best;
}

TEST(SurfaceDistance, OneFlatComponentClosedForm) {
  sogmm::Gmm g;
  g.resize(1);
  set_component(g, 0, 1.0, Eigen::Vector3d::Zero(), Eigen::Vector3d(0.1 * 0.1, 0.05 * 0.05, 0.001 * 0.001).asDiagonal());
  // Disc: semi-axes 0.2 (x) and 0.1 (y) at the default 2 sigma, normal z.
  const std::vector<float> xyz = {0.02f, 0.01f, 0.3f, 0.5f, 0.0f, 0.1f, 0.0f, -0.4f, -0.2f, 0.0f, 0.0f, 0.0f};
  const Result r = distance(g, xyz);
  EXPECT_NEAR(r.d[0], 0.3, 1e-6);
  EXPECT_NEAR(r.g[2], 1.0, 1e-9);
  EXPECT_NEAR(r.d[1], std::hypot(0.3, 0.1), 1e-6);  // nearest: the rim point (0.2, 0, 0)
  EXPECT_NEAR(r.g[3], 0.3 / std::hypot(0.3, 0.1), 1e-6);
  EXPECT_NEAR(r.g[5], 0.1 / std::hypot(0.3, 0.1), 1e-6);
  EXPECT_NEAR(r.d[2], std::hypot(0.3, 0.2), 1e-6);  // rim point (0, -0.1, 0)
  EXPECT_NEAR(r.g[7], -0.3 / std::hypot(0.3, 0.2), 1e-6);
  EXPECT_NEAR(r.d[3], 0.0, 1e-12);
  EXPECT_NEAR(std::abs(r.g[11]), 1.0, 1e-9);  // on the disc: its normal
}

TEST(SurfaceDistance, RotatedDiscAgainstASampledRim) {
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitX()) *
                             Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitZ()))
                                .toRotationMatrix();
  const Eigen::Vector3d mu(0.3, -0.2, 1.5), sd(0.08, 0.03, 0.002);
  sogmm::Gmm g;
  g.resize(1);
  set_component(g, 0, 1.0, mu, R * sd.cwiseProduct(sd).asDiagonal() * R.transpose());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.4, 0.4);
  std::vector<float> xyz;
  for (int i = 0; i < 200; ++i)
    for (int k = 0; k < 3; ++k) xyz.push_back(static_cast<float>(mu(k) + u(rng)));
  const Result r = distance(g, xyz);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d x(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    const double ref = sampled_distance(x, mu, R.col(0), R.col(1), 2 * sd(0), 2 * sd(1));
    // The sampled rim is at most a * (1 - cos(pi / n)) ~ 5e-8 m off.
    EXPECT_NEAR(r.d[i], ref, 2e-5) << "point " << i;  // float32 covariance: a relative 1e-6 of the axes
    // The gradient points from the nearest disc point to x: x - d grad is on the disc.
    const Eigen::Vector3d grad(r.g[3 * i], r.g[3 * i + 1], r.g[3 * i + 2]);
    EXPECT_NEAR(grad.norm(), 1.0, 1e-9);
    const Eigen::Vector3d foot = x - r.d[i] * grad - mu;
    EXPECT_NEAR(foot.dot(R.col(2)), 0.0, 1e-4);
  }
}

TEST(SurfaceDistance, ExactSearchEqualsTheMinimumOverEachComponentAlone) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> pos(-1.0, 1.0), ang(-M_PI, M_PI), sc(0.01, 0.1);
  const std::size_t m = 150;
  sogmm::Gmm g;
  g.resize(m);
  for (std::size_t k = 0; k < m; ++k) {
    const Eigen::Matrix3d R = (Eigen::AngleAxisd(ang(rng), Eigen::Vector3d::UnitX()) *
                               Eigen::AngleAxisd(ang(rng), Eigen::Vector3d::UnitY()))
                                  .toRotationMatrix();
    const Eigen::Vector3d sd(sc(rng), sc(rng), 0.002);
    set_component(g, k, 1.0 / m, Eigen::Vector3d(pos(rng), pos(rng), pos(rng)),
                  R * sd.cwiseProduct(sd).asDiagonal() * R.transpose());
  }
  std::vector<float> xyz;
  for (int i = 0; i < 1000; ++i)
    for (int k = 0; k < 3; ++k) xyz.push_back(static_cast<float>(1.5 * pos(rng)));
  const Result all = distance(g, xyz);
  std::vector<double> brute(1000, std::numeric_limits<double>::infinity());
  for (std::size_t k = 0; k < m; ++k) {
    sogmm::Gmm one;
    one.resize(1);
    one.weights[0] = 1.0f;
    std::copy(g.mean(k), g.mean(k) + 4, one.means.begin());
    std::copy(g.covariance(k), g.covariance(k) + 16, one.covariances.begin());
    const Result r = distance(one, xyz);
    for (int i = 0; i < 1000; ++i) brute[i] = std::min(brute[i], r.d[i]);
  }
  for (int i = 0; i < 1000; ++i) EXPECT_EQ(all.d[i], brute[i]) << "point " << i;
  const Result one_thread = distance(g, xyz, 1);
  EXPECT_EQ(one_thread.d, all.d);
  EXPECT_EQ(one_thread.g, all.g);
}

TEST(SurfaceDistance, FittedPlaneMatchesTheClosedForm) {
  const sogmm::Map map = sogmm_test::plane_map();
  // Points over the middle of the plane (|x|, |y| <= 0.5 m; the plane spans
  // 2.56 x 1.92 m), 2 cm to 50 cm on either side.
  std::vector<float> xyz;
  std::vector<double> truth;
  for (int i = 0; i < 11; ++i)
    for (double dz : {-0.5, -0.2, -0.05, -0.02, 0.02, 0.05, 0.2, 0.5}) {
      xyz.insert(xyz.end(), {static_cast<float>(0.1 * i - 0.5), static_cast<float>(0.04 * i - 0.2),
                             static_cast<float>(2.0 + dz)});
      truth.push_back(std::abs(dz));
    }
  std::vector<double> d(truth.size()), g(3 * truth.size());
  sogmm::surface_distance(map, xyz.data(), truth.size(), d.data(), g.data());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    EXPECT_NEAR(d[i], truth[i], 0.005) << "point " << i;
    const double sign = xyz[3 * i + 2] > 2.0 ? 1.0 : -1.0;
    EXPECT_GT(sign * g[3 * i + 2], std::cos(10 * M_PI / 180)) << "point " << i;  // within 10 degrees of the normal
  }
}

TEST(SurfaceDistance, BadInputIsRefused) {
  sogmm::Gmm g;
  g.resize(1);
  set_component(g, 0, 1.0, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity() * 0.01);
  std::vector<float> xyz = {0, 0, 1, std::numeric_limits<float>::infinity(), 0, 0};
  std::vector<double> d(2, -1.0);
  sogmm_test::expect_error([&] { sogmm::surface_distance(g, xyz.data(), 2, d.data(), nullptr); },
                           sogmm::ErrorCode::InvalidData, {"row 1"}, "an Inf point");
  EXPECT_EQ(d[0], -1.0);
  sogmm::SurfaceDistanceOptions bad;
  bad.disc_sigmas = 0;
  sogmm_test::expect_error([&] { sogmm::surface_distance(g, xyz.data(), 1, d.data(), nullptr, bad); },
                           sogmm::ErrorCode::InvalidArgument, {"disc_sigmas"}, "disc_sigmas 0");
  const sogmm::Gmm empty;
  sogmm_test::expect_error([&] { sogmm::surface_distance(empty, xyz.data(), 1, d.data(), nullptr); },
                           sogmm::ErrorCode::InvalidData, {"no component"}, "an empty model");
  const sogmm::Map empty_map;
  sogmm_test::expect_error([&] { sogmm::surface_distance(empty_map, xyz.data(), 1, d.data(), nullptr); },
                           sogmm::ErrorCode::InvalidData, {"component"}, "an empty map");
}

}  // namespace
