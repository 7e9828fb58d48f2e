/* sogmm_map_occupancy_f32, sogmm_model_surface_distance_f32 and
 * sogmm_map_surface_distance_f32 (issue 31) through the C API: a plane at
 * z = 2 m seen by a camera at the origin (z = 1 free, z = 2 occupied, z = 3
 * and outside the frustum unknown at exactly 0.5), the distance |z - 2| and
 * its gradient, collision probability of spheres on and clear of the
 * plane, a map and its export agree, options reach the core, cancel
 * leaves the outputs untouched, and a status and message for bad input. */
#include "test_util.h"

enum { W = 64, H = 48 };
static const double k_identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

static int message_has(const char* needle) { return strstr(sogmm_last_error(), needle) != NULL; }

static int32_t cancel_at_once(int32_t stage, uint64_t step, uint64_t total, double ll, void* user_data) {
  (void)stage, (void)step, (void)total, (void)ll, (void)user_data;
  return 1;
}

static sogmm_map* plane_map(void) {
  static uint16_t depth[W * H];
  static uint8_t gray[W * H];
  sogmm_options* o = NULL;
  sogmm_map* m = NULL;
  int i;
  for (i = 0; i < W * H; ++i) depth[i] = 2000, gray[i] = 128;
  REQUIRE_OK(sogmm_options_create(&o));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_MAP_NOVELTY, 0));
  REQUIRE_OK(sogmm_map_create(&m, o));
  REQUIRE_OK(test_map_insert_rgbd(m, depth, gray, SOGMM_COLOR_GRAY8, W, H, 50.0, 50.0, 31.5, 23.5, k_identity));
  REQUIRE_OK(sogmm_map_flush(m));
  sogmm_options_free(o);
  return m;
}

static void test_occupancy(sogmm_map* m) {
  const float xyz[] = {0, 0, 1, 0, 0, 2, 0, 0, 3, 5, 0, 2};
  double p[4];
  uint8_t s[4];
  REQUIRE_OK(sogmm_map_occupancy_f32(m, xyz, 4, NULL, p, s));
  EXPECT_TRUE(s[0] == SOGMM_OCCUPANCY_FREE && p[0] < 1e-6);
  EXPECT_TRUE(s[1] == SOGMM_OCCUPANCY_OCCUPIED && p[1] > 0.9);
  EXPECT_TRUE(s[2] == SOGMM_OCCUPANCY_UNKNOWN && p[2] == 0.5);
  EXPECT_TRUE(s[3] == SOGMM_OCCUPANCY_UNKNOWN && p[3] == 0.5);
  {
    /* 3 cm in front of the plane: free with the 2 cm shell, occupied with 5 cm. */
    const float near_plane[] = {0, 0, 1.97f};
    double q0, q1;
    sogmm_options* o = NULL;
    REQUIRE_OK(sogmm_map_occupancy_f32(m, near_plane, 1, NULL, &q0, NULL));
    REQUIRE_OK(sogmm_options_create(&o));
    REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_OCCUPANCY_THICKNESS, 0.05));
    REQUIRE_OK(sogmm_map_occupancy_f32(m, near_plane, 1, o, &q1, NULL));
    EXPECT_TRUE(q0 < 0.5 && q1 > 0.5);
    EXPECT_STATUS(sogmm_options_set_f64(o, SOGMM_OPT_OCCUPANCY_SIGMA, 0.0), SOGMM_E_INVALID_ARG);
    /* Cancel: the outputs stay as they were. */
    REQUIRE_OK(sogmm_options_set_progress(o, cancel_at_once, NULL));
    p[0] = -1.0;
    EXPECT_STATUS(sogmm_map_occupancy_f32(m, xyz, 4, o, p, s), SOGMM_E_CANCELLED);
    EXPECT_TRUE(p[0] == -1.0);
    sogmm_options_free(o);
  }
}

