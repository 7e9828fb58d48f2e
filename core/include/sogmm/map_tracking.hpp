// Tracking: an RGB-D frame inserted at the pose that registration to the map
// finds (issue 32), so that a user with only an RGB-D stream gets a map.
//
// Why in the core: every front end (the CLI's `sogmm map` without
// --trajectory, the C API's sogmm_map_track_frame, Python, Rust and Go) runs
// the same rules: which target the frame is registered to, when pending
// points are flushed to serve as target, what is inserted and what is not.
//
// The target is the map's components joined by its pending points (novel
// surfaces not yet fitted), summarised as 6 cm cells of their mean and
// covariance (core/src/tracking_target.hpp): the views that leave the mapped
// space are the ones that need the newest surfaces, and without them the
// synthetic loop's errors came in steps (frames 0-99 with gray: 1.94 cm ATE
// against 0.46 cm with the cells). Pending points are flushed only when the
// map has no component yet, or when a registration against that target does
// not converge: a flush per frame would fit each frame's few novel points
// alone (thousands of small batches, a poorer map and 10x the fit time).
//
// Odometry when the map registration fails. The frame is also registered to
// the last inserted frame (its points as 4 cm cells, in its camera frame):
// on the synthetic loop the views of a checkered wall behind a box are
// flagged Degenerate against the map (eigen ratio 5e-4 to 9e-4 with gray)
// although their poses are within 5 mm, and skipping them lost track for
// good (the guess fell behind, the map stopped growing towards the views).
// Frame-to-frame with gray, every one of the loop's 299 steps converged
// within 5.1 mm (mean 0.9 mm); without gray some converged 2.3 cm off, so
// odometry runs only with gray. A frame the map does not accept is inserted
// only when the odometry converged and either agrees with the map's pose
// (within TrackingOptions::max_disagreement) or the map has too few inliers
// to judge; the rule is decide_pose() below.
//
// Only the points some inserted frame has seen are registered to the map
// (core/src/tracking_overlap.hpp; the whole frame when they are fewer than
// half of it, and once more when the frame would not be inserted): the map's edge
// components pulled a view's points in new space back into the mapped
// space, so the pose lagged behind the motion; on the loop (frames 0-299,
// gray) every error step over 2 mm before the return to the start was such
// a lag along the motion (18.5
// and 12.4 mm at frames 129 and 136 after a flush and a refit), ATE 2.55 cm,
// and 0.56 cm with the rule (0.63 cm with the one-sample free-space carve
// of MapOptions::free_space_carve; README, Registration).
//
// A converged map registration is not checked against the odometry. Before
// the rule above, on the loop, inserting at the odometry's pose whenever the two
// differed by more than 5 mm lost the track (from frame 67 every frame
// disagreed and followed the odometry, 5.8 cm off by frame 80, and 219 were
// skipped after), and a blend of the two
// weighted by their information raised the ATE from 2.53 to 3.32 cm.
#pragma once

#include <cstdint>
#include <cstddef>

#include "sogmm/camera.hpp"
#include "sogmm/map.hpp"
#include "sogmm/registration.hpp"

