// Tracking's frame-to-frame odometry (sogmm/map_tracking.hpp): the last
// inserted frame as a registration target, and how far two poses of one
// frame place its points apart. Never installed.
//
// Why cells of the frame's own points: a fit per frame would cost as much as
// the map's fits; the cell grid (as the pending points' target,
// tracking_target.hpp) summarises the frame in one pass, and with gray a cell
// across a gray edge ties position to gray, which holds a view of a
// checkered wall that the geometry alone lets slide.
#pragma once

#include <cstddef>

#include "sogmm/gmm.hpp"
#include "sogmm/map.hpp"
#include "sogmm/point_cloud.hpp"

namespace sogmm::detail {

/// Edge (m) of the odometry's cells. Measured on the synthetic loop with
/// gray (d = 5, points about 2 cm apart at 2 m), frame k registered to frame
/// k - 1 from the constant-velocity guess: on frames 80-87, 6 cm cells erred
/// by 0.4 to 7.6 mm per step, 3 cm cells by 0.4 to 3.6 mm (inlier ratios
/// down to 0.82), 4 cm cells by 1.1 to 3.1 mm; over all 299 steps 4 cm
/// cells converged every time, 0.9 mm on average and 5.1 mm at most.
inline constexpr double kOdometryCell = 0.04;
/// Cells with fewer points are left out (their covariance is noise).
inline constexpr std::size_t kOdometryCellMin = 5;

/// The odometry target of a frame: cell_gaussians of its points (camera
/// frame) at kOdometryCell, kOdometryCellMin. Empty when no cell qualifies.
Gmm odometry_target(const PointsView& points);

/// RMS over `points` (camera frame) of the distance between each point
/// placed by pose `a` and by pose `b` (metres).
double rms_displacement(const PointsView& points, const Pose& a, const Pose& b);

}  // namespace sogmm::detail
