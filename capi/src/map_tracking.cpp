// sogmm_map_track_frame: an RGB-D frame inserted at the pose registration to
// the map finds (sogmm/map_tracking.hpp holds the rules; issue 32).
#include "internal.hpp"
#include "map_handle.hpp"
#include "sogmm/map_tracking.hpp"

extern "C" {

SOGMM_API sogmm_status sogmm_map_track_frame(sogmm_map* map, const sogmm_frame* frame, const double* guess,
                                             double* pose_out, int32_t* inserted_out,
                                             sogmm_registration_info* info_out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(map, "map");
    const sogmm_capi::MapWriter use(map, "sogmm_map_track_frame");
    sogmm_capi::require_nonnull(frame, "frame");
    if (info_out != nullptr) sogmm_capi::require_registration_info_size(info_out);
    const sogmm::Pose start =
        guess != nullptr ? sogmm_capi::require_rigid(guess, "guess") : sogmm::predict_constant_velocity(map->map);
    const sogmm_capi::RgbdPoints r = sogmm_capi::backproject_frame(frame, map->options);
    const sogmm::Settings& s = map->options.settings;
    const sogmm::TrackedFrame t =
        sogmm::track_backprojected(map->map, map->tracking, r.cloud.view(), r.camera, start, s.registration,
                                   s.tracking, s.query.threads, sogmm_capi::progress_sink(map->options));
    if (pose_out != nullptr)
      for (int i = 0; i < 16; ++i) pose_out[i] = t.pose[i];
    if (inserted_out != nullptr) *inserted_out = t.inserted ? 1 : 0;
    if (info_out != nullptr) sogmm_capi::write_registration_info(t.registration, info_out);
  }
  SOGMM_CATCH
}

}  // extern "C"
