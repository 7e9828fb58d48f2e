// Which of a map's frames may see a point (private; occupancy.cpp): the
// frames' view frusta, and a uniform grid over their world boxes so that a
// point tests only the frames whose box holds it, not every frame.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "sogmm/camera.hpp"
#include "sogmm/map.hpp"

namespace sogmm::detail {

/// One frame's view: world-to-camera rotation and translation.
struct FrameView {
  std::array<double, 9> r;  ///< R^T of the pose, row-major
  std::array<double, 3> t;  ///< -R^T t
};

/// Where a world point falls in a frame's image.
struct Projection {
  int pixel = -1;     ///< row-major pixel index; -1: the frame does not see the point
  double ray = 0.0;   ///< |p| / p_z: distance along the ray per unit of depth
  double depth = 0.0; ///< p_z, metres
};

/// Where a box of world points falls in a frame: bounds that hold for every
/// point of the box (widened past rounding), not the exact set.
struct BoxView {
  bool visible = false;   ///< some point of the box may be seen; false: none is
  bool bounded = false;   ///< the box is in front of the camera: the rest is set
  bool seen_all = false;  ///< every point of the box is seen (in depth range and image)
  int u0 = 0, v0 = 0, u1 = -1, v1 = -1;  ///< pixels any seen point of the box may fall on (inclusive)
  double z_lo = 0, z_hi = 0;              ///< the points' depths p_z lie in [z_lo, z_hi]
};

class FrameIndex {
 public:
  /// The views of `poses` through `camera` (already decimated) for depths in
  /// (depth_min, depth_max].
  FrameIndex(const std::vector<Pose>& poses, const Camera& camera, double depth_min, double depth_max);

  std::size_t size() const { return views_.size(); }
  /// The frames whose frustum box holds `x` (a superset of those that see it).
  const std::vector<std::uint32_t>* candidates(const double x[3]) const;
  /// The projection of world point `x` into frame f.
  Projection project(std::uint32_t f, const double x[3]) const;
  /// project() of `count` world points (coordinate arrays x, y, z) into frame
  /// f, as arrays: pixel (-1: not seen), depth and |p|^2, from which
  /// ray_of(norm2, depth) is bitwise project()'s ray (a caller that needs no
  /// ray for most points skips its root and division). One frame's view stays
  /// in registers across the points.
  void project(std::uint32_t f, const double* x, const double* y, const double* z, std::size_t count, int* pixel,
               double* depth, double* norm2) const;
  /// The ray factor |p| / p_z of a point with |p|^2 = norm2 and p_z = depth.
  static double ray_of(double norm2, double depth) { return std::sqrt(norm2) / depth; }
  /// The view of frame f of the box [lo, hi] (world).
  BoxView view(std::uint32_t f, const double lo[3], const double hi[3]) const;

 private:
  std::int64_t cell(double v, int axis) const;
  static std::uint64_t key(std::int64_t i, std::int64_t j, std::int64_t k);

  Camera camera_;
  double depth_min_, depth_max_;
  double cell_ = 1.0;
  std::array<double, 3> origin_{};
  std::vector<FrameView> views_;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells_;
  std::vector<std::uint32_t> large_;  ///< frames whose box spans too many cells
};

}  // namespace sogmm::detail
