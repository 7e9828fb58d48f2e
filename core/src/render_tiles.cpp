// Tiles of an image and the components their rays may meet (render_tiles.hpp).
#include "render_tiles.hpp"

#include <algorithm>
#include <cmath>

namespace sogmm::detail {

RayTiles ray_tiles(const Gmm& gmm, const Camera& camera, double r2, int tile) {
  RayTiles t;
  t.tile = tile;
  t.columns = (camera.width + tile - 1) / tile;
  const int rows = (camera.height + tile - 1) / tile;
  t.ids.resize(static_cast<std::size_t>(t.columns) * static_cast<std::size_t>(rows));
  for (std::size_t m = 0; m < gmm.size(); ++m) {
    const float* mu = gmm.mean(m);
    const float* s = gmm.covariance(m);
    double lo[3], hi[3];
    for (int i = 0; i < 3; ++i) {
      const double half = std::sqrt(r2 * static_cast<double>(s[5 * i]));  // diagonal entries 0, 5, 10
      lo[i] = mu[i] - half;
      hi[i] = mu[i] + half;
    }
    if (!(hi[2] > 0)) continue;  // entirely behind the camera: no ray meets it at t > 0
    int u0 = 0, u1 = camera.width - 1, v0 = 0, v1 = camera.height - 1;
    if (lo[2] > 0) {
      double x_lo = HUGE_VAL, x_hi = -HUGE_VAL, y_lo = HUGE_VAL, y_hi = -HUGE_VAL;
      for (double z : {lo[2], hi[2]}) {
        for (double x : {lo[0], hi[0]}) {
          x_lo = std::min(x_lo, x / z);
          x_hi = std::max(x_hi, x / z);
        }
        for (double y : {lo[1], hi[1]}) {
          y_lo = std::min(y_lo, y / z);
          y_hi = std::max(y_hi, y / z);
        }
      }
      // Pixel u looks along x/z = (u - cx)/fx (fx > 0): u = cx + fx x/z.
      const double uf0 = std::floor(camera.cx + camera.fx * x_lo) - 1, uf1 = std::ceil(camera.cx + camera.fx * x_hi) + 1;
      const double vf0 = std::floor(camera.cy + camera.fy * y_lo) - 1, vf1 = std::ceil(camera.cy + camera.fy * y_hi) + 1;
      if (!(uf1 >= 0 && vf1 >= 0 && uf0 <= camera.width - 1 && vf0 <= camera.height - 1)) continue;  // off the image
      u0 = static_cast<int>(std::max(uf0, 0.0));
      u1 = static_cast<int>(std::min(uf1, camera.width - 1.0));
      v0 = static_cast<int>(std::max(vf0, 0.0));
      v1 = static_cast<int>(std::min(vf1, camera.height - 1.0));
    }
    for (int tv = v0 / tile; tv <= v1 / tile; ++tv)
      for (int tu = u0 / tile; tu <= u1 / tile; ++tu)
        t.ids[static_cast<std::size_t>(tv) * static_cast<std::size_t>(t.columns) + static_cast<std::size_t>(tu)]
            .push_back(static_cast<std::uint32_t>(m));
  }
  return t;
}

}  // namespace sogmm::detail
