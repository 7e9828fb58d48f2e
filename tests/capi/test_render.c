/* sogmm_model_render_f32 and sogmm_map_render_f32: the closed-form depth,
 * gray and variance of one component seen along its axis; the same images
 * when model and pose move together; a map renders bitwise as its export;
 * threads change no bit; SOGMM_OPT_RENDER_SURFACE_SIGMA passes a graze on to
 * the surface behind; progress and cancel (outputs untouched); a status
 * and message for every bad input. */
#include "test_util.h"

static const double k_identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

enum { W = 9, H = 7, PIXELS = W * H, CENTRE = 3 * W + 4 };
static const double FX = 10.0, FY = 12.0, CX = 4.0, CY = 3.0;

static int message_has(const char* needle) { return strstr(sogmm_last_error(), needle) != NULL; }

/* One component on the optical axis at z = 1.5 m, gray 0.4, spatial
 * variances 0.05^2, 0.04^2, 0.01^2 and gray correlated with x (cov 0.002,
 * gray variance 0.01). Along the central ray d = (0, 0, 1) its density is a
 * Gaussian in t with its mode at t = 1.5 (the mean lies on the ray); there
 * x = mu, so gray = 0.4 and Var = 0.01 - 0.002^2 / 0.05^2 = 0.0084. */
static sogmm_model* on_axis_component(void) {
  const float w = 1.0f;
  const float mean[4] = {0.0f, 0.0f, 1.5f, 0.4f};
  const float cov[16] = {0.0025f, 0, 0, 0.002f, 0, 0.0016f, 0, 0, 0, 0, 0.0001f, 0, 0.002f, 0, 0, 0.01f};
  sogmm_model* m = NULL;
  REQUIRE_OK(sogmm_model_from_arrays_f32(&m, 1, &w, mean, cov, 1000));
  return m;
}

static int32_t cancel_at_once(int32_t stage, uint64_t step, uint64_t total, double ll, void* user_data) {
  int* calls = (int*)user_data;
  (void)stage, (void)step, (void)total, (void)ll;
  ++*calls;
  return 1;
}

typedef struct {
  int n;
  int32_t stage;
  uint64_t last_step, total;
} Seen;

static int32_t record(int32_t stage, uint64_t step, uint64_t total, double ll, void* user_data) {
  Seen* s = (Seen*)user_data;
  (void)ll;
  ++s->n;
  s->stage = stage;
  s->last_step = step;
  s->total = total;
  return 0;
}

static void test_closed_form(void) {
  sogmm_model* m = on_axis_component();
  float depth[PIXELS], gray[PIXELS], var[PIXELS];
  REQUIRE_OK(sogmm_model_render_f32(m, W, H, FX, FY, CX, CY, NULL, NULL, depth, gray, var));
  EXPECT_NEAR(depth[CENTRE], 1.5, 1e-5);
  EXPECT_NEAR(gray[CENTRE], 0.4, 1e-5);
  EXPECT_NEAR(var[CENTRE], 0.01 - 0.002 * 0.002 / 0.0025, 1e-6);
  /* Corner ray: x / z = -0.4, far outside 3 sigma of the component: NaN. */
  EXPECT_TRUE(isnan(depth[0]) && isnan(gray[0]) && isnan(var[0]));
  /* Variance is optional; identity pose = NULL. */
  {
    float d2[PIXELS], g2[PIXELS];
    EXPECT_OK(sogmm_model_render_f32(m, W, H, FX, FY, CX, CY, k_identity, NULL, d2, g2, NULL));
    EXPECT_TRUE(memcmp(d2, depth, sizeof d2) == 0 && memcmp(g2, gray, sizeof g2) == 0);
  }
  /* A depth range that ends before the surface shows nothing there. */
  {
    sogmm_options* o = NULL;
    REQUIRE_OK(sogmm_options_create(&o));
    REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_DEPTH_MAX, 1.4));
    EXPECT_OK(sogmm_model_render_f32(m, W, H, FX, FY, CX, CY, NULL, o, depth, gray, NULL));
    EXPECT_TRUE(isnan(depth[CENTRE]));
    sogmm_options_free(o);
  }
  sogmm_model_free(m);
}

/* SOGMM_OPT_RENDER_SURFACE_SIGMA. Two components (weights 0.5): A at
 * (0.025, 0, 1), isotropic sigma 0.01, gray 0.2; B a flat patch at (0, 0, 2)
 * (sigma 0.1, 0.1, 0.01), gray 0.8. The optical axis passes A at 2.5 sigma:
 * at z = 1 the evidence sum_k exp(-D_k^2 / 2) is exp(-3.125) = 0.044 (B is
 * 100 sigma away), at z = 2 it is 1. s = 0 shows A at 1 m (gray 0.2); s = 2
 * needs exp(-2) = 0.135 there, so the ray passes on to B at 2 m (gray 0.8);
 * s = 3 needs exp(-4.5) = 0.011 and shows A again. */
