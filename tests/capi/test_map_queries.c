/* Map queries (sogmm_map_score_samples_f32, _regress_gray_f32, _sample_f32):
 * bitwise equal to the same query on the exported map, with and without a
 * progress callback (and the model queries, which take one too); a cancel writes nothing; a status and message for every
 * bad input. Progress and cancel of inserts and flushes
 * (sogmm_map_set_progress): a cancelled insert or flush leaves the map as it
 * was. */
#include "test_util.h"

static const double k_identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

static int message_has(const char* needle) { return strstr(sogmm_last_error(), needle) != NULL; }

typedef struct {
  int n;
  int32_t first_stage, last_stage;
  uint64_t last_step, last_total;
  int decreasing; /* a step below the previous one of the same stage */
  int cancel;     /* non-zero: cancel at the first report */
} Recorder;

static int32_t record(int32_t stage, uint64_t step, uint64_t total, double ll, void* user_data) {
  Recorder* r = (Recorder*)user_data;
  (void)ll;
  if (r->n == 0) r->first_stage = stage;
  if (r->n > 0 && stage == r->last_stage && step < r->last_step) r->decreasing = 1;
  r->last_stage = stage;
  r->last_step = step;
  r->last_total = total;
  ++r->n;
  return r->cancel;
}

/* Two posed copies of the cluster cloud, flushed: a map of a few components. */
static sogmm_map* make_map(const float* pts, size_t n) {
  sogmm_options* o = NULL;
  sogmm_map* map = NULL;
  double moved[16];
  memcpy(moved, k_identity, sizeof moved);
  moved[3] = 2.0;
  REQUIRE_OK(sogmm_options_create(&o));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_MAP_BATCH_SIZE, 100000));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_THREADS, 2));
  REQUIRE_OK(sogmm_map_create(&map, o));
  REQUIRE_OK(sogmm_map_insert_points_f32(map, pts, n, k_identity));
  REQUIRE_OK(sogmm_map_insert_points_f32(map, pts, n, moved));
  REQUIRE_OK(sogmm_map_flush(map));
  sogmm_options_free(o);
  return map;
}

/* n query points: the cloud's own points, every fifth moved far off (the
 * regression's fallback to the prior). */
static float* query_points(const float* pts, size_t n, int dims) {
  float* q = (float*)malloc(n * (size_t)dims * sizeof(float));
  size_t i;
  int d;
  if (!q) exit(2);
  for (i = 0; i < n; ++i)
    for (d = 0; d < dims; ++d) q[(size_t)dims * i + d] = pts[4 * i + d] + (i % 5 == 0 && d == 0 ? 3.5f : 0.0f);
  return q;
}

/* The outputs of n query rows asked twice (w: without, g: with a callback
 * or from the other handle): scores and regressed means and variances. */
typedef struct {
  double *want, *got;
  float *mean_w, *var_w, *mean_g, *var_g;
} QueryBuffers;

static QueryBuffers query_buffers(size_t n) {
  QueryBuffers b;
  b.want = (double*)malloc(n * sizeof(double));
  b.got = (double*)malloc(n * sizeof(double));
  b.mean_w = (float*)malloc(n * sizeof(float));
  b.var_w = (float*)malloc(n * sizeof(float));
  b.mean_g = (float*)malloc(n * sizeof(float));
  b.var_g = (float*)malloc(n * sizeof(float));
  if (!b.want || !b.got || !b.mean_w || !b.var_w || !b.mean_g || !b.var_g) exit(2);
  return b;
}

static void free_query_buffers(QueryBuffers* b) {
  free(b->want);
  free(b->got);
  free(b->mean_w);
  free(b->var_w);
  free(b->mean_g);
  free(b->var_g);
}

