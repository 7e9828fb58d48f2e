// Fuzz target: sogmm_model_load_from_memory (C API) on arbitrary bytes, then
// every query on a model that loaded, and a save/load round trip that must
// reproduce it exactly. The decoded-size cap is lowered to 4 MiB so that no
// input can make one run allocate much (the cap itself is tested elsewhere).
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "fuzz_util.hpp"
#include "sogmm/sogmm.h"

namespace {

bool same_arrays(const sogmm_model* a, const sogmm_model* b, std::size_t m) {
  std::vector<float> x(16 * m), y(16 * m);
  if (sogmm_model_get_weights_f32(a, x.data(), m) || sogmm_model_get_weights_f32(b, y.data(), m)) return false;
  if (std::memcmp(x.data(), y.data(), m * sizeof(float)) != 0) return false;
  if (sogmm_model_get_means_f32(a, x.data(), 4 * m) || sogmm_model_get_means_f32(b, y.data(), 4 * m)) return false;
  if (std::memcmp(x.data(), y.data(), 4 * m * sizeof(float)) != 0) return false;
  if (sogmm_model_get_covariances_f32(a, x.data(), 16 * m) || sogmm_model_get_covariances_f32(b, y.data(), 16 * m))
    return false;
  return std::memcmp(x.data(), y.data(), 16 * m * sizeof(float)) == 0;
}

void exercise(const sogmm_model* model) {
  std::size_t m = 0;
  FUZZ_CHECK(sogmm_model_n_components(model, &m) == SOGMM_OK && m >= 1);
  std::vector<float> w(m), mu(4 * m), cov(16 * m);
  FUZZ_CHECK(sogmm_model_get_weights_f32(model, w.data(), w.size()) == SOGMM_OK);
  FUZZ_CHECK(sogmm_model_get_means_f32(model, mu.data(), mu.size()) == SOGMM_OK);
  FUZZ_CHECK(sogmm_model_get_covariances_f32(model, cov.data(), cov.size()) == SOGMM_OK);
  for (float v : w) FUZZ_CHECK(std::isfinite(v) && v >= 0.0f);
  for (float v : mu) FUZZ_CHECK(std::isfinite(v));
  for (float v : cov) FUZZ_CHECK(std::isfinite(v));

  std::size_t nv = 0;
  FUZZ_CHECK(sogmm_model_value_count(model, &nv) == SOGMM_OK);
  for (std::size_t i = 0; i < nv; ++i) {
    const char *k = nullptr, *v = nullptr, *again = nullptr;
    FUZZ_CHECK(sogmm_model_value_at(model, i, &k, &v) == SOGMM_OK && k && v);
    FUZZ_CHECK(sogmm_model_get_value(model, k, &again) == SOGMM_OK);
  }
  double d = 0;
  std::int64_t i64 = 0;
  double pose[16];
  for (sogmm_key key : {SOGMM_INFO_FIT_LOG_LIKELIHOOD, SOGMM_INFO_CAMERA_FX}) (void)sogmm_model_get_info_f64(model, key, &d);
  for (sogmm_key key : {SOGMM_INFO_SUPPORT_SIZE, SOGMM_INFO_FIT_ITERATIONS, SOGMM_INFO_CAMERA_WIDTH})
    (void)sogmm_model_get_info_i64(model, key, &i64);
  (void)sogmm_model_get_pose(model, pose);

  // Inference on a handful of points: a loaded model is valid, so these succeed
  // (scores may be -Inf far from every component, never NaN).
  const std::size_t n = 8;
  std::vector<float> samples(4 * n), xyz(3 * n), gray(n), var(n);
  std::vector<double> score(n);
  FUZZ_CHECK(sogmm_model_sample_f32(model, n, 7, 4, nullptr, samples.data()) == SOGMM_OK);
  for (std::size_t i = 0; i < n; ++i) std::memcpy(&xyz[3 * i], &samples[4 * i], 3 * sizeof(float));
  if (sogmm_model_regress_gray_f32(model, xyz.data(), n, nullptr, gray.data(), var.data()) == SOGMM_OK) {
    for (std::size_t i = 0; i < n; ++i) FUZZ_CHECK(!std::isnan(gray[i]) && !std::isnan(var[i]));
  }
  if (sogmm_model_score_samples_f32(model, samples.data(), n, 4, nullptr, score.data()) == SOGMM_OK) {
    for (double s : score) FUZZ_CHECK(!std::isnan(s));
  }

  // Round trip through memory: what was accepted is written and read back bit-exactly.
  sogmm_buffer* buf = nullptr;
  FUZZ_CHECK(sogmm_model_save_to_memory(&buf, model, nullptr) == SOGMM_OK);
  sogmm_model* back = nullptr;
  FUZZ_CHECK(sogmm_model_load_from_memory(&back, sogmm_buffer_data(buf), sogmm_buffer_size(buf), nullptr) == SOGMM_OK);
  FUZZ_CHECK(same_arrays(model, back, m));
  sogmm_model_free(back);
  sogmm_buffer_free(buf);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static sogmm_options* options = [] {
    sogmm_options* o = nullptr;
    sogmm_options_create(&o);
    sogmm_options_set_i64(o, SOGMM_OPT_MAX_DECODED_BYTES, 4 << 20);
    sogmm_options_set_i64(o, SOGMM_OPT_ZSTD_LEVEL, 1);
    return o;
  }();
  // libFuzzer may pass a null pointer for the empty input; the API wants data.
  static const std::uint8_t empty = 0;
  sogmm_model* model = nullptr;
  const sogmm_status s = sogmm_model_load_from_memory(&model, size ? data : &empty, size, options);
  if (s == SOGMM_OK) {
    FUZZ_CHECK(model != nullptr && sogmm_last_error()[0] == '\0');
    exercise(model);
  } else {
    FUZZ_CHECK(model == nullptr && sogmm_last_error()[0] != '\0');
    FUZZ_CHECK(s == SOGMM_E_FORMAT || s == SOGMM_E_INVALID_DATA || s == SOGMM_E_NUMERIC || s == SOGMM_E_LIMIT);
  }
  sogmm_model_free(model);
  return 0;
}
