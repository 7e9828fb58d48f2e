/* sogmm_map_*: insert, novelty, stats, export, save/load round trip with
 * provenance, and a status plus message for every bad input. */
#include "test_util.h"

static const double k_identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

static int message_has(const char* needle) { return strstr(sogmm_last_error(), needle) != NULL; }

static void insert_frames_and_check(const char* dir) {
  sogmm_options* o = NULL;
  sogmm_map* map = NULL;
  test_map_stats st;
  test_frame_stats fs;
  sogmm_model* all = NULL;
  sogmm_model* part = NULL;
  sogmm_map* loaded = NULL;
  size_t m = 0, m_part = 0;
  double moved[16];
  const char* value = NULL;
  char path[1024];
  float* pts = make_clusters(3000, 42);
  const float box[6] = {-0.2f, -0.2f, 0.8f, 0.2f, 0.2f, 1.2f};
  const float inverted[6] = {0.2f, -0.2f, 0.8f, -0.2f, 0.2f, 1.2f};

  REQUIRE_OK(sogmm_options_create(&o));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_MAP_BATCH_SIZE, 100000));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_THREADS, 2));
  REQUIRE_OK(sogmm_map_create(&map, o));

  /* Empty map: nothing to export or save. */
  EXPECT_STATUS(sogmm_map_export(&all, map, NULL), SOGMM_E_INVALID_DATA);
  EXPECT_TRUE(all == NULL);

  REQUIRE_OK(sogmm_map_insert_points_f32(map, pts, 3000, k_identity));
  REQUIRE_OK(test_map_get_stats(map, &st));
  EXPECT_TRUE(st.n_pending == 3000 && st.n_components == 0 && st.n_frames == 1);
  snprintf(path, sizeof path, "%s/map_pending.sogmm", dir);
  EXPECT_STATUS(sogmm_map_save(map, path, NULL), SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(message_has("flush"));
  REQUIRE_OK(sogmm_map_flush(map));
  REQUIRE_OK(test_map_get_stats(map, &st));
  EXPECT_TRUE(st.n_pending == 0 && st.n_components >= 3 && st.n_flushes == 1);

  /* The same points again: (almost) nothing is novel. */
  REQUIRE_OK(sogmm_map_insert_points_f32(map, pts, 3000, k_identity));
  REQUIRE_OK(test_map_get_frame_stats(map, 1, &fs));
  EXPECT_TRUE(fs.n_points == 3000 && fs.n_novel < 150);
  EXPECT_TRUE(fs.pose[0] == 1.0 && fs.pose[15] == 1.0);
  EXPECT_STATUS(test_map_get_frame_stats(map, 2, &fs), SOGMM_E_INVALID_ARG);
  /* Moved 3 m: all novel. */
  memcpy(moved, k_identity, sizeof moved);
  moved[3] = 3.0;
  REQUIRE_OK(sogmm_map_insert_points_f32(map, pts, 3000, moved));
  REQUIRE_OK(test_map_get_frame_stats(map, 2, &fs));
  EXPECT_TRUE(fs.n_novel == 3000);
  REQUIRE_OK(sogmm_map_flush(map));

  /* Export all and a box. */
  REQUIRE_OK(sogmm_map_export(&all, map, NULL));
  REQUIRE_OK(sogmm_model_n_components(all, &m));
  REQUIRE_OK(test_map_get_stats(map, &st));
  EXPECT_TRUE(m == st.n_components);
  REQUIRE_OK(sogmm_model_get_value(all, "coordinate_frame", &value));
  EXPECT_TRUE(strcmp(value, "world") == 0);
  REQUIRE_OK(sogmm_map_export(&part, map, box));
  REQUIRE_OK(sogmm_model_n_components(part, &m_part));
  EXPECT_TRUE(m_part >= 1 && m_part < m);
  sogmm_model_free(part);
  part = NULL;
  EXPECT_STATUS(sogmm_map_export(&part, map, inverted), SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(part == NULL);

  /* Save and load: same components, same provenance. */
  snprintf(path, sizeof path, "%s/map.sogmm", dir);
  REQUIRE_OK(sogmm_map_save(map, path, NULL));
  REQUIRE_OK(sogmm_map_load(&loaded, path, o));
  {
    test_map_stats ls;
    test_frame_stats lf;
    sogmm_model* reloaded = NULL;
    float *w1, *w2;
    size_t m2 = 0;
    REQUIRE_OK(test_map_get_stats(loaded, &ls));
    EXPECT_TRUE(ls.n_components == st.n_components && ls.n_frames == 3 && ls.n_pending == 0);
    REQUIRE_OK(test_map_get_frame_stats(loaded, 2, &lf));
    EXPECT_TRUE(lf.n_points == 3000 && lf.n_novel == 3000 && lf.pose[3] == 3.0);
    REQUIRE_OK(sogmm_map_export(&reloaded, loaded, NULL));
    REQUIRE_OK(sogmm_model_n_components(reloaded, &m2));
    EXPECT_TRUE(m2 == m);
    w1 = (float*)malloc(m * 4 * sizeof(float));
    w2 = (float*)malloc(m * 4 * sizeof(float));
    REQUIRE_OK(sogmm_model_get_means_f32(all, w1, m * 4));
    REQUIRE_OK(sogmm_model_get_means_f32(reloaded, w2, m * 4));
    EXPECT_TRUE(memcmp(w1, w2, m * 4 * sizeof(float)) == 0);
    free(w1);
    free(w2);
    sogmm_model_free(reloaded);
    /* The file is a plain world-frame model with the provenance keys. */
    REQUIRE_OK(sogmm_model_load(&reloaded, path, NULL));
    REQUIRE_OK(sogmm_model_get_value(reloaded, "map_frames", &value));
    EXPECT_TRUE(strncmp(value, "0 3000 3000 1 0 0 0 ", 20) == 0);
    REQUIRE_OK(sogmm_model_get_value(reloaded, "map_options", &value));
    EXPECT_TRUE(strncmp(value, "novelty=1 ", 10) == 0);
    sogmm_model_free(reloaded);
  }
  /* A loaded map keeps growing. */
  moved[3] = -3.0;
  REQUIRE_OK(sogmm_map_insert_points_f32(loaded, pts, 3000, moved));
  REQUIRE_OK(test_map_get_stats(loaded, &st));
  EXPECT_TRUE(st.n_frames == 4 && st.n_pending == 3000);

  /* A camera-frame model is not a map. */
  {
    sogmm_model* cam = NULL;
    sogmm_map* bad = NULL;
    REQUIRE_OK(sogmm_fit_points_f32(&cam, pts, 3000, NULL, o));
    snprintf(path, sizeof path, "%s/camera_frame.sogmm", dir);
    REQUIRE_OK(sogmm_model_save(cam, path, NULL));
    EXPECT_STATUS(sogmm_map_load(&bad, path, NULL), SOGMM_E_INVALID_ARG);
    EXPECT_TRUE(bad == NULL && message_has("camera"));
    snprintf(path, sizeof path, "%s/no_such_map.sogmm", dir);
    EXPECT_STATUS(sogmm_map_load(&bad, path, NULL), SOGMM_E_IO);
    sogmm_model_free(cam);
  }

  sogmm_model_free(all);
  sogmm_map_free(loaded);
  sogmm_map_free(map);
  sogmm_options_free(o);
  free(pts);
}

static void bad_input(void) {
  sogmm_map* map = NULL;
  sogmm_options* o = NULL;
  test_map_stats st;
  float* pts = make_clusters(300, 7);
  double pose[16];
  uint16_t* depth;
  uint8_t *gray, *rgb;

  EXPECT_STATUS(sogmm_map_create(NULL, NULL), SOGMM_E_NULL_ARG);
  REQUIRE_OK(sogmm_options_create(&o));
  EXPECT_STATUS(sogmm_options_set_i64(o, SOGMM_OPT_MAP_BATCH_SIZE, 0), SOGMM_E_INVALID_ARG);
  EXPECT_STATUS(sogmm_options_set_i64(o, SOGMM_OPT_MAP_FUSION_METHOD, 2), SOGMM_E_INVALID_ARG);
  EXPECT_STATUS(sogmm_options_set_f64(o, SOGMM_OPT_MAP_FUSION_THRESHOLD, 0.0), SOGMM_E_INVALID_ARG);
  EXPECT_STATUS(sogmm_options_set_f64(o, SOGMM_OPT_MAP_NOVELTY_THRESHOLD, NAN), SOGMM_E_INVALID_ARG);
  {
    double scale = 0.0;
    REQUIRE_OK(sogmm_options_get_f64(o, SOGMM_OPT_MAP_NOVELTY_BANDWIDTH_SCALE, &scale));
    EXPECT_TRUE(scale == 0.7);
    EXPECT_STATUS(sogmm_options_set_f64(o, SOGMM_OPT_MAP_NOVELTY_BANDWIDTH_SCALE, 0.0), SOGMM_E_INVALID_ARG);
    EXPECT_STATUS(sogmm_options_set_f64(o, SOGMM_OPT_MAP_NOVELTY_BANDWIDTH_SCALE, 1.5), SOGMM_E_INVALID_ARG);
    EXPECT_STATUS(sogmm_options_set_f64(o, SOGMM_OPT_MAP_NOVELTY_BANDWIDTH_SCALE, NAN), SOGMM_E_INVALID_ARG);
    REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_MAP_NOVELTY_BANDWIDTH_SCALE, 1.0));
  }
  {
    double ratio = 0.0;
    REQUIRE_OK(sogmm_options_get_f64(o, SOGMM_OPT_MAP_REVISIT_REFIT_RATIO, &ratio));
    EXPECT_TRUE(ratio == 1.25);
    EXPECT_STATUS(sogmm_options_set_f64(o, SOGMM_OPT_MAP_REVISIT_REFIT_RATIO, 0.5), SOGMM_E_INVALID_ARG);
    EXPECT_STATUS(sogmm_options_set_f64(o, SOGMM_OPT_MAP_REVISIT_REFIT_RATIO, -1.0), SOGMM_E_INVALID_ARG);
    EXPECT_STATUS(sogmm_options_set_f64(o, SOGMM_OPT_MAP_REVISIT_REFIT_RATIO, NAN), SOGMM_E_INVALID_ARG);
    EXPECT_STATUS(sogmm_options_set_f64(o, SOGMM_OPT_MAP_REVISIT_REFIT_RATIO, INFINITY), SOGMM_E_INVALID_ARG);
    REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_MAP_REVISIT_REFIT_RATIO, 0.0));
    REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_MAP_REVISIT_REFIT_RATIO, 2.0));
  }
  EXPECT_STATUS(sogmm_options_set_f64(o, SOGMM_OPT_MAP_NOVELTY, 1.0), SOGMM_E_INVALID_ARG); /* an i64 key */
  REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_DEPTH_MIN, 5.0));
  EXPECT_STATUS(sogmm_map_create(&map, o), SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(map == NULL && message_has("DEPTH_MIN"));
  REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_DEPTH_MIN, 0.1));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_MAP_FUSION, 1));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_MAP_FUSION_METHOD, SOGMM_FUSION_KL));
  REQUIRE_OK(sogmm_map_create(&map, o));

  EXPECT_STATUS(sogmm_map_insert_points_f32(NULL, pts, 300, k_identity), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_map_insert_points_f32(map, NULL, 300, k_identity), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_map_insert_points_f32(map, pts, 300, NULL), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_map_insert_points_f32(map, pts, 0, k_identity), SOGMM_E_INVALID_DATA);
  EXPECT_TRUE(message_has("no point"));
  memcpy(pose, k_identity, sizeof pose);
  pose[7] = INFINITY;
  EXPECT_STATUS(sogmm_map_insert_points_f32(map, pts, 300, pose), SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(message_has("not finite"));
  memcpy(pose, k_identity, sizeof pose);
  pose[0] = 1.5; /* scaled: not rigid */
  EXPECT_STATUS(sogmm_map_insert_points_f32(map, pts, 300, pose), SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(message_has("orthonormal"));
  pts[5] = NAN;
  EXPECT_STATUS(sogmm_map_insert_points_f32(map, pts, 300, k_identity), SOGMM_E_INVALID_DATA);
  pts[5] = 0.0f;
  REQUIRE_OK(test_map_get_stats(map, &st));
  EXPECT_TRUE(st.n_frames == 0 && st.n_pending == 0);

  /* RGB-D: the first frame fixes the size. */
  make_frame(64, 48, &depth, &gray, &rgb);
  REQUIRE_OK(test_map_insert_rgbd(map, depth, rgb, SOGMM_COLOR_RGB8, 64, 48, 50, 50, 32, 24, k_identity));
  EXPECT_STATUS(test_map_insert_rgbd(map, depth, gray, SOGMM_COLOR_GRAY8, 32, 48, 50, 50, 32, 24, k_identity),
                SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(message_has("differs"));
  EXPECT_STATUS(test_map_insert_rgbd(map, depth, gray, 99, 64, 48, 50, 50, 32, 24, k_identity),
                SOGMM_E_INVALID_ARG);
  EXPECT_STATUS(test_map_insert_rgbd(map, depth, gray, SOGMM_COLOR_GRAY8, 64, 48, 50, 50, 32, 24, NULL),
                SOGMM_E_NULL_ARG);
  memset(depth, 0, 64 * 48 * sizeof(uint16_t));
  EXPECT_STATUS(test_map_insert_rgbd(map, depth, gray, SOGMM_COLOR_GRAY8, 64, 48, 50, 50, 32, 24, k_identity),
                SOGMM_E_INVALID_DATA);
  EXPECT_TRUE(message_has("no valid depth"));
  REQUIRE_OK(test_map_get_stats(map, &st));
  EXPECT_TRUE(st.n_frames == 1);

  EXPECT_STATUS(sogmm_map_flush(NULL), SOGMM_E_NULL_ARG);
  /* The keyed statistics: each getter takes only its own keys, of its type. */
  {
    int64_t iv = -7;
    double fv = -7.0, pose_out[16];
    EXPECT_STATUS(sogmm_map_get_i64(map, SOGMM_MAP_N_FRAMES, NULL), SOGMM_E_NULL_ARG);
    EXPECT_STATUS(sogmm_map_get_i64(NULL, SOGMM_MAP_N_FRAMES, &iv), SOGMM_E_NULL_ARG);
    EXPECT_STATUS(sogmm_map_frame_get_i64(NULL, 0, SOGMM_MAP_FRAME_N_POINTS, &iv), SOGMM_E_NULL_ARG);
    EXPECT_STATUS(sogmm_map_frame_get_i64(map, 0, SOGMM_MAP_FRAME_N_POINTS, NULL), SOGMM_E_NULL_ARG);
    EXPECT_STATUS(sogmm_map_frame_get_f64(map, 0, SOGMM_MAP_FRAME_MS_FIT, NULL), SOGMM_E_NULL_ARG);
    EXPECT_STATUS(sogmm_map_frame_get_pose(map, 0, NULL), SOGMM_E_NULL_ARG);
    EXPECT_STATUS(sogmm_map_get_i64(map, SOGMM_MAP_FRAME_N_POINTS, &iv), SOGMM_E_INVALID_ARG);
    EXPECT_TRUE(message_has("SOGMM_MAP_FRAME_N_POINTS") && message_has("sogmm_map_frame_get_i64"));
    EXPECT_STATUS(sogmm_map_frame_get_i64(map, 0, SOGMM_MAP_N_FRAMES, &iv), SOGMM_E_INVALID_ARG);
    EXPECT_TRUE(message_has("sogmm_map_get_i64"));
    EXPECT_STATUS(sogmm_map_frame_get_i64(map, 0, SOGMM_MAP_FRAME_MS_FIT, &iv), SOGMM_E_INVALID_ARG);
    EXPECT_TRUE(message_has("f64") && message_has("sogmm_map_frame_get_f64"));
    EXPECT_STATUS(sogmm_map_frame_get_f64(map, 0, SOGMM_MAP_FRAME_N_POINTS, &fv), SOGMM_E_INVALID_ARG);
    EXPECT_STATUS(sogmm_map_get_i64(map, SOGMM_INFO_SUPPORT_SIZE, &iv), SOGMM_E_INVALID_ARG);
    EXPECT_TRUE(message_has("info key"));
    EXPECT_STATUS(sogmm_map_get_i64(map, 29999, &iv), SOGMM_E_INVALID_ARG);
    EXPECT_TRUE(message_has("unknown map key 29999"));
    EXPECT_STATUS(sogmm_map_frame_get_pose(map, 1, pose_out), SOGMM_E_INVALID_ARG); /* one frame so far */
    EXPECT_STATUS(sogmm_map_frame_get_f64(map, 1, SOGMM_MAP_FRAME_MS_FIT, &fv), SOGMM_E_INVALID_ARG);
    EXPECT_TRUE(message_has("does not exist"));
    EXPECT_TRUE(iv == -7 && fv == -7.0); /* a refused call writes nothing */
    REQUIRE_OK(sogmm_map_frame_get_pose(map, 0, pose_out));
    EXPECT_TRUE(memcmp(pose_out, k_identity, sizeof pose_out) == 0);
  }
  EXPECT_STATUS(sogmm_map_save(map, NULL, NULL), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_map_load(NULL, "x", NULL), SOGMM_E_NULL_ARG);
  sogmm_map_free(NULL);

  free(depth);
  free(gray);
  free(rgb);
  free(pts);
  sogmm_map_free(map);
  sogmm_options_free(o);
}

/* The revisit refit key reaches the map: a wall first seen in one gray, then
 * seen again with 8 gray stripes (many more modes than the map has components
 * there) is refitted at the default ratio (a second fit, nothing pending) and
 * not at ratio 0. */
static void revisit_refit(void) {
  enum { W = 64, H = 48 };
  uint16_t* depth = malloc(W * H * sizeof(uint16_t));
  uint8_t* plain = malloc(W * H);
  uint8_t* striped = malloc(W * H);
  for (int i = 0; i < W * H; ++i) {
    depth[i] = 1500;
    plain[i] = 128;
    striped[i] = (uint8_t)(32 * (((i % W) / 4) % 8));
  }
  for (int r = 0; r < 2; ++r) { /* r = 0: default ratio (1.25); r = 1: ratio 0 */
    sogmm_options* o = NULL;
    sogmm_map* map = NULL;
    test_map_stats st;
    REQUIRE_OK(sogmm_options_create(&o));
    REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_MAP_BATCH_SIZE, W * H)); /* the first frame is one batch */
    if (r == 1) REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_MAP_REVISIT_REFIT_RATIO, 0.0));
    REQUIRE_OK(sogmm_map_create(&map, o));
    REQUIRE_OK(test_map_insert_rgbd(map, depth, plain, SOGMM_COLOR_GRAY8, W, H, 60, 60, 32, 24, k_identity));
    REQUIRE_OK(test_map_insert_rgbd(map, depth, striped, SOGMM_COLOR_GRAY8, W, H, 60, 60, 32, 24, k_identity));
    REQUIRE_OK(test_map_get_stats(map, &st));
    EXPECT_TRUE(st.n_frames == 2 && st.n_pending == 0);
    EXPECT_TRUE(st.n_flushes == (r == 0 ? 2u : 1u));
    {
      int64_t replaced0 = 99, replaced1 = 99;
      test_frame_stats fs;
      REQUIRE_OK(sogmm_map_frame_get_i64(map, 0, SOGMM_MAP_FRAME_N_REPLACED, &replaced0));
      REQUIRE_OK(sogmm_map_frame_get_i64(map, 1, SOGMM_MAP_FRAME_N_REPLACED, &replaced1));
      REQUIRE_OK(test_map_get_frame_stats(map, 1, &fs));
      EXPECT_TRUE(replaced0 == 0);                         /* the first frame was a batch, not a refit */
      EXPECT_TRUE(r == 0 ? replaced1 > 0 : replaced1 == 0); /* the refit replaced the plain wall's components */
      EXPECT_TRUE(fs.flushed == (r == 0));                  /* a refit is a fit */
      EXPECT_TRUE(fs.n_replaced == (uint64_t)replaced1);
      EXPECT_TRUE(st.n_refits == (r == 0 ? 1u : 0u));       /* the frames with a replaced count */
      EXPECT_STATUS(sogmm_map_frame_get_i64(map, 2, SOGMM_MAP_FRAME_N_REPLACED, &replaced0), SOGMM_E_INVALID_ARG);
      EXPECT_STATUS(sogmm_map_frame_get_i64(map, 0, SOGMM_MAP_FRAME_N_REPLACED, NULL), SOGMM_E_NULL_ARG);
      EXPECT_STATUS(sogmm_map_frame_get_i64(NULL, 0, SOGMM_MAP_FRAME_N_REPLACED, &replaced0), SOGMM_E_NULL_ARG);
    }
    sogmm_map_free(map);
    sogmm_options_free(o);
  }
  free(depth);
  free(plain);
  free(striped);
}

int main(int argc, char** argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: %s SCRATCH_DIR\n", argv[0]);
    return 2;
  }
  bad_input();
  revisit_refit();
#ifdef SOGMM_CAPI_HAVE_FORMAT
  insert_frames_and_check(argv[1]);
#else
  (void)insert_frames_and_check;
#endif
  return test_summary("capi_map");
}