static void equals_exported_model(const sogmm_map* map, const float* pts, size_t n) {
  sogmm_model* model = NULL;
  sogmm_options* po = NULL;
  Recorder rec;
  float* q3 = query_points(pts, n, 3);
  float* q4 = query_points(pts, n, 4);
  QueryBuffers b = query_buffers(n);
  float* s_w = (float*)malloc(n * 4 * sizeof(float));
  float* s_g = (float*)malloc(n * 4 * sizeof(float));
  int dims;
  if (!s_w || !s_g) exit(2);

  REQUIRE_OK(sogmm_map_export(&model, map, NULL));
  REQUIRE_OK(sogmm_options_create(&po));
  REQUIRE_OK(sogmm_options_set_progress(po, record, &rec));

  for (dims = 3; dims <= 4; ++dims) {
    const float* q = dims == 3 ? q3 : q4;
    REQUIRE_OK(sogmm_model_score_samples_f32(model, q, n, dims, NULL, b.want));
    REQUIRE_OK(sogmm_map_score_samples_f32(map, q, n, dims, NULL, b.got));
    EXPECT_TRUE(memcmp(b.want, b.got, n * sizeof(double)) == 0);
    /* With a callback: in chunks, the same bits; reports of SCORING up to n. */
    memset(&rec, 0, sizeof rec);
    memset(b.got, 0, n * sizeof(double));
    REQUIRE_OK(sogmm_map_score_samples_f32(map, q, n, dims, po, b.got));
    EXPECT_TRUE(memcmp(b.want, b.got, n * sizeof(double)) == 0);
    EXPECT_TRUE(rec.n >= 2 && rec.first_stage == SOGMM_STAGE_SCORING && rec.last_stage == SOGMM_STAGE_SCORING);
    EXPECT_TRUE(rec.last_step == n && rec.last_total == n && !rec.decreasing);
  }
  /* A far point really is far: the test covers both regimes. */
  EXPECT_TRUE(b.want[0] < b.want[1] - 50.0);

  REQUIRE_OK(sogmm_model_regress_gray_f32(model, q3, n, NULL, b.mean_w, b.var_w));
  REQUIRE_OK(sogmm_map_regress_gray_f32(map, q3, n, NULL, b.mean_g, b.var_g));
  EXPECT_TRUE(memcmp(b.mean_w, b.mean_g, n * sizeof(float)) == 0 && memcmp(b.var_w, b.var_g, n * sizeof(float)) == 0);
  memset(&rec, 0, sizeof rec);
  memset(b.mean_g, 0, n * sizeof(float));
  REQUIRE_OK(sogmm_map_regress_gray_f32(map, q3, n, po, b.mean_g, NULL)); /* variance optional */
  EXPECT_TRUE(memcmp(b.mean_w, b.mean_g, n * sizeof(float)) == 0);
  EXPECT_TRUE(rec.first_stage == SOGMM_STAGE_REGRESSION && rec.last_step == n && !rec.decreasing);

  for (dims = 3; dims <= 4; ++dims) {
    REQUIRE_OK(sogmm_model_sample_f32(model, n, 99, dims, NULL, s_w));
    REQUIRE_OK(sogmm_map_sample_f32(map, n, 99, dims, NULL, s_g));
    EXPECT_TRUE(memcmp(s_w, s_g, n * (size_t)dims * sizeof(float)) == 0);
  }
  /* The truncation key and the callback apply as for a model. */
  REQUIRE_OK(sogmm_options_set_f64(po, SOGMM_OPT_SAMPLE_TRUNCATION, 1.0));
  REQUIRE_OK(sogmm_model_sample_f32(model, n, 7, 4, po, s_w));
  memset(&rec, 0, sizeof rec);
  REQUIRE_OK(sogmm_map_sample_f32(map, n, 7, 4, po, s_g));
  EXPECT_TRUE(memcmp(s_w, s_g, n * 4 * sizeof(float)) == 0);
  EXPECT_TRUE(rec.n >= 1 && rec.first_stage == SOGMM_STAGE_SAMPLING);

  /* Cancel: SOGMM_E_CANCELLED, the message names the stage, outputs untouched. */
  memset(&rec, 0, sizeof rec);
  rec.cancel = 1;
  memset(b.got, 0x7f, n * sizeof(double));
  EXPECT_STATUS(sogmm_map_score_samples_f32(map, q4, n, 4, po, b.got), SOGMM_E_CANCELLED);
  EXPECT_TRUE(message_has("scoring") && rec.n == 1);
  EXPECT_TRUE(b.got[0] == b.got[n - 1] && ((const unsigned char*)b.got)[0] == 0x7f);
  memset(b.mean_g, 0x7f, n * sizeof(float));
  memset(b.var_g, 0x7f, n * sizeof(float));
  EXPECT_STATUS(sogmm_map_regress_gray_f32(map, q3, n, po, b.mean_g, b.var_g), SOGMM_E_CANCELLED);
  EXPECT_TRUE(message_has("regression"));
  EXPECT_TRUE(((const unsigned char*)b.mean_g)[0] == 0x7f && ((const unsigned char*)b.var_g)[4 * n - 1] == 0x7f);
  memset(s_g, 0x7f, n * 4 * sizeof(float));
  EXPECT_STATUS(sogmm_map_sample_f32(map, n, 7, 4, po, s_g), SOGMM_E_CANCELLED);
  EXPECT_TRUE(message_has("sampling") && ((const unsigned char*)s_g)[0] == 0x7f);

  sogmm_options_free(po);
  sogmm_model_free(model);
  free(q3);
  free(q4);
  free_query_buffers(&b);
  free(s_w);
  free(s_g);
}

