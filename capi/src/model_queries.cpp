// sogmm_model_regress_gray_f32 and sogmm_model_score_samples_f32: the model
// queries, with options for threads, culling, progress and cancel
// (sogmm/query_progress.hpp).
#include "internal.hpp"
#include "queries.hpp"
#include "sogmm/query_progress.hpp"

extern "C" {

SOGMM_API sogmm_status sogmm_model_regress_gray_f32(const sogmm_model* model, const float* xyz, size_t n,
                                                    const sogmm_options* options, float* mean_out,
                                                    float* variance_out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(model, "model");
    sogmm_capi::run_regress_query(xyz, n, options, mean_out, variance_out,
                                  [&](float* mean, float* variance, const sogmm::QueryOptions& query, const sogmm::ProgressSink& sink) {
                                    sogmm::regress_gray(model->model.gmm, xyz, n, mean, variance, query, sink);
                                  });
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_score_samples_f32(const sogmm_model* model, const float* points,
                                                     size_t n, int32_t dims, const sogmm_options* options,
                                                     double* out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(model, "model");
    sogmm_capi::require_dims(dims);
    sogmm_capi::run_score_query(points, n, dims, options, out, [&](double* dst, const sogmm::QueryOptions& query, const sogmm::ProgressSink& sink) {
      sogmm::score_samples(model->model.gmm, points, n, dims, dst, query, sink);
    });
  }
  SOGMM_CATCH
}

}  // extern "C"
