// Depth ranges over pixel rectangles (depth_tiles.hpp).
#include "depth_tiles.hpp"

#include <algorithm>
#include <cmath>

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
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) {
      const float d = depth[static_cast<std::size_t>(v) * static_cast<std::size_t>(width) + static_cast<std::size_t>(u)];
      Range pixel;
      if (std::isnan(d)) {
        pixel.any_empty = true;
      } else {
        pixel.lo = pixel.hi = d;
        pixel.any_surface = true;
      }
      widen(tiles_[static_cast<std::size_t>(v / kTile) * static_cast<std::size_t>(columns_) +
                   static_cast<std::size_t>(u / kTile)],
            pixel);
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
