// The hand-made scene of the occupancy, distance and collision tests (issue
// 31): one RGB-D frame of a gray plane at z = 2 m, 64 x 48 pixels (it spans
// 2.56 x 1.92 m), fitted into a map with novelty off.
#pragma once

#include <cstdint>
#include <vector>

#include "sogmm/map.hpp"

namespace sogmm_test {

inline const sogmm::Camera kPlaneCamera{64, 48, 50.0, 50.0, 31.5, 23.5};
inline constexpr double kPlaneZ = 2.0;
inline const sogmm::Pose kIdentityPose = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

/// The plane seen from camera-to-world `pose`.
inline sogmm::Map plane_map(const sogmm::Pose& pose = kIdentityPose) {
  sogmm::MapOptions o;
  o.novelty = false;
  sogmm::Map map(o);
  const sogmm::Camera& cam = kPlaneCamera;
  std::vector<std::uint16_t> depth(static_cast<std::size_t>(cam.width * cam.height),
                                   static_cast<std::uint16_t>(kPlaneZ * 1000));
  std::vector<float> gray(depth.size(), 0.5f);
  map.insert_rgbd({depth.data(), gray.data(), cam}, pose);
  map.flush();
  return map;
}

}  // namespace sogmm_test
