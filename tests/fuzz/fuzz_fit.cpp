// Fuzz target: fitting from a point buffer (C API) with hostile parameters and
// data. The input is a 32-byte header, then the points as float32:
//   byte 0      flags: bit 0 fixed-K call, bit 1 Gaussian-blurring mode counter,
//               bit 2 use the raw bandwidth, bits 3-4 set tol / reg_covar raw
//   bytes 1-2   K (uint16; fixed-K: k = K % (N + 2), so 0 and N + 1 occur)
//   bytes 3-10  bandwidth (raw double: NaN, Inf, negative, denormal ...);
//               without bit 2 it is mapped to [1e-3, 10)
//   bytes 11-18 tol (raw double), bytes 19-26 reg_covar (raw double)
//   byte 27     max_iter = 1 + byte % 8
//   bytes 28-31 seed
//   rest        N = min(rest / 16, 256) points (x, y, z, gray) float32
// Each run also probes the size checks with huge declared sizes that must be
// rejected before any point is read (n * 4 overflows size_t).
// Invariants: a fit either succeeds with a valid model (finite weights summing
// to 1, finite means and covariances, 1 <= M <= N) or fails with a documented
// status and message, leaving the out-pointer NULL.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "fuzz_model_check.hpp"
#include "../hardening/capi_calls.hpp"
#include "fuzz_util.hpp"
#include "sogmm/sogmm.h"

