// Internals of sogmm::Map shared by map.cpp (insert, flush), map_novelty.cpp
// (the local 3-D likelihood), map_fusion.cpp (component fusion) and
// map_provenance.cpp (file keys). Never installed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <unordered_set>
#include <vector>

#include "map_depth_view.hpp"
#include "map_journal.hpp"
#include "map_renders.hpp"
#include "sogmm/map.hpp"

namespace sogmm::detail {

/// The 3-D marginal of one component, prepared for log N(x | mu, Sigma_xx):
/// log N = log_norm - |Linv (x - mu)|^2 / 2 with Linv the inverse of the
/// Cholesky factor of Sigma_xx (lower triangle, row-major: l00 l10 l11 l20
/// l21 l22). log_count = log(weight x support size): invariant under merge(),
/// which rescales old weights by S_old / S_new, so entries stay valid as the
/// map grows.
struct Marginal3 {
  double mu[3];
  double linv[6];
  double log_norm;
  double log_count;
};

/// Marginal3 of component m of `gmm` (Error(Numeric) if Sigma_xx is not
/// positive definite in double, which validate(Gmm) rules out).
Marginal3 marginal3(const Gmm& gmm, std::size_t m);

/// What the novelty test searches in a model: its component index and each
/// component's Marginal3 (one per component, in order).
struct Searches {
  ComponentIndex index;
  std::vector<Marginal3> marginals;
};

/// The Searches of `gmm`, its index built with `index_sigmas`.
Searches searches_of(const Gmm& gmm, double index_sigmas);

/// log N(x | component) of a world point.
inline double log_density(const Marginal3& c, const double x[3]) {
  const double d0 = x[0] - c.mu[0], d1 = x[1] - c.mu[1], d2 = x[2] - c.mu[2];
  const double z0 = c.linv[0] * d0;
  const double z1 = c.linv[1] * d0 + c.linv[2] * d1;
  const double z2 = c.linv[3] * d0 + c.linv[4] * d1 + c.linv[5] * d2;
  return c.log_norm - 0.5 * (z0 * z0 + z1 * z1 + z2 * z2);
}

/// Local submap log-likelihood (map.hpp, header comment) of n world points
/// (3 doubles each) into out (n doubles). With `dominant`, also each point's
/// dominant component into it (n ids): the one with the largest term
/// weight x N(x | mu, Sigma_xx) among those whose box holds the point (ties:
/// the lowest id), -1 where none does.
void local_log_likelihood(const ComponentIndex& index, const std::vector<Marginal3>& marginals, int threads,
                          const double* xyz, std::size_t n, double* out, std::int64_t* dominant = nullptr);

/// Fuses the components [first, gmm.size()) of `gmm` into the close
/// components of [0, first) (found through `index`, which covers exactly
/// those) as MapOptions say; removes the fused ones from `gmm`. Returns the
/// ids (< first) of the components that changed, ascending and unique.
std::vector<std::size_t> fuse_new_components(Gmm& gmm, std::size_t first, const ComponentIndex& index,
                                             const MapOptions& options);

/// Edge (m) of the world voxels that remember where pending points lie. A
/// point is taken as pending when a pending point lies in its voxel or one of
/// the 26 around it, i.e. within 1 to 3.5 cm: more than the spacing of a
/// frame decimated by 5 at 2 m (1.9 cm: 525 / 5 pixels per radian), so a new
/// view of a pending surface finds it, and less than the size of the
/// components the fit will give that surface.
inline constexpr double kPendingVoxel = 0.01;

/// A pending voxel: floor(coordinate / kPendingVoxel) per axis, kept in double
/// so that every finite world coordinate (any float32 pose, ~3.4e40 voxels)
/// has its own key: a packed 64-bit key held only +-2^20 voxels (+-10 km), and
/// beyond it no point was ever taken as pending (issue 36: the same frame
/// inserted again at 500 km grew the map). Integers are exact in double up to
/// 2^53 voxels (9e13 m); beyond, a neighbour may round onto the voxel itself,
/// which only widens what counts as near.
struct PendingVoxel {
  double v[3];
  bool operator==(const PendingVoxel& o) const { return v[0] == o.v[0] && v[1] == o.v[1] && v[2] == o.v[2]; }
};
struct PendingVoxelHash {
  std::size_t operator()(const PendingVoxel& k) const;
};
using PendingVoxelSet = std::unordered_set<PendingVoxel, PendingVoxelHash>;

/// The voxel of world point `xyz` (finite).
PendingVoxel pending_voxel(const double xyz[3]);
/// Whether a pending point lies in the voxel or one of its 26 neighbours.
bool near_pending(const PendingVoxelSet& voxels, const PendingVoxel& voxel);

/// The provenance lines (kMapFramesKey format) of frames [first, end).
std::string frames_text(const std::vector<FrameStats>& frames, std::size_t first = 0);
/// Frames from provenance lines whose indices run from first_index; a
/// malformed line -> Error(Format) naming `key` and the line.
std::vector<FrameStats> parse_frames(const std::string& text, std::uint64_t first_index = 0,
                                     const char* key = kMapFramesKey);

/// Grid (m) of the default origin: the first frame's translation rounded to
/// a multiple of it per axis. A map whose first frame is within 500 m of the
/// world origin keeps the origin 0 (components, files and results as before
/// anchors existed); 500 m from its origin a float32 coordinate still moves
/// in steps of 30 um.
inline constexpr double kOriginGrid = 1000.0;

/// The origin a map takes from its first frame's pose (map_anchor.cpp).
Origin default_origin(const Pose& first_pose);
bool is_zero(const Origin& origin);
/// `camera_to_world` as a camera-to-anchored-frame pose: translation minus
/// the origin, in double.
Pose anchored(const Origin& origin, const Pose& camera_to_world);
/// The world-frame model of a map held relative to `origin` (means moved by
/// it, rounded to float32; no pose). Error(InvalidArgument) for a mean beyond
/// float32.
Model world_frame(const Model& anchored_model, const Origin& origin);
/// Takes the pose off a world-frame model: its translation is returned as the
/// origin, its rotation (if any) applied to the components.
Origin split_origin(Model& model);
/// Error(InvalidArgument) naming the axis unless every entry is finite and
/// within float32 range.
void require_origin(const Origin& origin);

/// A revisit refit worked out but not committed (map_revisit.cpp).
struct RevisitRefit {
  std::vector<std::size_t> replaced;  ///< map components the frame sees (ascending), to be replaced
  double bandwidth = 0.0;             ///< the fit's bandwidth (the batch bandwidth)
  FitResult fit;                      ///< in the frame's camera frame
};

/// Novel points of one frame waiting for a fit, in that frame's camera frame.
struct PendingFrame {
  Pose pose{};
  bool from_rgbd = false;
  std::vector<float> xyzg;
};

/// The points a flush fits: every pending frame (and `extra`, when given, as
/// the latest) moved into the camera frame of the latest one, in float32;
/// from_depth_image when they are one RGB-D frame's.
PointCloud batch_cloud(const std::vector<PendingFrame>& pending, const PendingFrame* extra = nullptr);

/// The share of the ordered point pairs of a batch (the pending frames, and
/// `extra` when given) whose two points come from the same frame:
/// h = sum n_f^2 / N^2 (1 for one frame, 1/F for F frames of equal size).
double same_view_share(const std::vector<PendingFrame>& pending, const PendingFrame* extra = nullptr);

/// The bandwidth the batch of `pending` (and `extra`) is fitted with:
/// bandwidth x (s + (1 - s) h^2), s = novelty_bandwidth_scale and h =
/// same_view_share; the bandwidth itself with novelty off.
double batch_bandwidth(const MapOptions& options, const std::vector<PendingFrame>& pending,
                       const PendingFrame* extra = nullptr);

/// The bandwidth a revisit refit is fitted with (map_revisit.cpp): bandwidth
/// x s, s = novelty_bandwidth_scale. A refit pools the frame's points with
/// samples of the replaced components' mass from many views, so it keeps
/// the pooled batches' scale (fitting it at the bandwidth itself, or by the
/// frame's share of its points, cost the 300-frame loop 1.5-2.7 dB of
/// held-out PSNR on its worst frame: README, section 6).
double refit_bandwidth(const MapOptions& options);

/// Error(InvalidArgument) naming the point and axis unless every world
/// coordinate (3 per point) of a frame is within float32 range.
void require_float32_world(const std::vector<double>& world, bool from_rgbd);

/// Throws, naming the cause, unless the batch pending after `novel` joins it
/// is one a flush can fit: with a fixed K, at least K points when this insert
/// triggers the fit (Error(InvalidArgument)); else the mode count's range
/// rule (require_mode_count_range, Error(Limit)) on the batch in `novel`'s
/// camera frame at the batch bandwidth. Nothing changes.
void require_flushable(const Map::State& s, const PendingFrame& novel, bool from_rgbd);

}  // namespace sogmm::detail

