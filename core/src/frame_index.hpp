// Which of a map's frames may see a point (private; occupancy.cpp): the
// frames' view frusta, and a uniform grid whose cells list the frames whose
// (widened) frustum meets them, so that a point tests only those frames, not
// every frame.
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
  /// The frustum, widened by one pixel and past the depth range, as world
  /// half-spaces n . x + c >= 0 (n = [0..2], c = [3]): every point the
  /// frame sees is inside all six (may_see()).
  std::array<std::array<double, 4>, 6> planes;
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
  /// The frames whose widened frustum meets the grid cell of `x` (a superset
  /// of those that see it), in increasing order.
  const std::vector<std::uint32_t>* candidates(const double x[3]) const;
  /// True when every point of the box [lo, hi] falls in the grid cell of
  /// `lo` (then candidates() is the same list for all of them: a point's
  /// cell is monotone in each coordinate, as floor of correctly rounded
  /// operations).
  bool one_cell(const double lo[3], const double hi[3]) const;
  /// The projection of world point `x` into frame f.
  Projection project(std::uint32_t f, const double x[3]) const;
  /// Frame f's world-to-camera transform, the camera and the depth range
  /// (for occupancy_kernel.hpp, which repeats project()'s arithmetic).
  const FrameView& frame(std::uint32_t f) const { return views_[f]; }
  const Camera& camera() const { return camera_; }
  double depth_min() const { return depth_min_; }
  double depth_max() const { return depth_max_; }
  /// False when no point of the box [lo, hi] (world) can be seen by frame f:
  /// the box lies wholly outside one of the frame's widened frustum planes.
  /// A few products per plane, no division: it clears most listed frames
  /// before view(), which is several times dearer.
  bool may_see(std::uint32_t f, const double lo[3], const double hi[3]) const;
  /// The view of frame f of the box [lo, hi] (world).
  BoxView view(std::uint32_t f, const double lo[3], const double hi[3]) const;

 private:
  std::int64_t cell(double v, int axis) const;
  /// Frame f may see a point of cell (i, j, k).
  bool cell_meets(std::uint32_t f, std::int64_t i, std::int64_t j, std::int64_t k) const;
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
