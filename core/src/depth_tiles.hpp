// The range of a rendered depth image over pixel rectangles (private;
// occupancy.cpp): the least and greatest depth and whether a pixel shows no
// surface (NaN), kept per 8 x 8 tile, so that a rectangle costs a few reads
// however many pixels it covers. The range returned may be wider than the
// rectangle's (whole tiles are read), never narrower.
#pragma once

#include <cstdint>
#include <vector>

namespace sogmm::detail {

class DepthTiles {
 public:
  struct Range {
    float lo = 0, hi = 0;      ///< over the pixels that show a surface
    bool any_surface = false;  ///< some pixel shows a surface (lo, hi are set)
    bool any_empty = false;    ///< some pixel shows none (NaN)
  };

  DepthTiles() = default;
  /// The tiles of a width x height row-major image.
  DepthTiles(const std::vector<float>& depth, int width, int height);
  /// The range over pixels u0..u1, v0..v1 (inclusive, inside the image).
  Range over(int u0, int v0, int u1, int v1) const;

 private:
  static constexpr int kTile = 8;
  int columns_ = 0;
  std::vector<Range> tiles_;
};

}  // namespace sogmm::detail
