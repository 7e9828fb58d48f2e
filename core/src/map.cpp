// sogmm::Map: insert (novelty), flush (fit, move, merge, fuse), export
// (sogmm/map.hpp).
#include "sogmm/map.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "component_precision.hpp"
#include "map_state.hpp"
#include "parallel.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"
#include "sogmm/warm_start.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/mean_shift.hpp"
#include "sogmm/fit_record.hpp"
#include "sogmm/options.hpp"

namespace sogmm {
namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void require_rigid(const Pose& pose) {
  const std::string problem = rigid_pose_error(pose);
  require(problem.empty(), ErrorCode::InvalidArgument, "map: the camera-to-world pose is not a rigid transform: " + problem);
}

// x, y, z of each point moved by `pose` (to the world or the anchored frame),
// in double.
std::vector<double> moved_points(const PointsView& points, const Pose& pose) {
  std::vector<double> out(3 * points.size);
  for (std::size_t i = 0; i < points.size; ++i) {
    const float* p = points[i];
    for (int r = 0; r < 3; ++r)
      out[3 * i + r] = pose[4 * r] * p[0] + pose[4 * r + 1] * p[1] + pose[4 * r + 2] * p[2] + pose[4 * r + 3];
  }
  return out;
}

std::string camera_text(const Camera& c) {
  return std::to_string(c.width) + " x " + std::to_string(c.height) + ", fx " + checked::exact(c.fx) + ", fy " +
         checked::exact(c.fy) + ", cx " + checked::exact(c.cx) + ", cy " + checked::exact(c.cy);
}

bool same_camera(const Camera& a, const Camera& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy && a.cx == b.cx && a.cy == b.cy;
}

// A fit made in the camera frame of `pose` (camera to the map's anchored
// frame) with `bandwidth` as a model of the map's frame with its fit record
// (record_fit, as every front end writes it).
Model batch_model(const Map::State& s, const FitResult& r, const Pose& pose, double bandwidth, bool from_rgbd) {
  Model batch;
  // Rounded here, before anything records it: the map, its journal and so
  // every delta hold the same rounded bits (MapOptions::component_precision).
  batch.gmm = detail::round_to_precision(transform(r.gmm, pose), s.options.component_precision);
  FitOptions fo = s.options.fit;
  fo.bandwidth = bandwidth;
  record_fit(batch, r, fo);
  if (from_rgbd && s.camera) {
    batch.camera.known = true;
    batch.camera.camera = *s.camera;
    batch.camera.decimation = s.options.depth.decimate;
    batch.camera.depth_scale = s.options.depth.depth_scale;
    batch.camera.depth_min = s.options.depth.depth_min;
    batch.camera.depth_max = s.options.depth.depth_max;
  }
  batch.key_values.emplace_back(kCoordinateFrameKey, "world");
  return batch;
}

// What the map's searches are built from; swapped out whole by a revisit
// refit, and back when the insert that ran it fails later.
struct Searchable {
  Model model;
  ComponentIndex index;
  std::vector<detail::Marginal3> marginals;
  Gmm batch;    // the refit's fit, as merged (what a delta carries)
  Model world;  // State::world of `model`
};

// State::world for `model` (empty when the origin is 0).
Model world_of(const Map::State& s, const Model& model) {
  return detail::is_zero(s.origin) ? Model{} : detail::world_frame(model, s.origin);
}

// The map after a revisit refit, built without touching the map: the seen
// components dropped, the refit's merged in, index and marginals rebuilt.
Searchable after_refit(const Map::State& s, const detail::RevisitRefit& plan, const Pose& pose, bool from_rgbd) {
  Model batch = batch_model(s, plan.fit, pose, plan.bandwidth, from_rgbd);
  detail::carve_by_seen_frames(s, batch.gmm);
  Model kept = s.model;
  kept.gmm = detail::without_components(s.model.gmm, plan.replaced);
  Gmm batch_gmm = batch.gmm;
  Model model = kept.gmm.size() == 0 ? std::move(batch) : merge(kept, batch);
  detail::Searches searches = detail::searches_of(model.gmm, s.options.index_sigmas);
  Searchable out{std::move(model), std::move(searches.index), std::move(searches.marginals), std::move(batch_gmm), {}};
  out.world = world_of(s, out.model);
  return out;
}

}  // namespace

