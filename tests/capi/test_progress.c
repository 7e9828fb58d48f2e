/* Progress callback and cancel (sogmm_options_set_progress, spec/api.md
 * 4.2.1): called only on the calling thread, stages and EM steps in order,
 * results unchanged by a callback, a non-zero return gives SOGMM_E_CANCELLED
 * with no output (NULL model, sample buffer untouched), clone copies the
 * callback and NULL removes it. */
#include <pthread.h>

#include "test_util.h"

#define MAX_REPORTS 100000

typedef struct {
  pthread_t caller;
  int off_thread; /* calls made on another thread */
  int n;
  int32_t stage[MAX_REPORTS];
  uint64_t step[MAX_REPORTS];
  int32_t cancel_stage; /* cancel at the first report of this stage with step >= cancel_step */
  uint64_t cancel_step;
} Recorder;

static int32_t record(int32_t stage, uint64_t step, uint64_t total, double ll, void* user_data) {
  Recorder* r = (Recorder*)user_data;
  (void)total;
  (void)ll;
  if (!pthread_equal(pthread_self(), r->caller)) ++r->off_thread;
  if (r->n < MAX_REPORTS) {
    r->stage[r->n] = stage;
    r->step[r->n] = step;
    ++r->n;
  }
  return stage == r->cancel_stage && step >= r->cancel_step;
}

static sogmm_options* em_options(Recorder* r) {
  sogmm_options* o = NULL;
  REQUIRE_OK(sogmm_options_create(&o));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_N_COMPONENTS, 12));
  REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_TOL, 1e-300)); /* EM runs max_iter iterations */
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_MAX_ITER, 15));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_THREADS, 2));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_SEED, 4));
  if (r) REQUIRE_OK(sogmm_options_set_progress(o, record, r));
  return o;
}

static void get_means(const sogmm_model* m, float* out) { REQUIRE_OK(sogmm_model_get_means_f32(m, out, 12 * 4)); }

