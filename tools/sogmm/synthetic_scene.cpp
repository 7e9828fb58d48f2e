#include "synthetic_scene.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace sogmm::tools {

Camera synthetic_camera() { return Camera{640, 480, 525.0, 525.0, 319.5, 239.5}; }

LoadedFrame synthetic_frame() {
  const std::array<double, 16> identity{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  return synthetic_frame_at(identity);
}

LoadedFrame ray_cast_frame(const std::array<double, 16>& pose, const NearestHit& nearest) {
  const Camera cam = synthetic_camera();
  LoadedFrame f;
  f.width = cam.width;
  f.height = cam.height;
  f.depth.assign(static_cast<std::size_t>(cam.width) * cam.height, 0);
  f.gray.assign(f.depth.size(), 0.f);
  const double o[3] = {pose[3], pose[7], pose[11]};  // camera centre in the world
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      // Camera ray with z component 1, so the hit parameter t is the depth z;
      // in the world it is o + t R dc.
      const double dc[3] = {(u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0};
      double dw[3];
      for (int r = 0; r < 3; ++r) dw[r] = pose[4 * r] * dc[0] + pose[4 * r + 1] * dc[1] + pose[4 * r + 2] * dc[2];
      double gray = 0.0;
      const double best = nearest(o, dw, gray);
      const std::size_t i = static_cast<std::size_t>(v) * cam.width + u;
      if (std::isfinite(best) && best < 60.0) {
        f.depth[i] = static_cast<std::uint16_t>(std::lround(best * 1000.0));
        f.gray[i] = static_cast<float>(gray);
      }
    }
  }
  return f;
}

LoadedFrame synthetic_frame_at(const std::array<double, 16>& pose) {
  const double sphere_c[3] = {0.25, 0.15, 1.6}, sphere_r = 0.35;
  const double oc[3] = {sphere_c[0] - pose[3], sphere_c[1] - pose[7], sphere_c[2] - pose[11]};
  return ray_cast_frame(pose, [&](const double o[3], const double dw[3], double& gray) {
    const double dx = dw[0], dy = dw[1], dz = dw[2];
    double best = std::numeric_limits<double>::infinity();
    auto hit = [&](double t, double g) {
      if (t > 0 && t < best) {
        best = t;
        gray = g;
      }
    };
    if (dz > 1e-9) {  // back wall z = 2.5, 0.25 m checkers
      const double t = (2.5 - o[2]) / dz, x = o[0] + dx * t, y = o[1] + dy * t;
      const bool odd = (static_cast<int>(std::floor(x / 0.25)) + static_cast<int>(std::floor(y / 0.25))) & 1;
      hit(t, odd ? 0.8 : 0.25);
    }
    if (dy > 1e-9) {  // floor y = 0.8 (y points down), stripes along z
      const double t = (0.8 - o[1]) / dy, z = o[2] + dz * t;
      hit(t, 0.45 + 0.3 * (static_cast<int>(std::floor(z / 0.2)) & 1));
    }
    if (dx < -1e-9) {  // side wall x = -1.2, gray ramp with height
      const double t = (-1.2 - o[0]) / dx, y = o[1] + dy * t;
      hit(t, std::clamp(0.6 - 0.3 * y, 0.05, 0.95));
    }
    {  // sphere, Lambertian shading from a light towards -y, -z
      const double b = dx * oc[0] + dy * oc[1] + dz * oc[2];
      const double dd = dx * dx + dy * dy + dz * dz;
      const double cc = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - sphere_r * sphere_r;
      const double disc = b * b - dd * cc;
      if (disc >= 0) {
        const double t = (b - std::sqrt(disc)) / dd;
        const double n[3] = {(o[0] + dx * t - sphere_c[0]) / sphere_r, (o[1] + dy * t - sphere_c[1]) / sphere_r,
                             (o[2] + dz * t - sphere_c[2]) / sphere_r};
        const double l[3] = {0.3, -0.6, -0.74};
        const double shade = std::max(0.0, n[0] * l[0] + n[1] * l[1] + n[2] * l[2]);
        hit(t, 0.15 + 0.75 * shade);
      }
    }
    return best;
  });
}

}  // namespace sogmm::tools
