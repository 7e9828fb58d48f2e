// Stand-in for io.cpp when the project is configured without the format
// library (target sogmm_format): every entry point exists, so the exported
// symbol set does not change, but reports SOGMM_E_INTERNAL.
#include "internal.hpp"

namespace {
sogmm_status unavailable() {
  return sogmm_capi::set_error(SOGMM_E_INTERNAL, "libsogmm was built without the .sogmm format library");
}
}  // namespace

extern "C" {

SOGMM_API sogmm_status sogmm_map_export_delta(const sogmm_map*, uint64_t, const sogmm_options*, void*, size_t,
                                              size_t*) {
  return unavailable();
}
SOGMM_API sogmm_status sogmm_map_apply_delta(sogmm_map*, const void*, size_t, const sogmm_options*) {
  return unavailable();
}
SOGMM_API sogmm_status sogmm_model_save(const sogmm_model*, const char*, const sogmm_options*) {
  return unavailable();
}
SOGMM_API sogmm_status sogmm_model_load(sogmm_model** out, const char*, const sogmm_options*) {
  sogmm_capi::reset_out(out);
  return unavailable();
}
SOGMM_API sogmm_status sogmm_model_save_to_memory(sogmm_buffer** out, const sogmm_model*,
                                                  const sogmm_options*) {
  sogmm_capi::reset_out(out);
  return unavailable();
}
SOGMM_API sogmm_status sogmm_model_load_from_memory(sogmm_model** out, const void*, size_t,
                                                    const sogmm_options*) {
  sogmm_capi::reset_out(out);
  return unavailable();
}

// Frame images and trajectories are read by the format library too.
SOGMM_API sogmm_status sogmm_frame_read(sogmm_frame** out, const char*, const char*) {
  sogmm_capi::reset_out(out);
  return unavailable();
}
SOGMM_API sogmm_status sogmm_frame_decode(sogmm_frame** out, const void*, size_t, const void*, size_t) {
  sogmm_capi::reset_out(out);
  return unavailable();
}
SOGMM_API sogmm_status sogmm_trajectory_read(sogmm_trajectory** out, const char*) {
  sogmm_capi::reset_out(out);
  return unavailable();
}
SOGMM_API void sogmm_trajectory_free(sogmm_trajectory*) {}
SOGMM_API size_t sogmm_trajectory_size(const sogmm_trajectory*) { return 0; }
SOGMM_API const double* sogmm_trajectory_poses(const sogmm_trajectory*) { return nullptr; }
SOGMM_API const int64_t* sogmm_trajectory_ids(const sogmm_trajectory*) { return nullptr; }
SOGMM_API sogmm_status sogmm_trajectory_write(const char*, const double*, size_t) { return unavailable(); }

}  // extern "C"
