// Scoring and gray regression of a model with progress and cancel (issue 16):
// the model queries of sogmm/inference.hpp run in chunks of points, with a
// report after each (sogmm/progress.hpp).
#pragma once

#include <cstddef>

#include "sogmm/gmm.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/progress.hpp"

namespace sogmm {

/// score_samples(gmm, points, n, dims, out, options) (sogmm/inference.hpp), the same
/// bits, reporting Stage::Scoring to `progress` (step = points scored: the
/// first report at 0, the last at n; total = n). Without a sink it is that
/// one call. With one, the points go in chunks of at least 4,096 (at most 64
/// chunks, so the query's per-call set-up, O(M), is repeated at most 64
/// times); every point's answer depends on that point alone. Errors as
/// score_samples (a non-finite point is found before anything is written and
/// named by its row); a cancel throws Error(Cancelled) with `out` partly
/// written.
void score_samples(const Gmm& gmm, const float* points, std::size_t n, int dims, double* out,
                   const QueryOptions& options, const ProgressSink& progress);

/// regress_gray(gmm, xyz, n, mean, variance, options) (sogmm/inference.hpp) with
/// Stage::Regression reports, as score_samples above.
void regress_gray(const Gmm& gmm, const float* xyz, std::size_t n, float* mean, float* variance,
                  const QueryOptions& options, const ProgressSink& progress);

}  // namespace sogmm
