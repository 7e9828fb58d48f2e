// sogmm_model: construction from arrays, copies, array copy-out, fit report
// and metadata (info keys, pose, key/values).
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>

#include "internal.hpp"
#include "keys.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/gmm.hpp"
#include "sogmm/metadata_string.hpp"

namespace {

using sogmm_capi::fail;
using sogmm_capi::require_nonnull;

std::int64_t now_unix_ms() {
  using namespace std::chrono;
  return duration_cast<milliseconds>(system_clock::now().time_since_epoch()).count();
}

/// sogmm_model_get_weights_f32, _means_f32 and _covariances_f32: the
/// mixture's array `array` (named `what`) copied to `out`, which holds
/// `capacity` floats.
sogmm_status get_array(const sogmm_model* model, std::vector<float> sogmm::Gmm::*array, float* out,
                       std::size_t capacity, const char* what) {
  SOGMM_TRY {
    require_nonnull(model, "model");
    require_nonnull(out, "out");
    const std::vector<float>& src = model->model.gmm.*array;
    if (capacity < src.size())
      fail(SOGMM_E_BUFFER_TOO_SMALL, std::string(what) + ": capacity " + std::to_string(capacity) + " < " +
                                         std::to_string(src.size()) + " floats needed");
    if (!src.empty()) std::memcpy(out, src.data(), src.size() * sizeof(float));
  }
  SOGMM_CATCH
}

[[noreturn]] void absent(sogmm_key key, const char* what) {
  fail(SOGMM_E_NOT_FOUND, "info key " + sogmm_capi::key_label(key) + ": the model has no " + what);
}

const sogmm::FitInfo& fit_info(const sogmm_model& m, sogmm_key key) {
  if (!m.model.fit.known) absent(key, "fit report");
  return m.model.fit;
}
const sogmm_fit_timings& timings(const sogmm_model& m, sogmm_key key) {
  if (!m.timings.known) absent(key, "fit timings (only models fitted in this process have them)");
  return m.timings;
}
const sogmm::CameraInfo& camera_info(const sogmm_model& m, sogmm_key key) {
  if (!m.model.camera.known) absent(key, "camera");
  return m.model.camera;
}

double info_f64(const sogmm_model& m, sogmm_key key) {
  switch (key) {
    case SOGMM_INFO_FIT_LOG_LIKELIHOOD: return fit_info(m, key).log_likelihood;
    case SOGMM_INFO_FIT_BANDWIDTH: return fit_info(m, key).bandwidth;
    case SOGMM_INFO_FIT_TOL: return fit_info(m, key).tol;
    case SOGMM_INFO_FIT_REG_COVAR: return fit_info(m, key).reg_covar;
    case SOGMM_INFO_FIT_SECONDS_MODE_COUNT: return timings(m, key).seconds_mode_count;
    case SOGMM_INFO_FIT_SECONDS_SEEDING: return timings(m, key).seconds_seeding;
    case SOGMM_INFO_FIT_SECONDS_EM: return timings(m, key).seconds_em;
    case SOGMM_INFO_FIT_SECONDS_TOTAL: return timings(m, key).seconds_total;
    case SOGMM_INFO_CAMERA_FX: return camera_info(m, key).camera.fx;
    case SOGMM_INFO_CAMERA_FY: return camera_info(m, key).camera.fy;
    case SOGMM_INFO_CAMERA_CX: return camera_info(m, key).camera.cx;
    case SOGMM_INFO_CAMERA_CY: return camera_info(m, key).camera.cy;
    case SOGMM_INFO_CAMERA_DEPTH_SCALE: return camera_info(m, key).depth_scale;
    case SOGMM_INFO_CAMERA_DEPTH_MIN: return camera_info(m, key).depth_min;
    case SOGMM_INFO_CAMERA_DEPTH_MAX: return camera_info(m, key).depth_max;
    default: fail(SOGMM_E_INTERNAL, "info key table out of sync");
  }
}

std::int64_t info_i64(const sogmm_model& m, sogmm_key key) {
  switch (key) {
    case SOGMM_INFO_SUPPORT_SIZE: return static_cast<std::int64_t>(m.model.gmm.support_size);
    case SOGMM_INFO_CREATED_UNIX_MS: return m.model.created_unix_ms;
    case SOGMM_INFO_FIT_ITERATIONS: return fit_info(m, key).n_iter;
    case SOGMM_INFO_FIT_CONVERGED: return fit_info(m, key).converged ? 1 : 0;
    case SOGMM_INFO_FIT_N_COMPONENTS_REQUESTED:
      return static_cast<std::int64_t>(fit_info(m, key).n_components_requested);
    case SOGMM_INFO_FIT_MAX_ITER: return fit_info(m, key).max_iter;
    case SOGMM_INFO_FIT_SEED: return static_cast<std::int64_t>(fit_info(m, key).seed);
    case SOGMM_INFO_FIT_N_POINTS: return static_cast<std::int64_t>(timings(m, key).n_points);
    case SOGMM_INFO_FIT_N_INIT: return timings(m, key).n_init;
    case SOGMM_INFO_FIT_RUN: return timings(m, key).run;
    case SOGMM_INFO_CAMERA_WIDTH: return camera_info(m, key).camera.width;
    case SOGMM_INFO_CAMERA_HEIGHT: return camera_info(m, key).camera.height;
    case SOGMM_INFO_CAMERA_DECIMATION: return camera_info(m, key).decimation;
    default: fail(SOGMM_E_INTERNAL, "info key table out of sync");
  }
}

/// sogmm_model_get_info_f64 and _i64: the checks every info read makes
/// (handle, out, a known info key of `type`), then `read` of the key.
template <typename T>
sogmm_status get_info(const sogmm_model* model, sogmm_key key, T* out, sogmm_capi::KeyType type,
                      T (*read)(const sogmm_model&, sogmm_key)) {
  SOGMM_TRY {
    require_nonnull(model, "model");
    require_nonnull(out, "out");
    sogmm_capi::require_key(key, sogmm_capi::KeyKind::Info, type, "get");
    *out = read(*model, key);
  }
  SOGMM_CATCH
}

/// The structural checks of sogmm::validate that the C API reports as
/// SOGMM_E_INVALID_DATA (the caller's arrays are wrong), same tolerances:
/// weights >= 0 summing to 1 within 1e-4, covariances symmetric within
/// 1e-5 of their largest entry. Positive definiteness is left to
/// sogmm::validate (SOGMM_E_NUMERIC).
void require_weights_and_symmetry(const sogmm::Gmm& g) {
  double sum = 0.0;
  for (std::size_t k = 0; k < g.size(); ++k) {
    if (!(g.weights[k] >= 0.0f))
      fail(SOGMM_E_INVALID_DATA, "weights: component " + std::to_string(k) + " has a negative weight " +
                                     sogmm::checked::exact(g.weights[k]));
    sum += g.weights[k];
  }
  if (std::fabs(sum - 1.0) > 1e-4)
    fail(SOGMM_E_INVALID_DATA, "weights sum to " + sogmm::checked::exact(sum) + ", not 1 (tolerance 1e-4)");
  for (std::size_t k = 0; k < g.size(); ++k) {
    const float* c = g.covariance(k);
    double scale = 0.0, asym = 0.0;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        scale = std::max(scale, std::fabs(static_cast<double>(c[4 * i + j])));
        asym = std::max(asym, std::fabs(static_cast<double>(c[4 * i + j]) - static_cast<double>(c[4 * j + i])));
      }
    if (asym > 1e-5 * scale)
      fail(SOGMM_E_INVALID_DATA, "covariances: component " + std::to_string(k) + " is not symmetric");
  }
}

}  // namespace

