// An incremental world map: frames are inserted with their camera-to-world
// pose; only the part of each frame that the map does not yet explain is
// fitted and added (issue 18).
//
// Pipeline of one insert:
// 1. novelty (option): every point, moved to the world frame, is scored with
//    the 3-D marginal log-likelihood of its neighbourhood in the map: the
//    components whose sigma box (ComponentIndex) holds the point, with their
//    weights renormalised over that neighbourhood. A component outside its
//    box is beyond Mahalanobis distance 3 and contributes at most exp(-4.5)
//    of its peak, which is left out. The authors' scripts renormalise over
//    every component near any point of the frame instead; at room scale that
//    is most of the map, so their score falls with how much of the map is in
//    view (the log of the in-view share of the map's mass) and 3.0 became the
//    median score of already mapped points. Renormalised per point, the score
//    is the log-density (per m^3) of the surfaces the map holds right there,
//    whatever else is in view: high on mapped surfaces (a surface component
//    of 2 x 2 cm and 3 mm peaks near 11), low off them or where the map is
//    only a blur. Points scoring below the threshold, and not within a voxel
//    (1 cm, and its 26 neighbours) of a point already pending, are novel and
//    become pending; the others are dropped.
// 2. flush: once batch_size points are pending (or at flush()), the pending
//    points are fitted with the usual self-organizing fit (sogmm/fit.hpp; with
//    novelty on, at the bandwidth times a scale, MapOptions::novelty_bandwidth_scale) in
//    the camera frame of the latest frame that contributed to the batch, moved
//    to the world frame by its pose and merged into the map (merge() of
//    sogmm/model.hpp: weights by support size, metadata by spec/format.md 2.2).
// 3. fusion (option): each new component whose distance (Hellinger or
//    symmetric KL, full 4-D) to an overlapping map component is below the
//    threshold is merged into the nearest such component by moment matching
//    (mass, mean and covariance of the pair kept) instead of being appended.
//    Effect on likelihood: the fused Gaussian keeps the pair's mass and first
//    two moments, so samples and the mixture's total mean and covariance do
//    not change (to float rounding), while two peaks become one: the
//    likelihood of points between and on them changes little when the pair is
//    close. Measured in tests/core/test_map.cpp
//    (MapTest.FusionKeepsMomentsAndCostsLittleLikelihood; the same surfaces
//    seen twice 3 mm apart): 410 -> 227 components (Hellinger < 0.3) or 250
//    (symmetric KL < 0.2) at a mean 4-D log-likelihood of held-out points of
//    6.6965 -> 6.6975 / 6.6969 nats: no loss there; a loose pair (large
//    threshold) loses more.
//
// With novelty and fusion off, every insert fits its whole frame on its own in
// the camera frame, moves it with the pose and merges it: exactly what `sogmm
// fit --sequence` did (append everything), component for component.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sogmm/camera.hpp"
#include "sogmm/component_index.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/model.hpp"
#include "sogmm/point_cloud.hpp"

