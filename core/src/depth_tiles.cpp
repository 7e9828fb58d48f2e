// Depth ranges over pixel rectangles (depth_tiles.hpp).
#include "depth_tiles.hpp"

#include <algorithm>
#include <limits>

namespace sogmm::detail {

namespace {

void widen(DepthTiles::Range& r, const DepthTiles::Range& by) {
  r.any_empty = r.any_empty || by.any_empty;
  if (!by.any_surface) return;
  r.lo = r.any_surface ? std::min(r.lo, by.lo) : by.lo;
  r.hi = r.any_surface ? std::max(r.hi, by.hi) : by.hi;
  r.any_surface = true;
}

}  // namespace

DepthTiles::DepthTiles(const std::vector<float>& depth, int width, int height)
    : columns_((width + kTile - 1) / kTile),
      tiles_(static_cast<std::size_t>(columns_) * static_cast<std::size_t>((height + kTile - 1) / kTile)) {
  // Tile by tile, as selects that vectorize (a NaN compares false, so it
  // moves neither bound), instead of a branch per pixel: every occupancy
  // call builds the tiles of every frame it reads. The same ranges: min and
  // max are exact.
  const float inf = std::numeric_limits<float>::infinity();
  for (int v0 = 0; v0 < height; v0 += kTile)
    for (int u0 = 0; u0 < width; u0 += kTile) {
      float lo = inf, hi = -inf;
      bool empty = false;
      for (int v = v0; v < std::min(height, v0 + kTile); ++v) {
        const float* row = depth.data() + static_cast<std::size_t>(v) * static_cast<std::size_t>(width);
        for (int u = u0; u < std::min(width, u0 + kTile); ++u) {
          const float d = row[u];
          lo = d < lo ? d : lo;
          hi = d > hi ? d : hi;
          empty = empty || d != d;
        }
      }
      Range& t = tiles_[static_cast<std::size_t>(v0 / kTile) * static_cast<std::size_t>(columns_) +
                        static_cast<std::size_t>(u0 / kTile)];
      t.any_empty = empty;
      t.any_surface = lo <= hi;  // some pixel is not NaN (an infinite depth included)
      if (t.any_surface) {
        t.lo = lo;
        t.hi = hi;
      }
    }
}

DepthTiles::Range DepthTiles::over(int u0, int v0, int u1, int v1) const {
  Range r;
  for (int j = v0 / kTile; j <= v1 / kTile; ++j)
    for (int i = u0 / kTile; i <= u1 / kTile; ++i)
      widen(r, tiles_[static_cast<std::size_t>(j) * static_cast<std::size_t>(columns_) + static_cast<std::size_t>(i)]);
  return r;
}

}  // namespace sogmm::detail