int main(void) {
  const size_t n = 20000;
  float* pts = make_clusters(n, 7);
  static Recorder rec;
  float plain_means[48], means[48];
  size_t i;

  /* Reports: seeding, then EM steps 0..15 in order, all on this thread; the
   * model equals the one fitted without a callback. */
  {
    sogmm_options* plain_o = em_options(NULL);
    sogmm_options* o;
    sogmm_model *plain = NULL, *m = NULL;
    uint64_t next = 0;
    memset(&rec, 0, sizeof rec);
    rec.caller = pthread_self();
    rec.cancel_stage = -1;
    o = em_options(&rec);
    REQUIRE_OK(sogmm_fit_points_f32(&plain, pts, n, NULL, plain_o));
    REQUIRE_OK(sogmm_fit_points_f32(&m, pts, n, NULL, o));
    get_means(plain, plain_means);
    get_means(m, means);
    EXPECT_TRUE(memcmp(plain_means, means, sizeof means) == 0);
    EXPECT_TRUE(rec.off_thread == 0);
    EXPECT_TRUE(rec.n > 16);
    EXPECT_TRUE(rec.stage[0] == SOGMM_STAGE_SEEDING);
    for (i = 0; i < (size_t)rec.n; ++i) {
      if (rec.stage[i] != SOGMM_STAGE_EM) continue;
      EXPECT_TRUE(rec.step[i] == next || rec.step[i] + 1 == next); /* new step, or a heartbeat */
      if (rec.step[i] == next) ++next;
    }
    EXPECT_TRUE(next == 16);
    sogmm_model_free(plain);
    sogmm_model_free(m);
    sogmm_options_free(plain_o);

    /* Cancel at EM iteration 3: CANCELLED, NULL model, no report after it. */
    memset(&rec, 0, sizeof rec);
    rec.caller = pthread_self();
    rec.cancel_stage = SOGMM_STAGE_EM;
    rec.cancel_step = 3;
    m = (sogmm_model*)&rec; /* must become NULL */
    EXPECT_STATUS(sogmm_fit_points_f32(&m, pts, n, NULL, o), SOGMM_E_CANCELLED);
    EXPECT_TRUE(m == NULL);
    EXPECT_TRUE(strstr(sogmm_last_error(), "EM iteration 3") != NULL);
    EXPECT_TRUE(rec.stage[rec.n - 1] == SOGMM_STAGE_EM && rec.step[rec.n - 1] == 3);
    EXPECT_TRUE(strcmp(sogmm_status_string(SOGMM_E_CANCELLED), "unknown status") != 0);

    /* Cancel at the first report: the seeding stage. */
    memset(&rec, 0, sizeof rec);
    rec.caller = pthread_self();
    rec.cancel_stage = SOGMM_STAGE_SEEDING;
    EXPECT_STATUS(test_fit_fixed_k(&m, pts, n, 12, o), SOGMM_E_CANCELLED);
    EXPECT_TRUE(m == NULL && rec.n == 1);

    /* A clone keeps the callback; NULL removes it. */
    {
      sogmm_options* c = NULL;
      REQUIRE_OK(sogmm_options_clone(&c, o));
      memset(&rec, 0, sizeof rec);
      rec.caller = pthread_self();
      rec.cancel_stage = SOGMM_STAGE_SEEDING;
      EXPECT_STATUS(sogmm_fit_points_f32(&m, pts, n, NULL, c), SOGMM_E_CANCELLED);
      REQUIRE_OK(sogmm_options_set_progress(c, NULL, &rec));
      memset(&rec, 0, sizeof rec);
      REQUIRE_OK(sogmm_fit_points_f32(&m, pts, n, NULL, c));
      EXPECT_TRUE(rec.n == 0);
      sogmm_model_free(m);
      sogmm_options_free(c);
    }
    EXPECT_STATUS(sogmm_options_set_progress(NULL, record, &rec), SOGMM_E_NULL_ARG);

    /* The self-organizing fit starts with the mode count. */
    {
      sogmm_options* so = NULL;
      REQUIRE_OK(sogmm_options_create(&so));
      REQUIRE_OK(sogmm_options_set_f64(so, SOGMM_OPT_BANDWIDTH, 0.05));
      REQUIRE_OK(sogmm_options_set_progress(so, record, &rec));
      memset(&rec, 0, sizeof rec);
      rec.caller = pthread_self();
      rec.cancel_stage = SOGMM_STAGE_MODE_COUNT;
      rec.cancel_step = 0;
      EXPECT_STATUS(sogmm_fit_points_f32(&m, pts, n, NULL, so), SOGMM_E_CANCELLED);
      EXPECT_TRUE(m == NULL && rec.n == 1 && rec.stage[0] == SOGMM_STAGE_MODE_COUNT);
      sogmm_options_free(so);
    }

    /* Sampling: a cancelled sample leaves `out` untouched; without a cancel
     * the samples equal those drawn without a callback. */
    {
      const size_t ns = 5000;
      float* out = (float*)malloc(ns * 4 * sizeof(float));
      float* ref = (float*)malloc(ns * 4 * sizeof(float));
      REQUIRE_OK(sogmm_fit_points_f32(&m, pts, n, NULL, plain_o = em_options(NULL)));
      for (i = 0; i < ns * 4; ++i) out[i] = -7.0f;
      memset(&rec, 0, sizeof rec);
      rec.caller = pthread_self();
      rec.cancel_stage = SOGMM_STAGE_SAMPLING;
      EXPECT_STATUS(sogmm_model_sample_f32(m, ns, 3, 4, o, out), SOGMM_E_CANCELLED);
      for (i = 0; i < ns * 4; ++i)
        if (out[i] != -7.0f) break;
      EXPECT_TRUE(i == ns * 4);
      rec.cancel_stage = -1;
      REQUIRE_OK(sogmm_model_sample_f32(m, ns, 3, 4, o, out));
      REQUIRE_OK(sogmm_model_sample_f32(m, ns, 3, 4, NULL, ref));
      EXPECT_TRUE(memcmp(out, ref, ns * 4 * sizeof(float)) == 0);
      free(out);
      free(ref);
      sogmm_model_free(m);
      sogmm_options_free(plain_o);
    }
    sogmm_options_free(o);
  }
  free(pts);
  return test_summary("capi_progress");
}
