#include "synthetic_room.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "synthetic_scene.hpp"

namespace sogmm::tools {

namespace {
struct Sphere {
  double c[3], r;
};
struct Box {
  double lo[3], hi[3];
};
// Both spheres and both boxes stand on the floor (y = 1) away from the walls.
constexpr Sphere kSpheres[] = {{{0.8, 0.7, 1.4}, 0.3}, {{-1.3, 0.6, -1.2}, 0.4}};
constexpr Box kBoxes[] = {{{1.2, 0.3, -0.7}, {1.8, 1.0, 0.1}}, {{-1.8, -0.4, 0.4}, {-1.3, 1.0, 1.2}}};

int cell(double v, double size) { return static_cast<int>(std::floor(v / size)); }

// Nearest hit along o + t d (t > 0) and its gray.
struct Hit {
  double t = std::numeric_limits<double>::infinity();
  double gray = 0.0;
  void offer(double t_new, double g) {
    if (t_new > 0 && t_new < t) {
      t = t_new;
      gray = g;
    }
  }
};

void hit_walls(const double o[3], const double d[3], Hit& h) {
  // The room is closed, so exactly one of each pair of planes faces the ray.
  for (int axis : {0, 2}) {
    if (std::abs(d[axis]) < 1e-12) continue;
    const double plane = d[axis] > 0 ? room::kWall : -room::kWall;
    const double t = (plane - o[axis]) / d[axis];
    const double along = o[2 - axis] + d[2 - axis] * t, y = o[1] + d[1] * t;
    h.offer(t, (cell(along, 0.3) + cell(y, 0.3)) & 1 ? 0.8 : 0.3);
  }
  if (d[1] > 1e-12) {  // floor: stripes along x
    const double t = (room::kFloor - o[1]) / d[1];
    h.offer(t, 0.45 + 0.3 * (cell(o[0] + d[0] * t, 0.25) & 1));
  } else if (d[1] < -1e-12) {  // ceiling: a gray ramp along z
    const double t = (room::kCeiling - o[1]) / d[1];
    h.offer(t, std::clamp(0.6 + 0.1 * (o[2] + d[2] * t), 0.05, 0.95));
  }
}

void hit_objects(const double o[3], const double d[3], Hit& h) {
  const double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  for (const Sphere& s : kSpheres) {  // Lambertian shading from a light towards -y, -z
    const double oc[3] = {s.c[0] - o[0], s.c[1] - o[1], s.c[2] - o[2]};
    const double b = d[0] * oc[0] + d[1] * oc[1] + d[2] * oc[2];
    const double disc = b * b - dd * (oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - s.r * s.r);
    if (disc < 0) continue;
    const double t = (b - std::sqrt(disc)) / dd;
    double n[3];
    for (int i = 0; i < 3; ++i) n[i] = (o[i] + d[i] * t - s.c[i]) / s.r;
    h.offer(t, 0.15 + 0.75 * std::max(0.0, 0.3 * n[0] - 0.6 * n[1] - 0.74 * n[2]));
  }
  for (const Box& b : kBoxes) {  // slab test; the face entered sets the gray
    double t_in = -std::numeric_limits<double>::infinity(), t_out = std::numeric_limits<double>::infinity();
    int face = 0;
    bool miss = false;
    for (int i = 0; i < 3 && !miss; ++i) {
      if (std::abs(d[i]) < 1e-12) {
        miss = o[i] < b.lo[i] || o[i] > b.hi[i];
        continue;
      }
      double t0 = (b.lo[i] - o[i]) / d[i], t1 = (b.hi[i] - o[i]) / d[i];
      if (t0 > t1) std::swap(t0, t1);
      if (t0 > t_in) {
        t_in = t0;
        face = i;
      }
      t_out = std::min(t_out, t1);
    }
    if (!miss && t_in <= t_out) h.offer(t_in, 0.25 + 0.2 * face);
  }
}
}  // namespace

std::array<double, 16> room_loop_pose(int k, int n) {
  const double a = 2.0 * M_PI * k / (n - 1), p = room::kPitch * M_PI / 180.0;
  const double ca = std::cos(a), sa = std::sin(a), cp = std::cos(p), sp = std::sin(p);
  // R = R_y(a) R_x(-p): columns are the camera's x, y, z axes in the world;
  // the optical axis R (0, 0, 1) = (sa cp, sp, ca cp) points outwards and down.
  return {ca,  -sa * sp, sa * cp, room::kOrbitRadius * sa,  //
          0,   cp,       sp,      0.0,                      //
          -sa, -ca * sp, ca * cp, room::kOrbitRadius * ca,  //
          0,   0,        0,       1};
}

LoadedFrame room_frame_at(const std::array<double, 16>& pose) {
  return ray_cast_frame(pose, [](const double o[3], const double d[3], double& gray) {
    Hit h;
    hit_walls(o, d, h);
    hit_objects(o, d, h);
    gray = h.gray;
    return h.t;
  });
}

}  // namespace sogmm::tools
