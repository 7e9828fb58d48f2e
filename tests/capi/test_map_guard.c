/* The map's use guard and the progress callback's re-entry rules (issue 36,
 * sogmm.h "Use guard" and sogmm_progress_fn):
 * - a call on a map from the progress callback of a call on that map returns
 *   SOGMM_E_BUSY ("map busy: ...") and changes nothing: a nested flush no
 *   longer merges the batch twice, a nested free frees nothing, a map-to-map
 *   merge that would write or read the busy map is refused;
 * - a call from another thread while one runs gets the same error (the two
 *   threads meet at a handshake inside the first call's callback, so the
 *   overlap is certain, not a matter of timing);
 * - a SOGMM call made inside a callback runs without a callback (a nested fit
 *   with NULL options does not report to the running callback);
 * - a slow callback is called once per 20 ms of work, not at every poll
 *   point (counted against the fit's poll points, no clock assert).
 * Registered as capi_threads_map_guard, so the ThreadSanitizer job
 * (tools/test.sh, -R '^capi_threads') runs it too. */
#define _POSIX_C_SOURCE 200809L /* nanosleep */
#include <pthread.h>
#include <time.h>

#include "test_util.h"

static const double k_identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

/* The fits' OpenMP team: 2, or 1 where the run pins OMP_NUM_THREADS=1 (the
 * ThreadSanitizer stage: libgomp is not instrumented, so a team of 2 reports
 * its own barriers as races; the threads under test there are pthreads). */
static int64_t team(void) {
  const char* e = getenv("OMP_NUM_THREADS");
  return e != NULL && strcmp(e, "1") == 0 ? 1 : 2;
}

static int message_starts(const char* prefix) { return strncmp(sogmm_last_error(), prefix, strlen(prefix)) == 0; }

/* A map whose first insert of 3000 points triggers a fit (batch of 2000). */
static sogmm_map* small_batch_map(void) {
  sogmm_options* o = NULL;
  sogmm_map* map = NULL;
  REQUIRE_OK(sogmm_options_create(&o));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_MAP_BATCH_SIZE, 2000));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_THREADS, team()));
  REQUIRE_OK(sogmm_map_create(&map, o));
  sogmm_options_free(o);
  return map;
}

/* ---- re-entry from the map's own callback --------------------------------- */

typedef struct {
  sogmm_map* map;
  sogmm_map* idle;       /* another map, not in use (NULL: no merge is tried) */
  const float* points;
  int calls;             /* callback invocations */
  int nested_done;       /* the nested calls ran (on the first invocation) */
  sogmm_status insert, flush, set_progress, stats, score, merge_into, merge_from;
  int busy_messages;     /* nested failures whose message starts "map busy: " */
  int free_refused;      /* sogmm_map_free left the map and said "map busy" */
} Reentry;

static int32_t reenter(int32_t stage, uint64_t step, uint64_t total, double ll, void* user_data) {
  Reentry* r = (Reentry*)user_data;
  int64_t frames = 0;
  double score = 0.0;
  const float xyz[4] = {0.f, 0.f, 1.f, 0.5f};
  (void)stage, (void)step, (void)total, (void)ll;
  ++r->calls;
  if (r->nested_done) return 0;
  r->nested_done = 1;
  r->insert = sogmm_map_insert_points_f32(r->map, r->points, 3000, k_identity);
  r->busy_messages += message_starts("map busy: sogmm_map_insert_points_f32");
  r->flush = sogmm_map_flush(r->map);
  r->busy_messages += message_starts("map busy: sogmm_map_flush");
  r->set_progress = sogmm_map_set_progress(r->map, NULL, NULL);
  r->busy_messages += message_starts("map busy: sogmm_map_set_progress");
  r->stats = sogmm_map_get_i64(r->map, SOGMM_MAP_N_FRAMES, &frames);
  r->busy_messages += message_starts("map busy: sogmm_map_get_i64");
  r->score = sogmm_map_score_samples_f32(r->map, xyz, 1, 4, NULL, &score);
  r->busy_messages += message_starts("map busy: sogmm_map_score_samples_f32");
  if (r->idle != NULL) { /* merging into the busy map writes it; merging it into another reads it */
    r->merge_into = sogmm_map_merge_map(r->map, r->idle, k_identity, NULL);
    r->busy_messages += message_starts("map busy: sogmm_map_merge_map");
    r->merge_from = sogmm_map_merge_map(r->idle, r->map, k_identity, NULL);
    r->busy_messages += message_starts("map busy: sogmm_map_merge_map");
  }
  sogmm_map_free(r->map); /* refused: the map is in use; the outer call goes on with it */
  r->free_refused = message_starts("map busy: sogmm_map_free");
  return 0;
}

