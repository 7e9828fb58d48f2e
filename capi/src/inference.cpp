// Inference on a model: sample, regress gray, score, merge, transform.
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "internal.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/inference.hpp"

namespace {

using sogmm_capi::fail;
using sogmm_capi::require_nonnull;

void require_dims(int32_t dims) {
  if (dims != 3 && dims != 4)
    fail(SOGMM_E_INVALID_ARG, "dims = " + std::to_string(dims) + " (must be 3 or 4)");
}

// The query keys of `options` (NULL = defaults).
sogmm::QueryOptions query_options(const sogmm_options* options) {
  const sogmm_options& o = sogmm_capi::opts_or_default(options);
  sogmm::QueryOptions q;
  q.threads = static_cast<int>(o.threads);
  q.truncation_nats = o.query_truncation_nats;
  return q;
}

}  // namespace

extern "C" {

SOGMM_API sogmm_status sogmm_model_sample_f32(const sogmm_model* model, size_t n, uint64_t seed,
                                              int32_t dims, const sogmm_options* options, float* out) {
  SOGMM_TRY {
    require_nonnull(model, "model");
    require_dims(dims);
    if (n == 0) return SOGMM_OK;
    require_nonnull(out, "out");
    sogmm::checked::mul<std::size_t>(n, static_cast<std::size_t>(dims), "samples");
    const sogmm_options& o = sogmm_capi::opts_or_default(options);
    if (!o.progress) {
      sogmm::sample(model->model.gmm, n, seed, dims, out, o.sample_truncation);
    } else {
      // A cancel must leave `out` untouched: draw into a buffer, copy on success.
      std::vector<float> drawn(n * static_cast<std::size_t>(dims));
      const sogmm::ProgressScope scope(sogmm_capi::progress_sink(o));
      sogmm::sample(model->model.gmm, n, seed, dims, drawn.data(), o.sample_truncation);
      std::copy(drawn.begin(), drawn.end(), out);
    }
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_regress_gray_f32(const sogmm_model* model, const float* xyz, size_t n,
                                                    float* mean_out, float* variance_out) {
  return sogmm_model_regress_gray_opt_f32(model, xyz, n, nullptr, mean_out, variance_out);
}

SOGMM_API sogmm_status sogmm_model_regress_gray_opt_f32(const sogmm_model* model, const float* xyz, size_t n,
                                                        const sogmm_options* options, float* mean_out,
                                                        float* variance_out) {
  SOGMM_TRY {
    require_nonnull(model, "model");
    if (n == 0) return SOGMM_OK;
    require_nonnull(xyz, "xyz");
    require_nonnull(mean_out, "mean_out");
    sogmm_capi::require_finite(xyz, sogmm::checked::mul<std::size_t>(n, 3, "xyz"), "xyz");
    sogmm::regress_gray(model->model.gmm, xyz, n, mean_out, variance_out, query_options(options));
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_score_samples_f32(const sogmm_model* model, const float* points,
                                                     size_t n, int32_t dims, double* out) {
  return sogmm_model_score_samples_opt_f32(model, points, n, dims, nullptr, out);
}

SOGMM_API sogmm_status sogmm_model_score_samples_opt_f32(const sogmm_model* model, const float* points,
                                                         size_t n, int32_t dims, const sogmm_options* options,
                                                         double* out) {
  SOGMM_TRY {
    require_nonnull(model, "model");
    require_dims(dims);
    if (n == 0) return SOGMM_OK;
    require_nonnull(points, "points");
    require_nonnull(out, "out");
    sogmm_capi::require_finite(points, sogmm::checked::mul<std::size_t>(n, static_cast<std::size_t>(dims), "points"),
                               "points");
    sogmm::score_samples(model->model.gmm, points, n, dims, out, query_options(options));
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_merge(sogmm_model** out, const sogmm_model* a, const sogmm_model* b) {
  SOGMM_TRY {
    sogmm_capi::reset_out(out);
    require_nonnull(out, "out");
    require_nonnull(a, "a");
    require_nonnull(b, "b");
    auto handle = std::make_unique<sogmm_model>();
    handle->model = sogmm::merge(a->model, b->model);  // metadata: spec/format.md section 2.2
    handle->model.created_unix_ms = sogmm_capi::creation_time_now();
    *out = handle.release();
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_transform(sogmm_model** out, const sogmm_model* model,
                                             const double* pose) {
  SOGMM_TRY {
    sogmm_capi::reset_out(out);
    require_nonnull(out, "out");
    require_nonnull(model, "model");
    require_nonnull(pose, "pose");
    const std::array<double, 16> t = sogmm_capi::require_rigid(pose, "pose");
    auto handle = std::make_unique<sogmm_model>(*model);
    handle->model.gmm = sogmm::transform(model->model.gmm, t);
    if (handle->model.pose) {
      // P * pose^-1 of two valid poses is finite unless a translation overflows.
      const std::array<double, 16> moved = sogmm::compose_poses(*handle->model.pose, sogmm::inverse_rigid(t));
      const std::string problem = sogmm::rigid_pose_error(moved);
      if (!problem.empty()) fail(SOGMM_E_INVALID_ARG, "the model's pose moved by pose: " + problem);
      handle->model.pose = moved;
    }
    *out = handle.release();
  }
  SOGMM_CATCH
}

}  // extern "C"
