// A synthetic RGB-D scene the demo and tests can use without external data.
#pragma once

#include <array>

#include "image_io.hpp"
#include "sogmm/camera.hpp"

namespace sogmm::tools {

/// A 640x480 frame ray-cast from a room corner: a checkered back wall at
/// 2.5 m, a striped floor, a side wall with a gray ramp and a shaded sphere.
/// Depth in millimetres (depth_scale 1000); intrinsics as the PrimeSense
/// default (fx = fy = 525, cx = 319.5, cy = 239.5). Deterministic.
LoadedFrame synthetic_frame();
/// The same scene seen from a camera with the given camera-to-world pose
/// (row-major 4x4 rigid transform; identity gives synthetic_frame()).
LoadedFrame synthetic_frame_at(const std::array<double, 16>& pose);
/// The camera of synthetic_frame().
Camera synthetic_camera();

}  // namespace sogmm::tools