namespace {

constexpr std::size_t kMaxFuzzPoints = 256;

void check_model(const sogmm_model* model, std::size_t n, const sogmm_options* o) {
  FUZZ_CHECK(sogmm_fuzz::check_model(model) <= n);
  double ll = 0;
  FUZZ_CHECK(sogmm_model_get_info_f64(model, SOGMM_INFO_FIT_LOG_LIKELIHOOD, &ll) == SOGMM_OK);
  FUZZ_CHECK(!std::isnan(ll));
  // A fitted model can be saved and read back.
  sogmm_buffer* buf = nullptr;
  FUZZ_CHECK(sogmm_model_save_to_memory(&buf, model, o) == SOGMM_OK);
  sogmm_model* back = nullptr;
  FUZZ_CHECK(sogmm_model_load_from_memory(&back, sogmm_buffer_data(buf), sogmm_buffer_size(buf), nullptr) ==
             SOGMM_OK);
  sogmm_model_free(back);
  sogmm_buffer_free(buf);
}

void probe_huge_sizes(const float* pts, std::size_t n, const sogmm_options* o) {
  // n * 4 floats overflows size_t: refused before the buffer is read.
  for (std::size_t huge : {SIZE_MAX, SIZE_MAX / 4 + 1, SIZE_MAX / 2}) {
    sogmm_model* m = reinterpret_cast<sogmm_model*>(1);
    FUZZ_CHECK(sogmm_fit_points_f32(&m, pts, huge, nullptr, o) == SOGMM_E_LIMIT && m == nullptr);
    m = reinterpret_cast<sogmm_model*>(1);
    FUZZ_CHECK(sogmm_test::fit_fixed_k(&m, pts, huge, 1, o) == SOGMM_E_LIMIT && m == nullptr);
  }
  // A huge K with a real (small) buffer: K > N.
  if (n > 0) {
    sogmm_model* m = nullptr;
    FUZZ_CHECK(sogmm_test::fit_fixed_k(&m, pts, n, SIZE_MAX, o) != SOGMM_OK && m == nullptr);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  sogmm_fuzz::Reader in(data, size);
  const std::uint8_t flags = in.take<std::uint8_t>();
  const std::uint16_t k_raw = in.take<std::uint16_t>();
  const double bw_raw = in.take<double>();
  const double tol = in.take<double>();
  const double reg = in.take<double>();
  const std::uint8_t iters = in.take<std::uint8_t>();
  const std::uint32_t seed = in.take<std::uint32_t>();
  const std::size_t n = std::min(in.remaining() / 16, kMaxFuzzPoints);
  std::vector<float> pts(4 * n + 4);  // never empty, so .data() is never null
  if (n) std::memcpy(pts.data(), in.rest(), 16 * n);

  sogmm_options* o = nullptr;
  FUZZ_CHECK(sogmm_options_create(&o) == SOGMM_OK);
  FUZZ_CHECK(sogmm_options_set_i64(o, SOGMM_OPT_THREADS, 1) == SOGMM_OK);
  FUZZ_CHECK(sogmm_options_set_i64(o, SOGMM_OPT_ZSTD_LEVEL, 1) == SOGMM_OK);
  FUZZ_CHECK(sogmm_options_set_i64(o, SOGMM_OPT_MAX_ITER, 1 + iters % 8) == SOGMM_OK);
  FUZZ_CHECK(sogmm_options_set_i64(o, SOGMM_OPT_SEED, seed) == SOGMM_OK);
  if (flags & 2) FUZZ_CHECK(sogmm_options_set_i64(o, SOGMM_OPT_MODE_COUNTER, SOGMM_MODE_COUNTER_GAUSSIAN_BLURRING) == SOGMM_OK);
  double bw = bw_raw;
  if (!(flags & 4)) {
    const double u = std::isfinite(bw_raw) ? std::fabs(std::fmod(bw_raw, 1.0)) : 0.5;
    bw = 1e-3 * std::pow(1e4, u);  // [1e-3, 10)
  }
  // The setter's rule (spec/api.md): bw, bw^2, (3 bw)^2 and 1 / (2 bw^2)
  // finite and non-zero, so the mode counter never sees an infinite kernel.
  auto finite_nonzero = [](double v) { return std::isfinite(v) && v != 0.0; };
  const bool bw_valid = std::isfinite(bw) && bw > 0 && finite_nonzero(bw * bw) && std::isfinite(9.0 * bw * bw) &&
                        finite_nonzero(1.0 / (2.0 * bw * bw));
  FUZZ_CHECK(sogmm_options_set_f64(o, SOGMM_OPT_BANDWIDTH, bw) == (bw_valid ? SOGMM_OK : SOGMM_E_INVALID_ARG));
  if (flags & 8) {
    const bool ok = std::isfinite(tol) && tol >= 0;  // 0: EM runs max_iter iterations
    FUZZ_CHECK(sogmm_options_set_f64(o, SOGMM_OPT_TOL, tol) == (ok ? SOGMM_OK : SOGMM_E_INVALID_ARG));
  }
  if (flags & 16) {
    // float32 covariances; -1 is SOGMM_REG_COVAR_AUTO
    const bool ok = reg == SOGMM_REG_COVAR_AUTO || (std::isfinite(reg) && reg >= 0 && std::isfinite(static_cast<float>(reg)));
    FUZZ_CHECK(sogmm_options_set_f64(o, SOGMM_OPT_REG_COVAR, reg) == (ok ? SOGMM_OK : SOGMM_E_INVALID_ARG));
  }

  bool finite = true;
  for (std::size_t i = 0; i < 4 * n; ++i) finite = finite && std::isfinite(pts[i]);

  sogmm_model* model = reinterpret_cast<sogmm_model*>(1);
  sogmm_status s;
  if (flags & 1) {
    const std::size_t k = 1 + k_raw % (n + 1);  // K = 0 would be a self-organizing fit
    s = sogmm_test::fit_fixed_k(&model, pts.data(), n, k, o);
    if (n == 0 || !finite) FUZZ_CHECK(s == SOGMM_E_INVALID_DATA);
    else if (k > n) FUZZ_CHECK(s == SOGMM_E_INVALID_ARG);
  } else {
    s = sogmm_fit_points_f32(&model, pts.data(), n, nullptr, o);
    if (n == 0 || !finite) FUZZ_CHECK(s == SOGMM_E_INVALID_DATA);
  }
  if (s == SOGMM_OK) {
    FUZZ_CHECK(model != nullptr);
    check_model(model, n, o);
  } else {
    FUZZ_CHECK(model == nullptr && sogmm_last_error()[0] != '\0');
    // Valid input may still fail only with a clear numerical or limit status.
    FUZZ_CHECK(s == SOGMM_E_INVALID_DATA || s == SOGMM_E_INVALID_ARG || s == SOGMM_E_NUMERIC || s == SOGMM_E_LIMIT);
  }
  sogmm_model_free(model);
  probe_huge_sizes(pts.data(), n, o);
  sogmm_options_free(o);
  return 0;
}
