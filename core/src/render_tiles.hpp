// Which components a pixel's ray can meet (private; render.cpp). Rendering
// tests every component against every pixel's ray; a component whose
// ellipsoid lies in one corner of the image cannot shape the other rays, so
// the image is cut into square tiles and each tile keeps the components that
// may meet one of its rays. The result is bitwise the same as testing every
// component: a tile's list is a superset of what its rays meet, in
// ascending component order, so the sums run over the same terms in the
// same order.
#pragma once

#include <cstdint>
#include <vector>

#include "sogmm/camera.hpp"
#include "sogmm/gmm.hpp"

namespace sogmm::detail {

/// Per tile of `tile` x `tile` pixels (row-major over the tiles), the
/// ascending ids of the components whose ellipsoid
/// {x : (x - mu)^T Sigma_xx^-1 (x - mu) <= r2} may meet a ray of one of its
/// pixels at positive depth.
///
/// Why it is complete: a ray t d (d = ((u - cx)/fx, (v - cy)/fy, 1)) meets
/// the ellipsoid at some t > 0 only at a point with z = t > 0 and x/z =
/// (u - cx)/fx, y/z = (v - cy)/fy. The ellipsoid lies in its axis-aligned box
/// mu_i +- sqrt(r2 Sigma_ii). A box entirely at z <= 0 meets no ray; a box
/// reaching z <= 0 may meet any ray (it is kept for every tile); a box at
/// z > 0 sees its x/z and y/z extremes at its corners (each ratio is
/// monotone in x and in z separately), so only pixels between the corners'
/// projections (widened by one pixel against rounding) can meet it.
struct RayTiles {
  int tile = 8;
  int columns = 0;  ///< tiles across
  std::vector<std::vector<std::uint32_t>> ids;

  const std::vector<std::uint32_t>& at(int u, int v) const {
    return ids[static_cast<std::size_t>(v / tile) * static_cast<std::size_t>(columns) + static_cast<std::size_t>(u / tile)];
  }
};

/// The tiles of `camera`'s image for `gmm` (in the camera's frame) and the
/// squared Mahalanobis radius `r2` (> 0).
RayTiles ray_tiles(const Gmm& gmm, const Camera& camera, double r2, int tile = 8);

}  // namespace sogmm::detail
