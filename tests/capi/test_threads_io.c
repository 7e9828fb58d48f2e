/* Concurrency of independent handles across the whole API (spec/api.md,
 * section 6), written to run under ThreadSanitizer: N threads at once each
 * fit their own model (points and fixed K), save it to their own path, load
 * it back, save/load through memory, sample, regress and score, merge with a
 * shared read-only model, and load one shared file and save one shared const
 * model concurrently (each to its own path, and all to one common path). Results are compared with the
 * same work done serially beforehand.
 *
 * Usage: sogmm_capi_test_threads_io SCRATCH_DIR
 * Under TSan run with OMP_NUM_THREADS=1 (libgomp is not instrumented); the
 * fits also set SOGMM_OPT_THREADS = 1. */
#include <unistd.h>

#include "test_util.h"
#include "worker_check.h"

#define N_THREADS 4
#define N_POINTS 400
#define ROUNDS 3

static const char* g_dir;
static const sogmm_model* g_shared;
static char g_shared_path[512];
static char g_same_path[512];
static float* g_points[N_THREADS];
static float g_ref_weights[N_THREADS][4];
static float g_ref_samples[N_THREADS][64 * 4];
static size_t g_ref_M[N_THREADS];

static sogmm_options* one_thread_options(void) {
  sogmm_options* o = NULL;
  if (sogmm_options_create(&o) != SOGMM_OK) return NULL;
  sogmm_options_set_i64(o, SOGMM_OPT_THREADS, 1);
  sogmm_options_set_i64(o, SOGMM_OPT_ZSTD_LEVEL, 3);
  return o;
}

/* The work of one thread; fills the reference arrays when `record` is set. */
static void work(worker_arg* arg, int record) {
  const int t = arg->index;
  sogmm_options* o = one_thread_options();
  char path[600], shared_copy[600];
  int r;
  snprintf(path, sizeof path, "%s/thread-%d.sogmm", g_dir, t);
  snprintf(shared_copy, sizeof shared_copy, "%s/shared-copy-%d.sogmm", g_dir, t);
  WCHECK(o != NULL);
  for (r = 0; r < (record ? 1 : ROUNDS); ++r) {
    sogmm_model *fit = NULL, *so = NULL, *loaded = NULL, *from_mem = NULL, *merged = NULL, *shared_loaded = NULL;
    sogmm_buffer* buf = NULL;
    float w[4], samples[64 * 4], xyz[64 * 3], gray[64], var[64];
    double score[64];
    size_t M = 0, i;
    /* fit: fixed K and self-organizing */
    WCHECK(test_fit_fixed_k(&fit, g_points[t], N_POINTS, 4, o) == SOGMM_OK);
    WCHECK(sogmm_fit_points_f32(&so, g_points[t], N_POINTS, NULL, o) == SOGMM_OK);
    WCHECK(sogmm_model_n_components(so, &M) == SOGMM_OK && M >= 1);
    if (record) g_ref_M[t] = M;
    else WCHECK(M == g_ref_M[t]);
    /* save to its own path, load back */
    WCHECK(sogmm_model_set_value(fit, "thread", "x") == SOGMM_OK);
    WCHECK(sogmm_model_save(fit, path, o) == SOGMM_OK);
    WCHECK(sogmm_model_load(&loaded, path, o) == SOGMM_OK);
    WCHECK(sogmm_model_get_weights_f32(loaded, w, 4) == SOGMM_OK);
    if (record) memcpy(g_ref_weights[t], w, sizeof w);
    else WCHECK(memcmp(w, g_ref_weights[t], sizeof w) == 0);
    /* through memory */
    WCHECK(sogmm_model_save_to_memory(&buf, loaded, o) == SOGMM_OK);
    WCHECK(sogmm_model_load_from_memory(&from_mem, sogmm_buffer_data(buf), sogmm_buffer_size(buf), o) == SOGMM_OK);
    /* inference */
    WCHECK(sogmm_model_sample_f32(from_mem, 64, (uint64_t)t, 4, NULL, samples) == SOGMM_OK);
    if (record) memcpy(g_ref_samples[t], samples, sizeof samples);
    else WCHECK(memcmp(samples, g_ref_samples[t], sizeof samples) == 0);
    for (i = 0; i < 64; ++i) memcpy(xyz + 3 * i, samples + 4 * i, 3 * sizeof(float));
    WCHECK(sogmm_model_regress_gray_f32(from_mem, xyz, 64, NULL, gray, var) == SOGMM_OK);
    WCHECK(sogmm_model_score_samples_f32(from_mem, samples, 64, 4, NULL, score) == SOGMM_OK);
    /* the shared const model: merge, save (own path), and the shared file: load */
    WCHECK(sogmm_model_merge(&merged, from_mem, g_shared) == SOGMM_OK);
    WCHECK(sogmm_model_save(g_shared, shared_copy, o) == SOGMM_OK);
    WCHECK(sogmm_model_load(&shared_loaded, g_shared_path, NULL) == SOGMM_OK);
    WCHECK(sogmm_model_n_components(shared_loaded, &M) == SOGMM_OK && M == 3);
    /* all threads save the shared model to one common path and load it: the
     * renames are atomic, so every load sees one complete file */
    {
      sogmm_model* same = NULL;
      WCHECK(sogmm_model_save(g_shared, g_same_path, o) == SOGMM_OK);
      WCHECK(sogmm_model_load(&same, g_same_path, o) == SOGMM_OK);
      WCHECK(sogmm_model_n_components(same, &M) == SOGMM_OK && M == 3);
      sogmm_model_free(same);
    }
    /* errors stay per thread */
    {
      sogmm_model* missing = NULL;
      WCHECK(sogmm_model_load(&missing, "/nonexistent/dir/x.sogmm", o) == SOGMM_E_IO && missing == NULL);
    }
    WCHECK(strstr(sogmm_last_error(), "nonexistent") != NULL);
    sogmm_model_free(shared_loaded);
    sogmm_model_free(merged);
    sogmm_model_free(from_mem);
    sogmm_buffer_free(buf);
    sogmm_model_free(loaded);
    sogmm_model_free(so);
    sogmm_model_free(fit);
  }
  sogmm_options_free(o);
  unlink(path);
  unlink(shared_copy);
}

