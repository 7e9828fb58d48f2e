// The component index (sogmm/component_index.hpp): 100 % recall against
// brute force for every component within Mahalanobis distance 3, through
// build, add and update, and the exact box semantics of its queries.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

#include "sogmm/component_index.hpp"
#include "test_util.hpp"

namespace {
using namespace sogmm_test;

using sogmm::Box3;
using sogmm::ComponentIndex;
using sogmm::Gmm;

// A random rotation (QR of a Gaussian matrix, sign-fixed to det +1).
Eigen::Matrix3d random_rotation(TestRng& rng) {
  Eigen::Matrix3d a;
  for (int i = 0; i < 9; ++i) a(i / 3, i % 3) = rng.normal();
  Eigen::HouseholderQR<Eigen::Matrix3d> qr(a);
  Eigen::Matrix3d q = qr.householderQ();
  if (q.determinant() < 0) q.col(0) *= -1.0;
  return q;
}

// m components in a 4 m cube, each rotated and anisotropic (axis sigmas from
// 1 mm to 10 cm, a few up to 1 m so that the index's wide-box list is used).
Gmm random_components(std::size_t m, std::uint64_t seed) {
  TestRng rng(seed);
  Gmm g;
  g.resize(m);
  for (std::size_t k = 0; k < m; ++k) {
    const Eigen::Matrix3d r = random_rotation(rng);
    Eigen::Vector3d s;
    for (int i = 0; i < 3; ++i) s[i] = std::exp(std::log(0.001) + rng.uniform() * std::log(100.0));
    if (k % 97 == 0) s[0] = 1.0;
    const Eigen::Matrix3d c3 = r * s.cwiseAbs2().asDiagonal() * r.transpose();
    Eigen::Matrix4d c = Eigen::Matrix4d::Zero();
    c.topLeftCorner<3, 3>() = c3;
    c(3, 3) = 0.01;
    Eigen::Vector4d mu(4 * rng.uniform() - 2, 4 * rng.uniform() - 2, 4 * rng.uniform() - 2, rng.uniform());
    set_component(g, k, 1.0 / m, mu, c);
  }
  g.support_size = m;
  return g;
}

// Mahalanobis distance of x from component k's 3-D marginal, in double from
// the float32 model (the index's exact claim).
double mahalanobis(const Gmm& g, std::size_t k, const Eigen::Vector3d& x) {
  const Eigen::Matrix3d c = cov_of(g, k).topLeftCorner<3, 3>();
  const Eigen::Vector3d d = x - mean_of(g, k).head<3>();
  return std::sqrt(d.dot(c.ldlt().solve(d)));
}

// The inverses of every component's Sigma_xx, for the brute-force loops.
std::vector<Eigen::Matrix3d> inverses(const Gmm& g) {
  std::vector<Eigen::Matrix3d> out(g.size());
  for (std::size_t k = 0; k < g.size(); ++k) out[k] = cov_of(g, k).topLeftCorner<3, 3>().inverse();
  return out;
}

// Query points: half near component centres (inside and around their
// ellipsoids), half uniform in the cube.
std::vector<Eigen::Vector3d> query_points(const Gmm& g, std::size_t n, std::uint64_t seed) {
  TestRng rng(seed);
  std::vector<Eigen::Vector3d> pts;
  for (std::size_t i = 0; i < n; ++i) {
    if (i % 2 == 0) {
      const std::size_t k = rng.next() % g.size();
      const Eigen::Matrix3d l = cov_of(g, k).topLeftCorner<3, 3>().llt().matrixL();
      const Eigen::Vector3d z(rng.normal(), rng.normal(), rng.normal());
      pts.push_back(mean_of(g, k).head<3>() + 1.5 * (l * z));
    } else {
      pts.emplace_back(4 * rng.uniform() - 2, 4 * rng.uniform() - 2, 4 * rng.uniform() - 2);
    }
  }
  return pts;
}

// Checks every query point: the result is ascending and exactly the set of
// boxes holding the point, and holds every component within distance 3.
void expect_full_recall(const ComponentIndex& index, const Gmm& g, const std::vector<Eigen::Vector3d>& pts,
                        std::size_t* within3_total) {
  std::vector<std::uint32_t> got;
  const std::vector<Eigen::Matrix3d> inv = inverses(g);
  std::vector<Box3> box(g.size());
  for (std::size_t k = 0; k < g.size(); ++k) box[k] = sogmm::component_box(g, k, 3.0);
  for (const Eigen::Vector3d& x : pts) {
    const double p[3] = {x[0], x[1], x[2]};
    index.query_point(p, got);
    ASSERT_TRUE(std::is_sorted(got.begin(), got.end()));
    std::vector<std::uint32_t> boxes;
    for (std::size_t k = 0; k < g.size(); ++k) {
      if (box[k].contains(p)) boxes.push_back(static_cast<std::uint32_t>(k));
      const Eigen::Vector3d d = x - mean_of(g, k).head<3>();
      // Slightly inside 3 (1e-9 relative) so the inverse's rounding cannot
      // turn a point on the ellipsoid into a false alarm.
      if (d.dot(inv[k] * d) <= 9.0 * (1 - 1e-9)) {
        ++*within3_total;
        ASSERT_TRUE(std::binary_search(got.begin(), got.end(), k))
            << "component " << k << " at Mahalanobis distance " << mahalanobis(g, k, x) << " missed";
      }
    }
    ASSERT_EQ(got, boxes);
  }
}

TEST(ComponentIndexTest, RecallAgainstBruteForceWithinMahalanobis3) {
  const Gmm g = random_components(3000, 7);
  ComponentIndex index;
  index.build(g);
  ASSERT_EQ(index.size(), g.size());
  std::size_t within = 0;
  expect_full_recall(index, g, query_points(g, 4000, 11), &within);
  EXPECT_GT(within, 1500u);  // the test exercised many in-ellipsoid pairs
}

TEST(ComponentIndexTest, BoxBoundsTheEllipsoidExactly) {
  // A point on the 3-sigma ellipsoid at its extreme along x lies on the box
  // face: the half-width r sqrt(Sigma_xx) is attained, not just an upper bound.
  const Gmm g = random_components(50, 3);
  for (std::size_t k = 0; k < g.size(); ++k) {
    const Eigen::Matrix3d c = cov_of(g, k).topLeftCorner<3, 3>();
    for (int axis = 0; axis < 3; ++axis) {
      const Eigen::Vector3d d = 3.0 * c.col(axis) / std::sqrt(c(axis, axis));  // argmax of e_axis^T x
      EXPECT_NEAR(d.dot(c.ldlt().solve(d)), 9.0, 1e-6);
      const Box3 b = sogmm::component_box(g, k, 3.0);
      const double mu = mean_of(g, k)[axis];
      EXPECT_NEAR(b.hi[axis] - mu, d[axis], 1e-5 * (1 + std::fabs(mu)));
      EXPECT_NEAR(mu - b.lo[axis], d[axis], 1e-5 * (1 + std::fabs(mu)));
    }
  }
}

TEST(ComponentIndexTest, RecallAfterAddAndUpdate) {
  Gmm g = random_components(2400, 21);
  Gmm first = g;
  first.resize(1000);
  ComponentIndex index;
  index.build(first);
  index.add(g, 1000);  // more than doubles: rebuilds
  // Move and reshape some components, then re-key them.
  TestRng rng(5);
  for (std::size_t k = 0; k < g.size(); k += 7) {
    Eigen::Vector4d mu = mean_of(g, k);
    mu.head<3>() += Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal()) * 0.3;
    set_component(g, k, g.weights[k], mu, cov_of(g, k) * (0.25 + rng.uniform() * 4));
    index.update(g, k);
  }
  std::size_t within = 0;
  expect_full_recall(index, g, query_points(g, 2000, 13), &within);
  EXPECT_GT(within, 700u);
}