namespace sogmm {

struct Map::State {
  MapOptions options;
  Model model;                 ///< the map relative to `origin`; gmm empty until the first flush
  /// The anchor: components, index, marginals, pending frames (their poses
  /// too) and the previous fit are all relative to it (map_anchor.cpp).
  Origin origin{};
  bool origin_fixed = false;   ///< by the first frame, set_origin or a load
  /// model moved to the world frame (Map::model), kept only when the origin
  /// is not 0 (else model is the world-frame model itself).
  Model world;
  ComponentIndex index;
  std::vector<detail::Marginal3> marginals;  ///< one per component of model.gmm
  std::vector<detail::PendingFrame> pending;
  std::size_t n_pending = 0;
  /// pending_voxel of every pending point: a later point in one of these
  /// voxels is already waiting for the fit and is not novel again.
  detail::PendingVoxelSet pending_voxels;
  std::vector<FrameStats> frames;
  std::uint64_t n_flushes = 0;
  std::uint64_t n_fused = 0;
  std::uint64_t n_refits = 0;
  std::optional<Camera> camera;  ///< fixed by the first RGB-D frame
  /// options.warm_start: the last flush's fit in its camera frame, and that
  /// camera's pose (empty before the first flush).
  Gmm previous_fit;
  Pose previous_pose{};
  /// Bumped whenever the components change (a flush, a revisit refit or its
  /// undo): what is kept about them (renders) is valid for one revision.
  std::uint64_t revision = 0;
  mutable detail::FrameRenders renders;  // filled by const queries (Map::frame_depth)
  /// The observed depth of every RGB-D frame inserted since the map was
  /// created or loaded, with free_space_carve on (not saved): new components
  /// are carved by all of them (detail::carve_by_seen_frames). 4 bytes per
  /// pixel of the decimated camera a frame (48 KiB at 128 x 96).
  std::vector<detail::SeenFrame> seen_frames;
  /// The public revision and the changes deltas are cut from
  /// (sogmm/map_delta.hpp); unlike `revision` it also counts frames.
  detail::Journal journal;
  explicit State(const MapOptions& o) : options(o), index(o.index_sigmas) {
    journal.map_id = detail::new_map_id();
    journal.history = o.delta_history;
  }
};

}  // namespace sogmm

