// Occupancy of world points from a map (issue 31): free, occupied or unknown,
// from what the map's own frames would have seen.
#pragma once

namespace sogmm {

/// How occupancy() turns a frame's view of a point into probabilities
/// (the model: spec/api.md, "Occupancy").
struct OccupancyOptions {
  /// Standard deviation, in metres along the ray, of the true surface about
  /// the depth the map renders there. > 0, finite.
  double surface_sigma = 0.01;
  /// Half-thickness h, in metres, of the occupied shell about a surface: a
  /// point within h of the true surface along the ray is occupied. > 0, finite.
  double thickness = 0.02;
};

}  // namespace sogmm