namespace sogmm_capi {
std::int64_t creation_time_now() { return now_unix_ms(); }
}  // namespace sogmm_capi

extern "C" {

SOGMM_API sogmm_status sogmm_model_from_arrays_f32(sogmm_model** out, size_t m, const float* weights,
                                                   const float* means, const float* covariances,
                                                   uint64_t support_size) {
  SOGMM_TRY {
    sogmm_capi::require_out(out);
    require_nonnull(weights, "weights");
    require_nonnull(means, "means");
    require_nonnull(covariances, "covariances");
    if (m == 0) fail(SOGMM_E_INVALID_DATA, "m is 0: a model needs at least one component");
    const std::size_t n_cov = sogmm::checked::mul<std::size_t>(m, 16, "covariances");
    sogmm_capi::require_finite(weights, m, "weights");
    sogmm_capi::require_finite(means, 4 * m, "means");
    sogmm_capi::require_finite(covariances, n_cov, "covariances");
    auto handle = std::make_unique<sogmm_model>();
    sogmm::Gmm& g = handle->model.gmm;
    g.weights.assign(weights, weights + m);
    g.means.assign(means, means + 4 * m);
    g.covariances.assign(covariances, covariances + n_cov);
    g.support_size = support_size;
    require_weights_and_symmetry(g);
    sogmm::validate(g);  // what remains: a covariance that is not positive definite (Numeric)
    handle->model.created_unix_ms = now_unix_ms();
    *out = handle.release();
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_clone(sogmm_model** out, const sogmm_model* model) {
  SOGMM_TRY {
    sogmm_capi::require_out(out);
    require_nonnull(model, "model");
    *out = new sogmm_model(*model);
  }
  SOGMM_CATCH
}

SOGMM_API void sogmm_model_free(sogmm_model* model) { delete model; }

SOGMM_API sogmm_status sogmm_model_n_components(const sogmm_model* model, size_t* out) {
  SOGMM_TRY {
    require_nonnull(model, "model");
    require_nonnull(out, "out");
    *out = model->model.gmm.size();
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_get_weights_f32(const sogmm_model* model, float* out, size_t capacity) {
  return get_array(model, &sogmm::Gmm::weights, out, capacity, "weights");
}

SOGMM_API sogmm_status sogmm_model_get_means_f32(const sogmm_model* model, float* out, size_t capacity) {
  return get_array(model, &sogmm::Gmm::means, out, capacity, "means");
}

SOGMM_API sogmm_status sogmm_model_get_covariances_f32(const sogmm_model* model, float* out,
                                                       size_t capacity) {
  return get_array(model, &sogmm::Gmm::covariances, out, capacity, "covariances");
}

SOGMM_API sogmm_status sogmm_model_get_info_f64(const sogmm_model* model, sogmm_key key, double* out) {
  return get_info(model, key, out, sogmm_capi::KeyType::F64, info_f64);
}

SOGMM_API sogmm_status sogmm_model_get_info_i64(const sogmm_model* model, sogmm_key key, int64_t* out) {
  return get_info(model, key, out, sogmm_capi::KeyType::I64, info_i64);
}

SOGMM_API sogmm_status sogmm_model_get_pose(const sogmm_model* model, double* pose_out) {
  SOGMM_TRY {
    require_nonnull(model, "model");
    require_nonnull(pose_out, "pose_out");
    if (!model->model.pose) fail(SOGMM_E_NOT_FOUND, "the model has no pose");
    std::copy(model->model.pose->begin(), model->model.pose->end(), pose_out);
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_set_pose(sogmm_model* model, const double* pose) {
  SOGMM_TRY {
    require_nonnull(model, "model");
    require_nonnull(pose, "pose");
    model->model.pose = sogmm_capi::require_rigid(pose, "pose");
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_clear_pose(sogmm_model* model) {
  SOGMM_TRY {
    require_nonnull(model, "model");
    model->model.pose.reset();
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_get_value(const sogmm_model* model, const char* key,
                                             const char** value_out) {
  SOGMM_TRY {
    require_nonnull(model, "model");
    require_nonnull(key, "key");
    require_nonnull(value_out, "value_out");
    if (const std::string* v = sogmm::find_value(model->model, key)) {
      *value_out = v->c_str();
      return SOGMM_OK;
    }
    fail(SOGMM_E_NOT_FOUND, std::string("no metadata key \"") + key + "\"");
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_set_value(sogmm_model* model, const char* key, const char* value) {
  SOGMM_TRY {
    require_nonnull(model, "model");
    require_nonnull(key, "key");
    require_nonnull(value, "value");
    if (*key == '\0') fail(SOGMM_E_INVALID_ARG, "metadata key is empty");
    // What no reader accepts, no setter stores (spec/format.md section 4.4).
    for (const char* s : {key, value}) {
      const std::string problem = sogmm::metadata_string_problem(s, std::strlen(s));
      if (!problem.empty())
        fail(SOGMM_E_INVALID_ARG, std::string("metadata ") + (s == key ? "key" : "value") + ": " + problem);
    }
    sogmm::set_value(model->model, key, value);
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_value_count(const sogmm_model* model, size_t* out) {
  SOGMM_TRY {
    require_nonnull(model, "model");
    require_nonnull(out, "out");
    *out = model->model.key_values.size();
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_value_at(const sogmm_model* model, size_t index, const char** key_out,
                                            const char** value_out) {
  SOGMM_TRY {
    require_nonnull(model, "model");
    require_nonnull(key_out, "key_out");
    require_nonnull(value_out, "value_out");
    const auto& kvs = model->model.key_values;
    if (index >= kvs.size())
      fail(SOGMM_E_INVALID_ARG, "index " + std::to_string(index) + " >= count " +
                                    std::to_string(kvs.size()));
    *key_out = kvs[index].first.c_str();
    *value_out = kvs[index].second.c_str();
  }
  SOGMM_CATCH
}

}  // extern "C"
