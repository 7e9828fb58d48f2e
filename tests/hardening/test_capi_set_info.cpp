// sogmm_model_set_info_f64 / _i64 at the C boundary: NULL handles, keys of
// the wrong kind, type or storage are refused by name and leave the model
// unchanged; accepted values survive save_to_memory / load_from_memory.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>

#include "sogmm/sogmm.h"

namespace {

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

sogmm_model* two_components() {
  const float w[2] = {0.5f, 0.5f};
  const float mu[8] = {0, 0, 1, 0.5f, 1, 0, 1, 0.5f};
  float cov[32] = {};
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < 4; ++i) cov[16 * k + 5 * i] = 0.01f;
  sogmm_model* m = nullptr;
  EXPECT_EQ(sogmm_model_from_arrays_f32(&m, 2, w, mu, cov, 100), SOGMM_OK);
  return m;
}

TEST(CapiSetInfo, NullAndWrongKeysAreRefusedByName) {
  EXPECT_EQ(sogmm_model_set_info_f64(nullptr, SOGMM_INFO_FIT_TOL, 1e-3), SOGMM_E_NULL_ARG);
  EXPECT_EQ(sogmm_model_set_info_i64(nullptr, SOGMM_INFO_FIT_SEED, 1), SOGMM_E_NULL_ARG);
  sogmm_model* m = two_components();
  EXPECT_EQ(sogmm_model_set_info_f64(m, SOGMM_OPT_BANDWIDTH, 0.1), SOGMM_E_INVALID_ARG);  // an option key
  EXPECT_TRUE(has(sogmm_last_error(), "SOGMM_OPT_BANDWIDTH")) << sogmm_last_error();
  EXPECT_EQ(sogmm_model_set_info_f64(m, SOGMM_INFO_FIT_ITERATIONS, 3), SOGMM_E_INVALID_ARG);  // an i64 key
  EXPECT_TRUE(has(sogmm_last_error(), "sogmm_model_set_info_i64")) << sogmm_last_error();
  EXPECT_EQ(sogmm_model_set_info_i64(m, SOGMM_INFO_SUPPORT_SIZE, 3), SOGMM_E_INVALID_ARG);  // not stored
  EXPECT_TRUE(has(sogmm_last_error(), "not stored")) << sogmm_last_error();
  EXPECT_EQ(sogmm_model_set_info_f64(m, SOGMM_INFO_FIT_SECONDS_EM, 1.0), SOGMM_E_INVALID_ARG);
  EXPECT_EQ(sogmm_model_set_info_f64(m, SOGMM_INFO_FIT_TOL, NAN), SOGMM_E_INVALID_ARG);
  EXPECT_EQ(sogmm_model_set_info_i64(m, SOGMM_INFO_CAMERA_DECIMATION, 0), SOGMM_E_INVALID_ARG);
  EXPECT_EQ(sogmm_model_set_info_i64(m, SOGMM_INFO_FIT_MAX_ITER, INT64_C(1) << 31), SOGMM_E_INVALID_ARG);
  double v = 0;
  int64_t i = 0;
  // Every refusal came before a record was created.
  EXPECT_EQ(sogmm_model_get_info_f64(m, SOGMM_INFO_FIT_TOL, &v), SOGMM_E_NOT_FOUND);
  EXPECT_EQ(sogmm_model_get_info_i64(m, SOGMM_INFO_CAMERA_DECIMATION, &i), SOGMM_E_NOT_FOUND);
  sogmm_model_free(m);
}

TEST(CapiSetInfo, ValuesSurviveAFileRoundTrip) {
  sogmm_model* m = two_components();
  ASSERT_EQ(sogmm_model_set_info_f64(m, SOGMM_INFO_FIT_LOG_LIKELIHOOD, -1.25), SOGMM_OK);
  ASSERT_EQ(sogmm_model_set_info_i64(m, SOGMM_INFO_FIT_SEED, -1), SOGMM_OK);  // the bits of 2^64 - 1
  ASSERT_EQ(sogmm_model_set_info_i64(m, SOGMM_INFO_FIT_CONVERGED, 1), SOGMM_OK);
  ASSERT_EQ(sogmm_model_set_info_i64(m, SOGMM_INFO_CAMERA_WIDTH, 640), SOGMM_OK);
  sogmm_buffer* buf = nullptr;
  ASSERT_EQ(sogmm_model_save_to_memory(&buf, m, nullptr), SOGMM_OK);
  sogmm_model* back = nullptr;
  ASSERT_EQ(sogmm_model_load_from_memory(&back, sogmm_buffer_data(buf), sogmm_buffer_size(buf), nullptr), SOGMM_OK);
  double v = 0;
  int64_t i = 0;
  EXPECT_EQ(sogmm_model_get_info_f64(back, SOGMM_INFO_FIT_LOG_LIKELIHOOD, &v), SOGMM_OK);
  EXPECT_EQ(v, -1.25);
  EXPECT_EQ(sogmm_model_get_info_i64(back, SOGMM_INFO_FIT_SEED, &i), SOGMM_OK);
  EXPECT_EQ(i, -1);
  EXPECT_EQ(sogmm_model_get_info_i64(back, SOGMM_INFO_FIT_CONVERGED, &i), SOGMM_OK);
  EXPECT_EQ(i, 1);
  EXPECT_EQ(sogmm_model_get_info_f64(back, SOGMM_INFO_FIT_TOL, &v), SOGMM_OK);  // the format's default
  EXPECT_EQ(v, 0.0);
  EXPECT_EQ(sogmm_model_get_info_i64(back, SOGMM_INFO_CAMERA_WIDTH, &i), SOGMM_OK);
  EXPECT_EQ(i, 640);
  EXPECT_EQ(sogmm_model_get_info_f64(back, SOGMM_INFO_CAMERA_DEPTH_SCALE, &v), SOGMM_OK);
  EXPECT_EQ(v, 1000.0);
  sogmm_model_free(back);
  sogmm_buffer_free(buf);
  sogmm_model_free(m);
}

}  // namespace