namespace sogmm::detail {

/// The revisit refit of one frame (MapOptions::revisit_refit_ratio), fitted
/// but not committed, or nothing when it does not apply: novelty off, ratio
/// 0, no camera (points-only inserts), an empty map, no map component on the
/// frame's surfaces, no explained point, fewer modes than the ratio asks, or
/// too much mass to sample. `points` is the frame in its camera frame, `ll`
/// and `dominant` their novelty scores and dominant components
/// (local_log_likelihood). A cancel propagates (nothing has changed).
std::optional<RevisitRefit> plan_revisit_refit(const Map::State& s, const PointsView& points, const Pose& pose,
                                               const std::vector<double>& ll,
                                               const std::vector<std::int64_t>& dominant, std::uint64_t frame_index,
                                               const ProgressSink& progress);

/// Whether inserts carve (MapOptions::free_space_carve): novelty on, a share
/// above 0, no warm start.
bool carving(const MapOptions& o);

/// The free-space carve of one RGB-D frame (MapOptions::free_space_carve):
/// the ids (ascending) of the map components it reshapes, and in `carved` the
/// map's mixture with them reshaped (weights unchanged). Nothing when it does
/// not apply: novelty off, share 0, a warm start, an empty map.
std::vector<std::size_t> plan_free_space_carve(const Map::State& s, const SeenFrame& frame, Gmm& carved);

/// The components of `batch` (new ones, in the map's frame) carved by every
/// RGB-D frame the map has seen (State::seen_frames), in insert order: a
/// component fitted from later views is held to the free space of earlier
/// ones. Nothing when the carve does not apply.
void carve_by_seen_frames(const Map::State& s, Gmm& batch);

/// Error(InvalidArgument) naming both cameras when the map has a camera
/// (fixed by its first RGB-D frame) and `camera` differs from it; `what`
/// names the newcomer ("frame camera").
void require_map_camera(const Map::State& s, const Camera& camera, const char* what = "frame camera");

/// `gmm` without the components `removed`; the others keep their mass in
/// points (weights renormalised, support size scaled). Empty when all go.
Gmm without_components(const Gmm& gmm, const std::vector<std::size_t>& removed);

}  // namespace sogmm::detail
