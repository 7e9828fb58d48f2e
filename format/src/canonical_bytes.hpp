// Canonical bytes of an array (spec/format.md 5.2) and the upper triangle of
// UPPER_PACKED covariances (5.1): one definition for the writer (what it
// stores and checksums), the reader (the CRC-32C of a quantized file's
// decoded model, section 5.7) and the frame record (section 2.3.2).
#pragma once

#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

#include "container.hpp"
#include "sogmm/checked.hpp"

namespace sogmm::format::detail {

/// The n values at `v`, each converted to Wire (float or double; exact: the
/// writer widens float32 to binary64, never narrows) and written
/// little-endian one after another.
template <typename Wire, typename T>
std::vector<std::uint8_t> canonical_bytes(const T* v, std::size_t n) {
  static_assert(std::is_floating_point_v<Wire> && sizeof(Wire) >= sizeof(T), "an exact conversion");
  using Bits = std::conditional_t<sizeof(Wire) == 8, std::uint64_t, std::uint32_t>;
  std::vector<std::uint8_t> out(checked::bytes(n, sizeof(Wire), "array bytes"));
  for (std::size_t i = 0; i < n; ++i) {
    const Wire w = static_cast<Wire>(v[i]);
    Bits bits;
    std::memcpy(&bits, &w, sizeof bits);
    store_le<Bits>(&out[i * sizeof(Wire)], bits);
  }
  return out;
}

/// The UPPER_PACKED values of m full 4x4 covariances (16 floats each, row
/// major): entries (0,0) (0,1) (0,2) (0,3) (1,1) ... (3,3) of each.
inline std::vector<float> pack_upper(const float* cov, std::size_t m) {
  std::vector<float> out;
  out.reserve(10 * m);
  for (std::size_t k = 0; k < m; ++k) {
    for (int i = 0; i < 4; ++i) {
      for (int j = i; j < 4; ++j) out.push_back(cov[16 * k + 4 * i + j]);
    }
  }
  return out;
}

}  // namespace sogmm::format::detail
