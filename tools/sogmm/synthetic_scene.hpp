// A synthetic RGB-D scene the demo and tests can use without external data.
#pragma once

#include <array>
#include <functional>

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

/// The nearest surface along the world ray o + t d (t > 0): returns t, or
/// +infinity for none, and sets `gray` in [0, 1] for a hit.
using NearestHit = std::function<double(const double o[3], const double d[3], double& gray)>;
/// Ray-casts a frame of synthetic_camera() from a camera-to-world pose. Each
/// pixel's ray has camera z component 1, so t is its depth (stored in mm,
/// rounded; pixels without a hit within 60 m stay 0).
LoadedFrame ray_cast_frame(const std::array<double, 16>& pose, const NearestHit& nearest);

}  // namespace sogmm::tools