void validate(const MapOptions& o) {
  require_option(OptionKey::MAP_NOVELTY_THRESHOLD, o.novelty_threshold, "map: novelty_threshold");
  // batch_size is a size_t: a value above the int64 range is out of range too.
  require_option(OptionKey::MAP_BATCH_SIZE,
                 static_cast<std::int64_t>(std::min<std::size_t>(o.batch_size, std::size_t{1} << 62)),
                 "map: batch_size");
  require_option(OptionKey::MAP_NOVELTY_BANDWIDTH_SCALE, o.novelty_bandwidth_scale, "map: novelty_bandwidth_scale");
  require_option(OptionKey::MAP_FUSION_THRESHOLD, o.fusion_threshold, "map: fusion_threshold");
  require_option(OptionKey::MAP_REVISIT_REFIT_RATIO, o.revisit_refit_ratio, "map: revisit_refit_ratio");
  require_option(OptionKey::MAP_COMPONENT_PRECISION, o.component_precision, "map: component_precision");
  require_option(OptionKey::MAP_FREE_SPACE_CARVE, o.free_space_carve, "map: free_space_carve");
  require(std::isfinite(o.index_sigmas) && o.index_sigmas > 0 && o.index_sigmas <= 100, ErrorCode::InvalidArgument,
          "map: index_sigmas " + checked::exact(o.index_sigmas) + " is not in (0, 100]");
  require(o.fusion_method == FusionMethod::Hellinger || o.fusion_method == FusionMethod::KL,
          ErrorCode::InvalidArgument, "map: unknown fusion method");
  require_usable_bandwidth(o.fit.bandwidth);
  require_usable_bandwidth(detail::refit_bandwidth(o));  // the smallest any batch or refit fits with
  // A triggered fit of a fixed K needs K points: a smaller batch could only
  // flush when one insert happened to bring K.
  require(!o.novelty || o.fit.n_components <= o.batch_size, ErrorCode::InvalidArgument,
          "map: batch_size " + std::to_string(o.batch_size) + " is below the fixed K = " +
              std::to_string(o.fit.n_components) + " components a batch is fitted with");
  require(!o.warm_start || o.fit.n_init == 1, ErrorCode::InvalidArgument,
          "map: a warm start is one run: fit.n_init must be 1, got " + std::to_string(o.fit.n_init));
  validate(o.depth);
}

Map::Map(const MapOptions& options) {
  validate(options);
  s_ = std::make_unique<State>(options);
}
Map::~Map() = default;
Map::Map(Map&&) noexcept = default;
Map& Map::operator=(Map&&) noexcept = default;

const MapOptions& Map::options() const { return s_->options; }
std::size_t Map::size() const { return s_->model.gmm.size(); }
std::size_t Map::pending() const { return s_->n_pending; }
const std::vector<FrameStats>& Map::frames() const { return s_->frames; }
const ComponentIndex& Map::index() const { return s_->index; }

MapStats Map::stats() const {
  MapStats t;
  t.n_components = size();
  t.n_pending = s_->n_pending;
  t.n_frames = s_->frames.size();
  t.n_flushes = s_->n_flushes;
  t.n_fused = s_->n_fused;
  t.n_refits = s_->n_refits;
  return t;
}

const Model& Map::model() const {
  require(size() > 0, ErrorCode::InvalidData, "map: the map has no component yet (insert and flush a frame first)");
  return detail::is_zero(s_->origin) ? s_->model : s_->world;
}

const Origin& Map::origin() const { return s_->origin; }

void Map::set_origin(const Origin& origin) {
  State& s = *s_;
  require(s.frames.empty() && s.model.gmm.size() == 0, ErrorCode::InvalidArgument,
          "map: the origin is set before the first insert (this map has " + std::to_string(s.frames.size()) +
              " frames and " + std::to_string(s.model.gmm.size()) + " components)");
  detail::require_origin(origin);
  s.origin = origin;
  s.origin_fixed = true;
}

void Map::local_log_likelihood(const double* xyz, std::size_t n, double* out) const {
  const Origin& o = s_->origin;
  std::vector<double> anchored(xyz, xyz + 3 * n);
  for (std::size_t i = 0; i < 3 * n; ++i) anchored[i] -= o[i % 3];
  detail::local_log_likelihood(s_->index, s_->marginals, s_->options.fit.em.threads, anchored.data(), n, out);
}