static void test_reentry_from_callback(void) {
  float* pts = make_clusters(3000, 7);
  sogmm_map* ref = small_batch_map();
  sogmm_map* map = small_batch_map();
  test_map_stats want, got;
  Reentry r;
  memset(&r, 0, sizeof r);
  r.map = map;
  r.idle = ref;
  r.points = pts;

  /* Reference: the same insert without a callback. */
  REQUIRE_OK(sogmm_map_insert_points_f32(ref, pts, 3000, k_identity));
  REQUIRE_OK(test_map_get_stats(ref, &want));
  EXPECT_TRUE(want.n_flushes == 1 && want.n_components > 0);

  /* The insert's fit calls the callback, which calls into the map. */
  REQUIRE_OK(sogmm_map_set_progress(map, reenter, &r));
  REQUIRE_OK(sogmm_map_insert_points_f32(map, pts, 3000, k_identity));
  EXPECT_TRUE(r.calls > 0 && r.nested_done);
  EXPECT_TRUE(r.insert == SOGMM_E_BUSY && r.flush == SOGMM_E_BUSY && r.set_progress == SOGMM_E_BUSY);
  EXPECT_TRUE(r.stats == SOGMM_E_BUSY && r.score == SOGMM_E_BUSY);
  EXPECT_TRUE(r.merge_into == SOGMM_E_BUSY && r.merge_from == SOGMM_E_BUSY);
  EXPECT_TRUE(r.busy_messages == 7);
  EXPECT_TRUE(r.free_refused);
  /* Nothing nested took effect: the map is the reference, frame for frame. */
  REQUIRE_OK(test_map_get_stats(map, &got));
  EXPECT_TRUE(got.n_components == want.n_components && got.n_frames == 1 && got.n_pending == want.n_pending);
  EXPECT_TRUE(got.n_flushes == 1);
  /* Nor did the refused merge change the idle map. */
  REQUIRE_OK(test_map_get_stats(ref, &got));
  EXPECT_TRUE(got.n_components == want.n_components && got.n_frames == want.n_frames && got.n_flushes == 1);

  /* A nested flush (the C finding: it merged one batch twice). The frame
   * goes in pending (large batch), the outer flush runs the callback. */
  {
    sogmm_options* o = NULL;
    sogmm_map *a = NULL, *b = NULL;
    test_map_stats sa, sb;
    REQUIRE_OK(sogmm_options_create(&o));
    REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_MAP_BATCH_SIZE, 100000));
    REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_THREADS, team()));
    REQUIRE_OK(sogmm_map_create(&a, o));
    REQUIRE_OK(sogmm_map_create(&b, o));
    REQUIRE_OK(sogmm_map_insert_points_f32(a, pts, 3000, k_identity));
    REQUIRE_OK(sogmm_map_insert_points_f32(b, pts, 3000, k_identity));
    REQUIRE_OK(sogmm_map_flush(a));
    memset(&r, 0, sizeof r);
    r.map = b;
    r.points = pts;
    REQUIRE_OK(sogmm_map_set_progress(b, reenter, &r));
    REQUIRE_OK(sogmm_map_flush(b));
    EXPECT_TRUE(r.flush == SOGMM_E_BUSY);
    REQUIRE_OK(test_map_get_stats(a, &sa));
    REQUIRE_OK(test_map_get_stats(b, &sb));
    EXPECT_TRUE(sb.n_components == sa.n_components && sb.n_flushes == 1 && sb.n_pending == 0);
    sogmm_map_free(a);
    sogmm_map_free(b);
    sogmm_options_free(o);
  }

  /* Once the call returned the map is free again, and free frees it. */
  REQUIRE_OK(sogmm_map_set_progress(map, NULL, NULL));
  sogmm_map_free(map);
  sogmm_map_free(ref);
  free(pts);
}

/* A render is a const call and holds the map like the other queries: from
 * its callback a flush is refused and the pending points stay (fuzz_map: the
 * render took no guard, so the nested flush fitted them while the render
 * read the model). */
typedef struct {
  sogmm_map* map;
  int calls;
  sogmm_status flush;
  int busy_message;
} RenderReentry;

static int32_t flush_from_render(int32_t stage, uint64_t step, uint64_t total, double ll, void* user_data) {
  RenderReentry* r = (RenderReentry*)user_data;
  (void)step, (void)total, (void)ll;
  if (stage != SOGMM_STAGE_RENDERING || r->calls++ > 0) return 0;
  r->flush = sogmm_map_flush(r->map);
  r->busy_message = message_starts("map busy: sogmm_map_flush");
  return 0;
}

