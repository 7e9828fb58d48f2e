// The flat mean shift (issue 17's faster mode count) against a brute-force
// reference written out here from the header's description: bin seeds, each
// seed moved to the mean of every point within the bandwidth (found by testing
// all N points), converged seeds ordered by strength and near duplicates
// dropped. The implementation adds the coordinates in an order of its own
// (runs of whole cells as differences of running sums, issue 35), so the
// reference's means may differ from it by rounding: strengths must agree
// exactly and centres to 1e-12 (sums of at most 1,500 values below 5, each
// mean off by a few ulps of its sum, far below the 1e-3 bandwidth stop). On
// dyadic values every sum is exact in any order, and there centres must agree
// bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

#include "sogmm/mean_shift.hpp"
#include "test_util.hpp"

namespace {

struct RefMode {
  double x, y;
  std::size_t strength;
};

sogmm::MeanShiftResult brute_force_mean_shift(const std::vector<double>& xy, double h) {
  const std::size_t n = xy.size() / 2;
  double min_x = INFINITY, min_y = INFINITY, max_x = -INFINITY;
  for (std::size_t i = 0; i < n; ++i) {
    min_x = std::min(min_x, xy[2 * i]);
    min_y = std::min(min_y, xy[2 * i + 1]);
    max_x = std::max(max_x, xy[2 * i]);
  }
  // Summation order (any fixed one): (row-major cell key, index).
  const auto nx = static_cast<std::int64_t>(std::floor((max_x - min_x) / h)) + 1;
  std::vector<std::int64_t> key(n);
  for (std::size_t i = 0; i < n; ++i)
    key[i] = static_cast<std::int64_t>(std::floor((xy[2 * i + 1] - min_y) / h)) * nx +
             static_cast<std::int64_t>(std::floor((xy[2 * i] - min_x) / h));
  // Bin seeds: occupied cells of the grid anchored at the data minimum, in
  // ascending (x cell, y cell) order.
  std::set<std::pair<std::int64_t, std::int64_t>> bins;
  for (std::size_t i = 0; i < n; ++i)
    bins.insert({static_cast<std::int64_t>(std::floor((xy[2 * i] - min_x) / h + 0.5)),
                 static_cast<std::int64_t>(std::floor((xy[2 * i + 1] - min_y) / h + 0.5))});
  std::vector<RefMode> modes;
  for (const auto& bin : bins) {
    double mx = bin.first * h + min_x, my = bin.second * h + min_y;
    std::size_t within = 0;
    for (int it = 0;; ++it) {
      std::vector<std::pair<std::int64_t, std::size_t>> near;
      for (std::size_t i = 0; i < n; ++i) {
        const double dx = xy[2 * i] - mx, dy = xy[2 * i + 1] - my;
        if (dx * dx + dy * dy <= h * h) near.push_back({key[i], i});
      }
      std::sort(near.begin(), near.end());
      within = near.size();
      if (near.empty()) break;
      double sx = 0.0, sy = 0.0;
      for (const auto& p : near) sx += xy[2 * p.second], sy += xy[2 * p.second + 1];
      const double nx2 = sx / near.size(), ny2 = sy / near.size();
      const double moved = std::hypot(nx2 - mx, ny2 - my);
      mx = nx2, my = ny2;
      if (moved <= 1e-3 * h || it == 300) break;
    }
    if (within > 0) modes.push_back({mx, my, within});
  }
  std::sort(modes.begin(), modes.end(), [](const RefMode& a, const RefMode& b) {
    return std::make_tuple(a.strength, a.x, a.y) > std::make_tuple(b.strength, b.x, b.y);
  });
  sogmm::MeanShiftResult r;
  std::vector<RefMode> kept;
  for (const RefMode& m : modes) {
    bool near_kept = false;
    for (const RefMode& k : kept) {
      const double dx = m.x - k.x, dy = m.y - k.y;
      near_kept = near_kept || dx * dx + dy * dy <= h * h;
    }
    if (near_kept) continue;
    kept.push_back(m);
    r.centers.insert(r.centers.end(), {m.x, m.y});
    r.strengths.push_back(m.strength);
  }
  return r;
}

// `tolerance` 0: centres bit for bit (dyadic data).
void expect_same_as_brute_force(const std::vector<double>& xy, double h, const char* what, double tolerance = 0.0) {
  const sogmm::MeanShiftResult got = sogmm::mean_shift_flat(xy, h);
  const sogmm::MeanShiftResult want = brute_force_mean_shift(xy, h);
  EXPECT_EQ(got.strengths, want.strengths) << what << ", bandwidth " << h;
  ASSERT_EQ(got.centers.size(), want.centers.size()) << what << ", bandwidth " << h;
  for (std::size_t i = 0; i < got.centers.size(); ++i) {
    if (tolerance == 0.0)
      EXPECT_EQ(got.centers[i], want.centers[i]) << what << ", bandwidth " << h << ", centre value " << i;
    else
      EXPECT_NEAR(got.centers[i], want.centers[i], tolerance) << what << ", bandwidth " << h << ", centre value " << i;
  }
}

// Blobs of different spread and size over a uniform background, like the
// (range, gray) features of a frame.
std::vector<double> random_cloud(std::uint64_t seed, std::size_t n) {
  sogmm_test::TestRng rng(seed);
  std::vector<double> xy;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t pick = rng.next() % 5;
    if (pick == 0) {
      xy.insert(xy.end(), {1.0 + 3.0 * rng.uniform(), rng.uniform()});
    } else {
      const double cx = 1.0 + 0.7 * pick, cy = 0.2 * pick, s = 0.01 * pick;
      xy.insert(xy.end(), {cx + s * rng.normal(), cy + s * rng.normal()});
    }
  }
  return xy;
}

}  // namespace

