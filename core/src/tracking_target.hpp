// What tracking registers a frame to (sogmm/map_tracking.hpp): the map's
// components and its pending points, as one mixture. Never installed.
//
// Why the pending points: they are the newest surfaces, seen by the last
// frames but not yet fitted (a flush waits for a batch of them). A view that
// turns towards them found only part of itself in the components (inlier
// ratio below 0.6 on the synthetic loop) and its pose slid by a few
// millimetres each frame until the next flush: the loop's errors came in such
// steps. A fit per frame would cost 10x the map's fit time; a cell grid (the
// normal distributions transform) summarises the points in one pass.
#pragma once

#include <cstddef>

#include "sogmm/gmm.hpp"
#include "sogmm/map.hpp"
#include "sogmm/point_cloud.hpp"

namespace sogmm::detail {

/// Edge (m) of the cells that summarise pending points. Pending points lie
/// 1 to 3.5 cm apart (kPendingVoxel and its neighbours), so a 6 cm cell of a
/// surface holds about 4 to 30 of them: enough for a covariance, and still
/// small against the curvature of a room's surfaces.
inline constexpr double kPendingCell = 0.06;
/// Cells with fewer points than this are left out (their covariance is noise).
inline constexpr std::size_t kPendingCellMin = 6;
/// Variance (m^2) added to each cell's spatial axes: the spread of a surface
/// along its normal is the depth noise (a few mm), which a handful of points
/// estimates badly; 3 mm standard deviation keeps a flat cell a plane.
inline constexpr double kPendingCellSpatialFloor = 9e-6;
/// Variance added to each cell's gray (gray in [0, 1]).
inline constexpr double kPendingCellGrayFloor = 1e-4;

/// One Gaussian per cell of `cell` metres (cells ordered by their integer
/// coordinates) holding at least `min_points` of `points`: the mean and the
/// (floored) covariance of its points, weight by count, support_size the
/// points kept. An empty Gmm when no cell qualifies.
Gmm cell_gaussians(const PointsView& points, double cell, std::size_t min_points);

/// The map's components (map.size() > 0) with the cells of its pending
/// points (world frame), weights by support: pi_k S / (S + P) for a component
/// and n_c / (S + P) for a cell of n_c points, S the map's support size and P
/// the points in cells.
Gmm tracking_target(const Map& map);

}  // namespace sogmm::detail