TEST(ComponentIndexTest, IncrementalAddMatchesBuild) {
  const Gmm g = random_components(1200, 31);
  ComponentIndex built, grown;
  built.build(g);
  for (std::size_t m = 100; m <= g.size(); m += 100) {
    Gmm part = g;
    part.resize(m);
    grown.add(part, grown.size());
  }
  std::vector<std::uint32_t> a, b;
  for (const Eigen::Vector3d& x : query_points(g, 2000, 17)) {
    const double p[3] = {x[0], x[1], x[2]};
    built.query_point(p, a);
    grown.query_point(p, b);
    ASSERT_EQ(a, b);
  }
}

TEST(ComponentIndexTest, BoxQueryRecall) {
  const Gmm g = random_components(2000, 41);
  ComponentIndex index;
  index.build(g);
  TestRng rng(43);
  std::vector<std::uint32_t> got;
  for (int q = 0; q < 300; ++q) {
    Box3 box;
    for (int i = 0; i < 3; ++i) {
      const double c = 4 * rng.uniform() - 2, h = q % 10 == 0 ? 2.0 * rng.uniform() : 0.1 * rng.uniform();
      box.lo[i] = c - h;
      box.hi[i] = c + h;
    }
    index.query_box(box, got);
    std::vector<std::uint32_t> brute;
    for (std::size_t k = 0; k < g.size(); ++k)
      if (sogmm::component_box(g, k, 3.0).intersects(box)) brute.push_back(static_cast<std::uint32_t>(k));
    ASSERT_EQ(got, brute) << "query " << q;
  }
}

TEST(ComponentIndexTest, FarAndNonFinitePointsAreSafe) {
  const Gmm g = random_components(200, 51);
  ComponentIndex index;
  index.build(g);
  std::vector<std::uint32_t> got;
  const double far[3] = {1e30, -1e30, 1e300};
  index.query_point(far, got);
  EXPECT_TRUE(got.empty());
  const double nan[3] = {std::nan(""), 0, 0};
  index.query_point(nan, got);
  EXPECT_TRUE(got.empty());
  expect_error([] { ComponentIndex bad(0.0); }, sogmm::ErrorCode::InvalidArgument, {"radius"}, "sigmas 0");
  expect_error([] { ComponentIndex bad(std::nan("")); }, sogmm::ErrorCode::InvalidArgument, {"radius"}, "sigmas NaN");
}

}  // namespace
