// Model queries with progress: chunked runs of the sogmm/inference.hpp
// queries (sogmm/query_progress.hpp).
#include "sogmm/query_progress.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "finite_rows.hpp"
#include "progress.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"

namespace sogmm {
namespace {

// Points per progress step: at least kMinChunk, and at most kMaxChunks
// chunks per call, so that the per-call set-up of the model query (per
// component, O(M)) is repeated at most kMaxChunks times.
constexpr std::size_t kMinChunk = 4096;
constexpr std::size_t kMaxChunks = 64;

// The model queries' own check (finite_rows.hpp), on the whole input before
// the first chunk, so that the message names the row in the caller's array
// and nothing is written for bad input.
using detail::require_finite_rows;

// Runs query(first, count) over [0, n) in chunks, reporting to `progress`
// the start, the chunks done (when a report is due, sogmm/progress.hpp) and
// the end (step = n). Every point's answer depends on that point alone, so
// chunking changes no result.
template <class Query>
void run_query(Stage stage, std::size_t n, const ProgressSink& progress, const Query& query) {
  const ProgressScope scope(progress);
  detail::progress_begin(stage, n);
  const std::size_t chunk = std::max(kMinChunk, n / kMaxChunks);
  for (std::size_t first = 0; first < n; first += chunk) {
    const std::size_t count = std::min(chunk, n - first);
    query(first, count);
    if (first + count < n) detail::progress_at(first + count);  // reported when due
  }
  detail::progress_event(n, 0.0);  // the end, always reported
}

}  // namespace

void score_samples(const Gmm& gmm, const float* points, std::size_t n, int dims, double* out,
                   const QueryOptions& options, const ProgressSink& progress) {
  if (!progress || n == 0 || dims < 3 || dims > 4 || points == nullptr || out == nullptr) {
    score_samples(gmm, points, n, dims, out, options);  // its checks and errors
    return;
  }
  const std::size_t width = static_cast<std::size_t>(dims);
  require_finite_rows(points, n, width, "points to score");
  run_query(Stage::Scoring, n, progress, [&](std::size_t first, std::size_t count) {
    score_samples(gmm, points + width * first, count, dims, out + first, options);
  });
}

void regress_gray(const Gmm& gmm, const float* xyz, std::size_t n, float* mean, float* variance,
                  const QueryOptions& options, const ProgressSink& progress) {
  if (!progress || n == 0 || xyz == nullptr || mean == nullptr) {
    regress_gray(gmm, xyz, n, mean, variance, options);
    return;
  }
  require_finite_rows(xyz, n, 3, "points to regress");
  run_query(Stage::Regression, n, progress, [&](std::size_t first, std::size_t count) {
    regress_gray(gmm, xyz + 3 * first, count, mean + first, variance ? variance + first : nullptr, options);
  });
}

}  // namespace sogmm
