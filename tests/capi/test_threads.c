/* Thread-safety rules of spec/api.md: const queries on one shared handle run
 * concurrently and give the same results as serial calls; independent
 * handles are used from several threads at once; the last-error message is
 * per thread. */

#include "test_util.h"
#include "worker_check.h"

#define N_THREADS 4
#define N_POINTS 500
#define ROUNDS 5

static const sogmm_model* g_shared;
static float g_points[N_POINTS * 4];
static double g_ref_score[N_POINTS];
static float g_ref_gray[N_POINTS], g_ref_var[N_POINTS];
static float g_ref_samples[N_POINTS * 4];
static float g_xyz[N_POINTS * 3];

static void* worker(void* p) {
  worker_arg* arg = (worker_arg*)p;
  double score[N_POINTS];
  float gray[N_POINTS], var[N_POINTS];
  float* samples = (float*)malloc(sizeof g_ref_samples);
  int r;
  for (r = 0; r < ROUNDS; ++r) {
    const char* v = NULL;
    int64_t support = 0;
    size_t M = 0;
    /* const queries on the shared handle */
    WCHECK(sogmm_model_score_samples_f32(g_shared, g_points, N_POINTS, 4, NULL, score) == SOGMM_OK);
    WCHECK(memcmp(score, g_ref_score, sizeof score) == 0);
    WCHECK(sogmm_model_regress_gray_f32(g_shared, g_xyz, N_POINTS, NULL, gray, var) == SOGMM_OK);
    WCHECK(memcmp(gray, g_ref_gray, sizeof gray) == 0 && memcmp(var, g_ref_var, sizeof var) == 0);
    WCHECK(sogmm_model_sample_f32(g_shared, N_POINTS, 99, 4, NULL, samples) == SOGMM_OK);
    WCHECK(memcmp(samples, g_ref_samples, sizeof g_ref_samples) == 0);
    WCHECK(sogmm_model_get_value(g_shared, "owner", &v) == SOGMM_OK && strcmp(v, "main") == 0);
    WCHECK(sogmm_model_get_info_i64(g_shared, SOGMM_INFO_SUPPORT_SIZE, &support) == SOGMM_OK);
    WCHECK(sogmm_model_n_components(g_shared, &M) == SOGMM_OK && M == 3);
    /* independent handles: this thread's own fit, clone, merge, transform */
    {
      float* pts = make_clusters(600, (uint64_t)(arg->index * 1000 + r));
      sogmm_model *own = NULL, *merged = NULL, *moved = NULL;
      sogmm_options* o = NULL;
      const double T[16] = {1, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
      char key[32];
      WCHECK(sogmm_options_create(&o) == SOGMM_OK);
      WCHECK(sogmm_options_set_i64(o, SOGMM_OPT_THREADS, 1) == SOGMM_OK);
      WCHECK(test_fit_fixed_k(&own, pts, 600, 3, o) == SOGMM_OK);
      snprintf(key, sizeof key, "thread-%d", arg->index);
      WCHECK(sogmm_model_set_value(own, key, "x") == SOGMM_OK);
      WCHECK(sogmm_model_merge(&merged, own, g_shared) == SOGMM_OK);
      WCHECK(sogmm_model_transform(&moved, merged, T) == SOGMM_OK);
      WCHECK(sogmm_model_n_components(moved, &M) == SOGMM_OK && M == 6);
      /* per-thread last error: a failure here does not leak to other threads */
      WCHECK(sogmm_model_get_value(own, "missing", &v) == SOGMM_E_NOT_FOUND);
      WCHECK(strstr(sogmm_last_error(), "missing") != NULL);
      WCHECK(sogmm_model_n_components(own, &M) == SOGMM_OK);
      WCHECK(sogmm_last_error()[0] == '\0');
      sogmm_model_free(moved);
      sogmm_model_free(merged);
      sogmm_model_free(own);
      sogmm_options_free(o);
      free(pts);
    }
  }
  free(samples);
  return NULL;
}

int main(void) {
  worker_arg args[N_THREADS];
  float* pts = make_clusters(N_POINTS, 11);
  sogmm_model* shared = NULL;
  int failures = 0;
  size_t i;
  memcpy(g_points, pts, sizeof g_points);
  for (i = 0; i < N_POINTS; ++i) memcpy(g_xyz + 3 * i, g_points + 4 * i, 3 * sizeof(float));
  REQUIRE_OK(test_fit_fixed_k(&shared, pts, N_POINTS, 3, NULL));
  REQUIRE_OK(sogmm_model_set_value(shared, "owner", "main"));
  REQUIRE_OK(sogmm_model_score_samples_f32(shared, g_points, N_POINTS, 4, NULL, g_ref_score));
  REQUIRE_OK(sogmm_model_regress_gray_f32(shared, g_xyz, N_POINTS, NULL, g_ref_gray, g_ref_var));
  REQUIRE_OK(sogmm_model_sample_f32(shared, N_POINTS, 99, 4, NULL, g_ref_samples));
  g_shared = shared;
  /* a failure on the main thread: workers must still see their own (empty) message */
  EXPECT_STATUS(sogmm_model_n_components(NULL, &i), SOGMM_E_NULL_ARG);
  failures = run_workers(worker, args, N_THREADS);
  if (failures < 0) return 1;
  EXPECT_TRUE(failures == 0);
  /* main thread's message survived the workers' calls */
  EXPECT_TRUE(strstr(sogmm_last_error(), "model") != NULL);
  sogmm_model_free(shared);
  free(pts);
  return test_summary("capi_threads");
}