namespace sogmm {

struct MapDelta;  // sogmm/map_delta.hpp

/// Row-major 4 x 4 rigid transform [R t; 0 0 0 1] (camera-to-world).
using Pose = std::array<double, 16>;
/// A point of the world frame (x, y, z in metres), in double.
using Origin = std::array<double, 3>;

/// How fusion measures the distance of two components (full 4-D Gaussians).
enum class FusionMethod {
  Hellinger,  ///< H = sqrt(1 - BC), BC the Bhattacharyya coefficient; in [0, 1]
  KL,         ///< symmetric KL, (KL(a||b) + KL(b||a)) / 2, in nats; >= 0
};

/// Parameters of a map. The defaults are the authors' (novelty 3.0, batch of
/// one decimated frame, 12,288 points at d = 5 on 640 x 480), fusion off.
struct MapOptions {
  bool novelty = true;              ///< false: every point is novel (append everything)
  /// Nats: a point is novel when its neighbourhood's 3-D log-density (see
  /// the header comment; per m^3) is below this. The default 3.0 is the
  /// authors' number; with the score per point it flags points outside every
  /// component's box and points the map explains only by a blur (a density
  /// below e^3 per m^3: e.g. 2.9 sigma from a 5 x 5 x 2 cm component).
  double novelty_threshold = 3.0;
  std::size_t batch_size = 12288;   ///< pending points that trigger a flush, in [1, kMaxPoints]
  FitOptions fit;                   ///< the fit of each batch (fit.em.threads also runs the novelty test)
  /// With novelty on, a batch of novel points that pools the slivers of many
  /// frames is fitted with fit.bandwidth times this, in (0, 1], and a batch
  /// that is mostly one frame's view with nearly fit.bandwidth (the rule is
  /// below; a revisit refit uses this scale itself). (With novelty off each frame is
  /// fitted with fit.bandwidth itself, so append-everything is `sogmm fit
  /// --sequence`.) A frame's own fit serves one view; a map component serves
  /// every later view of its surface, closer ones too, and a batch pools the
  /// novel slivers of ~40 frames, which share (range, gray) modes: at the
  /// frame's bandwidth a batch got about one frame's worth of components
  /// (137 against 113) for a far larger area. On the synthetic loop, every
  /// third frame scored against its own fit (tools/sogmm-perf/map_loop.py
  /// --accuracy-step 3): at scale 1, 49 of 101 frames lose more than 0.5 dB
  /// (worst 3.50 dB, median 0.41 dB); at 0.7 (0.014 for the default 0.02),
  /// 8 of 101 (worst 2.04 dB, frames 6-27 next to the first frame's batch;
  /// median -1.08 dB: the map is better), at 4.9% of append-everything's
  /// components (before revisit_refit_ratio, which fixes frames 6-27).
  /// Scaling only the batches of several frames did less.
  /// The scale applies in proportion to how much a batch pools views: a
  /// batch is fitted at fit.bandwidth x (s + (1 - s) h^2), s this scale and
  /// h = sum n_f^2 / N^2 the share of its point pairs from one frame (n_f
  /// points of frame f, N in all): a batch of one frame (h = 1, a map's
  /// first insert) gets the bandwidth itself, as that frame's own fit; the
  /// slivers of many frames (h ~ 0.1-0.2) stay within 1% of s. On livingroom
  /// frames 0-2 (one batch, h = 0.73, 0.861 x 0.02) the map keeps 904 of
  /// append-everything's 1877 components (48%, 1251 at s alone).
  double novelty_bandwidth_scale = 0.7;
  DepthOptions depth;               ///< back-projection of insert_rgbd frames
  bool fusion = false;              ///< fuse new components into close map components
  FusionMethod fusion_method = FusionMethod::Hellinger;
  double fusion_threshold = 0.3;    ///< fuse when the distance is below this (method's unit), > 0
  double index_sigmas = ComponentIndex::kDefaultSigmas;  ///< box radius of the index, (0, 100]
  /// Warm-start each flush's fit from the previous flush's model moved into
  /// this batch's camera frame (fit_warm, sogmm/warm_start.hpp) instead of a
  /// cold fit. Meant for novelty off, where a batch is one whole frame and
  /// consecutive frames overlap; needs fit.n_init == 1.
  bool warm_start = false;
  /// Revisit refit, with novelty on and RGB-D inserts (the camera tells
  /// what a frame sees): the map components whose mean lies on the frame's
  /// observed surface (depth within 3% of the frame's at its pixel) are
  /// replaced when the frame's explained points that they dominate (largest
  /// weight x density among the point's neighbourhood) have at least this
  /// many times as many modes (mean shift at the batch bandwidth) as they are
  /// components. The replacement is a fit of those points plus
  /// samples (untruncated) of the replaced mass that the frame does not see:
  /// outside its view, hidden behind its surfaces or where it has no depth,
  /// as many as the points that mass stands for; samples in its free space
  /// are dropped, and so is the replaced mass on its surfaces where a kept
  /// component dominates (those points stay that component's). Other
  /// components keep their mass. So the map keeps the
  /// finest view of each surface it has had, not the first: the mode count
  /// of a view varies with the view (52 modes for the synthetic loop's first
  /// frame, which faces a wall, against 191 for frame 12 of nearly the same
  /// surfaces), and without the refit a coarse first view fixed the map there
  /// for good (loop, every third frame against its own fit: the worst frame
  /// 2.04 dB below without, every frame at least 0.39 dB above with, at 8.1%
  /// of append-everything's components; tools/sogmm-perf/map_loop.py). No refit with a fixed K (fit.n_components > 0:
  /// no mode count to compare), with warm_start (whose restore after a load
  /// assumes a map grown by appends only) or for insert_points (no camera). A refit whose fit fails on the
  /// data (a limit, a numeric failure) is skipped and the map kept; a cancel
  /// propagates and undoes the insert. The check (one mode count) reports no
  /// progress. 0 = off; else >= 1. The ratio is also a hysteresis: the
  /// mode count of the same surface seen again varies by a few percent, and
  /// only a count above the ratio runs a refit (a lower one never removes
  /// what an earlier refit added), so at 1 a map can creep on the same data
  /// (the loop's map, 16 laps of the same frames: 2221 to 2451 components,
  /// +10%); 1.25 asks for a quarter more detail than the map has there,
  /// beyond that variation (MapTest.RevisitRefitAtTheDefaultRatioDoesNot-
  /// CreepOnRepeats).
  double revisit_refit_ratio = 1.25;
  /// Free-space carve (issue 29): an RGB-D insert reshapes each map component
  /// on the frame's surfaces that has at least this share of a fixed set of
  /// 256 samples (whitened standard normals moved by the component) where the
  /// frame sees past them at their pixel and its 8 neighbours: the
  /// component's mean and covariance become the moments of its other samples,
  /// its weight stays. Why: a flat component fitted to a patch of surface has
  /// the patch's edge at about 1.7 sigma, and the renderer's first surface
  /// stops rays out to 3 sigma; where the patch's edge is an outline from
  /// another view, the tail hangs in space that other views see through. On
  /// the 300-frame loop those tails were the frames whose rendered depth was
  /// more than 1 mm worse than their own fits' (rays stopped 0.7-1 m early
  /// beside the boxes' outlines). A component needs some samples on the
  /// frame's surface and keeps at least half of them. New components (each
  /// flush and revisit refit) are carved by every RGB-D frame inserted since
  /// the map was created or loaded, whose depth on the decimated grid the map
  /// keeps for that (4 bytes a pixel a frame, not saved). 0: off (and no
  /// depth kept); ignored with warm_start (its restore assumes a map that
  /// only grows by appends). Default 0.002: one sample of the 256 (the
  /// share is rounded up to whole samples). Each carve then drops the few
  /// samples a view sees through, so repeated views trim a tail out to
  /// about 3 sigma, where the renderer stops looking; at 0.01 (3 samples)
  /// the trimming stopped near 2.3 sigma, and rays past an outline still
  /// stopped at tails 2-3 sigma out (the loop's frame 279, +1.37 mm against
  /// its own fit; at 0.002 every frame of the loop and of livingroom 0-2 is
  /// within the bounds: README, section 6).
  double free_space_carve = 0.002;
  /// How many of its latest revisions a map keeps the changes of, so that
  /// deltas (sogmm/map_delta.hpp) can be cut from any of them: 0 keeps every
  /// revision since the map was created or loaded (memory grows with every
  /// fit: each explicit component it ever fitted is kept); N keeps the last
  /// N, so a robot that streams deltas to receivers at most N revisions
  /// behind holds a bounded record. A delta from an older revision is then
  /// refused naming the oldest one kept (a receiver that far behind takes
  /// the whole map instead).
  std::uint64_t delta_history = 0;
  /// Each fitted component is rounded, before the map stores it, to grids
  /// that move it by at most this many of its own standard deviations (mean)
  /// and this relative change of its covariance's eigenvalues in its own
  /// frame (detail::round_to_precision, core/src/component_precision.hpp,
  /// states the bounds): the low mantissa bits of its floats become zero, so
  /// a delta's (and a map file's) arrays compress better, and a receiver
  /// gets the same bits as the sender, as the rounding happens before the
  /// component is recorded. 0 = off (full float32); in [0, 0.5]. Off by
  /// default: on the synthetic loop 0.25 cuts the mean delta by 34% (9,390
  /// to 6,202 bytes) with held-out PSNR inside the map's seed spread, but an
  /// F-score at 1 cm 0.001-0.004 lower on two seeds (README section 8).
  /// `sogmm map` also writes its file with WriteOptions::component_precision
  /// at this value (quantized arrays, spec/format.md 5.7).
  double component_precision = 0.0;
};

/// Throws Error(InvalidArgument) naming the field unless every option is in
/// range: finite threshold, batch_size in [1, kMaxPoints] (and, with novelty
/// and a fixed K, at least fit.n_components), fusion_threshold
/// finite and > 0, index_sigmas in (0, 100], fit bandwidth usable, a valid
/// DepthOptions (validate in sogmm/camera.hpp).
void validate(const MapOptions& options);

/// What happened to one inserted frame.
struct FrameStats {
  std::uint64_t index = 0;          ///< insertion order, from 0
  Pose pose{};                      ///< camera-to-world pose given with the frame
  std::size_t n_points = 0;         ///< points of the frame (after back-projection)
  std::size_t n_novel = 0;          ///< of which novel (all of them with novelty off)
  std::size_t n_components = 0;     ///< map components after this insert (and any flush it ran)
  bool flushed = false;             ///< this insert ran a fit: a flush or a revisit refit
  double ms_novelty = 0.0;          ///< novelty test, milliseconds
  double ms_fit = 0.0;              ///< fits this insert ran (a refit's with its check and sampling)
  double ms_merge = 0.0;            ///< transform + merge + fusion (+ index) of that flush (and refit)
  /// Map components a revisit refit of this frame replaced (0: none ran;
  /// MapOptions::revisit_refit_ratio). Its fit time is in ms_fit. (C API:
  /// key SOGMM_MAP_FRAME_N_REPLACED.)
  std::size_t n_replaced = 0;
};

/// Totals of a map.
struct MapStats {
  std::size_t n_components = 0;
  std::size_t n_pending = 0;        ///< novel points waiting for a flush
  std::uint64_t n_frames = 0;       ///< frames inserted (including loaded provenance)
  std::uint64_t n_flushes = 0;      ///< fits run (batches and revisit refits)
  std::uint64_t n_fused = 0;        ///< new components fused instead of appended
  std::uint64_t n_refits = 0;       ///< revisit refits run (also counted in n_flushes: fits run)
};

/// What Map::merge_map did (counts of components and frame lines).
struct MapMergeStats {
  std::size_t n_kept = 0;     ///< this map's components kept
  std::size_t n_removed = 0;  ///< this map's components the other map holds more sharply (removed)
  std::size_t n_added = 0;    ///< the other map's components added
  std::size_t n_skipped = 0;  ///< the other map's components this map already holds as sharply (left out)
  std::size_t n_frames = 0;   ///< frame provenance lines added (the other map's frames)
};

/// Metadata keys of a saved map (Map::to_model / Map::from_model; listed in
/// spec/format.md section 2.3). Values are ASCII text.
inline constexpr const char* kMapFramesKey = "map_frames";    ///< per-frame provenance, one line per frame
inline constexpr const char* kMapOptionsKey = "map_options";  ///< the options the map was built with

/// The incremental world map. Not thread-safe: one writer at a time; const
/// members may run concurrently.
class Map {
 public:
  /// An empty map. Throws as validate(options).
  explicit Map(const MapOptions& options = {});
  ~Map();
  Map(Map&&) noexcept;
  Map& operator=(Map&&) noexcept;
  Map(const Map&) = delete;
  Map& operator=(const Map&) = delete;

