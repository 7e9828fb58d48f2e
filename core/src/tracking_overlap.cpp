// Tracking's overlap test (tracking_overlap.hpp).
#include "tracking_overlap.hpp"

#include "sogmm/model.hpp"

namespace sogmm::detail {

namespace {
// Nearer than this (metres) in front of a camera a point does not count as
// seen by it (and its projection is ill-conditioned).
constexpr double kMinSeenDepth = 0.05;

void apply(const Pose& p, const double in[3], double out[3]) {
  for (int r = 0; r < 3; ++r) out[r] = p[4 * r] * in[0] + p[4 * r + 1] * in[1] + p[4 * r + 2] * in[2] + p[4 * r + 3];
}
}  // namespace

std::vector<float> seen_points(const PointsView& points, const Pose& camera_to_world,
                               const std::vector<Pose>& seen_from, const Camera& camera, double margin) {
  std::vector<Pose> world_to_camera;
  world_to_camera.reserve(seen_from.size());
  for (auto it = seen_from.rbegin(); it != seen_from.rend(); ++it) world_to_camera.push_back(inverse_rigid(*it));
  const double u_lo = margin, u_hi = camera.width - 1 - margin, v_lo = margin, v_hi = camera.height - 1 - margin;
  std::vector<float> out;
  for (std::size_t i = 0; i < points.size; ++i) {
    const float* p = points[i];
    const double local[3] = {p[0], p[1], p[2]};
    double world[3];
    apply(camera_to_world, local, world);
    for (const Pose& q : world_to_camera) {
      double c[3];
      apply(q, world, c);
      if (!(c[2] > kMinSeenDepth)) continue;
      const double u = camera.fx * c[0] / c[2] + camera.cx, v = camera.fy * c[1] / c[2] + camera.cy;
      if (u >= u_lo && u <= u_hi && v >= v_lo && v <= v_hi) {
        out.insert(out.end(), p, p + 4);
        break;
      }
    }
  }
  return out;
}

}  // namespace sogmm::detail
