// Argument checks and output handling shared by the model queries
// (inference.cpp) and the map queries (map_queries.cpp) of the C API, so that
// both refuse the same inputs with the same statuses. Never installed.
#pragma once

#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

#include "internal.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/inference.hpp"

namespace sogmm_capi {

inline void require_dims(int32_t dims) {
  if (dims != 3 && dims != 4) fail(SOGMM_E_INVALID_ARG, "dims = " + std::to_string(dims) + " (must be 3 or 4)");
}

/// Checks `n` rows of `width` floats at `in` for a query writing to `out`
/// (both required): SOGMM_E_NULL_ARG, SOGMM_E_LIMIT when n * width
/// overflows, SOGMM_E_INVALID_DATA for NaN/Inf. Call only for n > 0.
inline void require_query_input(const float* in, std::size_t n, std::size_t width, const char* in_name,
                                const void* out, const char* out_name) {
  require_nonnull(in, in_name);
  require_nonnull(out, out_name);
  require_finite(in, sogmm::checked::mul<std::size_t>(n, width, in_name), in_name);
}

/// The query keys of `o`: SOGMM_OPT_THREADS, SOGMM_OPT_QUERY_TRUNCATION_NATS.
inline const sogmm::QueryOptions& query_options(const sogmm_options& o) { return o.settings.query; }

/// Runs write(dst) for an output of `count` values: straight into `out`, or,
/// when `progress` is set, into a temporary copied to `out` only on success,
/// so that a cancelled call leaves `out` untouched (sogmm_progress_fn).
template <class T, class Write>
void write_on_success(bool progress, T* out, std::size_t count, const Write& write) {
  if (!progress || out == nullptr) {
    write(out);
    return;
  }
  std::vector<T> tmp(count);
  write(tmp.data());
  std::copy(tmp.begin(), tmp.end(), out);
}

/// The body of a score query (model or map) after the handle and dims
/// checks: n == 0 writes nothing; then require_query_input; then
/// score(dst, query options, sink) with the options' query keys and progress sink, through
/// write_on_success.
template <class Score>
void run_score_query(const float* points, std::size_t n, int32_t dims, const sogmm_options* options, double* out,
                     const Score& score) {
  if (n == 0) return;
  require_query_input(points, n, static_cast<std::size_t>(dims), "points", out, "out");
  const sogmm_options& o = opts_or_default(options);
  write_on_success(o.progress != nullptr, out, n, [&](double* dst) { score(dst, query_options(o), progress_sink(o)); });
}

/// The same for a gray regression: regress(mean, variance, query options, sink), the
/// variance optional (NULL stays NULL).
template <class Regress>
void run_regress_query(const float* xyz, std::size_t n, const sogmm_options* options, float* mean_out,
                       float* variance_out, const Regress& regress) {
  if (n == 0) return;
  require_query_input(xyz, n, 3, "xyz", mean_out, "mean_out");
  const sogmm_options& o = opts_or_default(options);
  write_on_success(o.progress != nullptr, mean_out, n, [&](float* mean) {
    write_on_success(o.progress != nullptr, variance_out, n,
                     [&](float* variance) { regress(mean, variance, query_options(o), progress_sink(o)); });
  });
}

}  // namespace sogmm_capi
