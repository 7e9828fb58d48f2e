// The registration's candidate cache (core/src/registration_candidates.hpp):
// at every step of seeded random walks its list filtered by an index's box
// test (what the registration's pair kernel does) is exactly that index's
// own query_point answer (the same ids, ascending), for the index it was
// built on and for a finer index whose boxes lie inside it (as a
// registration's later levels use it). No kernel-dispatched code runs: the comparisons are of
// integers from double box tests, identical under sse2, avx2 and avx512.
// Mutations tried: never re-querying a moved point (no margin check), and
// (when the filter was the cache's) filtering by the cache's own boxes
// instead of the finer ones: each fails.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <vector>

#include "registration_candidates.hpp"
#include "sogmm/component_index.hpp"
#include "test_util.hpp"

namespace {
using namespace sogmm_test;

// The cache's list for point i at x, filtered by `boxes`' box test.
std::vector<std::uint32_t> held(sogmm::detail::CandidateCache& cache, std::size_t i, const Eigen::Vector3d& x,
                                const sogmm::ComponentIndex& boxes, std::vector<std::uint32_t>& scratch) {
  std::vector<std::uint32_t> out;
  const double xyz[3] = {x(0), x(1), x(2)};
  for (std::uint32_t id : cache.near(i, x, scratch))
    if (boxes.box(id).contains(xyz)) out.push_back(id);
  return out;
}

// 300 components in a 1 m cube with axis sigmas of 5 mm to 5 cm and a
// random correlation; `extra` is added to each spatial variance (a
// registration level's smoothing s^2).
sogmm::Gmm scene(double extra) {
  TestRng rng(7);
  sogmm::Gmm g;
  const std::size_t m = 300;
  g.resize(m);
  for (std::size_t k = 0; k < m; ++k) {
    Eigen::Matrix3d a;
    for (int i = 0; i < 9; ++i) a(i / 3, i % 3) = 0.005 + 0.045 * rng.uniform();
    Eigen::Matrix4d c = Eigen::Matrix4d::Zero();
    c.topLeftCorner<3, 3>() = a * a.transpose() / 3.0 + (1e-6 + extra) * Eigen::Matrix3d::Identity();
    c(3, 3) = 0.01;
    const Eigen::Vector4d mu(rng.uniform(), rng.uniform(), rng.uniform(), 0.5);
    set_component(g, k, 1.0 / m, mu, c);
  }
  g.support_size = m;
  return g;
}

// Walks 200 points through 60 steps of sizes from 0.1 mm to 4 cm (around
// the 1 cm margin) and checks every answer against `fine`.query_point.
void expect_exact_along_walks(const sogmm::ComponentIndex& coarse, const sogmm::ComponentIndex& fine) {
  TestRng rng(11);
  const std::size_t n = 200;
  sogmm::detail::CandidateCache cache(coarse, n, 0.01);
  std::vector<Eigen::Vector3d> x(n);
  for (auto& p : x) p = Eigen::Vector3d(rng.uniform(), rng.uniform(), rng.uniform());
  std::vector<std::uint32_t> want, scratch;
  std::size_t nonempty = 0;
  for (int step = 0; step < 60; ++step) {
    const double size = 1e-4 * std::pow(400.0, rng.uniform());
    for (std::size_t i = 0; i < n; ++i) {
      x[i] += size * Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal()).normalized();
      const std::vector<std::uint32_t> got = held(cache, i, x[i], fine, scratch);
      const double xyz[3] = {x[i](0), x[i](1), x[i](2)};
      fine.query_point(xyz, want);
      ASSERT_EQ(got, want) << "point " << i << " step " << step;
      nonempty += !want.empty();
    }
  }
  EXPECT_GT(nonempty, n * 60 / 2);  // the walks mostly stay among components
}

TEST(RegistrationCandidates, SameAnswerAsTheIndexAlongRandomWalks) {
  sogmm::ComponentIndex index;
  index.build(scene(0.0));
  expect_exact_along_walks(index, index);
}

TEST(RegistrationCandidates, FinerBoxesFilterTheCoarseList) {
  // The coarse level smooths by 4 cm (variance + 0.0016): boxes hold the fine ones.
  sogmm::ComponentIndex coarse, fine;
  coarse.build(scene(0.0016));
  fine.build(scene(0.0));
  expect_exact_along_walks(coarse, fine);
}

TEST(RegistrationCandidates, NonFinitePointHasNoCandidate) {
  sogmm::ComponentIndex index;
  index.build(scene(0.0));
  sogmm::detail::CandidateCache cache(index, 1, 0.01);
  std::vector<std::uint32_t> scratch;
  EXPECT_TRUE(cache.near(0, Eigen::Vector3d(std::numeric_limits<double>::quiet_NaN(), 0.5, 0.5), scratch).empty());
}

}  // namespace
