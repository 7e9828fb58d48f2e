/* Warm start through the C API (issue 17): a fixed-K fit started from its own
 * optimum stays there; the self-organizing warm start keeps what the cloud
 * still supports; argument errors.
 * Usage: sogmm_capi_test_warm */
#include "test_util.h"

int main(void) {
  const size_t n = 3000;
  float* pts = make_clusters(n, 42);
  sogmm_options* o = NULL;
  sogmm_model* cold = NULL;
  sogmm_model* warm = NULL;
  double ll_cold = 0, ll_warm = 0;
  int64_t iters = 0;
  size_t m = 0;
  REQUIRE_OK(sogmm_options_create(&o));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_SEED, 7));
  REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_TOL, 1e-6));
  REQUIRE_OK(test_fit_fixed_k(&cold, pts, n, 3, o));
  REQUIRE_OK(sogmm_model_get_info_f64(cold, SOGMM_INFO_FIT_LOG_LIKELIHOOD, &ll_cold));

  /* Fixed K = 3 from the converged model: converged at once, same likelihood. */
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_N_COMPONENTS, 3));
  REQUIRE_OK(sogmm_fit_points_f32(&warm, pts, n, cold, o));
  EXPECT_OK(sogmm_model_get_info_f64(warm, SOGMM_INFO_FIT_LOG_LIKELIHOOD, &ll_warm));
  EXPECT_OK(sogmm_model_get_info_i64(warm, SOGMM_INFO_FIT_ITERATIONS, &iters));
  EXPECT_NEAR(ll_warm, ll_cold, 1e-4);
  EXPECT_TRUE(iters >= 1 && iters <= 3);
  sogmm_model_free(warm);
  warm = NULL;

  /* Self-organizing from the same model on the same points: all three
   * clusters are explained, so every component is kept. */
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_N_COMPONENTS, 0));
  REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_BANDWIDTH, 0.05));
  REQUIRE_OK(sogmm_fit_points_f32(&warm, pts, n, cold, o));
  EXPECT_OK(sogmm_model_n_components(warm, &m));
  EXPECT_TRUE(m >= 3);
  EXPECT_OK(sogmm_model_get_info_f64(warm, SOGMM_INFO_FIT_LOG_LIKELIHOOD, &ll_warm));
  EXPECT_TRUE(ll_warm >= ll_cold - 0.02);
  sogmm_model_free(warm);
  warm = NULL;

  /* Errors: several runs, K not the initial model's size (initial NULL is a
   * cold fit, not an error). */
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_N_INIT, 2));
  EXPECT_STATUS(sogmm_fit_points_f32(&warm, pts, n, cold, o), SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(strstr(sogmm_last_error(), "n_init") != NULL);
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_N_INIT, 1));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_N_COMPONENTS, 2));
  EXPECT_STATUS(sogmm_fit_points_f32(&warm, pts, n, cold, o), SOGMM_E_INVALID_ARG);
  EXPECT_STATUS(sogmm_fit_points_f32(&warm, pts, 0, cold, o), SOGMM_E_INVALID_DATA);

  sogmm_model_free(cold);
  sogmm_options_free(o);
  free(pts);
  return test_summary("capi_warm");
}
