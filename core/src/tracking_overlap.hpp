// Which of a frame's points tracking registers to the map
// (sogmm/map_tracking.hpp): those the map's frames have seen. Never installed.
//
// Why. A frame that looks a little past the mapped space sees surfaces the
// map does not hold yet. The map's components at the edge of what it holds
// have tails past that edge, so the registration pulls those points back
// into the mapped space and the pose lags behind the camera's motion; on a
// wall, where only the texture holds the slide, by millimetres per frame and
// by 1-2 cm on a view into new space (the synthetic loop's errors were all
// such lags, along the camera's motion). A point that no frame inserted
// so far saw has nothing in the map to match; leaving it out of the
// registration removes the pull, and the frame still adds it to the map.
#pragma once

#include <cstddef>
#include <vector>

#include "sogmm/camera.hpp"
#include "sogmm/map.hpp"
#include "sogmm/point_cloud.hpp"

namespace sogmm::detail {

/// Pixels a point must lie inside an earlier frame's image border to count
/// as seen by it: the constant-velocity guess places a point a few pixels
/// off (mm at 1-3 m), and a point right at the border met only the edge of
/// what that frame showed. Measured on the synthetic loop (frames 0-299,
/// README Registration): margins of 2 / 8 / 24 pixels gave ATE 1.20 /
/// 0.55 / 0.82 cm in a build without the whole-frame retry (2.55 cm without
/// the rule; the rule as built, 8 pixels: 0.56 cm, 0.63 cm with the
/// one-sample free-space carve).
inline constexpr double kOverlapMarginPixels = 8.0;

/// The rows of `points` (camera frame: x, y, z, gray) that, placed in the
/// world by `camera_to_world`, lie in front of at least one of the
/// camera-to-world poses `seen_from` and project into its image (through
/// `camera`: tracking assumes one camera for a map's frames) at least
/// `margin` pixels inside the border. Poses are tested newest (last) first.
std::vector<float> seen_points(const PointsView& points, const Pose& camera_to_world,
                               const std::vector<Pose>& seen_from, const Camera& camera, double margin);

}  // namespace sogmm::detail
