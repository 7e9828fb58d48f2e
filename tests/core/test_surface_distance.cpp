// Distance to the surface (sogmm/surface_distance.hpp, issue 31) against
// independent truth: the closed form above and beside one flat component's
// disc, a rotated disc against a dense sampling of its rim, the exact search
// of many components against a brute-force minimum over each alone, a fitted
// plane against |z - 2|, threads, and bad input; the tree search bit for
// bit against the brute-force answer (the nearest of each component alone,
// the lowest id among equal distances) on random discs and a room of tiles.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <utility>
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

// The brute-force answer: each component alone gives its distance and
// gradient; the nearest wins, the lowest id among equal distances.
Result alone(const sogmm::Gmm& g, std::size_t k, const std::vector<float>& xyz) {
  sogmm::Gmm one;
  one.resize(1);
  one.weights[0] = 1.0f;
  std::copy(g.mean(k), g.mean(k) + 4, one.means.begin());
  std::copy(g.covariance(k), g.covariance(k) + 16, one.covariances.begin());
  return distance(one, xyz, 1);
}

// The face rule's tolerance (surface_distance.hpp): a face at most this much
// farther than the nearest disc gives the gradient when that disc's nearest
// point is on its rim.
constexpr double kFaceTolerance = 0.015;

// Whether component k alone answers x from its face: its gradient is its
// normal (the smallest principal axis), not tilted towards a rim point.
bool from_face(const sogmm::Gmm& g, std::size_t k, const double* grad) {
  Eigen::Matrix3d cov;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) cov(i, j) = g.covariance(k)[4 * i + j];
  const Eigen::Vector3d n = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
  return std::abs(n.dot(Eigen::Vector3d(grad[0], grad[1], grad[2]))) > 1.0 - 1e-12;
}

Result brute_force(const sogmm::Gmm& g, const std::vector<float>& xyz) {
  const std::size_t n = xyz.size() / 3;
  std::vector<Result> each;
  for (std::size_t k = 0; k < g.size(); ++k) each.push_back(alone(g, k, xyz));
  Result best;
  best.d.assign(n, std::numeric_limits<double>::infinity());
  best.g.assign(3 * n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t win = 0;
    for (std::size_t k = 0; k < g.size(); ++k)
      if (each[k].d[i] < best.d[i]) {  // strict: an equal distance keeps the lower id
        best.d[i] = each[k].d[i];
        win = k;
      }
    std::size_t grad_of = win;
    if (!from_face(g, win, &each[win].g[3 * i])) {  // a rim: the nearest face within the tolerance, if any
      double face = best.d[i] + kFaceTolerance;
      bool found = false;
      for (std::size_t k = 0; k < g.size(); ++k)
        if ((found ? each[k].d[i] < face : each[k].d[i] <= face) && from_face(g, k, &each[k].g[3 * i])) {
          face = each[k].d[i];
          grad_of = k;
          found = true;
        }
    }
    std::copy(each[grad_of].g.begin() + 3 * i, each[grad_of].g.begin() + 3 * i + 3, best.g.begin() + 3 * i);
  }
  return best;
}

void expect_bitwise(const Result& got, const Result& want, const char* what) {
  std::size_t differ = 0;
  for (std::size_t i = 0; i < want.d.size(); ++i) {
    const bool same = got.d[i] == want.d[i] && got.g[3 * i] == want.g[3 * i] && got.g[3 * i + 1] == want.g[3 * i + 1] &&
                      got.g[3 * i + 2] == want.g[3 * i + 2];
    if (!same && ++differ <= 5)
      ADD_FAILURE() << what << ": point " << i << " distance " << got.d[i] << " against " << want.d[i];
  }
  EXPECT_EQ(differ, 0u) << what;
}