static void test_distance(sogmm_map* m) {
  const float xyz[] = {0.2f, -0.1f, 1.7f, 0.2f, -0.1f, 2.05f};
  double d[2], g[6], d2[2];
  sogmm_model* exported = NULL;
  REQUIRE_OK(sogmm_map_surface_distance_f32(m, xyz, 2, NULL, d, g));
  EXPECT_NEAR(d[0], 0.3, 0.005);
  EXPECT_NEAR(d[1], 0.05, 0.005);
  EXPECT_TRUE(g[2] < -0.98 && g[5] > 0.98);
  REQUIRE_OK(sogmm_map_export(&exported, m, NULL));
  REQUIRE_OK(sogmm_model_surface_distance_f32(exported, xyz, 2, NULL, d2, NULL));
  EXPECT_TRUE(d2[0] == d[0] && d2[1] == d[1]);
  sogmm_model_free(exported);
}

static void test_collision(sogmm_map* m) {
  /* Spheres of radius 0.1 m centred on the plane and 20 cm in front of it. */
  const double centers[] = {0.1, 0.05, 2.0, 0.1, 0.05, 1.8};
  const double sphere[] = {0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01, 0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01};
  const double bad[] = {0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01, -0.01, 0, 0, 0, -0.01, 0, 0, 0, -0.01};
  double p[2] = {-1.0, -1.0};
  REQUIRE_OK(sogmm_map_collision_probability(m, centers, sphere, 2, NULL, p));
  EXPECT_TRUE(p[0] >= 0.99 && p[1] <= 0.01);
  p[0] = -1.0;
  EXPECT_STATUS(sogmm_map_collision_probability(m, centers, bad, 2, NULL, p), SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(message_has("robot 1") && p[0] == -1.0);
  EXPECT_STATUS(sogmm_map_collision_probability(m, NULL, sphere, 2, NULL, p), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_model_collision_probability(NULL, centers, sphere, 2, NULL, p), SOGMM_E_NULL_ARG);
}

static void test_bad_input(sogmm_map* m) {
  const float bad[] = {0, 0, 1, 0, NAN, 1};
  double p[2] = {-1.0, -1.0};
  sogmm_map* empty = NULL;
  EXPECT_STATUS(sogmm_map_occupancy_f32(NULL, bad, 1, NULL, p, NULL), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_map_occupancy_f32(m, NULL, 1, NULL, p, NULL), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_map_occupancy_f32(m, bad, 1, NULL, NULL, NULL), SOGMM_E_NULL_ARG);
  EXPECT_TRUE(message_has("probability_out"));
  EXPECT_STATUS(sogmm_map_occupancy_f32(m, bad, 2, NULL, p, NULL), SOGMM_E_INVALID_DATA);
  EXPECT_TRUE(p[0] == -1.0);
  EXPECT_STATUS(sogmm_map_surface_distance_f32(m, bad, 2, NULL, p, NULL), SOGMM_E_INVALID_DATA);
  EXPECT_STATUS(sogmm_model_surface_distance_f32(NULL, bad, 1, NULL, p, NULL), SOGMM_E_NULL_ARG);
  EXPECT_OK(sogmm_map_occupancy_f32(m, bad, 0, NULL, NULL, NULL));
  REQUIRE_OK(sogmm_map_create(&empty, NULL));
  EXPECT_STATUS(sogmm_map_surface_distance_f32(empty, bad, 1, NULL, p, NULL), SOGMM_E_INVALID_DATA);
  /* A map that observed nothing answers unknown (documented, not refused). */
  EXPECT_OK(sogmm_map_occupancy_f32(empty, bad, 1, NULL, p, NULL));
  EXPECT_TRUE(p[0] == 0.5);
  sogmm_map_free(empty);
}

int main(void) {
  sogmm_map* m = plane_map();
  test_occupancy(m);
  test_distance(m);
  test_collision(m);
  test_bad_input(m);
  sogmm_map_free(m);
  return test_summary("test_surface_queries");
}
