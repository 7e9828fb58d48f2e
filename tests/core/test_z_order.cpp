// The Z-order point order of the culled queries and occupancy (core/src/z_order.hpp):
// its radix sort must give exactly std::sort's order of (key, index) pairs,
// so the blocks, and with them every answer's bits, are what they were.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "z_order.hpp"

namespace {

using Keyed = std::vector<std::pair<std::uint64_t, std::size_t>>;

Keyed keyed(const std::vector<std::uint64_t>& keys) {
  Keyed v(keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i) v[i] = {keys[i], i};
  return v;
}

void expect_as_std_sort(const std::vector<std::uint64_t>& keys, const char* what) {
  Keyed radix = keyed(keys), reference = keyed(keys);
  sogmm::detail::sort_by_key(radix);
  std::sort(reference.begin(), reference.end());
  EXPECT_EQ(radix, reference) << what;
}

// The box of n rows of `width` floats (x y z first), recomputed here, and
// the scale of its longest side onto `cells` - 1.
double box_scale(const std::vector<float>& rows, int width, double cells, double lo[3]) {
  double hi[3] = {-1e9, -1e9, -1e9};
  for (int j = 0; j < 3; ++j) lo[j] = 1e9;
  for (std::size_t i = 0; i < rows.size() / static_cast<std::size_t>(width); ++i)
    for (int j = 0; j < 3; ++j) {
      lo[j] = std::min<double>(lo[j], rows[width * i + j]);
      hi[j] = std::max<double>(hi[j], rows[width * i + j]);
    }
  return (cells - 1.0) / std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
}

}  // namespace

TEST(ZOrder, RadixSortIsStdSortOfKeyIndexPairs) {
  std::mt19937_64 rng(29);
  std::vector<std::uint64_t> wide(5000), ties(5000), high(5000), equal(300, 7);
  for (auto& k : wide) k = rng();                        // every byte varies
  for (auto& k : ties) k = (rng() % 97) << 20;           // many equal keys: ties by index
  for (auto& k : high) k = (rng() % 5) << 56 | (rng() & 0xff);  // middle bytes constant (skipped passes)
  expect_as_std_sort(wide, "64-bit keys");
  expect_as_std_sort(ties, "repeated keys");
  expect_as_std_sort(high, "constant middle bytes");
  expect_as_std_sort(equal, "one key");
  expect_as_std_sort({}, "empty");
  expect_as_std_sort({5}, "one element");
  expect_as_std_sort({3, 1, 2, 1, 0, 3}, "hand case");  // -> (0,4) (1,1) (1,3) (2,2) (3,0) (3,5)
}

TEST(ZOrder, PointOrderIsTheSameForEveryTeam) {
  // Points with repeats (equal cells) and a spread, as x y z g rows.
  std::mt19937_64 rng(35);
  std::uniform_real_distribution<float> u(-2.0f, 2.0f);
  std::vector<float> rows;
  for (int i = 0; i < 20000; ++i) {
    const float x = (i % 7 == 0) ? 0.5f : u(rng), y = u(rng), z = (i % 5 == 0) ? 1.0f : u(rng);
    rows.insert(rows.end(), {x, y, z, 0.3f});
  }
  const std::size_t n = rows.size() / 4;
  const auto one = sogmm::detail::z_ordered(rows.data(), n, 4, 1);
  EXPECT_EQ(sogmm::detail::z_ordered(rows.data(), n, 4, 2), one);
  // A permutation, in non-decreasing key order with ties by index (checked
  // against keys recomputed the way z_ordered makes them).
  std::vector<std::size_t> sorted = one;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(sorted[i], i);
  double lo[3];
  const double scale = box_scale(rows, 4, 65536.0, lo);
  auto key = [&](std::size_t i) {
    std::uint32_t c[3];
    for (int j = 0; j < 3; ++j) c[j] = static_cast<std::uint32_t>(std::clamp((rows[4 * i + j] - lo[j]) * scale, 0.0, 65535.0));
    return sogmm::detail::z_order_key(c[0], c[1], c[2]);
  };
  for (std::size_t i = 1; i < n; ++i) {
    const auto a = std::make_pair(key(one[i - 1]), one[i - 1]), b = std::make_pair(key(one[i]), one[i]);
    ASSERT_LT(a, b) << "at " << i;
  }
}

// The coarse order of occupancy (z_ordered_coarse): exactly std::sort's order
// of (key, index) with keys of 2^10 cells a side recomputed here, the same
// for every team. The points repeat cells (ties by index) and span all three
// 10-bit passes. Mutation: a pass that shifts by kPassBits * pass without the
// index bits' offset, or keys of 2^16 cells, break the order asserted here.
TEST(ZOrder, CoarseOrderIsStdSortOfItsKeysForEveryTeam) {
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<float> u(-3.0f, 1.0f);
  std::vector<float> rows;
  for (int i = 0; i < 30000; ++i) {
    const float x = (i % 3 == 0) ? -0.25f : u(rng), y = u(rng), z = (i % 11 == 0) ? 0.75f : u(rng);
    rows.insert(rows.end(), {x, y, z});
  }
  const std::size_t n = rows.size() / 3;
  const auto one = sogmm::detail::z_ordered_coarse(rows.data(), n, 3, 1);
  EXPECT_EQ(sogmm::detail::z_ordered_coarse(rows.data(), n, 3, 2), one);
  double lo[3];
  const double scale = box_scale(rows, 3, 1024.0, lo);
  Keyed reference(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t c[3];
    for (int j = 0; j < 3; ++j)
      c[j] = static_cast<std::uint32_t>(std::clamp((rows[3 * i + j] - lo[j]) * scale, 0.0, 1023.0));
    reference[i] = {sogmm::detail::z_order_key(c[0], c[1], c[2]), i};
  }
  std::sort(reference.begin(), reference.end());
  ASSERT_EQ(one.size(), n);
  for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(one[i], reference[i].second) << "at " << i;
  EXPECT_TRUE(sogmm::detail::z_ordered_coarse(rows.data(), 0, 3, 2).empty());
  EXPECT_EQ(sogmm::detail::z_ordered_coarse(rows.data(), 1, 3, 2), std::vector<std::size_t>{0});
}
