// Z-order (Morton) keys of 3-D cells and a parallel sort (private), for the
// spatially compact point orders of the EM blocks and the culled queries.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "parallel.hpp"

namespace sogmm::detail {

/// Bit b of v (b < 21) moved to bit 3 b; the other bits 0.
inline std::uint64_t spread_bits(std::uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffull;
  v = (v | v << 16) & 0x1f0000ff0000ffull;
  v = (v | v << 8) & 0x100f00f00f00f00full;
  v = (v | v << 4) & 0x10c30c30c30c30c3ull;
  v = (v | v << 2) & 0x1249249249249249ull;
  return v;
}

/// The Z-order key of cell (c0, c1, c2), each below 2^21: bit b of c_j at
/// bit 3 b + j.
inline std::uint64_t z_order_key(std::uint64_t c0, std::uint64_t c1, std::uint64_t c2) {
  return spread_bits(c0) | spread_bits(c1) << 1 | spread_bits(c2) << 2;
}

/// Sorts v by operator< on `team` threads: one piece per thread sorted in
/// parallel, then merged pairwise. For a strict total order (no two equal
/// elements, e.g. pairs ending in a unique index) the sorted sequence is
/// unique, so the result does not depend on the team size.
template <class T>
void parallel_sort(std::vector<T>& v, int team) {
  // Pieces of at least 4096 elements: below that a region costs more than it saves.
  const std::size_t pieces = std::clamp<std::size_t>(v.size() / 4096, 1, static_cast<std::size_t>(std::max(team, 1)));
  std::vector<std::size_t> edge(pieces + 1);
  for (std::size_t p = 0; p <= pieces; ++p) edge[p] = v.size() * p / pieces;
  const auto at = [&](std::size_t p) { return v.begin() + static_cast<std::ptrdiff_t>(edge[std::min(p, pieces)]); };
  parallel_for(pieces, team, 1, [&](std::size_t p, int) { std::sort(at(p), at(p + 1)); });
  for (std::size_t width = 1; width < pieces; width *= 2) {
    const std::size_t pairs = (pieces + 2 * width - 1) / (2 * width);
    parallel_for(pairs, team, 1, [&](std::size_t q, int) {
      const std::size_t first = 2 * width * q;
      if (first + width < pieces) std::inplace_merge(at(first), at(first + width), at(first + 2 * width));
    });
  }
}

/// The permutation of n points (rows of `width` floats, x y z first) along a
/// Z-order curve over their bounding box (2^16 cells a side). Keys and sort
/// run on `team` threads; (key, index) pairs are all distinct, so the order
/// is the same for any team.
inline std::vector<std::size_t> z_ordered(const float* points, std::size_t n, int width, int team) {
  if (n == 0) return {};
  double lo[3], hi[3];
  for (int j = 0; j < 3; ++j) lo[j] = hi[j] = points[j];
  for (std::size_t i = 1; i < n; ++i)
    for (int j = 0; j < 3; ++j) {
      lo[j] = std::min<double>(lo[j], points[width * i + j]);
      hi[j] = std::max<double>(hi[j], points[width * i + j]);
    }
  double extent = 0.0;
  for (int j = 0; j < 3; ++j) extent = std::max(extent, hi[j] - lo[j]);
  const double scale = extent > 0 ? 65535.0 / extent : 0.0;
  std::vector<std::pair<std::uint64_t, std::size_t>> keyed(n);
  parallel_for(n, team, 4096, [&](std::size_t i, int) {
    std::uint32_t c[3];
    for (int j = 0; j < 3; ++j)
      c[j] = static_cast<std::uint32_t>(std::clamp((points[width * i + j] - lo[j]) * scale, 0.0, 65535.0));
    keyed[i] = {z_order_key(c[0], c[1], c[2]), i};
  });
  parallel_sort(keyed, team);
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = keyed[i].second;
  return order;
}

}  // namespace sogmm::detail
