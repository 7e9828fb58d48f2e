// Inference on a model: sample, merge, transform (score and regress: model_queries.cpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "internal.hpp"
#include "queries.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/inference.hpp"

namespace {

using sogmm_capi::fail;
using sogmm_capi::require_dims;
using sogmm_capi::require_nonnull;

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
    // With a callback, draw into a buffer (a cancel leaves `out` untouched).
    sogmm_capi::write_on_success(o.progress != nullptr, out, n * static_cast<std::size_t>(dims), [&](float* dst) {
      const sogmm::ProgressScope scope(sogmm_capi::progress_sink(o));
      sogmm::sample(model->model.gmm, n, seed, dims, dst, o.settings.sample.truncation);
    });
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_merge(sogmm_model** out, const sogmm_model* a, const sogmm_model* b) {
  SOGMM_TRY {
    sogmm_capi::require_out(out);
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
    sogmm_capi::require_out(out);
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
