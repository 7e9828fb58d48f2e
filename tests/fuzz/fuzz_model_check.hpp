// The invariant every model handle satisfies, checked by the fuzz targets that
// make models through the C API: M >= 1, finite weights >= 0 summing to 1
// within 1e-4, finite means and covariances with a positive diagonal (no NaN
// or Inf model ever exists), and arrays that sogmm_model_from_arrays_f32
// accepts (every covariance positive definite as stored). A violation aborts
// (see FUZZ_CHECK).
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include "fuzz_util.hpp"
#include "sogmm/sogmm.h"

namespace sogmm_fuzz {

/// Checks `model` and returns its number of components M.
inline std::size_t check_model(const sogmm_model* model) {
  std::size_t m = 0;
  FUZZ_CHECK(sogmm_model_n_components(model, &m) == SOGMM_OK);
  FUZZ_CHECK(m >= 1);
  std::vector<float> w(m), mu(4 * m), cov(16 * m);
  FUZZ_CHECK(sogmm_model_get_weights_f32(model, w.data(), w.size()) == SOGMM_OK);
  FUZZ_CHECK(sogmm_model_get_means_f32(model, mu.data(), mu.size()) == SOGMM_OK);
  FUZZ_CHECK(sogmm_model_get_covariances_f32(model, cov.data(), cov.size()) == SOGMM_OK);
  double sum = 0;
  for (float v : w) {
    FUZZ_CHECK(std::isfinite(v) && v >= 0);
    sum += v;
  }
  FUZZ_CHECK(std::fabs(sum - 1.0) <= 1e-4);
  for (float v : mu) FUZZ_CHECK(std::isfinite(v));
  for (float v : cov) FUZZ_CHECK(std::isfinite(v));
  for (std::size_t k = 0; k < m; ++k)
    for (int i = 0; i < 4; ++i) FUZZ_CHECK(cov[16 * k + 5 * i] > 0);  // diagonal of an SPD matrix
  // Valid by the library's own test (each covariance's symmetric part positive
  // definite by the Cholesky a file reader makes): the handle rebuilt from its
  // own arrays. A call that makes a handle no later call accepts is then caught
  // where it made it, not at a later save (a rotated thin component once was).
  sogmm_model* rebuilt = nullptr;
  FUZZ_CHECK(sogmm_model_from_arrays_f32(&rebuilt, m, w.data(), mu.data(), cov.data(), 0) == SOGMM_OK);
  sogmm_model_free(rebuilt);
  return m;
}

}  // namespace sogmm_fuzz