namespace {

// The checks of a frame's points, before anything changes.
void check_frame(const PointsView& points) {
  require(points.size > 0, ErrorCode::InvalidData, "map: the frame has no point");
  require(points.size <= kMaxPoints, ErrorCode::Limit,
          "map: the frame has " + std::to_string(points.size) + " points, more than the limit of " +
              std::to_string(kMaxPoints));
  require_finite_points(points, "map frame");
}

// The first frame fixes the map's origin (Map::origin); an insert that fails
// leaves it unfixed again.
class OriginGuard {
 public:
  OriginGuard(Map::State& s, const Pose& pose) : s_(s), fixes_(!s.origin_fixed) {
    if (!fixes_) return;
    s.origin = detail::default_origin(pose);
    s.origin_fixed = true;
  }
  ~OriginGuard() {
    if (!fixes_ || committed_) return;
    s_.origin = Origin{};
    s_.origin_fixed = false;
  }
  void commit() { committed_ = true; }
  OriginGuard(const OriginGuard&) = delete;
  OriginGuard& operator=(const OriginGuard&) = delete;

 private:
  Map::State& s_;
  bool fixes_, committed_ = false;
};

FrameStats insert_frame(Map::State& s, Map& map, const PointsView& points, const Pose& world_pose, bool from_rgbd,
                        const ProgressSink& progress) {
  check_frame(points);
  detail::JournalScope journal(s.journal, s.frames.size());
  OriginGuard origin(s, world_pose);
  // Everything below works in the map's anchored frame; only the frame's
  // record keeps the world pose.
  const Pose pose = detail::anchored(s.origin, world_pose);
  FrameStats f;
  f.index = s.frames.size();
  f.pose = detail::recorded_pose(world_pose, s.options.component_precision);
  f.n_points = points.size;
  const auto t0 = std::chrono::steady_clock::now();
  detail::PendingFrame novel;
  novel.pose = pose;
  novel.from_rgbd = from_rgbd;
  std::vector<detail::PendingVoxel> novel_voxels;
  std::vector<double> ll;
  std::vector<std::int64_t> dominant;  // each point's dominant map component (revisit refit)
  // The points in the anchored frame, in double. Both frames hold float32
  // coordinates: the anchored one in the map, the world one in exports.
  const std::vector<double> xyz = moved_points(points, pose);
  detail::require_float32_world(xyz, from_rgbd);
  if (!detail::is_zero(s.origin)) detail::require_float32_world(moved_points(points, world_pose), from_rgbd);
  if (!s.options.novelty) {
    novel.xyzg.assign(points.data, points.data + 4 * points.size);
  } else {
    // Novel: the map does not explain the point (below the threshold) and no
    // earlier frame's pending point lies near it (that surface is already
    // waiting for the next fit).
    ll.assign(points.size, -std::numeric_limits<double>::infinity());
    dominant.assign(points.size, -1);
    if (s.model.gmm.size() > 0)
      detail::local_log_likelihood(s.index, s.marginals, s.options.fit.em.threads, xyz.data(), points.size,
                                   ll.data(), dominant.data());
    // Per point: 0 explained (or near a pending point), 1 novel.
    std::vector<std::uint8_t> state(points.size, 0);
    std::vector<detail::PendingVoxel> voxels(points.size);
    detail::parallel_for(points.size, detail::team_size(s.options.fit.em.threads), 1024, [&](std::size_t i, int) {
      if (ll[i] >= s.options.novelty_threshold) return;
      voxels[i] = detail::pending_voxel(xyz.data() + 3 * i);
      if (!detail::near_pending(s.pending_voxels, voxels[i])) state[i] = 1;
    });
    for (std::size_t i = 0; i < points.size; ++i) {
      if (state[i] == 0) continue;
      novel_voxels.push_back(voxels[i]);
      novel.xyzg.insert(novel.xyzg.end(), points[i], points[i] + 4);
    }
  }
  f.ms_novelty = ms_since(t0);
  f.n_novel = novel.xyzg.size() / 4;
  require(s.n_pending <= kMaxPoints - f.n_novel, ErrorCode::Limit,
          "map: more than " + std::to_string(kMaxPoints) + " points pending");
  // Nothing is committed that a flush could not fit (issue 36).
  detail::require_flushable(s, novel, from_rgbd);
  // Revisit refit (MapOptions::revisit_refit_ratio) and free-space carve
  // (MapOptions::free_space_carve): computed first, committed with the
  // previous searchable map kept aside until the insert succeeds.
  std::optional<Searchable> before_change;
  std::optional<detail::SeenFrame> seen;  // this frame's depth, for the carve
  bool refit_ran = false;
  auto keep_before = [&] {
    if (!before_change)
      before_change =
          Searchable{std::move(s.model), std::move(s.index), std::move(s.marginals), {}, std::move(s.world)};
  };
  if (from_rgbd) {
    const auto t1 = std::chrono::steady_clock::now();
    std::optional<detail::RevisitRefit> plan = detail::plan_revisit_refit(s, points, pose, ll, dominant, f.index, progress);
    if (!plan) {
      f.ms_novelty += ms_since(t1);  // the check (a mode count) is part of the novelty test
    } else {
      f.ms_fit += ms_since(t1);
      const auto t2 = std::chrono::steady_clock::now();
      Searchable next = after_refit(s, *plan, pose, from_rgbd);
      s.journal.remove(plan->replaced);
      s.journal.merge(next.batch);
      keep_before();
      s.model = std::move(next.model);
      s.index = std::move(next.index);
      s.marginals = std::move(next.marginals);
      s.world = std::move(next.world);
      refit_ran = true;
      ++s.n_flushes;
      ++s.n_refits;
      ++s.revision;
      f.n_replaced = plan->replaced.size();
      f.flushed = true;  // ran a fit
      f.ms_merge += ms_since(t2);
    }
    const auto t3 = std::chrono::steady_clock::now();
    if (detail::carving(s.options) && s.camera)
      seen.emplace(detail::SeenFrame{inverse_rigid(pose),
                                     detail::DepthView(decimated(*s.camera, s.options.depth.decimate), s.options.depth,
                                                       points)});
    Gmm carved;
    const std::vector<std::size_t> changed =
        seen ? detail::plan_free_space_carve(s, *seen, carved) : std::vector<std::size_t>{};
    if (!changed.empty()) {
      // Index and marginals updated on copies (as fusion does in flush):
      // only the carved components moved.
      std::vector<detail::Marginal3> marginals = s.marginals;
      ComponentIndex index = s.index;
      for (std::size_t k : changed) {
        marginals[k] = detail::marginal3(carved, k);
        index.update(carved, k);
      }
      Model model = s.model;  // the refit's, when one ran: its components are carved too
      model.gmm = std::move(carved);
      s.journal.set(model.gmm, changed);
      keep_before();
      s.world = world_of(s, model);
      s.model = std::move(model);
      s.index = std::move(index);
      s.marginals = std::move(marginals);
      ++s.revision;
    }
    f.ms_novelty += ms_since(t3);  // a test of the frame's view, like the novelty test
  }
  // Undoes the refit and the carve when a later step of this insert fails.
  auto undo_refit = [&] {
    if (!before_change) return;
    s.model = std::move(before_change->model);
    s.index = std::move(before_change->index);
    s.marginals = std::move(before_change->marginals);
    s.world = std::move(before_change->world);
    if (refit_ran) {
      --s.n_flushes;
      --s.n_refits;
    }
    ++s.revision;  // the components changed back: never reuse what the refit's were
  };
  // From here on any failure (a failed or cancelled flush, which itself
  // commits nothing; an allocation) undoes the whole insert.
  bool pushed_pending = false, pushed_frame = false, pushed_seen = false;
  try {
    // Before the flush: its new components are carved by this frame too.
    if (seen) {
      s.seen_frames.push_back(std::move(*seen));
      pushed_seen = true;
    }
    if (f.n_novel > 0) {
      s.pending.push_back(std::move(novel));
      pushed_pending = true;
      s.n_pending += f.n_novel;
      s.pending_voxels.insert(novel_voxels.begin(), novel_voxels.end());
    }
    s.frames.push_back(f);
    pushed_frame = true;
    // Novelty off: each frame is its own batch (append everything).
    // flush() records its fit and merge times on this frame's stats.
    if (s.n_pending > 0 && (!s.options.novelty || s.n_pending >= s.options.batch_size)) map.flush(progress);
  } catch (...) {
    if (pushed_seen) s.seen_frames.pop_back();
    if (pushed_frame) s.frames.pop_back();
    if (pushed_pending) {
      s.pending.pop_back();
      s.n_pending -= f.n_novel;
      // Each of these voxels was new to the set (its points were not near a
      // pending one), so erasing them restores the set exactly (also after a
      // partial insert).
      for (const detail::PendingVoxel& key : novel_voxels) s.pending_voxels.erase(key);
    }
    undo_refit();
    throw;
  }
  s.frames.back().n_components = s.model.gmm.size();
  journal.commit(s.frames.size());
  origin.commit();
  return s.frames.back();
}

}  // namespace

