// A closed synthetic room and a camera loop through it: the test bed for
// incremental mapping (issue 18), where revisits, growth and accuracy are
// measured against surfaces known in closed form.
#pragma once

#include <array>

#include "image_io.hpp"

namespace sogmm::tools {

/// The room, in world coordinates (metres; y points down like the camera's):
/// walls x = +-2 and z = +-2 (0.3 m checkers), floor y = 1 (stripes along x),
/// ceiling y = -1.5, two spheres and two boxes standing on the floor. The
/// camera is synthetic_camera() (640x480, fx = fy = 525).
namespace room {
inline constexpr double kWall = 2.0;       ///< walls at x = +-kWall and z = +-kWall
inline constexpr double kFloor = 1.0;      ///< floor plane y = kFloor
inline constexpr double kCeiling = -1.5;   ///< ceiling plane y = kCeiling
inline constexpr double kOrbitRadius = 0.5;  ///< camera centres lie on this circle (y = 0)
inline constexpr double kPitch = 15.0;     ///< degrees the camera looks down (so the floor is seen)
}  // namespace room

/// Camera-to-world pose (row-major 4x4) of frame k of an n-frame loop
/// (n >= 2): the camera centre is (r sin a, 0, r cos a) with a = 2 pi k / (n-1),
/// it looks outwards (yaw a) and kPitch degrees down. Frame n-1 returns to the
/// pose of frame 0, so the last frames revisit what the first ones saw.
std::array<double, 16> room_loop_pose(int k, int n);

/// The room ray-cast from a camera with the given camera-to-world pose: depth
/// in millimetres (rounded; every pixel hits a surface), gray in [0, 1].
/// Deterministic.
LoadedFrame room_frame_at(const std::array<double, 16>& pose);

}  // namespace sogmm::tools