  const MapOptions& options() const;

  /// Inserts one frame of n points (x, y, z, gray) in the camera frame with
  /// its camera-to-world pose. Errors (nothing changes): empty frame or
  /// non-finite point -> Error(InvalidData); pose not rigid
  /// (rigid_pose_error) -> Error(InvalidArgument) naming the problem; more
  /// than kMaxPoints points -> Error(Limit). So that every commit can be
  /// flushed, it also refuses (nothing changes) a point beyond float32 range
  /// after the pose -> Error(InvalidArgument); with a fixed K
  /// (fit.n_components > 0), a fit it would trigger on fewer than K points ->
  /// Error(InvalidArgument); else a batch (the pending points and this
  /// frame's new ones, in this frame's camera frame) beyond the mode count's
  /// range at the batch bandwidth (require_mode_count_range in
  /// sogmm/mean_shift.hpp) -> Error(Limit): the same rule a fit of those
  /// points at that bandwidth applies. A flush it triggers that fails anyway
  /// (a numeric failure, a cancel) throws as flush() and the insert is
  /// undone: the map is as before the call, so the call can be retried.
  /// `progress` reports that fit and may cancel it (Error(Cancelled)).
  FrameStats insert_points(const PointsView& points, const Pose& camera_to_world, const ProgressSink& progress = {});

