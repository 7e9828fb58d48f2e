// sogmm_model_set_info_f64 / _i64: the information keys a .sogmm file stores
// (the fit record and the camera), so that a model rebuilt from arrays (e.g.
// sogmm_ray's canonical map) carries the provenance of its fits as the
// fit and map tools write it, not as free-form key/values.
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "internal.hpp"
#include "keys.hpp"
#include "sogmm/checked.hpp"

namespace {

using sogmm_capi::fail;
using sogmm_capi::require_nonnull;

[[noreturn]] void bad_value(sogmm_key key, const std::string& value, const char* rule) {
  fail(SOGMM_E_INVALID_ARG, "info key " + sogmm_capi::key_label(key) + ": value " + value + " " + rule);
}

[[noreturn]] void not_stored(sogmm_key key) {
  fail(SOGMM_E_INVALID_ARG, "info key " + sogmm_capi::key_label(key) +
                                " is not stored in .sogmm files (support size: sogmm_model_from_arrays_f32; creation "
                                "time: the writer; timings: the fit) and cannot be set");
}

// The record a key lives in, created with the format's defaults
// (spec/format.md 4.2) the first time one of its keys is set.
sogmm::FitInfo& fit_record(sogmm_model& m) {
  if (!m.model.fit.known) {
    m.model.fit = sogmm::FitInfo{};
    m.model.fit.known = true;
  }
  return m.model.fit;
}

sogmm::CameraInfo& camera_record(sogmm_model& m) {
  if (!m.model.camera.known) {
    m.model.camera = sogmm::CameraInfo{};
    m.model.camera.known = true;
  }
  return m.model.camera;
}

std::int32_t int32_value(sogmm_key key, std::int64_t v, std::int64_t lo) {
  if (v < lo || v > std::numeric_limits<std::int32_t>::max())
    bad_value(key, std::to_string(v), ("is outside [" + std::to_string(lo) + ", 2^31 - 1]").c_str());
  return static_cast<std::int32_t>(v);
}

}  // namespace

SOGMM_API sogmm_status sogmm_model_set_info_f64(sogmm_model* model, sogmm_key key, double value) {
  SOGMM_TRY {
    require_nonnull(model, "model");
    sogmm_capi::require_key(key, sogmm_capi::KeyKind::Info, sogmm_capi::KeyType::F64, "set");
    if (key >= SOGMM_INFO_FIT_SECONDS_MODE_COUNT && key <= SOGMM_INFO_FIT_SECONDS_TOTAL) not_stored(key);
    // Readers reject non-finite doubles in both records (spec/format.md 4.2).
    if (!std::isfinite(value)) bad_value(key, sogmm::checked::exact(value), "is not finite");
    sogmm_model& m = *model;
    switch (key) {
      case SOGMM_INFO_FIT_LOG_LIKELIHOOD: fit_record(m).log_likelihood = value; break;
      case SOGMM_INFO_FIT_BANDWIDTH: fit_record(m).bandwidth = value; break;
      case SOGMM_INFO_FIT_TOL: fit_record(m).tol = value; break;
      case SOGMM_INFO_FIT_REG_COVAR: fit_record(m).reg_covar = value; break;
      case SOGMM_INFO_CAMERA_FX: camera_record(m).camera.fx = value; break;
      case SOGMM_INFO_CAMERA_FY: camera_record(m).camera.fy = value; break;
      case SOGMM_INFO_CAMERA_CX: camera_record(m).camera.cx = value; break;
      case SOGMM_INFO_CAMERA_CY: camera_record(m).camera.cy = value; break;
      case SOGMM_INFO_CAMERA_DEPTH_SCALE: camera_record(m).depth_scale = value; break;
      case SOGMM_INFO_CAMERA_DEPTH_MIN: camera_record(m).depth_min = value; break;
      case SOGMM_INFO_CAMERA_DEPTH_MAX: camera_record(m).depth_max = value; break;
      default: fail(SOGMM_E_INTERNAL, "info key table out of sync");
    }
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_set_info_i64(sogmm_model* model, sogmm_key key, int64_t value) {
  SOGMM_TRY {
    require_nonnull(model, "model");
    sogmm_capi::require_key(key, sogmm_capi::KeyKind::Info, sogmm_capi::KeyType::I64, "set");
    sogmm_model& m = *model;
    switch (key) {
      // Values are checked before the record is created: a refused value leaves the model unchanged.
      case SOGMM_INFO_FIT_ITERATIONS: {
        const std::int32_t v = int32_value(key, value, std::numeric_limits<std::int32_t>::min());
        fit_record(m).n_iter = v;
        break;
      }
      case SOGMM_INFO_FIT_CONVERGED:
        if (value != 0 && value != 1) bad_value(key, std::to_string(value), "is not 0 or 1");
        fit_record(m).converged = value == 1;
        break;
      case SOGMM_INFO_FIT_N_COMPONENTS_REQUESTED:
        if (value < 0) bad_value(key, std::to_string(value), "is negative");
        fit_record(m).n_components_requested = static_cast<std::uint64_t>(value);
        break;
      case SOGMM_INFO_FIT_MAX_ITER: {
        const std::int32_t v = int32_value(key, value, std::numeric_limits<std::int32_t>::min());
        fit_record(m).max_iter = v;
        break;
      }
      case SOGMM_INFO_FIT_SEED: fit_record(m).seed = static_cast<std::uint64_t>(value); break;  // the bits, as get
      case SOGMM_INFO_CAMERA_WIDTH: {
        const std::int32_t v = int32_value(key, value, 0);
        camera_record(m).camera.width = v;
        break;
      }
      case SOGMM_INFO_CAMERA_HEIGHT: {
        const std::int32_t v = int32_value(key, value, 0);
        camera_record(m).camera.height = v;
        break;
      }
      case SOGMM_INFO_CAMERA_DECIMATION: {
        const std::int32_t v = int32_value(key, value, 1);
        camera_record(m).decimation = v;
        break;
      }
      default: not_stored(key);  // support size, creation time, n_points, n_init, run
    }
  }
  SOGMM_CATCH
}
