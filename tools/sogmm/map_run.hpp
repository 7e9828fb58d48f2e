// Feeding a posed RGB-D sequence into the core's incremental Map: the one
// code path behind `sogmm fit --sequence` (novelty and fusion off: append
// everything) and `sogmm map`.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "file_util.hpp"
#include "sequence.hpp"
#include "sogmm/map.hpp"
#include "sogmm/map_tracking.hpp"
#include "sogmm/registration.hpp"

namespace sogmm::tools {

/// Stage times and EM iterations of the fits one insert ran, taken from the
/// fit's progress callback (the Map reports only the total fit time).
struct FitRecord {
  int em_iterations = 0;      ///< iterations of the last EM run (the kept one when n_init is 1)
  double log_likelihood = 0;  ///< mean log-likelihood of its last iteration
  double seconds_mode_count = 0, seconds_seeding = 0, seconds_em = 0;
};

/// One inserted frame: which file, what the Map did, what its fit did.
struct MapRunFrame {
  SequenceFrame file;
  std::string label;  ///< "frame k/N (00012.png)"
  FrameStats stats;
  FitRecord fit;
  Pose pose{};               ///< the camera-to-world pose used (given or estimated)
  bool registered = false;   ///< the pose was estimated (no trajectory)
  bool skipped = false;      ///< the registration failed: the frame was not inserted
  PoseSource source = PoseSource::None;  ///< when registered: where the inserted pose came from
  RegistrationResult registration;  ///< when registered or skipped
};

/// A sequence resolved from the command line: frame files, poses, the
/// selection and the camera flags (intrinsics.json of DIR when none given).
struct SequenceInput {
  std::string dir, trajectory;
  std::vector<SequenceFrame> frames;
  std::vector<std::size_t> selected;
  std::vector<Pose> poses;  ///< poses[k]: the pose of frames[selected[k]] (poses_of_frames); empty: estimate them
  /// With poses: register each frame to the map from its given pose (a guess,
  /// e.g. odometry) instead of inserting it there (--refine-poses).
  bool refine_poses = false;
  CameraFlags camera;
};
/// Lists, reads and checks them (no trajectory: no poses, they are estimated;
/// errors name the file; a selected frame
/// without its pose -> Error(InvalidData)); images and poses are paired by
/// frame number unless src.pair_by_order (sequence.hpp).
SequenceInput resolve_sequence(const FrameSource& src, const CameraFlags& camera);

/// The files a sequence run reads that an output must not replace: the
/// trajectory and the intrinsics (--intrinsics, else DIR/intrinsics.json).
std::vector<NamedFile> sequence_inputs(const FrameSource& src, const CameraFlags& camera);

/// Inserts every selected frame into `map` in order: loads it (a missing or
/// unreadable file -> Error(Io) naming it), checks the camera against the
/// frame size (another size -> Error(InvalidData)), back-projects it with the
/// map's depth options (no valid
/// pixel -> Error(InvalidData) naming the file) and inserts it with its pose.
/// Without poses each frame's pose is estimated by the core's tracking
/// (track_backprojected of sogmm/map_tracking.hpp, with `registration`): the
/// first is the identity, the others are registered to the map from a
/// constant-velocity prediction (with in.refine_poses: from its given pose),
/// with the odometry fallback of `tracking`; a frame the tracking does not
/// insert is skipped with a warning on stderr.
/// `progress` shows each fit's stages; `after` is called after each insert.
/// Returns the camera of the frames.
Camera run_map_over_sequence(Map& map, const SequenceInput& in, ProgressPrinter& progress,
                             const std::function<void(const MapRunFrame&)>& after,
                             const RegistrationOptions& registration = {}, const TrackingOptions& tracking = {});

/// Comma-separated frame indices of the selection ("0,1,2").
std::string frame_list(const SequenceInput& in);

/// The model with this tool's producer, the creation time now and the keys
/// "sequence", "trajectory" and "frames" (frame_list) appended.
Model with_sequence_metadata(Model model, const SequenceInput& in);

}  // namespace sogmm::tools
