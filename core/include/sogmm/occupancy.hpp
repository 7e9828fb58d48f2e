// Occupancy of world points from a map (issue 31): free, occupied or unknown,
// from what the map's own frames would have seen, with no voxel grid and
// nothing stored beyond the map file (its frames' poses, its camera and its
// components).
//
// The model (spec/api.md, "Occupancy", has the formula). A frame f sees a
// world point x when x, moved into f's camera, lies in the image and at a
// depth in (depth_min, depth_max] of the map's camera record. The map
// rendered from f's pose (render(), sogmm/render.hpp, at the map's decimated
// camera) gives the depth D of the first surface at x's pixel. Along the
// ray, the true surface is taken as S ~ N(D, sigma^2); x at distance r from
// the camera along the ray is
//   free      with probability e_f = P(r < S - h) = 1 - Phi((r - D' + h) / sigma),
//   occupied  with probability o_f = P(|r - S| <= h),
//   hidden    with probability b_f = P(r > S + h) = Phi((r - D' - h) / sigma)
// (D' = D scaled from z to the distance along x's ray; h the thickness).
// A pixel without a surface and a frame that does not see x give b_f = 1:
// no evidence (the observed depth images are not in the map, so a pixel
// without a surface may have had no return). Over the frames:
//   U = prod_f b_f (x is unknown only if no frame observed it),
//   q = sum_f o_f / sum_f (o_f + e_f) (occupied share of the evidence),
//   P(occupied) = (1 - U) q + U / 2,
// and the state is the largest of free (1 - U)(1 - q), occupied (1 - U) q and
// unknown U (ties go to unknown, then occupied).
//
// Cost: a frame index (a uniform grid whose cells list the frames whose
// widened frustum meets them) gives each point the frames that may see it,
// and only frames that see
// at least one query point are rendered, once until the components change
// (Map::frame_depth keeps the renders between calls). So the first call
// after an insert costs O(frames seen x pixels x components near a ray) for
// the renders, and every call O(n x frames listed in a point's cell) for the
// lookups at worst; per block of 64 points the frames whose surface is more
// than h + 9 sigma from every point of the block are decided once (spec/api.md
// 4.9 has the bound this cut puts on the answer), so a point asks only the
// frames whose surface band may reach it.
#pragma once

#include <cstddef>
#include <cstdint>

#include "sogmm/map.hpp"
#include "sogmm/progress.hpp"

namespace sogmm {

/// How occupancy() turns a frame's view of a point into probabilities
/// (the model above).
struct OccupancyOptions {
  /// Standard deviation, in metres along the ray, of the true surface about
  /// the depth the map renders there. > 0, finite.
  double surface_sigma = 0.01;
  /// Half-thickness h, in metres, of the occupied shell about a surface: a
  /// point within h of the true surface along the ray is occupied. > 0, finite.
  double thickness = 0.02;
};

/// Throws Error(InvalidArgument) naming the field unless both are > 0 and finite.
void validate(const OccupancyOptions& options);

/// The state of a point (values are the C API's SOGMM_OCCUPANCY_*).
enum class OccupancyState : std::uint8_t { Free = 0, Occupied = 1, Unknown = 2 };

/// P(occupied) of n world points (`xyz`: rows of 3 floats) into
/// `probability` (n values in [0, 1]) and, if not null, their state into
/// `state`. A map without frames, without a camera record (points-only
/// inserts) or without components answers unknown (0.5) everywhere: it has
/// observed nothing. `threads` as QueryOptions::threads. Errors: a
/// non-finite point -> Error(InvalidData) naming its row (nothing written);
/// bad options -> Error(InvalidArgument). `progress` receives the renders'
/// Stage::Rendering reports and a Stage::Scoring report over the points,
/// and may cancel (Error(Cancelled), outputs partly written).
void occupancy(const Map& map, const float* xyz, std::size_t n, double* probability, std::uint8_t* state,
               const OccupancyOptions& options = {}, int threads = 0, const ProgressSink& progress = {});

}  // namespace sogmm