static void test_surface_sigma(void) {
  const float w[2] = {0.5f, 0.5f};
  const float mean[8] = {0.025f, 0, 1, 0.2f, 0, 0, 2, 0.8f};
  const float cov[32] = {1e-4f, 0, 0, 0, 0, 1e-4f, 0, 0, 0, 0, 1e-4f, 0, 0, 0, 0, 0.01f,
                         0.01f, 0, 0, 0, 0, 0.01f, 0, 0, 0, 0, 1e-4f, 0, 0, 0, 0, 0.01f};
  const double s[3] = {0, 2, 3}, want_depth[3] = {1, 2, 1}, want_gray[3] = {0.2, 0.8, 0.2};
  sogmm_model* m = NULL;
  sogmm_options* o = NULL;
  REQUIRE_OK(sogmm_model_from_arrays_f32(&m, 2, w, mean, cov, 100));
  REQUIRE_OK(sogmm_options_create(&o));
  for (int i = 0; i < 3; ++i) {
    float depth = 0, gray = 0;
    REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_RENDER_SURFACE_SIGMA, s[i]));
    EXPECT_OK(sogmm_model_render_f32(m, 1, 1, 100, 100, 0, 0, NULL, o, &depth, &gray, NULL));
    EXPECT_NEAR(depth, want_depth[i], 1e-5);
    EXPECT_NEAR(gray, want_gray[i], 1e-5);
  }
  EXPECT_STATUS(sogmm_options_set_f64(o, SOGMM_OPT_RENDER_SURFACE_SIGMA, -1), SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(message_has("SOGMM_OPT_RENDER_SURFACE_SIGMA"));
  sogmm_options_free(o);
  sogmm_model_free(m);
}

static void test_pose_invariance(void) {
  /* The component moved by T (a rotation about (1, 1, 0) and a shift) and
   * seen from pose T: the same images as the unmoved one from the origin. */
  const double c = cos(0.7), s = sin(0.7), r = 1.0 / sqrt(2.0);
  /* Rodrigues for axis (r, r, 0). */
  const double T[16] = {c + r * r * (1 - c), r * r * (1 - c), r * s, 1.0,
                        r * r * (1 - c), c + r * r * (1 - c), -r * s, -2.0,
                        -r * s, r * s, c, 0.5,
                        0, 0, 0, 1};
  sogmm_model* m = on_axis_component();
  sogmm_model* moved = NULL;
  float d0[PIXELS], g0[PIXELS], v0[PIXELS], d1[PIXELS], g1[PIXELS], v1[PIXELS];
  int i, same_empty = 1;
  REQUIRE_OK(sogmm_model_transform(&moved, m, T));
  REQUIRE_OK(sogmm_model_render_f32(m, W, H, FX, FY, CX, CY, NULL, NULL, d0, g0, v0));
  REQUIRE_OK(sogmm_model_render_f32(moved, W, H, FX, FY, CX, CY, T, NULL, d1, g1, v1));
  for (i = 0; i < PIXELS; ++i) {
    if (isnan(d0[i]) != isnan(d1[i])) same_empty = 0;
    if (isnan(d0[i])) continue;
    EXPECT_NEAR(d0[i], d1[i], 1e-5);
    EXPECT_NEAR(g0[i], g1[i], 1e-5);
    EXPECT_NEAR(v0[i], v1[i], 1e-6);
  }
  EXPECT_TRUE(same_empty);
  EXPECT_NEAR(d1[CENTRE], 1.5, 1e-5);
  sogmm_model_free(moved);
  sogmm_model_free(m);
}