  /// Inserts an RGB-D frame: back-projected with options().depth
  /// (backproject() of sogmm/camera.hpp), then as insert_points. The first
  /// RGB-D frame fixes the camera; a frame whose size or intrinsics differ
  /// -> Error(InvalidArgument) naming both. A frame without a valid pixel ->
  /// Error(InvalidData). The map's model records the camera (CameraInfo).
  FrameStats insert_rgbd(const RgbdView& frame, const Pose& camera_to_world, const ProgressSink& progress = {});

  /// insert_rgbd for a frame already back-projected (e.g. by the C API, which
  /// converts color formats first): `points` are backproject() of an image of
  /// `camera` with options().depth. Same camera rule and errors.
  FrameStats insert_backprojected(const PointsView& points, const Camera& camera, const Pose& camera_to_world,
                                  const ProgressSink& progress = {});

  /// Fits the pending points (if any) and merges them into the map; returns
  /// the number of components added (0 when nothing was pending). A fit error
  /// (sogmm::fit) propagates and leaves the map and the pending points as
  /// they were.
  std::size_t flush(const ProgressSink& progress = {});

  /// Drops the pending points (they never become components) and returns how
  /// many there were. The frames stay recorded (their n_novel counts the
  /// points as they were then), and so does the camera an RGB-D frame fixed.
  /// The way out when a flush keeps failing and the map cannot be saved.
  std::size_t discard_pending();

