// sogmm_map_*: the incremental world map (sogmm::Map) behind a handle.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>

#include "internal.hpp"
#include "keys.hpp"
#include "map_handle.hpp"
#include "sogmm/map.hpp"

namespace {

using sogmm_capi::fail;
using sogmm_capi::require_nonnull;

sogmm::MapOptions map_options(const sogmm_options& o) {
  sogmm_capi::require_depth_range(o);
  return sogmm::map_options(o.settings);
}

sogmm::Pose pose_of(const double* pose) { return sogmm_capi::require_rigid(pose, "pose"); }

// A count of the map (points, frames, components) as the keyed getters'
// int64: such counts stay far below 2^63.
std::int64_t count(std::uint64_t v) { return static_cast<std::int64_t>(v); }

}  // namespace

extern "C" {

SOGMM_API sogmm_status sogmm_map_create(sogmm_map** out, const sogmm_options* options) {
  SOGMM_TRY {
    sogmm_capi::require_out(out);
    const sogmm_options& o = sogmm_capi::opts_or_default(options);
    *out = new sogmm_map{sogmm::Map(map_options(o)), o, {}};
  }
  SOGMM_CATCH
}

SOGMM_API void sogmm_map_free(sogmm_map* map) {
  if (map != nullptr && sogmm_capi::take_for_free(map)) delete map;
}

SOGMM_API sogmm_status sogmm_map_insert_points_f32(sogmm_map* map, const float* points, size_t n,
                                                   const double* pose) {
  SOGMM_TRY {
    require_nonnull(map, "map");
    const sogmm_capi::MapWriter use(map, "sogmm_map_insert_points_f32");
    require_nonnull(points, "points");
    require_nonnull(pose, "pose");
    const sogmm::Pose p = pose_of(pose);
    if (n == 0) fail(SOGMM_E_INVALID_DATA, "n is 0: the frame has no point");
    if (n > sogmm::kMaxPoints)
      fail(SOGMM_E_LIMIT, "n = " + std::to_string(n) + " points exceeds the limit of " +
                              std::to_string(sogmm::kMaxPoints) + " per frame");
    sogmm_capi::require_finite(points, 4 * n, "points");
    map->map.insert_points(sogmm::PointsView{points, n}, p, sogmm_capi::progress_sink(map->options));
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_map_insert_frame(sogmm_map* map, const sogmm_frame* frame, const double* pose) {
  SOGMM_TRY {
    require_nonnull(map, "map");
    const sogmm_capi::MapWriter use(map, "sogmm_map_insert_frame");
    require_nonnull(frame, "frame");
    require_nonnull(pose, "pose");
    const sogmm::Pose p = pose_of(pose);
    const sogmm_capi::RgbdPoints r = sogmm_capi::backproject_frame(frame, map->options);
    map->map.insert_backprojected(r.cloud.view(), r.camera, p, sogmm_capi::progress_sink(map->options));
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_map_flush(sogmm_map* map) {
  SOGMM_TRY {
    require_nonnull(map, "map");
    const sogmm_capi::MapWriter use(map, "sogmm_map_flush");
    map->map.flush(sogmm_capi::progress_sink(map->options));
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_map_discard_pending(sogmm_map* map, uint64_t* dropped) {
  SOGMM_TRY {
    require_nonnull(map, "map");
    const sogmm_capi::MapWriter use(map, "sogmm_map_discard_pending");
    const std::size_t n = map->map.discard_pending();
    if (dropped != nullptr) *dropped = n;
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_map_get_origin(const sogmm_map* map, double* origin_out) {
  SOGMM_TRY {
    require_nonnull(map, "map");
    const sogmm_capi::MapReader use(map, "sogmm_map_get_origin");
    require_nonnull(origin_out, "origin_out");
    const sogmm::Origin& o = map->map.origin();
    std::copy(o.begin(), o.end(), origin_out);
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_map_set_origin(sogmm_map* map, const double* origin) {
  SOGMM_TRY {
    require_nonnull(map, "map");
    const sogmm_capi::MapWriter use(map, "sogmm_map_set_origin");
    require_nonnull(origin, "origin");
    map->map.set_origin({origin[0], origin[1], origin[2]});
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_map_set_progress(sogmm_map* map, sogmm_progress_fn fn, void* user_data) {
  SOGMM_TRY {
    require_nonnull(map, "map");
    const sogmm_capi::MapWriter use(map, "sogmm_map_set_progress");
    map->options.progress = fn;
    map->options.progress_user_data = user_data;
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_map_get_i64(const sogmm_map* map, sogmm_key key, int64_t* out) {
  SOGMM_TRY {
    require_nonnull(map, "map");
    const sogmm_capi::MapReader use(map, "sogmm_map_get_i64");
    require_nonnull(out, "out");
    sogmm_capi::require_key(key, sogmm_capi::KeyKind::MapStat, sogmm_capi::KeyType::I64, "get");
    const sogmm::MapStats s = map->map.stats();
    switch (key) {
      case SOGMM_MAP_N_COMPONENTS: *out = count(s.n_components); break;
      case SOGMM_MAP_N_PENDING: *out = count(s.n_pending); break;
      case SOGMM_MAP_N_FRAMES: *out = count(s.n_frames); break;
      case SOGMM_MAP_N_FLUSHES: *out = count(s.n_flushes); break;
      case SOGMM_MAP_N_FUSED: *out = count(s.n_fused); break;
      case SOGMM_MAP_N_REFITS: *out = count(s.n_refits); break;
      case SOGMM_MAP_REVISION: *out = count(map->map.revision()); break;
      default: fail(SOGMM_E_INTERNAL, "map key table out of sync");
    }
  }
  SOGMM_CATCH
}

namespace {
const sogmm::FrameStats& frame_of(const sogmm_map* map, uint64_t frame) {
  const auto& frames = map->map.frames();
  if (frame >= frames.size())
    fail(SOGMM_E_INVALID_ARG, "frame " + std::to_string(frame) + " does not exist (" +
                                  std::to_string(frames.size()) + " frames)");
  return frames[static_cast<std::size_t>(frame)];
}
}  // namespace

SOGMM_API sogmm_status sogmm_map_frame_get_i64(const sogmm_map* map, uint64_t frame, sogmm_key key, int64_t* out) {
  SOGMM_TRY {
    require_nonnull(map, "map");
    const sogmm_capi::MapReader use(map, "sogmm_map_frame_get_i64");
    require_nonnull(out, "out");
    sogmm_capi::require_key(key, sogmm_capi::KeyKind::FrameStat, sogmm_capi::KeyType::I64, "get");
    const sogmm::FrameStats& f = frame_of(map, frame);
    switch (key) {
      case SOGMM_MAP_FRAME_N_POINTS: *out = count(f.n_points); break;
      case SOGMM_MAP_FRAME_N_NOVEL: *out = count(f.n_novel); break;
      case SOGMM_MAP_FRAME_N_COMPONENTS: *out = count(f.n_components); break;
      case SOGMM_MAP_FRAME_FLUSHED: *out = f.flushed ? 1 : 0; break;
      case SOGMM_MAP_FRAME_N_REPLACED: *out = count(f.n_replaced); break;
      default: fail(SOGMM_E_INTERNAL, "map frame key table out of sync");
    }
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_map_frame_get_f64(const sogmm_map* map, uint64_t frame, sogmm_key key, double* out) {
  SOGMM_TRY {
    require_nonnull(map, "map");
    const sogmm_capi::MapReader use(map, "sogmm_map_frame_get_f64");
    require_nonnull(out, "out");
    sogmm_capi::require_key(key, sogmm_capi::KeyKind::FrameStat, sogmm_capi::KeyType::F64, "get");
    const sogmm::FrameStats& f = frame_of(map, frame);
    switch (key) {
      case SOGMM_MAP_FRAME_MS_NOVELTY: *out = f.ms_novelty; break;
      case SOGMM_MAP_FRAME_MS_FIT: *out = f.ms_fit; break;
      case SOGMM_MAP_FRAME_MS_MERGE: *out = f.ms_merge; break;
      default: fail(SOGMM_E_INTERNAL, "map frame key table out of sync");
    }
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_map_frame_get_pose(const sogmm_map* map, uint64_t frame, double* pose_out) {
  SOGMM_TRY {
    require_nonnull(map, "map");
    const sogmm_capi::MapReader use(map, "sogmm_map_frame_get_pose");
    require_nonnull(pose_out, "pose_out");
    const sogmm::FrameStats& f = frame_of(map, frame);
    std::memcpy(pose_out, f.pose.data(), sizeof(double) * 16);
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_map_export(sogmm_model** out, const sogmm_map* map, const float* box) {
  SOGMM_TRY {
    sogmm_capi::require_out(out);
    require_nonnull(map, "map");
    const sogmm_capi::MapReader use(map, "sogmm_map_export");
    auto handle = std::make_unique<sogmm_model>();
    if (box == nullptr) {
      handle->model = map->map.model();
    } else {
      sogmm::Box3 b;
      for (int i = 0; i < 3; ++i) {
        b.lo[i] = box[i];
        b.hi[i] = box[3 + i];
        if (!(b.lo[i] <= b.hi[i]))  // also NaN
          fail(SOGMM_E_INVALID_ARG, "box axis " + std::to_string(i) + ": min " + std::to_string(box[i]) +
                                        " is not <= max " + std::to_string(box[3 + i]));
      }
      handle->model = map->map.extract(b);
    }
    *out = handle.release();
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_map_save(const sogmm_map* map, const char* path, const sogmm_options* options) {
  SOGMM_TRY {
    require_nonnull(map, "map");
    const sogmm_capi::MapReader use(map, "sogmm_map_save");
    require_nonnull(path, "path");
    // The model save path (atomic, same checks and errors) on the map's model.
    sogmm_model file;
    file.model = map->map.to_model();
    file.model.created_unix_ms = sogmm_capi::creation_time_now();
    const sogmm_status status = sogmm_model_save(&file, path, options);
    if (status != SOGMM_OK) return status;  // message already set
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_map_load(sogmm_map** out, const char* path, const sogmm_options* options) {
  SOGMM_TRY {
    sogmm_capi::require_out(out);
    sogmm_model* loaded = nullptr;
    const sogmm_status status = sogmm_model_load(&loaded, path, options);
    if (status != SOGMM_OK) return status;
    const std::unique_ptr<sogmm_model> owned(loaded);
    const sogmm_options& o = sogmm_capi::opts_or_default(options);
    *out = new sogmm_map{sogmm::Map::from_model(owned->model, map_options(o)), o, {}};
  }
  SOGMM_CATCH
}

}  // extern "C"
