// sogmm_map_merge_map: one map merged into another (Map::merge_map of
// sogmm/map.hpp; issue 33, two robots, one map).
#include <cstdint>

#include "internal.hpp"
#include "map_handle.hpp"
#include "sogmm/map.hpp"

extern "C" {

SOGMM_API sogmm_status sogmm_map_merge_map(sogmm_map* map, const sogmm_map* other, const double* other_to_map,
                                           uint64_t* stats_out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(map, "map");
    sogmm_capi::require_nonnull(other, "other");
    // Before the guards: the same handle as reader and writer would read as
    // "busy", which hides the real mistake.
    if (map == other) sogmm_capi::fail(SOGMM_E_INVALID_ARG, "a map cannot be merged into itself (merge a copy)");
    const sogmm_capi::MapWriter use(map, "sogmm_map_merge_map");
    const sogmm_capi::MapReader read(other, "sogmm_map_merge_map");
    sogmm_capi::require_nonnull(other_to_map, "other_to_map");
    sogmm::Pose pose;
    for (int i = 0; i < 16; ++i) pose[i] = other_to_map[i];
    const sogmm::MapMergeStats st = map->map.merge_map(other->map, pose);
    if (stats_out != nullptr) {
      stats_out[0] = st.n_kept;
      stats_out[1] = st.n_removed;
      stats_out[2] = st.n_added;
      stats_out[3] = st.n_skipped;
      stats_out[4] = st.n_frames;
    }
  }
  SOGMM_CATCH
}

}  // extern "C"
