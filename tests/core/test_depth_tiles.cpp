// The depth ranges of occupancy's block tests (core/src/depth_tiles.hpp):
// over() must return exactly the least and greatest depth, and whether a
// surface and a hole (NaN) show, over the pixels of the 8 x 8 tiles that a
// rectangle touches (never narrower than the rectangle: a block's whole
// free or no-evidence decision relies on it). Checked against those pixels
// read one by one, on an image with holes, a tile of holes only, infinite
// depths and a width and height that leave partial tiles. Exact comparisons:
// min and max round nothing. Mutations: the NaN flag dropped, or the last
// partial row of tiles skipped, make ranges differ.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "depth_tiles.hpp"

TEST(DepthTiles, RangesAreThoseOfTheTouchedTilesPixels) {
  const int W = 37, H = 29;  // partial tiles on both sides
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> depth(0.3f, 4.0f);
  std::vector<float> image(static_cast<std::size_t>(W * H));
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      float d = depth(rng);
      if ((u * 7 + v * 3) % 11 == 0) d = nan;  // scattered holes
      if (u >= 8 && u < 16 && v >= 8 && v < 16) d = nan;  // one tile of holes only
      if (u == 36 && v == 28) d = inf;  // the last partial tile's corner
      image[static_cast<std::size_t>(v * W + u)] = d;
    }
  const sogmm::detail::DepthTiles tiles(image, W, H);
  std::size_t checked = 0;
  for (int v0 = 0; v0 < H; v0 += 3)
    for (int u0 = 0; u0 < W; u0 += 4)
      for (int v1 = v0; v1 < H; v1 += 5)
        for (int u1 = u0; u1 < W; u1 += 6) {
          float lo = 0, hi = 0;
          bool surface = false, empty = false;
          for (int v = v0 / 8 * 8; v < std::min(H, (v1 / 8 + 1) * 8); ++v)
            for (int u = u0 / 8 * 8; u < std::min(W, (u1 / 8 + 1) * 8); ++u) {
              const float d = image[static_cast<std::size_t>(v * W + u)];
              if (std::isnan(d)) {
                empty = true;
                continue;
              }
              lo = surface ? std::min(lo, d) : d;
              hi = surface ? std::max(hi, d) : d;
              surface = true;
            }
          const auto r = tiles.over(u0, v0, u1, v1);
          ASSERT_EQ(r.any_surface, surface) << u0 << " " << v0 << " " << u1 << " " << v1;
          ASSERT_EQ(r.any_empty, empty) << u0 << " " << v0 << " " << u1 << " " << v1;
          if (surface) {
            ASSERT_EQ(r.lo, lo) << u0 << " " << v0 << " " << u1 << " " << v1;
            ASSERT_EQ(r.hi, hi) << u0 << " " << v0 << " " << u1 << " " << v1;
          }
          ++checked;
        }
  EXPECT_GT(checked, 1000u);
  // The tile of holes alone: no surface, a hole.
  const auto holes = tiles.over(8, 8, 15, 15);
  EXPECT_FALSE(holes.any_surface);
  EXPECT_TRUE(holes.any_empty);
  // The infinite depth is a surface at infinity.
  EXPECT_EQ(tiles.over(36, 28, 36, 28).hi, inf);
}