static void bad_input(const sogmm_map* map, const float* pts) {
  sogmm_map* empty = NULL;
  double out[4];
  float g[4], s[16], q[12];
  const size_t huge = (size_t)-1 / 2;
  memcpy(q, pts, sizeof q);

  EXPECT_STATUS(sogmm_map_score_samples_f32(NULL, q, 4, 3, NULL, out), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_map_regress_gray_f32(NULL, q, 4, NULL, g, NULL), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_map_sample_f32(NULL, 4, 1, 4, NULL, s), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_map_score_samples_f32(map, q, 4, 2, NULL, out), SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(message_has("dims"));
  EXPECT_STATUS(sogmm_map_sample_f32(map, 4, 1, 5, NULL, s), SOGMM_E_INVALID_ARG);

  /* An empty map has nothing to query, even for n == 0. */
  REQUIRE_OK(sogmm_map_create(&empty, NULL));
  EXPECT_STATUS(sogmm_map_score_samples_f32(empty, q, 4, 3, NULL, out), SOGMM_E_INVALID_DATA);
  EXPECT_TRUE(message_has("no component"));
  EXPECT_STATUS(sogmm_map_regress_gray_f32(empty, NULL, 0, NULL, NULL, NULL), SOGMM_E_INVALID_DATA);
  EXPECT_STATUS(sogmm_map_sample_f32(empty, 4, 1, 4, NULL, s), SOGMM_E_INVALID_DATA);
  /* Pending points are not components. */
  REQUIRE_OK(sogmm_map_insert_points_f32(empty, pts, 300, k_identity));
  EXPECT_STATUS(sogmm_map_sample_f32(empty, 4, 1, 4, NULL, s), SOGMM_E_INVALID_DATA);
  sogmm_map_free(empty);

  /* n == 0 writes nothing; arrays may be NULL. */
  EXPECT_OK(sogmm_map_score_samples_f32(map, NULL, 0, 4, NULL, NULL));
  EXPECT_OK(sogmm_map_regress_gray_f32(map, NULL, 0, NULL, NULL, NULL));
  EXPECT_OK(sogmm_map_sample_f32(map, 0, 1, 3, NULL, NULL));

  EXPECT_STATUS(sogmm_map_score_samples_f32(map, NULL, 4, 3, NULL, out), SOGMM_E_NULL_ARG);
  EXPECT_TRUE(message_has("points"));
  EXPECT_STATUS(sogmm_map_score_samples_f32(map, q, 4, 3, NULL, NULL), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_map_regress_gray_f32(map, NULL, 4, NULL, g, NULL), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_map_regress_gray_f32(map, q, 4, NULL, NULL, g), SOGMM_E_NULL_ARG);
  EXPECT_TRUE(message_has("mean_out"));
  EXPECT_STATUS(sogmm_map_sample_f32(map, 4, 1, 4, NULL, NULL), SOGMM_E_NULL_ARG);

  /* n * dims overflowing size_t: refused before anything is read or allocated. */
  EXPECT_STATUS(sogmm_map_score_samples_f32(map, q, huge, 4, NULL, out), SOGMM_E_LIMIT);
  EXPECT_STATUS(sogmm_map_regress_gray_f32(map, q, huge, NULL, g, NULL), SOGMM_E_LIMIT);
  EXPECT_STATUS(sogmm_map_sample_f32(map, huge, 1, 4, NULL, s), SOGMM_E_LIMIT);

  q[7] = NAN;
  EXPECT_STATUS(sogmm_map_score_samples_f32(map, q, 4, 3, NULL, out), SOGMM_E_INVALID_DATA);
  EXPECT_TRUE(message_has("index 7"));
  q[7] = INFINITY;
  EXPECT_STATUS(sogmm_map_regress_gray_f32(map, q, 4, NULL, g, NULL), SOGMM_E_INVALID_DATA);

  EXPECT_STATUS(sogmm_map_set_progress(NULL, record, NULL), SOGMM_E_NULL_ARG);
}

/* Means and stats of a map, to compare a map before and after a failed call. */
static void snapshot(const sogmm_map* map, test_map_stats* st, float* means, size_t cap) {
  sogmm_model* m = NULL;
  REQUIRE_OK(test_map_get_stats(map, st));
  memset(means, 0, cap * sizeof(float));
  if (st->n_components == 0) return;
  REQUIRE_OK(sogmm_map_export(&m, map, NULL));
  REQUIRE_OK(sogmm_model_get_means_f32(m, means, cap));
  sogmm_model_free(m);
}

static int same_stats(const test_map_stats* a, const test_map_stats* b) {
  return a->n_components == b->n_components && a->n_pending == b->n_pending && a->n_frames == b->n_frames &&
         a->n_flushes == b->n_flushes && a->n_fused == b->n_fused;
}

static void insert_progress_and_cancel(const float* pts, size_t n) {
  enum { kCap = 4 * 4096 };
  static float before[kCap], after[kCap];
  sogmm_options* o = NULL;
  sogmm_map* map = NULL;
  test_map_stats s0, s1;
  Recorder rec;
  double moved[16];
  memcpy(moved, k_identity, sizeof moved);

  /* Novelty off: every insert fits its frame, so every insert reports. */
  REQUIRE_OK(sogmm_options_create(&o));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_MAP_NOVELTY, 0));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_THREADS, 2));
  REQUIRE_OK(sogmm_options_set_progress(o, record, &rec)); /* taken over by the map */
  REQUIRE_OK(sogmm_map_create(&map, o));
  memset(&rec, 0, sizeof rec);
  REQUIRE_OK(sogmm_map_insert_points_f32(map, pts, n, k_identity));
  EXPECT_TRUE(rec.n >= 2 && rec.first_stage == SOGMM_STAGE_MODE_COUNT && rec.last_stage == SOGMM_STAGE_EM);

  /* A cancelled insert leaves the map as it was: no frame, no component. */
  snapshot(map, &s0, before, kCap);
  moved[3] = 2.0;
  memset(&rec, 0, sizeof rec);
  rec.cancel = 1;
  EXPECT_STATUS(sogmm_map_insert_points_f32(map, pts, n, moved), SOGMM_E_CANCELLED);
  EXPECT_TRUE(message_has("cancelled") && rec.n == 1);
  snapshot(map, &s1, after, kCap);
  EXPECT_TRUE(same_stats(&s0, &s1) && s1.n_frames == 1);
  EXPECT_TRUE(memcmp(before, after, sizeof before) == 0);
  /* ... and the next insert works: it is the second frame. */
  rec.cancel = 0;
  REQUIRE_OK(sogmm_map_insert_points_f32(map, pts, n, moved));
  REQUIRE_OK(test_map_get_stats(map, &s1));
  EXPECT_TRUE(s1.n_frames == 2 && s1.n_flushes == 2 && s1.n_components > s0.n_components);
  /* NULL removes the callback. */
  REQUIRE_OK(sogmm_map_set_progress(map, NULL, NULL));
  memset(&rec, 0, sizeof rec);
  moved[3] = 4.0;
  REQUIRE_OK(sogmm_map_insert_points_f32(map, pts, n, moved));
  EXPECT_TRUE(rec.n == 0);
  sogmm_map_free(map);

  /* Novelty on, batch large: a cancelled flush keeps the pending points and
   * the map; the RGB-D insert that triggers a fit is undone as well. */
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_MAP_NOVELTY, 1));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_MAP_BATCH_SIZE, 100000));
  REQUIRE_OK(sogmm_options_set_progress(o, NULL, NULL));
  REQUIRE_OK(sogmm_map_create(&map, o));
  REQUIRE_OK(sogmm_map_insert_points_f32(map, pts, n, k_identity));
  REQUIRE_OK(sogmm_map_set_progress(map, record, &rec));
  memset(&rec, 0, sizeof rec);
  rec.cancel = 1;
  snapshot(map, &s0, before, kCap);
  EXPECT_STATUS(sogmm_map_flush(map), SOGMM_E_CANCELLED);
  snapshot(map, &s1, after, kCap);
  EXPECT_TRUE(same_stats(&s0, &s1) && s1.n_pending == n && s1.n_components == 0);
  rec.cancel = 0;
  REQUIRE_OK(sogmm_map_flush(map));
  REQUIRE_OK(test_map_get_stats(map, &s1));
  EXPECT_TRUE(s1.n_pending == 0 && s1.n_components > 0 && rec.n >= 2);
  sogmm_map_free(map);

  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_MAP_NOVELTY, 0));
  REQUIRE_OK(sogmm_map_create(&map, o));
  {
    uint16_t* depth;
    uint8_t *gray, *rgb;
    make_frame(64, 48, &depth, &gray, &rgb);
    /* A cancelled first RGB-D frame does not fix the camera either. */
    REQUIRE_OK(sogmm_map_set_progress(map, record, &rec));
    memset(&rec, 0, sizeof rec);
    rec.cancel = 1;
    EXPECT_STATUS(test_map_insert_rgbd(map, depth, gray, SOGMM_COLOR_GRAY8, 64, 48, 60, 60, 32, 24, k_identity),
                  SOGMM_E_CANCELLED);
    REQUIRE_OK(sogmm_map_set_progress(map, NULL, NULL));
    REQUIRE_OK(test_map_insert_rgbd(map, depth, gray, SOGMM_COLOR_GRAY8, 64, 48, 50, 50, 32, 24, k_identity));
    snapshot(map, &s0, before, kCap);
    REQUIRE_OK(sogmm_map_set_progress(map, record, &rec));
    memset(&rec, 0, sizeof rec);
    rec.cancel = 1;
    EXPECT_STATUS(test_map_insert_rgbd(map, depth, gray, SOGMM_COLOR_GRAY8, 64, 48, 50, 50, 32, 24, moved),
                  SOGMM_E_CANCELLED);
    snapshot(map, &s1, after, kCap);
    EXPECT_TRUE(same_stats(&s0, &s1) && s1.n_frames == 1 && memcmp(before, after, sizeof before) == 0);
    free(depth);
    free(gray);
    free(rgb);
  }
  sogmm_map_free(map);
  sogmm_options_free(o);
}

