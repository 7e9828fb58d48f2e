// track_rgbd, its odometry rule and the constant-velocity guess
// (sogmm/map_tracking.hpp).
#include "sogmm/map_tracking.hpp"

#include <vector>

#include "sogmm/error.hpp"
#include "sogmm/model.hpp"
#include "sogmm/options.hpp"
#include "tracking_odometry.hpp"
#include "tracking_overlap.hpp"
#include "tracking_target.hpp"

namespace sogmm {

void validate(const TrackingOptions& o) {
  require_option(OptionKey::TRACKING_ODOMETRY, std::int64_t{o.odometry}, "tracking odometry");
  require_option(OptionKey::TRACKING_MAX_DISAGREEMENT, o.max_disagreement, "tracking max_disagreement");
}

const char* source_name(PoseSource source) {
  switch (source) {
    case PoseSource::None: return "none";
    case PoseSource::Guess: return "first";
    case PoseSource::Map: return "registered";
    case PoseSource::Odometry: return "odometry";
  }
  return "unknown";
}

Pose predict_constant_velocity(const Map& map) {
  const std::vector<FrameStats>& f = map.frames();
  if (f.empty()) return Pose{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  const Pose& last = f.back().pose;
  if (f.size() == 1) return last;
  const Pose motion = compose_poses(inverse_rigid(f[f.size() - 2].pose), last);  // in the last camera's frame
  return compose_poses(last, motion);
}

PoseSource decide_pose(const RegistrationResult& map, const RegistrationResult* odometry, double disagreement,
                       const RegistrationOptions& registration, const TrackingOptions& options) {
  if (map.status == RegistrationStatus::Converged) return PoseSource::Map;
  if (odometry == nullptr || odometry->status != RegistrationStatus::Converged) return PoseSource::None;
  if (disagreement <= options.max_disagreement)
    return map.status == RegistrationStatus::Degenerate ? PoseSource::Map : PoseSource::Odometry;
  return map.inlier_ratio < registration.min_inlier_ratio ? PoseSource::Odometry : PoseSource::None;
}

namespace {
// Whether `state` holds the map's last frame (the odometry's target).
bool holds_last_frame(const TrackingState& state, const Map& map) {
  return state.cells.size() > 0 && state.n_frames == map.frames().size() && state.n_frames > 0 &&
         map.frames().back().pose == state.pose;
}
}  // namespace

TrackedFrame track_rgbd(Map& map, TrackingState& state, const RgbdView& frame, const Pose& guess,
                        const RegistrationOptions& options, const TrackingOptions& tracking, int threads,
                        const ProgressSink& progress) {
  require(frame.depth != nullptr && frame.gray != nullptr, ErrorCode::InvalidArgument,
          "track: the RGB-D frame has no depth or gray image");
  const PointCloud cloud = backproject(frame, map.options().depth);
  return track_backprojected(map, state, cloud.view(), frame.camera, guess, options, tracking, threads, progress);
}

TrackedFrame track_backprojected(Map& map, TrackingState& state, const PointsView& points, const Camera& camera,
                                 const Pose& guess, const RegistrationOptions& options,
                                 const TrackingOptions& tracking, int threads, const ProgressSink& progress) {
  const std::string bad = rigid_pose_error(guess);
  require(bad.empty(), ErrorCode::InvalidArgument, "track: the guess " + bad);
  validate(options);
  validate(tracking);
  TrackedFrame t;
  t.registration.pose = guess;
  t.registration.status = RegistrationStatus::Converged;
  t.pose = guess;
  // Odometry runs only with gray: on the loop's wall views geometry-only
  // odometry converged 2.3 cm off with a non-degenerate status, which the
  // disagreement bound cannot tell from a good pose.
  const bool odometry = tracking.odometry && options.use_gray;
  auto insert_at = [&](const Pose& pose, PoseSource source) {
    t.stats = map.insert_backprojected(points, camera, pose, progress);
    t.inserted = true;
    t.source = source;
    t.pose = pose;
    // The odometry's next target (none when odometry cannot run, or when the
    // frame's cells are empty).
    state.cells = odometry ? detail::odometry_target(points) : Gmm{};
    // The pose as the map recorded it (on its precision's grid when
    // component_precision > 0), which holds_last_frame compares with.
    state.pose = map.frames().back().pose;
    state.n_frames = map.frames().size();
    return t;
  };
  if (map.size() == 0 && map.pending() == 0) return insert_at(guess, PoseSource::Guess);  // fixes the world frame

  // Only the points the map's frames have seen are registered
  // (tracking_overlap.hpp), unless they are too few to hold a pose: fewer
  // than half the frame's (a view mostly into new space) or than min_points.
  // A frame that would not be inserted (after the flush below) is registered
  // whole once more: a view of one wall, whose slides only the edges of the
  // map's wall hold, ran out of iterations without its border points (with
  // that retry on every unconverged registration instead, the loop's ATE
  // was 1.06 cm against 0.56 cm).
  std::vector<Pose> seen_from;
  seen_from.reserve(map.frames().size());
  for (const FrameStats& f : map.frames()) seen_from.push_back(f.pose);
  const std::vector<float> seen = detail::seen_points(points, guess, seen_from, camera, detail::kOverlapMarginPixels);
  const std::size_t n_seen = seen.size() / 4;
  const bool use_seen = 2 * n_seen >= points.size && n_seen >= static_cast<std::uint64_t>(options.min_points);
  const float* registered = use_seen ? seen.data() : points.data;
  const std::size_t n_registered = use_seen ? n_seen : points.size;
  auto register_to_map = [&](const float* source, std::size_t n_source) {
    t.registration =
        register_points(detail::tracking_target(map), source, n_source, guess, options, threads, progress);
    t.registered = true;
    t.pose = t.registration.pose;
  };
  // Odometry runs once, when the map first does not accept the frame (the
  // last frame does not change with a flush); its disagreement is with the
  // newest map registration.
  auto decide = [&] {
    if (t.registration.status != RegistrationStatus::Converged && odometry && !t.odometry_ran &&
        holds_last_frame(state, map)) {
      const Pose start = compose_poses(inverse_rigid(state.pose), guess);  // in the last frame's camera frame
      t.odometry = register_points(state.cells, points.data, points.size, start, options, threads, progress);
      t.odometry.pose = compose_poses(state.pose, t.odometry.pose);
      t.odometry_ran = true;
    }
    if (t.odometry_ran) t.disagreement = detail::rms_displacement(points, t.registration.pose, t.odometry.pose);
    return decide_pose(t.registration, t.odometry_ran ? &t.odometry : nullptr, t.disagreement, options, tracking);
  };
  if (map.size() == 0) {
    map.flush(progress);
    t.flushed = true;
  }
  register_to_map(registered, n_registered);
  PoseSource source = decide();
  if (source != PoseSource::Map && map.pending() > 0) {  // the newest surfaces fitted may let the map decide
    map.flush(progress);
    t.flushed = true;
    register_to_map(registered, n_registered);
    source = decide();
  }
  if (source == PoseSource::None && use_seen) {
    register_to_map(points.data, points.size);
    source = decide();
  }
  if (source == PoseSource::None) return t;
  return insert_at(source == PoseSource::Map ? t.registration.pose : t.odometry.pose, source);
}

}  // namespace sogmm