FrameStats Map::insert_points(const PointsView& points, const Pose& camera_to_world, const ProgressSink& progress) {
  require_rigid(camera_to_world);
  return insert_frame(*s_, *this, points, camera_to_world, false, progress);
}

void detail::require_map_camera(const Map::State& s, const Camera& camera, const char* what) {
  if (s.camera)
    require(same_camera(*s.camera, camera), ErrorCode::InvalidArgument,
            std::string("map: ") + what + " (" + camera_text(camera) + ") differs from the map's first frame (" +
                camera_text(*s.camera) + ")");
}

FrameStats Map::insert_rgbd(const RgbdView& frame, const Pose& camera_to_world, const ProgressSink& progress) {
  require_rigid(camera_to_world);
  require(frame.depth != nullptr && frame.gray != nullptr, ErrorCode::InvalidArgument,
          "map: the RGB-D frame has no depth or gray image");
  detail::require_map_camera(*s_, frame.camera);  // before the work of back-projecting
  const PointCloud cloud = backproject(frame, s_->options.depth);
  return insert_backprojected(cloud.view(), frame.camera, camera_to_world, progress);
}

FrameStats Map::insert_backprojected(const PointsView& points, const Camera& camera, const Pose& camera_to_world,
                                     const ProgressSink& progress) {
  require_rigid(camera_to_world);
  detail::require_map_camera(*s_, camera);
  require(points.size > 0, ErrorCode::InvalidData,
          "map: the RGB-D frame has no valid depth pixel (depth range " + checked::exact(s_->options.depth.depth_min) +
              " to " + checked::exact(s_->options.depth.depth_max) + " m)");
  check_frame(points);
  // Set before the insert: a flush it runs records the camera in the model.
  // A failed insert is undone, the camera included.
  const bool first_camera = !s_->camera;
  if (first_camera) s_->camera = camera;
  try {
    return insert_frame(*s_, *this, points, camera_to_world, true, progress);
  } catch (...) {
    if (first_camera) s_->camera.reset();
    throw;
  }
}

