// k-means++ seeding (issue 14 item 6) against a brute-force reference written
// out here: the plain greedy algorithm, O(N K trials), as the header
// documents it. Same seed, same centres.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "sogmm/kmeanspp.hpp"
#include "sogmm/random.hpp"
#include "test_util.hpp"

namespace {

double dist2(const float* a, const float* b) {
  double s = 0.0;
  for (int i = 0; i < 4; ++i) s += (static_cast<double>(a[i]) - b[i]) * (static_cast<double>(a[i]) - b[i]);
  return s;
}

// First seed uniform (Rng::next() % N); then 2 + floor(ln K) candidates, each
// drawn by searching u * potential in the running sum of the squared
// distances to the nearest seed; the candidate that leaves the lowest
// potential (ties: the first) becomes the next seed.
std::vector<std::size_t> brute_force_kmeanspp(const std::vector<float>& xyzg, std::size_t k, std::uint64_t seed) {
  const std::size_t n = xyzg.size() / 4;
  sogmm::Rng rng(seed);
  const int trials = 2 + static_cast<int>(std::log(static_cast<double>(k)));
  std::vector<std::size_t> centers = {static_cast<std::size_t>(rng.next() % n)};
  std::vector<double> closest(n), cumulative(n);
  for (std::size_t i = 0; i < n; ++i) closest[i] = dist2(&xyzg[4 * i], &xyzg[4 * centers[0]]);
  while (centers.size() < k) {
    double running = 0.0;
    for (std::size_t i = 0; i < n; ++i) cumulative[i] = (running += closest[i]);
    std::size_t best = 0;
    double best_potential = INFINITY;
    for (int t = 0; t < trials; ++t) {
      const double target = rng.uniform() * running;
      const std::size_t cand = std::min<std::size_t>(
          std::upper_bound(cumulative.begin(), cumulative.end(), target) - cumulative.begin(), n - 1);
      double potential = 0.0;
      for (std::size_t i = 0; i < n; ++i) potential += std::min(closest[i], dist2(&xyzg[4 * i], &xyzg[4 * cand]));
      if (potential < best_potential) best_potential = potential, best = cand;
    }
    centers.push_back(best);
    for (std::size_t i = 0; i < n; ++i) closest[i] = std::min(closest[i], dist2(&xyzg[4 * i], &xyzg[4 * best]));
  }
  return centers;
}

// A frame-like cloud: a tilted wall and a box (x, y, z, gray), 40 x 30 pixels.
std::vector<float> frame_cloud() {
  sogmm_test::TestRng rng(6);
  std::vector<float> p;
  for (int v = 0; v < 30; ++v)
    for (int u = 0; u < 40; ++u) {
      const bool box = u > 12 && u < 25 && v > 8 && v < 20;
      const double z = box ? 1.2 + 0.002 * rng.normal() : 1.5 + 0.02 * u + 0.01 * v + 0.003 * rng.normal();
      const double g = box ? 0.8 + 0.01 * rng.normal() : 0.4 + 0.2 * std::sin(u / 4.0) + 0.02 * rng.normal();
      p.insert(p.end(), {static_cast<float>((u - 19.5) / 33.0 * z), static_cast<float>((v - 14.5) / 33.0 * z),
                         static_cast<float>(z), static_cast<float>(g)});
    }
  return p;
}

void expect_same_as_brute_force(const std::vector<float>& cloud, std::size_t k, std::uint64_t seed) {
  const sogmm::PointsView view{cloud.data(), cloud.size() / 4};
  EXPECT_EQ(sogmm::kmeanspp_seeds(view, k, seed), brute_force_kmeanspp(cloud, k, seed))
      << "N = " << view.size << ", K = " << k << ", seed " << seed;
}

}  // namespace

TEST(KmeansPlusPlus, SameCentresAsBruteForceOnAFrame) {
  const std::vector<float> cloud = frame_cloud();
  for (std::size_t k : {1u, 2u, 7u, 60u, 300u, 1200u})
    for (std::uint64_t seed : {0u, 1u, 2u}) expect_same_as_brute_force(cloud, k, seed);
}

TEST(KmeansPlusPlus, SameCentresAsBruteForceWithDuplicatesAndAFarOutlier) {
  // Every point twice (zero distances, ties in the draw), plus one point 1 km
  // away; K up to N, where the potential reaches 0.
  std::vector<float> cloud = frame_cloud();
  cloud.resize(4 * 200);
  const std::vector<float> copy = cloud;
  cloud.insert(cloud.end(), copy.begin(), copy.end());
  cloud.insert(cloud.end(), {0.0f, 0.0f, 1000.0f, 0.5f});
  for (std::size_t k : {2u, 50u, 201u, 300u, 401u})
    for (std::uint64_t seed : {3u, 4u}) expect_same_as_brute_force(cloud, k, seed);
}

TEST(KmeansPlusPlus, SameCentresAsBruteForceOnCoincidentAndCollinearPoints) {
  // All points on a line with repeated coordinates: the k-d tree splits
  // through ties.
  std::vector<float> cloud;
  for (int i = 0; i < 500; ++i) cloud.insert(cloud.end(), {static_cast<float>(i % 17), 0.0f, 0.0f, 0.5f});
  for (std::size_t k : {3u, 17u, 40u})
    for (std::uint64_t seed : {5u, 6u}) expect_same_as_brute_force(cloud, k, seed);
}

TEST(KmeansPlusPlus, LargeCloudSameCentresForOneTwoThreeThreads) {
  // Above 65536 points the candidates' gains are computed in parallel: the
  // seeds must not depend on the team size, and still match the reference.
  sogmm_test::TestRng rng(17);
  std::vector<float> cloud;
  for (int i = 0; i < 70000; ++i) {
    const double blob = static_cast<double>(rng.next() % 7);
    cloud.insert(cloud.end(), {static_cast<float>(0.3 * blob + 0.05 * rng.normal()), static_cast<float>(0.05 * rng.normal()),
                               static_cast<float>(1.0 + 0.1 * blob + 0.02 * rng.normal()),
                               static_cast<float>(rng.uniform())});
  }
  const sogmm::PointsView view{cloud.data(), cloud.size() / 4};
  const std::vector<std::size_t> want = brute_force_kmeanspp(cloud, 40, 11);
  const int saved = omp_get_max_threads();
  for (int t : {1, 2, 3}) {
    omp_set_num_threads(t);
    EXPECT_EQ(sogmm::kmeanspp_seeds(view, 40, 11), want) << t << " threads";
  }
  omp_set_num_threads(saved);
}

TEST(KmeansPlusPlus, SameCentresAsBruteForceForEveryTreeShape) {
  // Each step's work is split over the k-d tree's parts (the nodes three
  // levels down, or leaves above that): from N <= 16 (the root is a leaf,
  // one part) through N = 129 (eight parts, the last ones leaves of 16 and
  // 17 points), so every shape of the tree's top is seeded and compared.
  // Exact equality of indices holds under every SOGMM_ISA: k-means++ calls
  // no dispatched kernel, and its gains are sums of the same double terms.
  const std::vector<float> frame = frame_cloud();
  for (std::size_t n : {1u, 2u, 16u, 17u, 40u, 65u, 129u}) {
    const std::vector<float> cloud(frame.begin(), frame.begin() + 4 * n);
    for (std::size_t k : {std::size_t{1}, std::min<std::size_t>(n, 5), n})
      expect_same_as_brute_force(cloud, k, 7);
  }
}