namespace sogmm {

/// How tracking uses odometry (the option registry's TRACKING_* rows).
struct TrackingOptions {
  /// Register a frame the map does not accept to the last inserted frame too
  /// (frame-to-frame odometry) and insert it when decide_pose() allows.
  /// Only with RegistrationOptions::use_gray (geometry alone let the
  /// odometry converge centimetres off on a wall). false, or without gray: a
  /// frame is inserted only when its map registration converged.
  bool odometry = true;
  /// Largest RMS distance (metres) between a frame's points placed by the
  /// map's pose and by the odometry's for the two to agree. > 0, finite.
  double max_disagreement = 0.02;
};

/// Throws Error(InvalidArgument) naming the first bad setting.
void validate(const TrackingOptions& options);

/// What tracking keeps between frames of one map: the last frame it
/// inserted, as the odometry's target. Fresh (empty) for a new map; a state
/// whose frame is not the map's last one (another insert, a loaded map) is
/// not used and is replaced by the next frame tracking inserts.
struct TrackingState {
  Gmm cells;                 ///< the frame's points as cells (in its camera frame); empty: nothing yet
  Pose pose{};               ///< its camera-to-world pose
  std::size_t n_frames = 0;  ///< map.frames().size() right after its insert
};

/// Where an inserted frame's pose came from.
enum class PoseSource : std::int32_t {
  None = 0,      ///< not inserted
  Guess = 1,     ///< the map's first frame: the guess
  Map = 2,       ///< the registration to the map
  Odometry = 3,  ///< the registration to the last inserted frame
};

/// Name of a source ("none", "first", "registered", "odometry": the CLI's
/// CSV words).
const char* source_name(PoseSource source);

/// What track_rgbd() did with one frame.
struct TrackedFrame {
  /// The frame's registration to the map. For the map's first frame there is
  /// nothing to register to: registered is false, registration.pose is the
  /// guess and its status Converged.
  RegistrationResult registration;
  bool registered = false;  ///< a registration ran (false: the map's first frame)
  /// The registration to the last inserted frame (when odometry_ran), its
  /// pose composed into camera-to-world.
  RegistrationResult odometry;
  bool odometry_ran = false;
  /// RMS distance (m) between the frame's points at the two poses (when
  /// odometry_ran; else 0).
  double disagreement = 0.0;
  PoseSource source = PoseSource::None;
  /// The pose the frame was inserted at; when not inserted, the map
  /// registration's last iterate.
  Pose pose{};
  bool inserted = false;    ///< the frame was inserted at pose
  bool flushed = false;     ///< pending points were flushed to serve as the target
  FrameStats stats;         ///< the insert's figures (when inserted)
};

/// The rule for a frame, from its map registration `map` and (when
/// `odometry` is not null) its odometry, whose disagreement is
/// `disagreement` (metres):
/// - the map's status is Converged: Map;
/// - otherwise nothing unless the odometry is Converged; then, when the two
///   agree (disagreement <= options.max_disagreement): Map if the map's
///   status is Degenerate (the map holds the directions it sees, the
///   odometry vouches for the ones it does not), else Odometry (LowFitness,
///   NotConverged: the map's pose is poorly supported);
/// - when they do not agree: Odometry if the map has too few inliers to
///   judge (inlier ratio below registration.min_inlier_ratio), else None.
PoseSource decide_pose(const RegistrationResult& map, const RegistrationResult* odometry, double disagreement,
                       const RegistrationOptions& registration, const TrackingOptions& options);

/// The constant-velocity guess for the next frame of a map: its last frame's
/// camera-to-world pose followed by the motion between its last two frames
/// (the last frame's pose when it has one frame; the identity when none).
/// Frames are assumed evenly spaced in time: a caller that skips frames
/// passes its own guess.
Pose predict_constant_velocity(const Map& map);

/// Registers the frame's points (backproject() with map.options().depth)
/// to the map (its components and pending points) from `guess`
/// (camera-to-world) and inserts the frame when the registration's status is
/// Converged. When it is not and `state` holds the map's last frame, the
/// frame is also registered to that frame from `guess` (odometry: with
/// tracking.odometry and options.use_gray) and inserted where decide_pose()
/// says; before
/// a frame is given up, pending points are flushed and the map registration
/// runs again. A frame that is not inserted leaves the map with only the
/// flush this call may have run: the caller reads why in the result. The
/// map's first frame (no component and nothing pending) is inserted at
/// `guess`. `state` becomes the inserted frame.
/// Errors: as Map::insert_rgbd (the camera rule, no valid pixel),
/// register_points (fewer than options.min_points points, a guess that is
/// not rigid), validate(TrackingOptions) and Map::flush; `progress` reports
/// and may cancel the flush, the registrations and the insert's fit
/// (Error(Cancelled)).
TrackedFrame track_rgbd(Map& map, TrackingState& state, const RgbdView& frame, const Pose& guess,
                        const RegistrationOptions& options = {}, const TrackingOptions& tracking = {},
                        int threads = 0, const ProgressSink& progress = {});

/// track_rgbd for a frame already back-projected (`points` = backproject()
/// of an image of `camera` with map.options().depth), as
/// Map::insert_backprojected.
TrackedFrame track_backprojected(Map& map, TrackingState& state, const PointsView& points, const Camera& camera,
                                 const Pose& guess, const RegistrationOptions& options = {},
                                 const TrackingOptions& tracking = {}, int threads = 0,
                                 const ProgressSink& progress = {});

}  // namespace sogmm