TEST(MeanShiftReference, RandomCloudsMatchBruteForce) {
  for (std::uint64_t seed : {1u, 2u, 3u})
    for (double h : {0.02, 0.05, 0.13}) expect_same_as_brute_force(random_cloud(seed, 1500), h, "random cloud", 1e-12);
}

TEST(MeanShiftReference, QuantisedValuesOnCellEdgesMatchBruteForce) {
  // Values on a 1/64 lattice with bandwidth 1/16: points on cell edges, at
  // exactly the bandwidth from a mean, and many duplicates (cells whose box
  // is a single point, or lies exactly on the disc's edge).
  sogmm_test::TestRng rng(9);
  std::vector<double> xy;
  for (int i = 0; i < 1200; ++i)
    xy.insert(xy.end(), {static_cast<double>(rng.next() % 40) / 64.0, static_cast<double>(rng.next() % 24) / 64.0});
  expect_same_as_brute_force(xy, 1.0 / 16.0, "lattice");
  expect_same_as_brute_force(xy, 3.0 / 64.0, "lattice");
}

TEST(MeanShiftReference, HandBuiltCloudWithAFarOutlier) {
  // Dyadic values, bandwidth 1/4: a square of 4 points with mean (1/16, 1/16),
  // a point exactly one bandwidth above that mean (included: the test is
  // <=), a 3-point cluster far away and one point 1 km away. The first two
  // form one mode of strength 5 at (1/16, 9/80).
  const std::vector<double> xy = {0.0, 0.0, 0.125, 0.0, 0.0, 0.125, 0.125, 0.125, 0.0625, 0.3125,
                                  1.0, 1.0, 1.125, 1.0, 1.0, 1.125, 1000.0, 0.5};
  expect_same_as_brute_force(xy, 0.25, "hand-built");
  const sogmm::MeanShiftResult r = sogmm::mean_shift_flat(xy, 0.25);
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r.strengths, (std::vector<std::size_t>{5, 3, 1}));
  EXPECT_EQ(r.centers[0], 0.0625);
  EXPECT_EQ(r.centers[1], 0.5625 / 5);
  EXPECT_EQ(r.centers[4], 1000.0);
  EXPECT_EQ(r.centers[5], 0.5);
}