  /// Components in the map.
  std::size_t size() const;
  /// Novel points waiting for a flush.
  std::size_t pending() const;
  /// Those points (x, y, z, gray) in the world frame, oldest frame first:
  /// the newest surfaces, which tracking registers to with the components
  /// (sogmm/map_tracking.hpp). Empty when nothing is pending.
  PointCloud pending_points() const;
  MapStats stats() const;
  /// One entry per inserted frame, in order.
  const std::vector<FrameStats>& frames() const;
  /// The index over the map's components (ids are component indices of model()).
  const ComponentIndex& index() const;

  /// The map's origin (anchor, world frame, metres): the map holds its
  /// components relative to it, so that they keep room-scale float32
  /// resolution however far from the world origin the frames are (1000 km
  /// out a world float32 coordinate moves in steps of 6.25 cm). By default
  /// the first frame's translation rounded to a multiple of 1 km per axis: 0
  /// for a map that starts within 500 m of the world origin, which is then
  /// held, saved and answered exactly as before anchors existed. Everything
  /// that meets a pose (novelty, pending voxels, fits, renders) is computed
  /// in double relative to it; model(), extract() and the queries convert at
  /// the boundary; a map file records it (to_model()).
  const Origin& origin() const;
  /// Declares the origin (e.g. a site's surveyed point, so that maps of one
  /// site share it) instead of the first frame's. Only before the first
  /// insert (no frame recorded, no component) -> else
  /// Error(InvalidArgument); every axis finite and within float32 range ->
  /// else Error(InvalidArgument).
  void set_origin(const Origin& origin);

  /// The whole map as a world-frame model (key coordinate_frame "world", no
  /// pose): the components moved by origin() and rounded to float32, so far
  /// from the world origin they have the world float32 resolution there (use
  /// to_model() for the exact map). Pending points are not in it. Throws
  /// Error(InvalidData) when the map has no component yet.
  const Model& model() const;
  /// The components whose index box meets `box`, weights renormalised over
  /// them and support size the map's times their weight share (rounded, at
  /// least 1). Metadata as model(). Throws Error(InvalidData) when no
  /// component meets the box (or the map is empty), Error(InvalidArgument)
  /// for a box with lo > hi or a non-finite bound.
  Model extract(const Box3& box) const;

  /// log p(x) of each point's 3-D marginal under its neighbourhood in the
  /// map, as the novelty test computes it (see the header comment): `xyz`
  /// holds n world points (3 doubles each; taken relative to origin() in
  /// double), `out` receives n values, each
  /// independent of the other points; -inf where no component's box holds
  /// the point. Uses fit.em.threads threads.
  void local_log_likelihood(const double* xyz, std::size_t n, double* out) const;

  /// The depth image (row-major, z in metres, NaN where nothing shows) of
  /// the map rendered from frame `frame`'s pose with the map's decimated
  /// camera and its depth range (render() of sogmm/render.hpp), as
  /// occupancy() reads it. Kept until the components change, so that
  /// repeated queries between two inserts render each frame once; the image
  /// is the same whether kept or not, for any `threads`
  /// (RenderOptions::threads). Errors: no camera record (points-only
  /// inserts) -> Error(InvalidData); frame >= frames().size() ->
  /// Error(InvalidArgument); as model() and render().
  std::shared_ptr<const std::vector<float>> frame_depth(std::size_t frame, int threads = 0) const;