// Flat tiles (axis-aligned squares of side 2 * tile, as a fitted wall's
// components are) covering the floor, the ceiling and four walls of a
// w x w x h room.
sogmm::Gmm tiled_room(double w, double h, double tile) {
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> patches;  // centre, sd per axis
  const double thin = 0.002, sd = tile / 2;                           // 2 sigma = the half side
  for (double u = tile; u < w; u += 2 * tile)
    for (double v = tile; v < w; v += 2 * tile) {
      patches.push_back({{u, v, 0.0}, {sd, sd, thin}});
      patches.push_back({{u, v, h}, {sd, sd, thin}});
    }
  for (double u = tile; u < w; u += 2 * tile)
    for (double v = tile; v < h; v += 2 * tile) {
      patches.push_back({{u, 0.0, v}, {sd, thin, sd}});
      patches.push_back({{u, w, v}, {sd, thin, sd}});
      patches.push_back({{0.0, u, v}, {thin, sd, sd}});
      patches.push_back({{w, u, v}, {thin, sd, sd}});
    }
  sogmm::Gmm g;
  g.resize(patches.size());
  for (std::size_t k = 0; k < patches.size(); ++k)
    set_component(g, k, 1.0 / patches.size(), patches[k].first,
                  patches[k].second.cwiseProduct(patches[k].second).asDiagonal());
  return g;
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

// Round discs of radius r (2 sigma) in the plane z = const or x = const.
void flat_disc(sogmm::Gmm& g, std::size_t k, const Eigen::Vector3d& mu, double r, int normal_axis = 2) {
  Eigen::Vector3d var = Eigen::Vector3d::Constant(0.25 * r * r);
  var(normal_axis) = 1e-6;
  set_component(g, k, 0.5, mu, var.asDiagonal());
}

TEST(SurfaceDistance, AFaceJustBehindARimGivesTheGradient) {
  // A wide floor disc (z = 0, radius 0.5) and a small disc 5 mm above it
  // (centre x = 0.3, radius 0.1). The point (0.19, 0, 0.02) is nearest to
  // the small disc's rim point (0.2, 0, 0.005), at hypot(0.01, 0.015) =
  // 18.0 mm; the floor's face under it is 20 mm away, within the 1.5 cm
  // tolerance: the distance is the rim's, the gradient the floor's normal
  // (the direction from the rim is 33.7 degrees off it). With the floor
  // 3 cm lower (50 mm, beyond the tolerance) the rim's direction stays. The
  // bounds are float32 rounding of the inputs, on every kernel (this path is
  // scalar double code).
  const std::vector<float> x = {0.19f, 0.0f, 0.02f};
  for (const double floor_z : {0.0, -0.03}) {
    sogmm::Gmm g;
    g.resize(2);
    flat_disc(g, 0, {0.3, 0.0, 0.005}, 0.1);
    flat_disc(g, 1, {0.0, 0.0, floor_z}, 0.5);
    const Result r = distance(g, x);
    const double rim = std::hypot(0.01, 0.015);
    EXPECT_NEAR(r.d[0], rim, 1e-6);
    if (floor_z == 0.0) {
      EXPECT_NEAR(r.g[0], 0.0, 1e-9);
      EXPECT_NEAR(r.g[2], 1.0, 1e-9) << "the floor's normal";
    } else {
      EXPECT_NEAR(r.g[0], -0.01 / rim, 1e-5) << "the rim's direction";
      EXPECT_NEAR(r.g[2], 0.015 / rim, 1e-5);
    }
    EXPECT_NEAR(r.g[1], 0.0, 1e-9);
  }
}

TEST(SurfaceDistance, AGapBetweenCoplanarDiscsKeepsTheRimDirection) {
  // Two discs in z = 0 with a 20 cm gap (x < -0.1 and x > 0.1). Over the
  // gap no face lies under the point, so the gradient stays the direction
  // from the nearest rim point (-0.1, 0, 0): (0.02, 0, 0.03) / |.|. A rule
  // that took the nearest plane's normal regardless of its rim would give
  // (0, 0, 1), 33.7 degrees off. Over a disc, its normal.
  sogmm::Gmm g;
  g.resize(2);
  flat_disc(g, 0, {-0.3, 0.0, 0.0}, 0.2);
  flat_disc(g, 1, {0.3, 0.0, 0.0}, 0.2);
  const Result r = distance(g, {-0.08f, 0.0f, 0.03f, 0.15f, 0.0f, -0.01f});
  const double rim = std::hypot(0.02, 0.03);
  EXPECT_NEAR(r.d[0], rim, 1e-6);
  EXPECT_NEAR(r.g[0], 0.02 / rim, 1e-5);
  EXPECT_NEAR(r.g[2], 0.03 / rim, 1e-5);
  EXPECT_NEAR(r.d[1], 0.01, 1e-6);
  EXPECT_NEAR(r.g[5], -1.0, 1e-9);
}

TEST(SurfaceDistance, PerpendicularDiscsAtACorner) {
  // A floor (z = 0, radius 0.5) and a wall (x = 0.3, centre height 0.25,
  // radius 0.2: it ends 5 cm above the floor). (0.29, 0, 0.035): the wall's
  // lower rim (0.3, 0, 0.05) is hypot(0.01, 0.015) = 18.0 mm away, the
  // floor's face 35 mm (beyond the tolerance): the rim's direction.
  // (0.29, 0, 0.025): the rim is 27 mm away, the floor 25 mm: the floor's
  // normal. (0.28, 0, 0.2): over the wall's face, 2 cm: -x.
  sogmm::Gmm g;
  g.resize(2);
  flat_disc(g, 0, {0.0, 0.0, 0.0}, 0.5);
  flat_disc(g, 1, {0.3, 0.0, 0.25}, 0.2, 0);
  const Result r = distance(g, {0.29f, 0.0f, 0.035f, 0.29f, 0.0f, 0.025f, 0.28f, 0.0f, 0.2f});
  const double rim = std::hypot(0.01, 0.015);
  EXPECT_NEAR(r.d[0], rim, 1e-6);
  EXPECT_NEAR(r.g[0], -0.01 / rim, 1e-5);
  EXPECT_NEAR(r.g[2], -0.015 / rim, 1e-5);
  EXPECT_NEAR(r.d[1], 0.025, 1e-6);
  EXPECT_NEAR(r.g[5], 1.0, 1e-9);
  EXPECT_NEAR(r.d[2], 0.02, 1e-6);
  EXPECT_NEAR(r.g[6], -1.0, 1e-9);
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
  // Random discs of every size and direction; points on them, millimetres
  // off them and metres away: distances and gradients bit for bit those of
  // the brute force, on one thread and on two.
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> pos(-2.0, 2.0), ang(-M_PI, M_PI), sc(0.005, 0.2), unit(0.0, 1.0);
  const std::size_t m = 300;
  sogmm::Gmm g;
  g.resize(m);
  for (std::size_t k = 0; k < m; ++k) {
    const Eigen::Matrix3d R = (Eigen::AngleAxisd(ang(rng), Eigen::Vector3d::UnitX()) *
                               Eigen::AngleAxisd(ang(rng), Eigen::Vector3d::UnitY()))
                                  .toRotationMatrix();
    const Eigen::Vector3d sd(sc(rng), sc(rng), 0.001 + 0.004 * unit(rng));
    set_component(g, k, 1.0 / m, Eigen::Vector3d(pos(rng), pos(rng), 0.3 * pos(rng)),
                  R * sd.cwiseProduct(sd).asDiagonal() * R.transpose());
  }
  std::vector<float> xyz;
  for (int i = 0; i < 900; ++i) {
    const double spread = i % 3 == 0 ? 4.0 : 1.0;  // a third far outside the discs' slab
    for (int k = 0; k < 3; ++k) xyz.push_back(static_cast<float>(spread * pos(rng)));
  }
  for (std::size_t k = 0; k < m; k += 2)  // near the centres: on or just off the surface
    for (int i = 0; i < 3; ++i) xyz.push_back(static_cast<float>(g.mean(k)[i] + 0.003 * (unit(rng) - 0.5)));
  const Result want = brute_force(g, xyz);
  expect_bitwise(distance(g, xyz), want, "two threads");
  expect_bitwise(distance(g, xyz, 1), want, "one thread");
}

TEST(SurfaceDistance, RoomOfTilesIsTheBruteForceAnswerBitwise) {
  // A loop-like scene: a 4 x 4 x 2.5 m room of flat tiles that meet edge to
  // edge, asked on the rays of cameras inside it at 20, 50, 80% and 100% of
  // the depth and 5 cm before it, as the occupancy benchmark asks. Points
  // above a seam are equally far from two tiles: the lower id's gradient.
  const double w = 4.0, h = 2.5;
  const sogmm::Gmm g = tiled_room(w, h, 0.25);
  ASSERT_GT(g.size(), 200u);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<float> xyz;
  for (int ray = 0; ray < 200; ++ray) {
    const Eigen::Vector3d eye(1.0 + 2.0 * unit(rng), 1.0 + 2.0 * unit(rng), 0.8 + 0.9 * unit(rng));
    Eigen::Vector3d dir(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5);
    dir.normalize();
    double depth = std::numeric_limits<double>::infinity();  // to the room's box
    for (int k = 0; k < 3; ++k) {
      const double top = k == 2 ? h : w;
      if (dir(k) > 0) depth = std::min(depth, (top - eye(k)) / dir(k));
      if (dir(k) < 0) depth = std::min(depth, -eye(k) / dir(k));
    }
    for (double along : {0.2 * depth, 0.5 * depth, 0.8 * depth, depth, depth - 0.05}) {
      const Eigen::Vector3d x = eye + along * dir;
      for (int k = 0; k < 3; ++k) xyz.push_back(static_cast<float>(x(k)));
    }
  }
  for (double u : {0.4, 1.2, 2.0}) xyz.insert(xyz.end(), {static_cast<float>(u), 1.0f, 1.0f});  // above seams
  const Result want = brute_force(g, xyz);
  expect_bitwise(distance(g, xyz), want, "two threads");
  expect_bitwise(distance(g, xyz, 1), want, "one thread");
}

TEST(SurfaceDistance, EqualDistancesGoToTheLowestId) {
  // Two equal discs at z = +1 and z = -1 among others: a point at the
  // origin is 1 from both, and its gradient is the one of the lower id
  // (pointing away from that disc), whichever the tree visits first.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> pos(3.0, 6.0);
  const std::size_t m = 200;
  for (const auto& [upper, lower] : {std::pair<std::size_t, std::size_t>{7, 150}, {150, 7}}) {
    sogmm::Gmm g;
    g.resize(m);
    const Eigen::Matrix3d flat = Eigen::Vector3d(0.01, 0.01, 1e-6).asDiagonal();
    for (std::size_t k = 0; k < m; ++k) set_component(g, k, 1.0 / m, Eigen::Vector3d(pos(rng), pos(rng), pos(rng)), flat);
    set_component(g, upper, 1.0 / m, Eigen::Vector3d(0, 0, 1), flat);
    set_component(g, lower, 1.0 / m, Eigen::Vector3d(0, 0, -1), flat);
    const std::vector<float> origin = {0.0f, 0.0f, 0.0f};
    ASSERT_EQ(alone(g, upper, origin).d[0], alone(g, lower, origin).d[0]) << "the two discs tie";
    const Result r = distance(g, origin);
    EXPECT_DOUBLE_EQ(r.d[0], 1.0);
    EXPECT_EQ(r.g[2], upper < lower ? -1.0 : 1.0) << "disc " << std::min(upper, lower) << " is the answer";
  }
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
