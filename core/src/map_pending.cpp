// Map::pending_points (sogmm/map.hpp): the pending frames' points moved to
// the world frame.
#include "map_state.hpp"

namespace sogmm {

PointCloud Map::pending_points() const {
  const State& s = *s_;
  PointCloud out;
  out.xyzg.reserve(4 * s.n_pending);
  for (const detail::PendingFrame& p : s.pending) {
    // Each frame's pose takes its camera to the anchored frame; the origin
    // then to the world (in double, rounded once).
    for (std::size_t i = 0; i < p.xyzg.size(); i += 4) {
      const float* q = p.xyzg.data() + i;
      for (int r = 0; r < 3; ++r)
        out.xyzg.push_back(static_cast<float>(p.pose[4 * r] * q[0] + p.pose[4 * r + 1] * q[1] +
                                              p.pose[4 * r + 2] * q[2] + p.pose[4 * r + 3] + s.origin[r]));
      out.xyzg.push_back(q[3]);
    }
  }
  return out;
}

}  // namespace sogmm
