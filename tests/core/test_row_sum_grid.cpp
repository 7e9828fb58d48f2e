// RowSumGrid (core/src/row_sum_grid.hpp), the flat mean shift's neighbour
// sums, against brute force: every point tested with the same predicate
// dx * dx + dy * dy <= r2. Coordinates on a dyadic lattice make every sum
// exact in any order, so the sums and counts must agree bit for bit, and
// many points lie exactly on a disc's edge, on cell edges and on top of each
// other, where a cell taken whole or skipped by a wrong bound would show.
// The grid is plain double arithmetic, not a dispatched kernel, so the same
// bits hold under every SOGMM_ISA.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "row_sum_grid.hpp"
#include "test_util.hpp"

namespace {

struct Sums {
  double x = 0.0, y = 0.0;
  std::size_t count = 0;
};

Sums brute_force(const std::vector<double>& xy, double x, double y, double r2) {
  Sums s;
  for (std::size_t i = 0; i < xy.size(); i += 2) {
    const double dx = xy[i] - x, dy = xy[i + 1] - y;
    if (dx * dx + dy * dy <= r2) s.x += xy[i], s.y += xy[i + 1], ++s.count;
  }
  return s;
}

// Every query of `queries` (x, y interleaved) against brute force; returns
// how many found at least one point.
int expect_same_sums(const std::vector<double>& xy, double radius, int split, const std::vector<double>& queries) {
  const sogmm::detail::RowSumGrid grid(xy.data(), xy.size() / 2, radius, split);
  int nonempty = 0;
  for (std::size_t q = 0; q < queries.size(); q += 2) {
    const double x = queries[q], y = queries[q + 1], r2 = radius * radius;
    Sums got;
    grid.sum_within(x, y, r2, got.x, got.y, got.count);
    const Sums want = brute_force(xy, x, y, r2);
    EXPECT_EQ(got.count, want.count) << "query (" << x << ", " << y << "), split " << split;
    EXPECT_EQ(got.x, want.x) << "query (" << x << ", " << y << "), split " << split;
    EXPECT_EQ(got.y, want.y) << "query (" << x << ", " << y << "), split " << split;
    nonempty += want.count > 0;
  }
  return nonempty;
}

// Points on a 1/64 lattice (as 8-bit gray is quantised), with duplicates.
std::vector<double> lattice_cloud(std::uint64_t seed, int n, int wide, int high) {
  sogmm_test::TestRng rng(seed);
  std::vector<double> xy;
  for (int i = 0; i < n; ++i)
    xy.insert(xy.end(), {static_cast<double>(rng.next() % wide) / 64.0, static_cast<double>(rng.next() % high) / 64.0});
  return xy;
}

}  // namespace

TEST(RowSumGrid, LatticeQueriesMatchBruteForceBitForBit) {
  const std::vector<double> xy = lattice_cloud(3, 3000, 80, 48);
  // Queries on the lattice (discs through many points exactly), on half
  // steps, and outside the points' span on every side.
  std::vector<double> queries;
  for (int i = -6; i <= 86; i += 2)
    for (int j = -6; j <= 54; j += 3) queries.insert(queries.end(), {i / 64.0, j / 64.0});
  for (int i = -5; i <= 85; i += 4)
    for (int j = -5; j <= 53; j += 4) queries.insert(queries.end(), {i / 64.0 + 1.0 / 128, j / 64.0 + 1.0 / 128});
  for (int split : {1, 2, 4, 8})
    for (double radius : {4.0 / 64, 5.0 / 64, 11.0 / 64}) EXPECT_GT(expect_same_sums(xy, radius, split, queries), 100);
}