/* The model queries with a progress callback: the same bits as without, reports
 * of SCORING / REGRESSION up to n, a cancel leaves the outputs untouched. */
static void model_with_progress(const sogmm_map* map, const float* pts, size_t n) {
  sogmm_model* model = NULL;
  sogmm_options* po = NULL;
  Recorder rec;
  float* q3 = query_points(pts, n, 3);
  QueryBuffers b = query_buffers(n);
  REQUIRE_OK(sogmm_map_export(&model, map, NULL));
  REQUIRE_OK(sogmm_options_create(&po));
  REQUIRE_OK(sogmm_options_set_progress(po, record, &rec));

  REQUIRE_OK(sogmm_model_score_samples_f32(model, q3, n, 3, NULL, b.want));
  memset(&rec, 0, sizeof rec);
  REQUIRE_OK(sogmm_model_score_samples_f32(model, q3, n, 3, po, b.got));
  EXPECT_TRUE(memcmp(b.want, b.got, n * sizeof(double)) == 0);
  EXPECT_TRUE(rec.first_stage == SOGMM_STAGE_SCORING && rec.last_step == n && rec.last_total == n);

  REQUIRE_OK(sogmm_model_regress_gray_f32(model, q3, n, NULL, b.mean_w, b.var_w));
  memset(&rec, 0, sizeof rec);
  REQUIRE_OK(sogmm_model_regress_gray_f32(model, q3, n, po, b.mean_g, b.var_g));
  EXPECT_TRUE(memcmp(b.mean_w, b.mean_g, n * sizeof(float)) == 0 && memcmp(b.var_w, b.var_g, n * sizeof(float)) == 0);
  EXPECT_TRUE(rec.first_stage == SOGMM_STAGE_REGRESSION && rec.last_step == n && !rec.decreasing);

  rec.cancel = 1;
  memset(b.got, 0x7f, n * sizeof(double));
  EXPECT_STATUS(sogmm_model_score_samples_f32(model, q3, n, 3, po, b.got), SOGMM_E_CANCELLED);
  EXPECT_TRUE(((const unsigned char*)b.got)[8 * n - 1] == 0x7f);
  memset(b.mean_g, 0x7f, n * sizeof(float));
  EXPECT_STATUS(sogmm_model_regress_gray_f32(model, q3, n, po, b.mean_g, NULL), SOGMM_E_CANCELLED);
  EXPECT_TRUE(((const unsigned char*)b.mean_g)[0] == 0x7f);
  /* Bad input, with and without options. */
  EXPECT_STATUS(sogmm_model_score_samples_f32(NULL, q3, n, 3, NULL, b.got), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_model_score_samples_f32(model, q3, n, 5, NULL, b.got), SOGMM_E_INVALID_ARG);
  EXPECT_OK(sogmm_model_regress_gray_f32(model, NULL, 0, po, NULL, NULL));
  EXPECT_STATUS(sogmm_model_regress_gray_f32(model, q3, (size_t)-1 / 2, NULL, b.mean_g, NULL), SOGMM_E_LIMIT);
  q3[4] = NAN;
  EXPECT_STATUS(sogmm_model_regress_gray_f32(model, q3, n, po, b.mean_g, NULL), SOGMM_E_INVALID_DATA);

  sogmm_options_free(po);
  sogmm_model_free(model);
  free(q3);
  free_query_buffers(&b);
}

int main(void) {
  const size_t n = 10000; /* more than one progress chunk (4096 points) */
  float* pts = make_clusters(n, 42);
  sogmm_map* map = make_map(pts, 3000);
  equals_exported_model(map, pts, n);
  model_with_progress(map, pts, n);
  bad_input(map, pts);
  insert_progress_and_cancel(pts, 3000);
  sogmm_map_free(map);
  free(pts);
  return test_summary("capi_map_queries");
}
