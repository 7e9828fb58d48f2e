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

}  // extern "C"
