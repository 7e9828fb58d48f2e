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

/// Sorts (key, index) pairs whose indices are 0..n-1 in order, as std::sort
/// would sort the pairs: by key, ties by index. A least-significant-digit
/// radix sort on the key, 8 bits a pass, is stable, so equal keys keep their
/// ascending indices and the result is exactly std::sort's (the order is
/// unique, whatever the thread count). Passes whose byte is the same for
/// every key are skipped (a Z-order key of 2^16 cells a side has 48 bits).
/// Why not std::sort: on 614,400 occupancy points it was 13% of a query
/// (perf), a radix pass is one read and one scatter.
inline void sort_by_key(std::vector<std::pair<std::uint64_t, std::size_t>>& v) {
  const std::size_t n = v.size();
  if (n < 2) return;
  std::vector<std::size_t> count(8 * 256, 0);
  for (const auto& e : v)
    for (int b = 0; b < 8; ++b) ++count[256 * b + ((e.first >> (8 * b)) & 0xff)];
  std::vector<std::pair<std::uint64_t, std::size_t>> other(n);
  for (int b = 0; b < 8; ++b) {
    std::size_t* c = &count[256 * static_cast<std::size_t>(b)];
    if (c[(v[0].first >> (8 * b)) & 0xff] == n) continue;  // one byte value: the order stands
    std::size_t at = 0;
    for (int d = 0; d < 256; ++d) {
      const std::size_t k = c[d];
      c[d] = at;
      at += k;
    }
    for (const auto& e : v) other[c[(e.first >> (8 * b)) & 0xff]++] = e;
    v.swap(other);
  }
}

/// The permutation of n points (rows of `width` floats, x y z first) along a
/// Z-order curve over their bounding box (2^16 cells a side), ties in index
/// order. Keys run on `team` threads, the sort on one (sort_by_key): the
/// order is the same for any team.
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
  sort_by_key(keyed);
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = keyed[i].second;
  return order;
}

}  // namespace sogmm::detail
