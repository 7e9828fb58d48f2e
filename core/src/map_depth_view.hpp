// A frame's observed depth as the map's insert judges other points against
// it: on its surface, in the free space in front of it, hidden behind it, or
// outside what it says anything about (the revisit refit, map_revisit.cpp;
// the free-space carve, map_carve.cpp). Never installed.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "sogmm/camera.hpp"
#include "sogmm/map.hpp"

namespace sogmm::detail {

// Relative depth tolerance of "on the observed surface": a world point whose
// camera depth is within this fraction of the depth observed at its pixel
// lies on what the frame sees (3%: 5 cm at 1.65 m, a few times the depth
// noise and the thickness of surface components, and the same at any scale).
constexpr double kSurfaceTolerance = 0.03;

// Where a camera-frame point lies relative to the frame's depth image.
enum class Seen { Outside, OnSurface, FreeSpace, Hidden };

// The frame's observed depth per pixel of the decimated camera (the nearest
// of its points: project_to_image's z-buffer), and the classification of
// other points against it with the same pixel rule.
class DepthView {
 public:
  DepthView(const Camera& decimated_camera, const DepthOptions& depth, const PointsView& frame)
      : cam_(decimated_camera), depth_(depth), observed_(observed_depth(frame, decimated_camera)) {}

  Seen classify(const float* p) const {
    std::size_t at = 0;
    const double z = p[2];
    if (!(z > depth_.depth_min && z <= depth_.depth_max) || !pixel(p, &at)) return Seen::Outside;
    const double o = observed_[at];
    if (!std::isfinite(o)) return Seen::Outside;  // no depth there: the frame says nothing
    const double tol = kSurfaceTolerance * o;
    if (z < o - tol) return Seen::FreeSpace;
    if (z > o + tol) return Seen::Hidden;
    return Seen::OnSurface;
  }

  // FreeSpace of classify() at the point's pixel and at each of its 8
  // neighbours: the frame saw past the point on every ray near it, so a point
  // of an object the frame sees, projected to the background pixel beside the
  // object's outline, is not taken for free space (pixels without depth, or
  // off the image, say nothing).
  bool surely_free(const float* p) const {
    std::size_t at = 0;
    const double z = p[2];
    if (!(z > depth_.depth_min && z <= depth_.depth_max) || !pixel(p, &at)) return false;
    const long w = cam_.width, h = cam_.height;
    const long u = static_cast<long>(at % static_cast<std::size_t>(w)), v = static_cast<long>(at / static_cast<std::size_t>(w));
    for (long dv = -1; dv <= 1; ++dv)
      for (long du = -1; du <= 1; ++du) {
        if (u + du < 0 || u + du >= w || v + dv < 0 || v + dv >= h) return false;
        const double o = observed_[static_cast<std::size_t>((v + dv) * w + u + du)];
        if (!std::isfinite(o) || !(z < o - kSurfaceTolerance * o)) return false;
      }
    return true;
  }

 private:
  bool pixel(const float* p, std::size_t* at) const {
    const double z = p[2];
    if (!(z > 0)) return false;
    const double u = std::nearbyint(cam_.fx * p[0] / z + cam_.cx), v = std::nearbyint(cam_.fy * p[1] / z + cam_.cy);
    if (!(u >= 0 && v >= 0 && u < cam_.width && v < cam_.height)) return false;
    *at = static_cast<std::size_t>(v) * static_cast<std::size_t>(cam_.width) + static_cast<std::size_t>(u);
    return true;
  }

  static std::vector<float> observed_depth(const PointsView& frame, const Camera& camera) {
    std::vector<float> z(frame.size);
    for (std::size_t i = 0; i < frame.size; ++i) z[i] = frame[i][2];
    return project_to_image(frame, z.data(), camera, std::numeric_limits<float>::infinity());
  }

  Camera cam_;
  DepthOptions depth_;
  std::vector<float> observed_;
};

// A point of the map's frame (x, y, z, gray) in the camera frame of
// `world_to_camera` (gray unchanged).
inline void to_camera(const Pose& world_to_camera, const float* w, float* c) {
  for (int r = 0; r < 3; ++r)
    c[r] = static_cast<float>(world_to_camera[4 * r] * w[0] + world_to_camera[4 * r + 1] * w[1] +
                              world_to_camera[4 * r + 2] * w[2] + world_to_camera[4 * r + 3]);
  c[3] = w[3];
}

// An RGB-D frame the map has seen: its depth and its map-to-camera pose.
struct SeenFrame {
  Pose to_camera;
  DepthView view;
};

}  // namespace sogmm::detail