static void test_render_holds_the_map(void) {
  float* pts = make_clusters(3000, 11);
  sogmm_map* map = small_batch_map();
  sogmm_options* o = NULL;
  test_map_stats before, after;
  float depth[16 * 12], gray[16 * 12];
  RenderReentry r;
  memset(&r, 0, sizeof r);
  r.map = map;
  REQUIRE_OK(sogmm_map_insert_points_f32(map, pts, 3000, k_identity)); /* fitted: batch of 2000 */
  REQUIRE_OK(sogmm_map_insert_points_f32(map, pts, 500, k_identity));  /* pending or not: the flush is refused */
  REQUIRE_OK(test_map_get_stats(map, &before));
  REQUIRE_OK(sogmm_options_create(&o));
  REQUIRE_OK(sogmm_options_set_progress(o, flush_from_render, &r));
  REQUIRE_OK(sogmm_map_render_f32(map, 16, 12, 10.0, 10.0, 8.0, 6.0, NULL, o, depth, gray, NULL));
  EXPECT_TRUE(r.calls > 0);
  EXPECT_TRUE(r.flush == SOGMM_E_BUSY && r.busy_message);
  REQUIRE_OK(test_map_get_stats(map, &after));
  EXPECT_TRUE(after.n_flushes == before.n_flushes && after.n_pending == before.n_pending &&
              after.n_components == before.n_components);
  sogmm_options_free(o);
  sogmm_map_free(map);
  free(pts);
}

/* ---- two threads --------------------------------------------------------- */

typedef struct {
  pthread_mutex_t mutex;
  pthread_cond_t cond;
  int inside;  /* thread A is inside its insert's callback */
  int tried;   /* thread B has made its calls */
  sogmm_map* map;
  const float* points;
  sogmm_status b_insert, b_stats, b_export;
  int b_busy_messages, b_free_refused;
} Meeting;

static int32_t hold_until_tried(int32_t stage, uint64_t step, uint64_t total, double ll, void* user_data) {
  Meeting* m = (Meeting*)user_data;
  (void)stage, (void)step, (void)total, (void)ll;
  pthread_mutex_lock(&m->mutex);
  m->inside = 1;
  pthread_cond_broadcast(&m->cond);
  while (!m->tried) pthread_cond_wait(&m->cond, &m->mutex);
  pthread_mutex_unlock(&m->mutex);
  return 0;
}

static void* thread_b(void* p) {
  Meeting* m = (Meeting*)p;
  test_map_stats st;
  sogmm_model* out = NULL;
  pthread_mutex_lock(&m->mutex);
  while (!m->inside) pthread_cond_wait(&m->cond, &m->mutex);
  pthread_mutex_unlock(&m->mutex);
  /* Thread A is inside sogmm_map_insert_points_f32 on this map. */
  m->b_insert = sogmm_map_insert_points_f32(m->map, m->points, 3000, k_identity);
  m->b_busy_messages += message_starts("map busy: ");
  m->b_stats = test_map_get_stats(m->map, &st);
  m->b_busy_messages += message_starts("map busy: ");
  m->b_export = sogmm_map_export(&out, m->map, NULL);
  m->b_busy_messages += message_starts("map busy: ") && out == NULL;
  sogmm_map_free(m->map);
  m->b_free_refused = message_starts("map busy: sogmm_map_free");
  pthread_mutex_lock(&m->mutex);
  m->tried = 1;
  pthread_cond_broadcast(&m->cond);
  pthread_mutex_unlock(&m->mutex);
  return NULL;
}

static void test_two_threads(void) {
  float* pts = make_clusters(3000, 8);
  sogmm_map* ref = small_batch_map();
  test_map_stats want, got;
  pthread_t b;
  Meeting m;
  memset(&m, 0, sizeof m);
  pthread_mutex_init(&m.mutex, NULL);
  pthread_cond_init(&m.cond, NULL);
  m.map = small_batch_map();
  m.points = pts;
  REQUIRE_OK(sogmm_map_insert_points_f32(ref, pts, 3000, k_identity));
  REQUIRE_OK(test_map_get_stats(ref, &want));

  REQUIRE_OK(sogmm_map_set_progress(m.map, hold_until_tried, &m));
  if (pthread_create(&b, NULL, thread_b, &m) != 0) {
    fprintf(stderr, "pthread_create failed\n");
    exit(1);
  }
  EXPECT_OK(sogmm_map_insert_points_f32(m.map, pts, 3000, k_identity));
  pthread_join(b, NULL);
  EXPECT_TRUE(m.b_insert == SOGMM_E_BUSY && m.b_stats == SOGMM_E_BUSY && m.b_export == SOGMM_E_BUSY);
  EXPECT_TRUE(m.b_busy_messages == 3 && m.b_free_refused);
  REQUIRE_OK(test_map_get_stats(m.map, &got));
  EXPECT_TRUE(got.n_frames == 1 && got.n_components == want.n_components && got.n_pending == want.n_pending);
  /* After the call, thread B's calls succeed (here, on this thread). */
  REQUIRE_OK(sogmm_map_set_progress(m.map, NULL, NULL));
  EXPECT_OK(sogmm_map_insert_points_f32(m.map, pts, 3000, k_identity));
  sogmm_map_free(m.map);
  sogmm_map_free(ref);
  pthread_cond_destroy(&m.cond);
  pthread_mutex_destroy(&m.mutex);
  free(pts);
}

