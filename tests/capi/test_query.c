/* The query options through the C API (issue 17): score and regression with
 * an options handle holding only fit keys equal NULL options bitwise, the thread
 * count does not change a bit, the culled score stays within its bound
 * log(1 + M exp(-nats)) below the exact one and never above it, and bad
 * option values are refused by the setter.
 * Usage: sogmm_capi_test_query */
#include "test_util.h"

int main(void) {
  const size_t n = 3000;
  float* pts = make_clusters(n, 11);
  float* xyz = (float*)malloc(n * 3 * sizeof(float));
  double *s0 = (double*)malloc(n * sizeof(double)), *s1 = (double*)malloc(n * sizeof(double));
  float *m0 = (float*)malloc(n * sizeof(float)), *v0 = (float*)malloc(n * sizeof(float));
  float *m1 = (float*)malloc(n * sizeof(float)), *v1 = (float*)malloc(n * sizeof(float));
  sogmm_options* o = NULL;
  sogmm_model* model = NULL;
  size_t i, m = 0;
  int t;
  for (i = 0; i < n; ++i) memcpy(xyz + 3 * i, pts + 4 * i, 3 * sizeof(float));
  REQUIRE_OK(sogmm_options_create(&o));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_SEED, 3));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_N_COMPONENTS, 12));
  REQUIRE_OK(test_fit_fixed_k(&model, pts, n, 12, o));
  REQUIRE_OK(sogmm_model_n_components(model, &m));

  /* Query keys at their defaults: the answers of NULL options, bit for bit. */
  REQUIRE_OK(sogmm_model_score_samples_f32(model, pts, n, 4, NULL, s0));
  REQUIRE_OK(sogmm_model_score_samples_f32(model, pts, n, 4, o, s1));
  EXPECT_TRUE(memcmp(s0, s1, n * sizeof(double)) == 0);
  REQUIRE_OK(sogmm_model_regress_gray_f32(model, xyz, n, NULL, m0, v0));
  REQUIRE_OK(sogmm_model_regress_gray_f32(model, xyz, n, o, m1, v1));
  EXPECT_TRUE(memcmp(m0, m1, n * sizeof(float)) == 0 && memcmp(v0, v1, n * sizeof(float)) == 0);

  /* Any thread count, exact: the same bits. */
  for (t = 1; t <= 3; ++t) {
    REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_THREADS, t));
    REQUIRE_OK(sogmm_model_score_samples_f32(model, pts, n, 4, o, s1));
    EXPECT_TRUE(memcmp(s0, s1, n * sizeof(double)) == 0);
    REQUIRE_OK(sogmm_model_regress_gray_f32(model, xyz, n, o, m1, v1));
    EXPECT_TRUE(memcmp(m0, m1, n * sizeof(float)) == 0 && memcmp(v0, v1, n * sizeof(float)) == 0);
  }

  /* Culled at 3 nats: within the bound, never above the exact score. */
  REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_QUERY_TRUNCATION_NATS, 3.0));
  REQUIRE_OK(sogmm_model_score_samples_f32(model, pts, n, 4, o, s1));
  for (i = 0; i < n; ++i) {
    EXPECT_TRUE(s1[i] <= s0[i] + 1e-12 * (1 + fabs(s0[i])));
    EXPECT_TRUE(s0[i] - s1[i] <= log1p((double)m * exp(-3.0)) + 1e-12 * (1 + fabs(s0[i])));
  }
  REQUIRE_OK(sogmm_model_regress_gray_f32(model, xyz, n, o, m1, NULL));

  /* Bad values are refused by the setter and leave the handle unchanged. */
  {
    double v = 0;
    EXPECT_STATUS(sogmm_options_set_f64(o, SOGMM_OPT_QUERY_TRUNCATION_NATS, -1.0), SOGMM_E_INVALID_ARG);
    EXPECT_STATUS(sogmm_options_set_f64(o, SOGMM_OPT_QUERY_TRUNCATION_NATS, INFINITY), SOGMM_E_INVALID_ARG);
    EXPECT_STATUS(sogmm_options_set_f64(o, SOGMM_OPT_QUERY_TRUNCATION_NATS, NAN), SOGMM_E_INVALID_ARG);
    EXPECT_OK(sogmm_options_get_f64(o, SOGMM_OPT_QUERY_TRUNCATION_NATS, &v));
    EXPECT_TRUE(v == 3.0);
  }
  /* The usual argument errors. */
  EXPECT_STATUS(sogmm_model_score_samples_f32(NULL, pts, n, 4, o, s1), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_model_score_samples_f32(model, pts, n, 5, o, s1), SOGMM_E_INVALID_ARG);
  EXPECT_STATUS(sogmm_model_regress_gray_f32(model, NULL, n, o, m1, v1), SOGMM_E_NULL_ARG);
  EXPECT_OK(sogmm_model_regress_gray_f32(model, NULL, 0, o, NULL, NULL));

  sogmm_model_free(model);
  sogmm_options_free(o);
  free(pts);
  free(xyz);
  free(s0);
  free(s1);
  free(m0);
  free(v0);
  free(m1);
  free(v1);
  return test_summary("capi_query");
}