static void* worker(void* p) {
  work((worker_arg*)p, 0);
  return NULL;
}

int main(int argc, char** argv) {
  worker_arg args[N_THREADS];
  sogmm_model* shared = NULL;
  float* pts;
  int t, failures = 0;
  g_dir = argc > 1 ? argv[1] : "/tmp";
  pts = make_clusters(N_POINTS, 5);
  REQUIRE_OK(test_fit_fixed_k(&shared, pts, N_POINTS, 3, NULL));
  snprintf(g_shared_path, sizeof g_shared_path, "%s/threads-io-shared.sogmm", g_dir);
  REQUIRE_OK(sogmm_model_save(shared, g_shared_path, NULL));
  snprintf(g_same_path, sizeof g_same_path, "%s/threads-io-same.sogmm", g_dir);
  g_shared = shared;
  for (t = 0; t < N_THREADS; ++t) g_points[t] = make_clusters(N_POINTS, (uint64_t)(100 + t));
  /* serial reference run */
  for (t = 0; t < N_THREADS; ++t) {
    args[t].index = t;
    args[t].failures = 0;
    work(&args[t], 1);
    failures += args[t].failures;
  }
  EXPECT_TRUE(failures == 0);
  /* concurrent run */
  failures = run_workers(worker, args, N_THREADS);
  if (failures < 0) return 1;
  EXPECT_TRUE(failures == 0);
  for (t = 0; t < N_THREADS; ++t) free(g_points[t]);
  unlink(g_shared_path);
  unlink(g_same_path);
  sogmm_model_free(shared);
  free(pts);
  return test_summary("capi_threads_io");
}