/* ---- nested calls start without a callback ------------------------------- */

typedef struct {
  const float* points;
  int depth, max_depth, calls;
  sogmm_status nested;
  size_t nested_k;
} Nesting;

static int32_t nest_fit(int32_t stage, uint64_t step, uint64_t total, double ll, void* user_data) {
  Nesting* n = (Nesting*)user_data;
  (void)stage, (void)step, (void)total, (void)ll;
  ++n->calls;
  if (++n->depth > n->max_depth) n->max_depth = n->depth;
  /* Every invocation nests a fit: before the fix the nested fit reported to
   * this callback, which nested again, without bound. Capped at depth 3 so a
   * regression fails the test instead of exhausting the stack. */
  if (n->depth < 3) {
    sogmm_model* inner = NULL;
    n->nested = test_fit_fixed_k(&inner, n->points, 600, 3, NULL);
    if (inner) sogmm_model_n_components(inner, &n->nested_k);
    sogmm_model_free(inner);
  }
  --n->depth;
  return 0;
}

static void test_nested_calls_have_no_callback(void) {
  float* pts = make_clusters(600, 9);
  sogmm_options* o = NULL;
  sogmm_model* outer = NULL;
  Nesting n;
  memset(&n, 0, sizeof n);
  n.points = pts;
  REQUIRE_OK(sogmm_options_create(&o));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_MAX_ITER, 3));
  REQUIRE_OK(sogmm_options_set_progress(o, nest_fit, &n));
  REQUIRE_OK(test_fit_fixed_k(&outer, pts, 600, 3, o));
  EXPECT_TRUE(n.calls > 0);
  EXPECT_TRUE(n.max_depth == 1); /* the nested fits reported to nothing */
  EXPECT_TRUE(n.nested == SOGMM_OK && n.nested_k == 3);
  sogmm_model_free(outer);
  sogmm_options_free(o);
  free(pts);
}

/* ---- a slow callback ------------------------------------------------------ */

typedef struct {
  int seeding_reports;
  int reports;
} SlowCount;

static int32_t slow(int32_t stage, uint64_t step, uint64_t total, double ll, void* user_data) {
  SlowCount* c = (SlowCount*)user_data;
  const struct timespec wait = {0, 25 * 1000 * 1000}; /* 25 ms: longer than the 20 ms interval */
  (void)step, (void)total, (void)ll;
  ++c->reports;
  if (stage == SOGMM_STAGE_SEEDING) ++c->seeding_reports;
  nanosleep(&wait, NULL);
  return 0;
}

static void test_slow_callback_reports_per_interval(void) {
  /* K = 120 seeds: k-means++ passes 120 poll points (one per seed) in a
   * millisecond or two of work. Before the fix the interval was timed from
   * the callback's start, so after one 25 ms call every poll point was due:
   * about 120 seeding reports. Now the 20 ms are of work after the callback
   * returned: one report at the stage start, plus one per 20 ms of seeding
   * work; 30 would need 580 ms of seeding, over 100 times what it takes. */
  const size_t k = 120;
  float* pts = make_clusters(1500, 10);
  sogmm_options* o = NULL;
  sogmm_model* m = NULL;
  SlowCount c = {0, 0};
  int threads;
  for (threads = 1; threads <= team(); ++threads) {
    c.seeding_reports = c.reports = 0;
    REQUIRE_OK(sogmm_options_create(&o));
    REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_MAX_ITER, 1));
    REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_THREADS, threads));
    REQUIRE_OK(sogmm_options_set_progress(o, slow, &c));
    REQUIRE_OK(test_fit_fixed_k(&m, pts, 1500, k, o));
    printf("threads %d: %d seeding reports for %zu seeds, %d reports in all\n", threads, c.seeding_reports, k,
           c.reports);
    EXPECT_TRUE(c.seeding_reports >= 1 && c.seeding_reports <= 30);
    sogmm_model_free(m);
    m = NULL;
    sogmm_options_free(o);
  }
  free(pts);
}

int main(void) {
  test_reentry_from_callback();
  test_render_holds_the_map();
  test_two_threads();
  test_nested_calls_have_no_callback();
  test_slow_callback_reports_per_interval();
  return test_summary("capi_threads_map_guard");
}