std::size_t Map::discard_pending() {
  State& s = *s_;
  const std::size_t dropped = s.n_pending;
  s.pending.clear();
  s.n_pending = 0;
  s.pending_voxels.clear();
  return dropped;
}

std::size_t Map::flush(const ProgressSink& progress) {
  State& s = *s_;
  if (s.n_pending == 0) return 0;
  detail::JournalScope journal(s.journal, s.frames.size());
  const auto t0 = std::chrono::steady_clock::now();
  // The batch is fitted in the camera frame of its latest frame: a batch of
  // one frame is then fitted exactly on that frame's points, as `sogmm fit
  // --sequence` does, and coordinates stay near the origin in float32.
  const Pose& last = s.pending.back().pose;
  const Pose to_last = inverse_rigid(last);
  const PointCloud cloud = detail::batch_cloud(s.pending);
  bool from_rgbd = false;
  for (const detail::PendingFrame& p : s.pending) from_rgbd = from_rgbd || p.from_rgbd;
  // Novel points: a finer mode count (MapOptions::novelty_bandwidth_scale
  // says why).
  FitOptions batch_options = s.options.fit;
  batch_options.bandwidth = detail::batch_bandwidth(s.options, s.pending);
  // Warm start: the last fit moved from its camera to this batch's
  // (world <- previous camera, then this camera <- world).
  const bool warm = s.options.warm_start && s.previous_fit.size() > 0;
  FitResult r = warm ? fit_warm(cloud.view(), transform(transform(s.previous_fit, s.previous_pose), to_last),
                                batch_options, progress)
                     : fit(cloud.view(), batch_options, progress);
  const double ms_fit = ms_since(t0);
  const auto t1 = std::chrono::steady_clock::now();

  Model batch = batch_model(s, r, last, batch_options.bandwidth, from_rgbd);
  detail::carve_by_seen_frames(s, batch.gmm);
  const std::size_t first = s.model.gmm.size();
  s.journal.merge(batch.gmm);
  Model merged = first == 0 ? std::move(batch) : merge(s.model, batch);
  std::vector<std::size_t> changed;
  if (s.options.fusion && first > 0) {
    const Gmm appended = detail::tail(merged.gmm, first);
    changed = detail::fuse_new_components(merged.gmm, first, s.index, s.options);
    s.journal.set(merged.gmm, changed);
    s.journal.drop(detail::dropped_positions(appended, merged.gmm, first));
  }
  const std::size_t added = merged.gmm.size() - first;
  const std::size_t fused = r.gmm.size() - added;
  // The marginals and index of the merged map, built on copies before
  // anything is committed: a throw here (non-PD data, an allocation) leaves
  // the map as it was, and the commit below only moves.
  std::vector<detail::Marginal3> marginals = s.marginals;
  ComponentIndex index = s.index;
  for (std::size_t k : changed) {
    marginals[k] = detail::marginal3(merged.gmm, k);
    index.update(merged.gmm, k);
  }
  for (std::size_t k = first; k < merged.gmm.size(); ++k) marginals.push_back(detail::marginal3(merged.gmm, k));
  index.add(merged.gmm, first);
  Model world = world_of(s, merged);

  // Commit.
  s.model = std::move(merged);
  s.marginals = std::move(marginals);
  s.index = std::move(index);
  s.world = std::move(world);
  s.pending.clear();
  s.n_pending = 0;
  s.pending_voxels.clear();
  if (s.options.warm_start) {
    s.previous_fit = std::move(r.gmm);
    s.previous_pose = last;
  }
  ++s.n_flushes;
  ++s.revision;
  s.n_fused += fused;
  if (!s.frames.empty()) {
    FrameStats& f = s.frames.back();
    f.flushed = true;
    f.ms_fit += ms_fit;
    f.ms_merge += ms_since(t1);
    f.n_components = s.model.gmm.size();
  }
  journal.commit(s.frames.size());
  return added;
}

