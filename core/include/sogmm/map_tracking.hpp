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
#pragma once

#include "sogmm/camera.hpp"
#include "sogmm/map.hpp"
#include "sogmm/registration.hpp"

namespace sogmm {

/// What track_rgbd() did with one frame.
struct TrackedFrame {
  /// The frame's registration to the map. For the map's first frame there is
  /// nothing to register to: registered is false, registration.pose is the
  /// guess and its status Converged.
  RegistrationResult registration;
  bool registered = false;  ///< a registration ran (false: the map's first frame)
  bool inserted = false;    ///< the frame was inserted at registration.pose
  bool flushed = false;     ///< pending points were flushed to serve as the target
  FrameStats stats;         ///< the insert's figures (when inserted)
};

/// The constant-velocity guess for the next frame of a map: its last frame's
/// camera-to-world pose followed by the motion between its last two frames
/// (the last frame's pose when it has one frame; the identity when none).
/// Frames are assumed evenly spaced in time: a caller that skips frames
/// passes its own guess.
Pose predict_constant_velocity(const Map& map);

/// Registers the frame's points (backproject() with map.options().depth) to
/// the map (its components and pending points) from `guess` (camera-to-world) and inserts the frame at the
/// registered pose when the registration's status is Converged. A frame
/// whose registration ends otherwise (not converged, low fitness,
/// degenerate) is not inserted: the caller reads why in the result, and the
/// map keeps only the flush this call may have run. The map's first frame
/// (no component and nothing pending) is inserted at `guess`.
/// Errors: as Map::insert_rgbd (the camera rule, no valid pixel),
/// register_points (fewer than options.min_points points, a guess that is
/// not rigid) and Map::flush; `progress` reports and may cancel the flush,
/// the registration and the insert's fit (Error(Cancelled)).
TrackedFrame track_rgbd(Map& map, const RgbdView& frame, const Pose& guess, const RegistrationOptions& options = {},
                        int threads = 0, const ProgressSink& progress = {});

/// track_rgbd for a frame already back-projected (`points` = backproject()
/// of an image of `camera` with map.options().depth), as
/// Map::insert_backprojected.
TrackedFrame track_backprojected(Map& map, const PointsView& points, const Camera& camera, const Pose& guess,
                                 const RegistrationOptions& options = {}, int threads = 0,
                                 const ProgressSink& progress = {});

}  // namespace sogmm
