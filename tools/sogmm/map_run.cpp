#include "map_run.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "sogmm/error.hpp"
#include "sogmm/map_tracking.hpp"
#include "sogmm/model.hpp"

namespace sogmm::tools {

namespace {
std::string base_name(const std::string& p) { return std::filesystem::path(p).filename().string(); }

// Wraps the printer's sink and records, per fit, the time spent in each
// stage (the time between two reports belongs to the earlier one's stage)
// and the last EM iteration.
ProgressSink recording(ProgressSink inner, FitRecord& record) {
  using clock = std::chrono::steady_clock;
  struct Clock {
    clock::time_point last = clock::now();
    Stage stage = Stage::Run;
    bool running = false;
  };
  auto c = std::make_shared<Clock>();
  return [inner = std::move(inner), &record, c](const Progress& p) {
    const auto now = clock::now();
    const double s = std::chrono::duration<double>(now - c->last).count();
    if (c->running && c->stage == Stage::ModeCount) record.seconds_mode_count += s;
    if (c->running && c->stage == Stage::Seeding) record.seconds_seeding += s;
    if (c->running && c->stage == Stage::Em) record.seconds_em += s;
    c->last = now;
    c->stage = p.stage;
    c->running = true;
    if (p.stage == Stage::Em) {
      record.em_iterations = static_cast<int>(p.step);
      record.log_likelihood = p.log_likelihood;
    }
    return inner ? inner(p) : false;
  };
}

// Rethrows an error of the library with the file it concerns in front.
[[noreturn]] void rethrow_naming(const Error& e, const std::string& path) { throw Error(e.code(), path + ": " + e.what()); }
}  // namespace

SequenceInput resolve_sequence(const FrameSource& src, const CameraFlags& camera) {
  SequenceInput in;
  in.dir = src.sequence;
  in.trajectory = src.trajectory;
  in.frames = list_sequence(src.sequence, src.pair_by_order);
  in.selected = parse_frame_range(src.frames.empty() ? std::string(":") : src.frames, in.frames.size());
  if (!src.trajectory.empty())
    in.poses = poses_of_frames(read_trajectory_log(src.trajectory), src.trajectory, in.frames, in.selected,
                               src.pair_by_order);
  in.camera = camera;
  if (!camera_flags_given(in.camera)) {
    const std::string guess = (std::filesystem::path(src.sequence) / "intrinsics.json").string();
    require(std::filesystem::is_regular_file(guess), ErrorCode::InvalidArgument,
            "no camera: give --intrinsics FILE (or put intrinsics.json in " + src.sequence + ")");
    in.camera.intrinsics = guess;
  }
  return in;
}

std::vector<NamedFile> sequence_inputs(const FrameSource& src, const CameraFlags& camera) {
  std::string intrinsics = camera.intrinsics;
  if (intrinsics.empty() && !src.sequence.empty())
    intrinsics = (std::filesystem::path(src.sequence) / "intrinsics.json").string();
  std::vector<NamedFile> out = {{"--intrinsics", intrinsics}};
  if (!src.trajectory.empty()) out.push_back({"--trajectory", src.trajectory});
  return out;
}

Camera run_map_over_sequence(Map& map, const SequenceInput& in, ProgressPrinter& progress,
                             const std::function<void(const MapRunFrame&)>& after,
                             const RegistrationOptions& registration, const TrackingOptions& tracking) {
  Camera camera;
  TrackingState tracking_state;
  for (std::size_t k = 0; k < in.selected.size(); ++k) {
    MapRunFrame r;
    r.file = in.frames[in.selected[k]];
    r.label = "frame " + std::to_string(k + 1) + "/" + std::to_string(in.selected.size()) + " (" +
              base_name(r.file.depth) + ")";
    const LoadedFrame frame = load_frame(r.file.depth, r.file.color);
    try {
      camera = resolve_camera(in.camera, frame);
    } catch (const Error& e) {  // e.g. a frame of another size than the camera
      rethrow_naming(e, r.file.depth);
    }
    // The tool's check first: its message names the file and the depth range.
    const PointCloud points = backproject_nonempty(frame, camera, map.options().depth, r.file.depth);
    try {
      if (!in.poses.empty() && !in.refine_poses) {
        r.pose = in.poses[k];
        r.stats = map.insert_backprojected(points.view(), camera, r.pose, recording(progress.fit_callback(r.label), r.fit));
      } else {  // the core's tracking: registered to the map from the given pose or a constant-velocity guess
        const Pose guess = in.poses.empty() ? predict_constant_velocity(map) : in.poses[k];
        const TrackedFrame t =
            track_backprojected(map, tracking_state, points.view(), camera, guess, registration, tracking, 0,
                                recording(progress.fit_callback(r.label), r.fit));
        r.registration = t.registration;
        r.registered = t.registered;
        r.source = t.source;
        r.skipped = !t.inserted;
        r.pose = t.pose;
        r.stats = t.stats;
        if (r.skipped && t.odometry_ran)
          std::fprintf(stderr,
                       "warning: %s not inserted: its registration to the map ended %s (inliers %.2f), to the last "
                       "frame %s, %.1f cm apart\n",
                       r.file.depth.c_str(), status_name(r.registration.status), r.registration.inlier_ratio,
                       status_name(t.odometry.status), 100.0 * t.disagreement);
        else if (r.skipped)
          std::fprintf(stderr, "warning: %s not inserted: its registration to the map ended %s (inliers %.2f)\n",
                       r.file.depth.c_str(), status_name(r.registration.status), r.registration.inlier_ratio);
      }
    } catch (const Error& e) {
      rethrow_naming(e, r.file.depth);
    }
    if (after) after(r);
  }
  return camera;
}

std::string frame_list(const SequenceInput& in) {
  std::string out;
  for (std::size_t i : in.selected) out += (out.empty() ? "" : ",") + std::to_string(in.frames[i].index);
  return out;
}

Model with_sequence_metadata(Model model, const SequenceInput& in) {
  model.producer_version = version_string();
  model.created_unix_ms = unix_ms_now();
  model.key_values.insert(model.key_values.end(),
                          {{"sequence", in.dir}, {"trajectory", in.trajectory}, {"frames", frame_list(in)}});
  return model;
}

}  // namespace sogmm::tools
