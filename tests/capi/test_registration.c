/* sogmm_register_points_f32 and sogmm_register_model (issue 32) through the
 * C API: points sampled from a corner of three planes, and the corner model
 * itself, rotated by 3 degrees about z and moved by -t, register back to the
 * closed-form pose; options reach the core (an
 * iteration cap gives NOT_CONVERGED); progress reports the REGISTRATION
 * stage and a cancel leaves the outputs untouched; a status and message for
 * bad input (NULLs, a small struct_size, a NaN or non-rigid init, too few
 * points, a non-finite point, a source model standing for too few points). */
#include "test_util.h"

enum { N = 3000, K = 75 };

static int message_has(const char* needle) { return strstr(sogmm_last_error(), needle) != NULL; }

static int32_t g_stage_seen = 0;
static int32_t record_stage(int32_t stage, uint64_t step, uint64_t total, double ll, void* cancel) {
  (void)step, (void)total, (void)ll;
  if (stage == SOGMM_STAGE_REGISTRATION) g_stage_seen = 1;
  return cancel != NULL;
}

/* Flat components tiling the unit squares of the planes x = 0, y = 0, z = 0. */
static sogmm_model* corner(uint64_t support_size) {
  static float w[K], mu[4 * K], cov[16 * K];
  sogmm_model* m = NULL;
  int axis, a, b, k = 0;
  memset(mu, 0, sizeof mu);
  memset(cov, 0, sizeof cov);
  for (axis = 0; axis < 3; ++axis)
    for (a = 0; a < 5; ++a)
      for (b = 0; b < 5; ++b, ++k) {
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        w[k] = 1.0f / K;
        mu[4 * k + u] = 0.1f + 0.2f * (float)a;
        mu[4 * k + v] = 0.1f + 0.2f * (float)b;
        mu[4 * k + 3] = 0.5f;
        cov[16 * k + 5 * u] = cov[16 * k + 5 * v] = 0.08f * 0.08f;
        cov[16 * k + 5 * axis] = 0.003f * 0.003f;
        cov[16 * k + 15] = 0.01f;
      }
  REQUIRE_OK(sogmm_model_from_arrays_f32(&m, K, w, mu, cov, support_size));
  return m;
}

