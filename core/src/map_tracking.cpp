// track_rgbd and the constant-velocity guess (sogmm/map_tracking.hpp).
#include "sogmm/map_tracking.hpp"

#include "sogmm/error.hpp"
#include "sogmm/model.hpp"
#include "tracking_target.hpp"

namespace sogmm {

Pose predict_constant_velocity(const Map& map) {
  const std::vector<FrameStats>& f = map.frames();
  if (f.empty()) return Pose{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  const Pose& last = f.back().pose;
  if (f.size() == 1) return last;
  const Pose motion = compose_poses(inverse_rigid(f[f.size() - 2].pose), last);  // in the last camera's frame
  return compose_poses(last, motion);
}

TrackedFrame track_rgbd(Map& map, const RgbdView& frame, const Pose& guess, const RegistrationOptions& options,
                        int threads, const ProgressSink& progress) {
  require(frame.depth != nullptr && frame.gray != nullptr, ErrorCode::InvalidArgument,
          "track: the RGB-D frame has no depth or gray image");
  const PointCloud cloud = backproject(frame, map.options().depth);
  return track_backprojected(map, cloud.view(), frame.camera, guess, options, threads, progress);
}

TrackedFrame track_backprojected(Map& map, const PointsView& points, const Camera& camera, const Pose& guess,
                                 const RegistrationOptions& options, int threads, const ProgressSink& progress) {
  const std::string bad = rigid_pose_error(guess);
  require(bad.empty(), ErrorCode::InvalidArgument, "track: the guess " + bad);
  validate(options);
  TrackedFrame t;
  t.registration.pose = guess;
  t.registration.status = RegistrationStatus::Converged;
  if (map.size() == 0 && map.pending() == 0) {  // the first frame fixes the world frame
    t.stats = map.insert_backprojected(points, camera, guess, progress);
    t.inserted = true;
    return t;
  }
  auto register_to_map = [&] {
    t.registration =
        register_points(detail::tracking_target(map), points.data, points.size, guess, options, threads, progress);
    t.registered = true;
  };
  if (map.size() == 0) {
    map.flush(progress);
    t.flushed = true;
  }
  register_to_map();
  if (t.registration.status != RegistrationStatus::Converged && map.pending() > 0) {
    map.flush(progress);
    t.flushed = true;
    register_to_map();
  }
  if (t.registration.status != RegistrationStatus::Converged) return t;
  t.stats = map.insert_backprojected(points, camera, t.registration.pose, progress);
  t.inserted = true;
  return t;
}

}  // namespace sogmm
