// Fixtures shared by the map tests (test_map*.cpp): the names they use from
// sogmm and the poses they insert frames at.
#pragma once

#include "sogmm/map.hpp"
#include "test_util.hpp"

namespace sogmm_test {

using sogmm::ErrorCode;
using sogmm::Map;
using sogmm::MapOptions;
using sogmm::Pose;

constexpr Pose kIdentity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

// The identity rotation with a translation of tx along x.
inline Pose translated(double tx) { return {1, 0, 0, tx, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }

}  // namespace sogmm_test