int main(void) {
  static float pts[4 * N];
  const double c = cos(3.0 * 3.14159265358979323846 / 180), s = sin(3.0 * 3.14159265358979323846 / 180);
  /* truth: x = R p + t with R the 3-degree turn about z. */
  const double truth[16] = {c, -s, 0, 0.02, s, c, 0, -0.01, 0, 0, 1, 0.03, 0, 0, 0, 1};
  double pose[16], nan_init[16], scaled[16];
  sogmm_registration_info info;
  sogmm_options* o = NULL;
  sogmm_model* m = corner(1);
  sogmm_model *whole = corner(30000), *moved = NULL;
  double back[16], first[16], again[16];
  int i, k;
  REQUIRE_OK(sogmm_model_sample_f32(m, N, 1, 4, NULL, pts));
  for (i = 0; i < N; ++i) { /* p = R^T (x - t) */
    const double x = pts[4 * i] - truth[3], y = pts[4 * i + 1] - truth[7], z = pts[4 * i + 2] - truth[11];
    pts[4 * i] = (float)(c * x + s * y);
    pts[4 * i + 1] = (float)(-s * x + c * y);
    pts[4 * i + 2] = (float)z;
  }
  memset(&info, 0, sizeof info);
  info.struct_size = sizeof info;
  EXPECT_OK(sogmm_register_points_f32(m, pts, N, NULL, NULL, pose, &info));
  EXPECT_TRUE(info.status == SOGMM_REGISTRATION_CONVERGED);
  /* Noise: 3 mm / sqrt(1000) per plane normal; 1 mm and 1e-3 in R bound it on every kernel. */
  for (k = 0; k < 16; ++k) EXPECT_NEAR(pose[k], truth[k], 1e-3);
  EXPECT_TRUE(info.inlier_ratio > 0.95 && info.unobservable == 0 && info.iterations > 1);
  EXPECT_TRUE(info.information[35] > 0 && info.eigen_ratio > 1e-3);
  memcpy(first, pose, sizeof first);
  /* The handle keeps the target that call prepared (capi/src/
   * registration_cache.hpp): the next call reuses it, with the same bits. */
  EXPECT_OK(sogmm_register_points_f32(m, pts, N, NULL, NULL, again, &info));
  EXPECT_TRUE(memcmp(first, again, sizeof first) == 0);

  /* Options reach the core; progress reports the stage. */
  REQUIRE_OK(sogmm_options_create(&o));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_REGISTRATION_LEVELS, 1));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_REGISTRATION_MAX_ITER, 1));
  REQUIRE_OK(sogmm_options_set_progress(o, record_stage, NULL));
  EXPECT_OK(sogmm_register_points_f32(m, pts, N, NULL, o, pose, &info));
  EXPECT_TRUE(info.status == SOGMM_REGISTRATION_NOT_CONVERGED && info.iterations == 1 && g_stage_seen);
  /* A cancel writes nothing. */
  for (k = 0; k < 16; ++k) pose[k] = -7;
  info.iterations = -7;
  REQUIRE_OK(sogmm_options_set_progress(o, record_stage, &g_stage_seen));
  EXPECT_STATUS(sogmm_register_points_f32(m, pts, N, NULL, o, pose, &info), SOGMM_E_CANCELLED);
  EXPECT_TRUE(pose[0] == -7 && pose[15] == -7 && info.iterations == -7);
  sogmm_options_free(o);
  /* The kept target is now the one-level calls': back at the default levels
   * a new one is prepared, and the answer is the first call's, bit for bit. */
  EXPECT_OK(sogmm_register_points_f32(m, pts, N, NULL, NULL, again, &info));
  EXPECT_TRUE(memcmp(first, again, sizeof first) == 0);

  /* Bad input. */
  EXPECT_STATUS(sogmm_register_points_f32(NULL, pts, N, NULL, NULL, pose, &info), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_register_points_f32(m, NULL, N, NULL, NULL, pose, &info), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_register_points_f32(m, pts, N, NULL, NULL, NULL, &info), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_register_points_f32(m, pts, N, NULL, NULL, pose, NULL), SOGMM_E_NULL_ARG);
  info.struct_size = 8;
  EXPECT_STATUS(sogmm_register_points_f32(m, pts, N, NULL, NULL, pose, &info), SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(message_has("struct_size"));
  info.struct_size = sizeof info;
  memcpy(nan_init, truth, sizeof truth);
  nan_init[7] = NAN;
  EXPECT_STATUS(sogmm_register_points_f32(m, pts, N, nan_init, NULL, pose, &info), SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(message_has("init"));
  memcpy(scaled, truth, sizeof truth);
  scaled[0] *= 2;
  EXPECT_STATUS(sogmm_register_points_f32(m, pts, N, scaled, NULL, pose, &info), SOGMM_E_INVALID_ARG);
  EXPECT_STATUS(sogmm_register_points_f32(m, pts, 50, NULL, NULL, pose, &info), SOGMM_E_INVALID_DATA);
  EXPECT_TRUE(message_has("min_points"));
  pts[4 * 9 + 2] = NAN;
  EXPECT_STATUS(sogmm_register_points_f32(m, pts, N, NULL, NULL, pose, &info), SOGMM_E_INVALID_DATA);
  EXPECT_TRUE(message_has("row 9"));

  /* D2D: the corner model moved by truth^-1 = [R^T, -R^T t] registers back
   * to truth (the optimum of a model against its own moved copy, up to the
   * float rounding of the copy: measured in the core's test at < 1 um). */
  memset(back, 0, sizeof back);
  back[0] = c, back[1] = s, back[4] = -s, back[5] = c, back[10] = 1, back[15] = 1;
  back[3] = -(c * truth[3] + s * truth[7]);
  back[7] = -(-s * truth[3] + c * truth[7]);
  back[11] = -truth[11];
  EXPECT_OK(sogmm_register_model(whole, whole, NULL, NULL, pose, &info)); /* whole keeps a prepared target */
  REQUIRE_OK(sogmm_model_transform(&moved, whole, back));
  EXPECT_OK(sogmm_register_model(whole, moved, NULL, NULL, pose, &info));
  EXPECT_TRUE(info.status == SOGMM_REGISTRATION_CONVERGED);
  for (k = 0; k < 16; ++k) EXPECT_NEAR(pose[k], truth[k], 1e-4);
  /* The moved copy prepares its own target, not the one `whole` kept. */
  EXPECT_OK(sogmm_register_model(moved, whole, NULL, NULL, pose, &info));
  for (k = 0; k < 16; ++k) EXPECT_NEAR(pose[k], back[k], 1e-4);
  EXPECT_TRUE(info.inlier_ratio > 0.95 && info.unobservable == 0);
  EXPECT_STATUS(sogmm_register_model(NULL, moved, NULL, NULL, pose, &info), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_register_model(whole, NULL, NULL, NULL, pose, &info), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_register_model(whole, moved, NULL, NULL, NULL, &info), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_register_model(whole, moved, nan_init, NULL, pose, &info), SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(message_has("init"));
  /* The sampled corner's model stands for one point: fewer than min_points. */
  EXPECT_STATUS(sogmm_register_model(whole, m, NULL, NULL, pose, &info), SOGMM_E_INVALID_DATA);
  EXPECT_TRUE(message_has("min_points"));
  sogmm_model_free(moved);
  sogmm_model_free(whole);
  sogmm_model_free(m);
  return test_summary("test_registration");
}