  /// What a map file stores: the components relative to origin() with the
  /// origin as the model's pose (a translation; spec/format.md 2.3; no pose
  /// when the origin is 0, so that such a model is model() itself) and the
  /// provenance keys kMapFramesKey and kMapOptionsKey. Throws
  /// Error(InvalidArgument) when points are pending (flush first: a file
  /// holds components only) and as model().
  Model to_model() const;
  /// A map holding `model`'s components (which must be a world-frame model,
  /// else Error(InvalidArgument)) and, when present, the frame provenance of
  /// kMapFramesKey (malformed, or a number with a sign -> Error(Format)
  /// naming the line). A pose, when present, maps the components to the
  /// world (spec/format.md 2.1): its translation becomes origin() and its
  /// rotation, if any, is applied to the components. A model of support size 0 (unknown) ->
  /// Error(InvalidArgument): every flush merges by support size and would
  /// have to guess its weight against the new points' (merge() refuses it).
  /// `options` govern later inserts.
  static Map from_model(const Model& model, const MapOptions& options = {});

  /// The map's revision: 0 when built, +1 for every call that changed the
  /// components or the frame provenance (an insert, a flush that fitted, a
  /// delta applied: a delta sets the sender's revision). A failed call
  /// changes nothing, the revision included. Kept in a saved map
  /// (kMapRevisionKey), with id() (kMapIdKey).
  std::uint64_t revision() const;
  /// The map's identity, 32 lowercase hex digits, random when the map is
  /// built (a receiver takes its sender's with its first delta).
  const std::string& id() const;
  /// What changed from revision `since` to revision() (sogmm/map_delta.hpp),
  /// pending points left out. Error(InvalidArgument) naming the range unless
  /// `since` is a revision this map recorded the changes after: from the
  /// revision it was built or loaded at, up to revision(); a receiver can
  /// relay from the revisions its deltas started at. Memory: the map keeps
  /// every explicit component it ever received (batches, fusion results).
  MapDelta delta_since(std::uint64_t since) const;
  /// Applies a delta of the sender (the map id()). Refused, nothing changed:
  /// another map's delta (unless this map is new: revision 0, no frame, no
  /// component, then it takes the sender's id) -> Error(InvalidArgument); a
  /// delta that does not start at revision() (a gap, a duplicate, one out of
  /// order) -> Error(InvalidArgument) naming both revisions; points pending
  /// -> Error(InvalidArgument); a delta whose steps do not fit this map or
  /// whose result differs from the sender's digest -> Error(Format). The new
  /// state is built aside and committed at once: a throw at any point leaves
  /// the map at its last revision. This map's options are kept (they govern
  /// later inserts).
  void apply_delta(const MapDelta& delta);

  /// Merges another map into this one (issue 33: two robots, one map),
  /// `other_to_this` the rigid transform of the other map's world frame into
  /// this map's (core/src/map_merge.cpp says why and how). Where both maps
  /// hold the same surface, the sharper view wins instead of both being
  /// stacked: first each of the other map's components whose test points
  /// (its mean and +-1 sigma along its three spatial axes) this map explains
  /// at least as sharply at most of them (the novelty test's local 3-D
  /// log-density, ties to this map) is left out; then each of this map's
  /// components that the other map's kept components explain more sharply
  /// at most of its test points is removed. Kept components keep their mass
  /// in points (weight x support size); the other map's frame provenance is
  /// appended (poses moved to this world, component counts 0). A map
  /// without an origin takes the other's, moved. One revision: a delta
  /// carries it as a Remove and a Merge step. Merging into an empty map
  /// gives the other map's components (bitwise for the identity); a map
  /// merged with a copy of itself keeps its own components only. Errors,
  /// nothing changed: `other` is this map, points pending in either map,
  /// or `other_to_this` not a finite rigid transform -> Error(InvalidArgument);
  /// the other map without components -> Error(InvalidData); both maps with
  /// cameras that differ -> Error(InvalidArgument) naming both; a component
  /// moved beyond float32 -> Error(InvalidArgument).
  MapMergeStats merge_map(const Map& other, const Pose& other_to_this);

  struct State;  ///< the implementation (core/src/map_state.hpp)

 private:
  std::unique_ptr<State> s_;
};

}  // namespace sogmm
