// What a map insert checks before it commits anything (issue 36): the pending
// batch it leaves must be one a flush can fit, so that no input locks the map
// (every later flush failing, and with it every save).
#include <cfloat>
#include <cmath>
#include <string>

#include "map_state.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"
#include "sogmm/mean_shift.hpp"

namespace sogmm::detail {

PointCloud batch_cloud(const std::vector<PendingFrame>& pending, const PendingFrame* extra) {
  const std::size_t groups = pending.size() + (extra ? 1 : 0);
  auto group = [&](std::size_t g) -> const PendingFrame& { return g < pending.size() ? pending[g] : *extra; };
  std::size_t n = 0;
  for (std::size_t g = 0; g < groups; ++g) n += group(g).xyzg.size();
  PointCloud cloud;
  cloud.xyzg.reserve(n);
  // One RGB-D frame's points in its own camera are a depth image's: the
  // automatic depth floor applies to them as to that frame's own fit (so
  // append-everything is the merge of the frames' fits). Points moved in from
  // other cameras do not sit on this camera's depth levels.
  cloud.from_depth_image = groups == 1 && group(0).from_rgbd;
  const Pose to_last = inverse_rigid(group(groups - 1).pose);
  for (std::size_t g = 0; g < groups; ++g) {
    const PendingFrame& p = group(g);
    if (g + 1 == groups) {
      cloud.xyzg.insert(cloud.xyzg.end(), p.xyzg.begin(), p.xyzg.end());
      continue;
    }
    const Pose rel = compose_poses(to_last, p.pose);
    for (std::size_t i = 0; i < p.xyzg.size(); i += 4) {
      const float* q = p.xyzg.data() + i;
      for (int r = 0; r < 3; ++r)
        cloud.xyzg.push_back(static_cast<float>(rel[4 * r] * q[0] + rel[4 * r + 1] * q[1] + rel[4 * r + 2] * q[2] +
                                                rel[4 * r + 3]));
      cloud.xyzg.push_back(q[3]);
    }
  }
  return cloud;
}

void require_float32_world(const std::vector<double>& world, bool from_rgbd) {
  for (std::size_t i = 0; i < world.size(); ++i)
    require(std::fabs(world[i]) <= FLT_MAX, ErrorCode::InvalidArgument,
            "map: point " + std::to_string(i / 3) + " of the frame lies at " + checked::exact(world[i]) +
                " on world axis " + std::to_string(i % 3) +
                " after the pose, beyond float32 (map coordinates are float32): check the pose" +
                (from_rgbd ? " and the intrinsics" : ""));
}

void require_flushable(const Map::State& s, const PendingFrame& novel, bool from_rgbd) {
  const std::size_t n_novel = novel.xyzg.size() / 4;
  if (n_novel == 0) return;  // the batch stays as it is
  const std::size_t n_after = s.n_pending + n_novel;
  const FitOptions& fit = s.options.fit;
  const bool triggers = !s.options.novelty || n_after >= s.options.batch_size;
  if (fit.n_components > 0) {
    // A fixed K needs K points; a batch this insert fits with fewer would
    // fail at every later attempt too.
    require(!triggers || n_after >= fit.n_components, ErrorCode::InvalidArgument,
            "map: this insert would fit a batch of " + std::to_string(n_after) + " points with the fixed K = " +
                std::to_string(fit.n_components) + " components, which needs at least K points" +
                (s.options.novelty ? ": raise the batch size to at least K" : ""));
    return;  // no mode count: its range rule does not apply
  }
  // The flush fits the batch in the camera frame of its latest frame (this
  // one) at the batch bandwidth: the mode count's range rule on exactly those
  // (float32) points decides whether it can.
  const double bandwidth = batch_bandwidth(s.options, s.pending, &novel);
  const PointCloud cloud = batch_cloud(s.pending, &novel);
  try {
    require_mode_count_range(range_gray_features(cloud.view()), bandwidth);
  } catch (const Error& e) {
    const std::string batch = s.n_pending == 0 ? "this frame's " + std::to_string(n_novel) + " new points"
                                               : "this frame's " + std::to_string(n_novel) + " new points and the " +
                                                     std::to_string(s.n_pending) + " points pending before it";
    throw Error(e.code(), "map: the batch a flush would fit (" + batch + ", in this frame's camera frame at the " +
                              "batch bandwidth " + checked::exact(bandwidth) + ") cannot be fitted: " + e.what() +
                              (s.n_pending == 0 ? std::string("; check the pose") + (from_rgbd ? " and the intrinsics" : "") +
                                                      " or the points"
                                                : "; flush (or discard the pending points) before inserting a frame this "
                                                  "far from them, or check the pose"));
  }
}

}  // namespace sogmm::detail
