// How much of the E-step's per-chunk statistics one parallel region may hold
// (private; em.cpp, tests/core/test_em_properties.cpp).
//
// A pass runs its chunks in regions of as many chunks as this budget allows,
// and reduces every chunk's sums in chunk order whatever the region size, so
// the budget changes the speed, never a bit. Real fits need M of a few
// thousand at more than 131k points before a second region starts; the
// setter lets a test force several regions per pass on a small fit and check
// that the bits stay the same.
#pragma once

#include <cstddef>

namespace sogmm::detail {

/// The default budget: 16 MiB of chunk statistics per region.
inline constexpr std::size_t kDefaultEmRegionBytes = std::size_t{16} << 20;

/// The budget in force (kDefaultEmRegionBytes unless a test set another).
std::size_t em_region_bytes();

/// Sets the budget for fits that start afterwards and returns the previous
/// one. For tests only: a fit that is running keeps the budget it read.
std::size_t set_em_region_bytes(std::size_t bytes);

}  // namespace sogmm::detail