TEST(RowSumGrid, SparseRowsAndAFarOutlierMatchBruteForce) {
  // A far outlier makes rows too sparse for the lookup tables (binary search
  // instead) and cells far apart in one row; a single point; all points equal.
  std::vector<double> xy = lattice_cloud(5, 500, 40, 40);
  xy.insert(xy.end(), {1024.0, 0.25, 0.25, 4096.0, 1024.0 + 1.0 / 64, 0.25});
  std::vector<double> queries = {1024.0, 0.25, 0.25, 4096.0, 1024.0 + 3.0 / 64, 0.25 + 1.0 / 64, 512.0, 0.25};
  for (int i = 0; i < 40; i += 3)
    for (int j = 0; j < 40; j += 3) queries.insert(queries.end(), {i / 64.0, j / 64.0});
  for (int split : {1, 4}) EXPECT_GT(expect_same_sums(xy, 5.0 / 64, split, queries), 50);
  expect_same_sums({0.5, 0.5}, 0.25, 4, {0.5, 0.75, 0.5, 0.76, 0.75, 0.5, 0.0, 0.0});
  expect_same_sums(std::vector<double>(40, 0.375), 0.125, 4, {0.375, 0.375, 0.5, 0.375, 0.5, 0.5});
}

TEST(RowSumGrid, AnyRadiusStillExact) {
  // A query radius other than the grid's: larger (the walks go on while the
  // bounds allow) or smaller than a cell, where a row or cell at the query's
  // own index may lie wholly on one side of it.
  const std::vector<double> xy = lattice_cloud(7, 800, 64, 64);
  for (int split : {1, 4}) {
    const sogmm::detail::RowSumGrid grid(xy.data(), xy.size() / 2, 4.0 / 64, split);
    for (double r : {0.3 / 64, 1.0 / 64, 1.5 / 64, 9.0 / 64, 0.5})
      for (int q = 0; q < 64; ++q) {
        // Just above a lattice line, or just below the next one.
        const double x = (q % 8) * 8.0 / 64 + (q % 2 ? 0.9 : 0.2) / 64, y = (q / 8) * 8.0 / 64 + (q % 3 ? 0.9 : 0.2) / 64;
        Sums got;
        grid.sum_within(x, y, r * r, got.x, got.y, got.count);
        const Sums want = brute_force(xy, x, y, r * r);
        EXPECT_EQ(got.count, want.count) << "r " << r << ", query " << q << ", split " << split;
        EXPECT_EQ(got.x, want.x) << "r " << r << ", query " << q << ", split " << split;
        EXPECT_EQ(got.y, want.y) << "r " << r << ", query " << q << ", split " << split;
      }
  }
}

// Far from the origin the whole cells' running sums must not carry the
// offset: 100,000 points 1 mm apart along a row at (1e9, 1e9), discs of
// radius 5 mm (about 10 points, 6 of them in whole cells). Sums of plain
// coordinates along the row reach 1e14, whose rounding (ulp 0.016) would
// move a disc's mean by ~1e-3; the grid sums coordinates less the cloud's
// lowest, so each mean must agree with brute force's (plain summation of
// ~10 values near 1e9: ~1e-7) within 1e-6. Brute force's count must match
// exactly (the same predicate on the same doubles). Plain double arithmetic:
// the same on every kernel.
TEST(RowSumGrid, MeansFarFromTheOriginKeepTheirPrecision) {
  constexpr double kOffset = 1e9;
  std::vector<double> xy;
  for (int i = 0; i < 100000; ++i) {
    xy.push_back(kOffset + 0.001 * i);
    xy.push_back(kOffset + 0.0001 * (i % 7));
  }
  const double radius = 0.005;
  const sogmm::detail::RowSumGrid grid(xy.data(), xy.size() / 2, radius, 4);
  for (int q : {10, 5000, 50000, 99990}) {
    const double x = kOffset + 0.001 * q + 0.0003, y = kOffset + 0.0002;
    double sx = 0.0, sy = 0.0;
    std::size_t count = 0;
    grid.sum_within(x, y, radius * radius, sx, sy, count);
    const Sums want = brute_force(xy, x, y, radius * radius);
    ASSERT_EQ(count, want.count) << "query at point " << q;
    ASSERT_GT(count, 5u);
    EXPECT_NEAR(sx / count, want.x / want.count, 1e-6) << "query at point " << q;
    EXPECT_NEAR(sy / count, want.y / want.count, 1e-6) << "query at point " << q;
  }
}
