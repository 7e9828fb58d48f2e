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

/// Sorts v stably by the low `key_bits` bits of key(e), a least-significant-
/// digit radix sort of `digit_bits` a pass: one read counts every pass's
/// digits, then each pass is one scatter, and a pass whose digit is the same
/// for every element is skipped (the order stands). Stable, so elements of
/// equal keys keep their order: the result is unique, whatever the threads.
template <typename T, typename Key>
void radix_sort(std::vector<T>& v, int key_bits, int digit_bits, Key key) {
  const std::size_t n = v.size();
  if (n < 2) return;
  const std::size_t digits = std::size_t{1} << digit_bits;
  const std::uint64_t mask = digits - 1;
  const int passes = (key_bits + digit_bits - 1) / digit_bits;
  std::vector<std::size_t> count(static_cast<std::size_t>(passes) * digits, 0);
  for (const T& e : v) {
    const std::uint64_t k = key(e);
    for (int p = 0; p < passes; ++p) ++count[digits * p + ((k >> (digit_bits * p)) & mask)];
  }
  std::vector<T> other(n);
  for (int p = 0; p < passes; ++p) {
    const int shift = digit_bits * p;
    std::size_t* c = &count[digits * p];
    if (c[(key(v[0]) >> shift) & mask] == n) continue;
    std::size_t at = 0;
    for (std::size_t d = 0; d < digits; ++d) {
      const std::size_t k = c[d];
      c[d] = at;
      at += k;
    }
    for (const T& e : v) other[c[(key(e) >> shift) & mask]++] = e;
    v.swap(other);
  }
}

/// Sorts (key, index) pairs whose indices are 0..n-1 in order, as std::sort
/// would sort the pairs: by key, ties by index (radix_sort is stable, so equal
/// keys keep their ascending indices), 8 bits a pass (a Z-order key of 2^16
/// cells a side has 48 bits: its top two passes are skipped).
/// Why not std::sort: on 614,400 occupancy points it was 13% of a query
/// (perf), a radix pass is one read and one scatter.
inline void sort_by_key(std::vector<std::pair<std::uint64_t, std::size_t>>& v) {
  radix_sort(v, 64, 8, [](const std::pair<std::uint64_t, std::size_t>& e) { return e.first; });
}

/// The bounding box of n points (rows of `width` floats, x y z first) and
/// the scale that maps its longest side onto `cells` - 1 (0 for one point).
inline double z_box(const float* points, std::size_t n, int width, double cells, double lo[3]) {
  double hi[3];
  for (int j = 0; j < 3; ++j) lo[j] = hi[j] = points[j];
  for (std::size_t i = 1; i < n; ++i)
    for (int j = 0; j < 3; ++j) {
      lo[j] = std::min<double>(lo[j], points[width * i + j]);
      hi[j] = std::max<double>(hi[j], points[width * i + j]);
    }
  double extent = 0.0;
  for (int j = 0; j < 3; ++j) extent = std::max(extent, hi[j] - lo[j]);
  return extent > 0 ? (cells - 1.0) / extent : 0.0;
}

/// The Z-order key of point i's cell in the box of z_box (cells a side).
inline std::uint64_t z_key(const float* points, std::size_t i, int width, const double lo[3], double scale,
                           double cells) {
  std::uint32_t c[3];
  for (int j = 0; j < 3; ++j)
    c[j] = static_cast<std::uint32_t>(std::clamp((points[width * i + j] - lo[j]) * scale, 0.0, cells - 1.0));
  return z_order_key(c[0], c[1], c[2]);
}

/// The permutation of n points (rows of `width` floats, x y z first) along a
/// Z-order curve over their bounding box (2^16 cells a side), ties in index
/// order. Keys run on `team` threads, the sort on one (sort_by_key): the
/// order is the same for any team.
inline std::vector<std::size_t> z_ordered(const float* points, std::size_t n, int width, int team) {
  if (n == 0) return {};
  constexpr double kCells = 65536.0;
  double lo[3];
  const double scale = z_box(points, n, width, kCells, lo);
  std::vector<std::pair<std::uint64_t, std::size_t>> keyed(n);
  parallel_for(n, team, 4096, [&](std::size_t i, int) { keyed[i] = {z_key(points, i, width, lo, scale, kCells), i}; });
  sort_by_key(keyed);
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = keyed[i].second;
  return order;
}

/// A cheaper Z-order for callers whose answers do not depend on the order,
/// only their speed (occupancy: a point's sums run in frame order whatever
/// its block): 2^10 cells a side (a millimetre or so on a room, finer than
/// the points of a block of 64 lie apart), the 30-bit key and the index
/// packed in one word, and three 10-bit radix passes over the key's bits
/// (stable, so ties stay in index order: the order is unique, whatever the
/// team). Against z_ordered's six 8-bit passes over (key, index) pairs of
/// 16 bytes: on 614,400 points it was a sixth of an occupancy query
/// (single-threaded, while the other thread waits). n >= 2^34: z_ordered.
inline std::vector<std::size_t> z_ordered_coarse(const float* points, std::size_t n, int width, int team) {
  constexpr int kAxisBits = 10, kPassBits = 10, kIndexBits = 64 - 3 * kAxisBits;
  constexpr double kCells = 1 << kAxisBits;
  if (n >> kIndexBits) return z_ordered(points, n, width, team);
  if (n == 0) return {};
  double lo[3];
  const double scale = z_box(points, n, width, kCells, lo);
  std::vector<std::uint64_t> word(n);
  parallel_for(n, team, 4096, [&](std::size_t i, int) {
    word[i] = z_key(points, i, width, lo, scale, kCells) << kIndexBits | static_cast<std::uint64_t>(i);
  });
  radix_sort(word, 3 * kAxisBits, kPassBits, [](std::uint64_t w) { return w >> kIndexBits; });
  std::vector<std::size_t> order(n);
  constexpr std::uint64_t kIndexMask = (std::uint64_t{1} << kIndexBits) - 1;
  for (std::size_t i = 0; i < n; ++i) order[i] = static_cast<std::size_t>(word[i] & kIndexMask);
  return order;
}

}  // namespace sogmm::detail