static void test_map_threads_progress(void) {
  float* pts = make_clusters(3000, 42);
  sogmm_options* o = NULL;
  sogmm_map* map = NULL;
  sogmm_model* exported = NULL;
  Seen seen = {0, 0, 0, 0};
  int calls = 0, i, shown = 0;
  enum { MW = 40, MH = 30 };
  float dm[MW * MH], gm[MW * MH], dx[MW * MH], gx[MW * MH], vx[MW * MH], d1[MW * MH], g1[MW * MH];
  REQUIRE_OK(sogmm_options_create(&o));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_MAP_BATCH_SIZE, 100000));
  REQUIRE_OK(sogmm_map_create(&map, o));
  /* Before anything is flushed the map has nothing to render. */
  EXPECT_STATUS(sogmm_map_render_f32(map, MW, MH, 30, 30, 19.5, 14.5, NULL, NULL, dm, gm, NULL),
                SOGMM_E_INVALID_DATA);
  REQUIRE_OK(sogmm_map_insert_points_f32(map, pts, 3000, k_identity));
  REQUIRE_OK(sogmm_map_flush(map));
  REQUIRE_OK(sogmm_map_export(&exported, map, NULL));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_THREADS, 2));
  REQUIRE_OK(sogmm_map_render_f32(map, MW, MH, 30, 30, 19.5, 14.5, NULL, o, dm, gm, NULL));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_THREADS, 1));
  REQUIRE_OK(sogmm_options_set_progress(o, record, &seen));
  REQUIRE_OK(sogmm_model_render_f32(exported, MW, MH, 30, 30, 19.5, 14.5, NULL, o, dx, gx, vx));
  /* Map = its export, 2 threads = 1 thread with a callback: the same bits. */
  EXPECT_TRUE(memcmp(dm, dx, sizeof dm) == 0 && memcmp(gm, gx, sizeof gm) == 0);
  for (i = 0; i < MW * MH; ++i) shown += !isnan(dm[i]);
  EXPECT_TRUE(shown > 0);
  EXPECT_TRUE(seen.n >= 2 && seen.stage == SOGMM_STAGE_RENDERING && seen.last_step == MH && seen.total == MH);
  /* A cancel: SOGMM_E_CANCELLED, outputs untouched. */
  for (i = 0; i < MW * MH; ++i) d1[i] = g1[i] = 7.0f;
  REQUIRE_OK(sogmm_options_set_progress(o, cancel_at_once, &calls));
  EXPECT_STATUS(sogmm_map_render_f32(map, MW, MH, 30, 30, 19.5, 14.5, NULL, o, d1, g1, NULL), SOGMM_E_CANCELLED);
  EXPECT_TRUE(calls >= 1);
  for (i = 0; i < MW * MH; ++i) EXPECT_TRUE(d1[i] == 7.0f && g1[i] == 7.0f);
  sogmm_model_free(exported);
  sogmm_map_free(map);
  sogmm_options_free(o);
  free(pts);
}

static void test_bad_input(void) {
  sogmm_model* m = on_axis_component();
  sogmm_options* o = NULL;
  float depth[PIXELS], gray[PIXELS];
  double scaled[16];
  memcpy(scaled, k_identity, sizeof scaled);
  scaled[0] = 2.0;
  REQUIRE_OK(sogmm_options_create(&o));
  EXPECT_STATUS(sogmm_model_render_f32(NULL, W, H, FX, FY, CX, CY, NULL, NULL, depth, gray, NULL), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_model_render_f32(m, W, H, FX, FY, CX, CY, NULL, NULL, NULL, gray, NULL), SOGMM_E_NULL_ARG);
  EXPECT_TRUE(message_has("depth_out"));
  EXPECT_STATUS(sogmm_model_render_f32(m, W, H, FX, FY, CX, CY, NULL, NULL, depth, NULL, NULL), SOGMM_E_NULL_ARG);
  EXPECT_TRUE(message_has("gray_out"));
  EXPECT_STATUS(sogmm_map_render_f32(NULL, W, H, FX, FY, CX, CY, NULL, NULL, depth, gray, NULL), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_model_render_f32(m, 0, H, FX, FY, CX, CY, NULL, NULL, depth, gray, NULL), SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(message_has("image size"));
  EXPECT_STATUS(sogmm_model_render_f32(m, 3000000000u, H, FX, FY, CX, CY, NULL, NULL, depth, gray, NULL),
                SOGMM_E_INVALID_ARG);
  EXPECT_STATUS(sogmm_model_render_f32(m, W, H, 0.0, FY, CX, CY, NULL, NULL, depth, gray, NULL), SOGMM_E_INVALID_ARG);
  EXPECT_STATUS(sogmm_model_render_f32(m, W, H, FX, FY, NAN, CY, NULL, NULL, depth, gray, NULL), SOGMM_E_INVALID_ARG);
  EXPECT_STATUS(sogmm_model_render_f32(m, W, H, FX, FY, CX, CY, scaled, NULL, depth, gray, NULL), SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(message_has("camera_to_world"));
  EXPECT_STATUS(sogmm_model_render_f32(m, 20000, 20000, FX, FY, CX, CY, NULL, NULL, depth, gray, NULL), SOGMM_E_LIMIT);
  REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_DEPTH_MIN, 2.0));
  REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_DEPTH_MAX, 1.0));
  EXPECT_STATUS(sogmm_model_render_f32(m, W, H, FX, FY, CX, CY, NULL, o, depth, gray, NULL), SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(message_has("depth_min"));
  sogmm_options_free(o);
  sogmm_model_free(m);
}

int main(void) {
  test_closed_form();
  test_surface_sigma();
  test_pose_invariance();
  test_map_threads_progress();
  test_bad_input();
  return test_summary("test_render");
}