Model Map::extract(const Box3& box) const {
  for (int i = 0; i < 3; ++i)
    require(std::isfinite(box.lo[i]) && std::isfinite(box.hi[i]) && box.lo[i] <= box.hi[i],
            ErrorCode::InvalidArgument,
            "map: box axis " + std::to_string(i) + " is [" + checked::exact(box.lo[i]) + ", " +
                checked::exact(box.hi[i]) + "], not finite with min <= max");
  const Model& all = model();
  std::vector<std::uint32_t> ids;
  Box3 anchored = box;  // the index is in the anchored frame
  for (int i = 0; i < 3; ++i) {
    anchored.lo[i] -= s_->origin[i];
    anchored.hi[i] -= s_->origin[i];
  }
  s_->index.query_box(anchored, ids);
  require(!ids.empty(), ErrorCode::InvalidData, "map: no component meets the box");
  Model out;
  out.fit = all.fit;
  out.camera = all.camera;
  out.key_values = all.key_values;
  out.producer_name = all.producer_name;
  out.gmm.resize(ids.size());
  double total = 0.0;
  for (std::uint32_t id : ids) total += all.gmm.weights[id];
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const std::size_t id = ids[k];
    out.gmm.weights[k] = static_cast<float>(total > 0 ? all.gmm.weights[id] / total : 1.0 / ids.size());
    std::copy_n(all.gmm.mean(id), 4, out.gmm.means.data() + 4 * k);
    std::copy_n(all.gmm.covariance(id), 16, out.gmm.covariances.data() + 16 * k);
  }
  const double support = std::round(static_cast<double>(all.gmm.support_size) * std::min(total, 1.0));
  out.gmm.support_size = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(support));
  return out;
}

}  // namespace sogmm
