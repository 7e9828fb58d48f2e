/* Every row of the bad-input table of spec/api.md ("Bad input"), in the same
 * order and with the same row ids: each call must return the documented
 * status, leave handle out-pointers NULL, set a non-empty last-error message,
 * and never abort. Usage: sogmm_capi_test_bad_input <scratch-dir> */
#include <float.h>

#include "test_util.h"

static int g_rows = 0;

/* One table row: the call must return `expected`; a failing call must leave
 * a non-empty message. */
#define ROW(id, expr, expected)                                                             \
  do {                                                                                      \
    sogmm_status r_ = (expr);                                                               \
    ++g_rows;                                                                               \
    ++g_checks;                                                                             \
    if (r_ != (expected)) {                                                                 \
      ++g_failures;                                                                         \
      fprintf(stderr, "row %s: %s\n  returned %d (%s), expected %d (%s); last error: %s\n", \
              id, #expr, (int)r_, sogmm_status_string(r_), (int)(expected),                 \
              sogmm_status_string(expected), sogmm_last_error());                           \
    } else if (r_ != SOGMM_OK && sogmm_last_error()[0] == '\0') {                           \
      ++g_failures;                                                                         \
      fprintf(stderr, "row %s: failed without a last-error message\n", id);                 \
    }                                                                                       \
  } while (0)

/* A row whose call creates a handle: also checks that *out stays NULL. */
#define ROW_OUT(id, out, expr, expected)            \
  do {                                              \
    out = (void*)&g_sentinel;                       \
    ROW(id, expr, expected);                        \
    if ((expected) != SOGMM_OK && out != NULL) {    \
      ++g_failures;                                 \
      fprintf(stderr, "row %s: out not NULL\n", id); \
    }                                               \
  } while (0)

static int g_sentinel;
static char g_dir[1024] = ".";

int main(int argc, char** argv) {
  const double nan_ = NAN, inf_ = INFINITY;
  const size_t huge = (size_t)-1;
  char path[1200], garbage_path[1200], trunc_path[1200];
  sogmm_options* o = NULL;
  sogmm_options* oc = NULL;
  sogmm_model* m = NULL;      /* valid model from a fit (fit report, no camera) */
  sogmm_model* a = NULL;      /* valid model from arrays (no fit report) */
  sogmm_model* out = NULL;
  sogmm_frame* fr = NULL;
  sogmm_buffer* buf = NULL;
  sogmm_buffer* bout = NULL;
  float* pts;
  float pts_bad[8];
  float w[2] = {0.5f, 0.5f}, mu[8] = {0, 0, 1, 0.5f, 1, 0, 1, 0.5f}, cov[32];
  float wbad[2], mubad[8], covbad[32], f1[64];
  float xyzbad[9] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
  double d1[64], pose_ok[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}, pose_bad[16];
  const char *s1 = NULL, *s2 = NULL;
  size_t n_out = 0;
  int64_t i64 = 0;
  double f64 = 0;
  uint16_t* depth;
  uint16_t depth_zero[16];
  uint8_t *gray, *rgb, gray_small[16];
  const uint32_t W = 40, H = 30;
  int k;

  if (argc > 1) snprintf(g_dir, sizeof g_dir, "%s", argv[1]);
  snprintf(path, sizeof path, "%s/bad_input.sogmm", g_dir);
  snprintf(garbage_path, sizeof garbage_path, "%s/bad_input_garbage.sogmm", g_dir);
  snprintf(trunc_path, sizeof trunc_path, "%s/bad_input_truncated.sogmm", g_dir);

  /* fixtures */
  memset(cov, 0, sizeof cov);
  for (k = 0; k < 8; ++k) cov[5 * (k % 4) + 16 * (k / 4)] = 0.01f;
  pts = make_clusters(30, 1);
  memcpy(pts_bad, pts, sizeof pts_bad);
  REQUIRE_OK(sogmm_options_create(&o));
  REQUIRE_OK(test_fit_fixed_k(&m, pts, 30, 2, NULL));
  REQUIRE_OK(sogmm_model_from_arrays_f32(&a, 2, w, mu, cov, 10));
  make_frame(W, H, &depth, &gray, &rgb);
  memset(depth_zero, 0, sizeof depth_zero);
  memset(gray_small, 100, sizeof gray_small);

  /* ---- options ---- */
  ROW("O1", sogmm_options_create(NULL), SOGMM_E_NULL_ARG);
  ROW_OUT("O2", oc, sogmm_options_clone(&oc, NULL), SOGMM_E_NULL_ARG);
  ROW("O3", sogmm_options_clone(NULL, o), SOGMM_E_NULL_ARG);
  ROW("O4", sogmm_options_set_f64(NULL, SOGMM_OPT_BANDWIDTH, 0.1), SOGMM_E_NULL_ARG);
  ROW("O5", sogmm_options_set_f64(o, 99999, 0.1), SOGMM_E_INVALID_ARG);
  ROW("O6", sogmm_options_set_f64(o, SOGMM_OPT_MAX_ITER, 10.0), SOGMM_E_INVALID_ARG);
  ROW("O7", sogmm_options_set_f64(o, SOGMM_OPT_BANDWIDTH, nan_), SOGMM_E_INVALID_ARG);
  ROW("O8", sogmm_options_set_f64(o, SOGMM_OPT_BANDWIDTH, inf_), SOGMM_E_INVALID_ARG);
  ROW("O9", sogmm_options_set_f64(o, SOGMM_OPT_BANDWIDTH, 0.0), SOGMM_E_INVALID_ARG);
  ROW("O10", sogmm_options_set_f64(o, SOGMM_OPT_BANDWIDTH, -0.01), SOGMM_E_INVALID_ARG);
  ROW("O11", sogmm_options_set_f64(o, SOGMM_OPT_TOL, -1e-9), SOGMM_E_INVALID_ARG);
  ROW("O12", sogmm_options_set_f64(o, SOGMM_OPT_REG_COVAR, -1e-9), SOGMM_E_INVALID_ARG);
  ROW("O13", sogmm_options_set_f64(o, SOGMM_OPT_DEPTH_SCALE, 0.0), SOGMM_E_INVALID_ARG);
  ROW("O14", sogmm_options_set_f64(o, SOGMM_OPT_DEPTH_MIN, -0.1), SOGMM_E_INVALID_ARG);
  ROW("O15", sogmm_options_set_f64(o, SOGMM_OPT_DEPTH_MAX, inf_), SOGMM_E_INVALID_ARG);
  ROW("O16", sogmm_options_set_f64(o, SOGMM_OPT_SAMPLE_TRUNCATION, 0.0), SOGMM_E_INVALID_ARG);
  ROW("O17", sogmm_options_set_f64(o, SOGMM_OPT_SAMPLE_TRUNCATION, nan_), SOGMM_E_INVALID_ARG);
  ROW("O18", sogmm_options_set_i64(NULL, SOGMM_OPT_SEED, 1), SOGMM_E_NULL_ARG);
  ROW("O19", sogmm_options_set_i64(o, -5, 1), SOGMM_E_INVALID_ARG);
  ROW("O20", sogmm_options_set_i64(o, SOGMM_OPT_BANDWIDTH, 1), SOGMM_E_INVALID_ARG);
  ROW("O21", sogmm_options_set_i64(o, SOGMM_OPT_N_COMPONENTS, -1), SOGMM_E_INVALID_ARG);
  ROW("O22", sogmm_options_set_i64(o, SOGMM_OPT_MAX_ITER, 0), SOGMM_E_INVALID_ARG);
  ROW("O23", sogmm_options_set_i64(o, SOGMM_OPT_MAX_ITER, (int64_t)1 << 31), SOGMM_E_INVALID_ARG);
  ROW("O24", sogmm_options_set_i64(o, SOGMM_OPT_THREADS, -1), SOGMM_E_INVALID_ARG);
  ROW("O25", sogmm_options_set_i64(o, SOGMM_OPT_THREADS, 4097), SOGMM_E_INVALID_ARG);
  ROW("O26", sogmm_options_set_i64(o, SOGMM_OPT_MODE_COUNTER, 2), SOGMM_E_INVALID_ARG);
  ROW("O27", sogmm_options_set_i64(o, SOGMM_OPT_DECIMATION, 0), SOGMM_E_INVALID_ARG);
  ROW("O28", sogmm_options_set_i64(o, SOGMM_OPT_DECIMATION, 1025), SOGMM_E_INVALID_ARG);
  ROW("O29", sogmm_options_set_i64(o, SOGMM_OPT_ZSTD_LEVEL, 0), SOGMM_E_INVALID_ARG);
  ROW("O30", sogmm_options_set_i64(o, SOGMM_OPT_ZSTD_LEVEL, 23), SOGMM_E_INVALID_ARG);
  ROW("O31", sogmm_options_set_i64(o, SOGMM_OPT_FLOAT64, 2), SOGMM_E_INVALID_ARG);
  ROW("O32", sogmm_options_set_i64(o, SOGMM_OPT_COMPRESS, -1), SOGMM_E_INVALID_ARG);
  ROW("O33", sogmm_options_set_i64(o, SOGMM_OPT_VERIFY_CHECKSUMS, 2), SOGMM_E_INVALID_ARG);
  ROW("O34", sogmm_options_set_i64(o, SOGMM_OPT_MAX_DECODED_BYTES, -1), SOGMM_E_INVALID_ARG);
  ROW("O35", sogmm_options_get_f64(NULL, SOGMM_OPT_BANDWIDTH, &f64), SOGMM_E_NULL_ARG);
  ROW("O36", sogmm_options_get_f64(o, SOGMM_OPT_BANDWIDTH, NULL), SOGMM_E_NULL_ARG);
  ROW("O37", sogmm_options_get_f64(o, SOGMM_OPT_SEED, &f64), SOGMM_E_INVALID_ARG);
  ROW("O38", sogmm_options_get_i64(NULL, SOGMM_OPT_SEED, &i64), SOGMM_E_NULL_ARG);
  ROW("O39", sogmm_options_get_i64(o, SOGMM_OPT_SEED, NULL), SOGMM_E_NULL_ARG);
  ROW("O40", sogmm_options_get_i64(o, 0, &i64), SOGMM_E_INVALID_ARG);
  ROW("O41", sogmm_options_set_i64(o, SOGMM_OPT_N_INIT, 0), SOGMM_E_INVALID_ARG);
  ROW("O42", sogmm_options_set_i64(o, SOGMM_OPT_N_INIT, 1001), SOGMM_E_INVALID_ARG);
  ROW("O43", sogmm_options_set_f64(o, SOGMM_INFO_FIT_LOG_LIKELIHOOD, 0.5), SOGMM_E_INVALID_ARG);
  ROW("O44", sogmm_options_set_i64(o, SOGMM_INFO_FIT_ITERATIONS, 5), SOGMM_E_INVALID_ARG);
  ROW("O45", sogmm_options_get_f64(o, SOGMM_INFO_FIT_TOL, &f64), SOGMM_E_INVALID_ARG);
  ROW("O46", sogmm_options_set_f64(o, SOGMM_OPT_BANDWIDTH, 4e-314), SOGMM_E_INVALID_ARG);
  ROW("O47", sogmm_options_set_f64(o, SOGMM_OPT_BANDWIDTH, 1e154), SOGMM_E_INVALID_ARG);
  ROW("O48", sogmm_options_set_f64(o, SOGMM_OPT_REG_COVAR, 1e39), SOGMM_E_INVALID_ARG);
  ROW("O49", sogmm_options_set_f64(o, SOGMM_OPT_DEPTH_SCALE, 1e-310), SOGMM_E_INVALID_ARG);
  /* a rejected value leaves the option unchanged */
  REQUIRE_OK(sogmm_options_get_f64(o, SOGMM_OPT_BANDWIDTH, &f64));
  EXPECT_TRUE(f64 == 0.02);

  /* ---- fit from points ---- */
  ROW("F1", sogmm_fit_points_f32(NULL, pts, 30, NULL, NULL), SOGMM_E_NULL_ARG);
  ROW_OUT("F2", out, sogmm_fit_points_f32(&out, NULL, 30, NULL, NULL), SOGMM_E_NULL_ARG);
  ROW_OUT("F3", out, sogmm_fit_points_f32(&out, pts, 0, NULL, NULL), SOGMM_E_INVALID_DATA);
  pts_bad[5] = (float)nan_;
  ROW_OUT("F4", out, sogmm_fit_points_f32(&out, pts_bad, 2, NULL, NULL), SOGMM_E_INVALID_DATA);
  pts_bad[5] = (float)inf_;
  ROW_OUT("F5", out, sogmm_fit_points_f32(&out, pts_bad, 2, NULL, NULL), SOGMM_E_INVALID_DATA);
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_N_COMPONENTS, 31));
  ROW_OUT("F6", out, sogmm_fit_points_f32(&out, pts, 30, NULL, o), SOGMM_E_INVALID_ARG);
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_N_COMPONENTS, 0));
  ROW_OUT("F7", out, sogmm_fit_points_f32(&out, pts, huge, NULL, NULL), SOGMM_E_LIMIT);
  /* F8-F13: a warm start from `m` (2 components). */
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_N_COMPONENTS, 3));
  ROW_OUT("F8", out, sogmm_fit_points_f32(&out, pts, 30, m, o), SOGMM_E_INVALID_ARG); /* K != the initial size */
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_N_COMPONENTS, 0));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_N_INIT, 2));
  ROW_OUT("F9", out, sogmm_fit_points_f32(&out, pts, 30, m, o), SOGMM_E_INVALID_ARG);
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_N_INIT, 1));
  ROW("F10", sogmm_fit_points_f32(NULL, pts, 30, m, NULL), SOGMM_E_NULL_ARG);
  ROW_OUT("F11", out, sogmm_fit_points_f32(&out, NULL, 30, m, NULL), SOGMM_E_NULL_ARG);
  ROW_OUT("F12", out, sogmm_fit_points_f32(&out, pts, 0, m, NULL), SOGMM_E_INVALID_DATA);
  pts_bad[5] = (float)nan_;
  ROW_OUT("F13", out, sogmm_fit_points_f32(&out, pts_bad, 2, m, NULL), SOGMM_E_INVALID_DATA);

  /* ---- fit from an RGB-D frame ---- */
#define FRAME(dep, col, fmt, w_, h_, fx_, fy_, cx_, cy_, opt) \
  test_fit_rgbd(&out, dep, col, fmt, w_, h_, fx_, fy_, cx_, cy_, opt)
  ROW("R1", test_fit_rgbd(NULL, depth, gray, SOGMM_COLOR_GRAY8, W, H, 35, 35, 20, 15, NULL), SOGMM_E_NULL_ARG);
  /* R2-R8: the frame's arrays, refused by sogmm_frame_from_arrays. */
#define FRAME_NEW(dep, col, fmt, w_, h_) sogmm_frame_from_arrays(&fr, w_, h_, dep, col, fmt)
  ROW_OUT("R2", fr, FRAME_NEW(NULL, gray, SOGMM_COLOR_GRAY8, W, H), SOGMM_E_NULL_ARG);
  ROW_OUT("R3", fr, FRAME_NEW(depth, NULL, SOGMM_COLOR_GRAY8, W, H), SOGMM_E_NULL_ARG);
  ROW_OUT("R4", fr, FRAME_NEW(depth, gray, SOGMM_COLOR_GRAY8, 0, H), SOGMM_E_INVALID_ARG);
  ROW_OUT("R5", fr, FRAME_NEW(depth, gray, SOGMM_COLOR_GRAY8, W, 0), SOGMM_E_INVALID_ARG);
  ROW_OUT("R6", fr, FRAME_NEW(depth, gray, SOGMM_COLOR_GRAY8, 0x80000000u, 1), SOGMM_E_INVALID_ARG);
  ROW_OUT("R7", fr, FRAME_NEW(depth, gray, 0, W, H), SOGMM_E_INVALID_ARG);
  ROW_OUT("R8", fr, FRAME_NEW(depth, gray, 4, W, H), SOGMM_E_INVALID_ARG);
  ROW_OUT("R9", out, FRAME(depth, gray, SOGMM_COLOR_GRAY8, W, H, 0, 35, 20, 15, NULL), SOGMM_E_INVALID_ARG);
  ROW_OUT("R10", out, FRAME(depth, gray, SOGMM_COLOR_GRAY8, W, H, 35, -35, 20, 15, NULL), SOGMM_E_INVALID_ARG);
  ROW_OUT("R11", out, FRAME(depth, gray, SOGMM_COLOR_GRAY8, W, H, nan_, 35, 20, 15, NULL), SOGMM_E_INVALID_ARG);
  ROW_OUT("R12", out, FRAME(depth, gray, SOGMM_COLOR_GRAY8, W, H, 35, 35, inf_, 15, NULL), SOGMM_E_INVALID_ARG);
  ROW_OUT("R13", out, FRAME(depth, gray, SOGMM_COLOR_GRAY8, W, H, 35, 35, 20, nan_, NULL), SOGMM_E_INVALID_ARG);
  REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_DEPTH_MIN, 2.0));
  REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_DEPTH_MAX, 1.0));
  ROW_OUT("R14", out, FRAME(depth, gray, SOGMM_COLOR_GRAY8, W, H, 35, 35, 20, 15, o), SOGMM_E_INVALID_ARG);
  REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_DEPTH_MIN, 0.1));
  REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_DEPTH_MAX, 3.0));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_DECIMATION, 41));
  ROW_OUT("R15", out, FRAME(depth, gray, SOGMM_COLOR_GRAY8, W, H, 35, 35, 20, 15, o), SOGMM_E_INVALID_ARG);
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_DECIMATION, 1));
  ROW_OUT("R16", out, FRAME(depth_zero, gray_small, SOGMM_COLOR_GRAY8, 4, 4, 3, 3, 2, 2, NULL),
          SOGMM_E_INVALID_DATA);
  REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_DEPTH_MAX, 0.5)); /* plane is at 1.0-1.6 m */
  ROW_OUT("R17", out, FRAME(depth, gray, SOGMM_COLOR_GRAY8, W, H, 35, 35, 20, 15, o), SOGMM_E_INVALID_DATA);
  REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_DEPTH_MAX, 3.0));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_N_COMPONENTS, (int64_t)W * H + 1));
  ROW_OUT("R18", out, FRAME(depth, rgb, SOGMM_COLOR_RGB8, W, H, 35, 35, 20, 15, o), SOGMM_E_INVALID_ARG);
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_N_COMPONENTS, 0));
  {
    float grayf[16], xyzg[4 * 16];
    size_t n_pts = 99;
    int k;
    for (k = 0; k < 16; ++k) grayf[k] = 0.5f;
    grayf[9] = (float)nan_;
    ROW_OUT("R19", out, FRAME(depth, (const uint8_t*)grayf, SOGMM_COLOR_GRAY_F32, 4, 4, 3, 3, 2, 2, NULL),
            SOGMM_E_INVALID_DATA);
    /* back-projection only */
    ROW("R20", test_rgbd_to_points(xyzg, 64, NULL, depth, gray, SOGMM_COLOR_GRAY8, 4, 4, 3, 3, 2, 2, NULL),
        SOGMM_E_NULL_ARG);
    ROW("R21", test_rgbd_to_points(NULL, 4, &n_pts, depth, gray, SOGMM_COLOR_GRAY8, 4, 4, 3, 3, 2, 2, NULL),
        SOGMM_E_NULL_ARG);
    ROW("R22", test_rgbd_to_points(xyzg, 59, &n_pts, depth, gray, SOGMM_COLOR_GRAY8, 4, 4, 3, 3, 2, 2, NULL),
        SOGMM_E_BUFFER_TOO_SMALL);
    EXPECT_TRUE(n_pts == 15); /* the size is reported with the error (pixel 0 has no depth) */
    ROW("R23", test_rgbd_to_points(xyzg, 64, &n_pts, depth, (const uint8_t*)grayf, SOGMM_COLOR_GRAY_F32, 4, 4, 3,
                                        3, 2, 2, NULL),
        SOGMM_E_INVALID_DATA);
    n_pts = 99;
    ROW("R24", test_rgbd_to_points(xyzg, 64, &n_pts, depth, gray, SOGMM_COLOR_GRAY8, 4, 0, 3, 3, 2, 2, NULL),
        SOGMM_E_INVALID_ARG);
    EXPECT_TRUE(n_pts == 99); /* an error other than BUFFER_TOO_SMALL writes no out-parameter */
    /* no valid pixel is not an error here: N = 0 */
    ROW("R25", test_rgbd_to_points(NULL, 0, &n_pts, depth_zero, gray_small, SOGMM_COLOR_GRAY8, 4, 4, 3, 3, 2,
                                        2, NULL),
        SOGMM_OK);
    EXPECT_TRUE(n_pts == 0);
    ROW_OUT("R26", out, FRAME(depth, gray, SOGMM_COLOR_GRAY8, W, H, 1e-300, 35, 20, 15, NULL), SOGMM_E_INVALID_ARG);
    n_pts = 99;
    ROW("R27", test_rgbd_to_points(xyzg, 64, &n_pts, depth, gray, SOGMM_COLOR_GRAY8, 4, 4, 3, 1e-300, 2, 2, NULL),
        SOGMM_E_INVALID_ARG);
    EXPECT_TRUE(n_pts == 99);
  }
  {
    /* 8200 x 8200 zero pixels (calloc: untouched pages), over 2^26 points: refused from the size */
    const uint32_t big = 8200;
    uint16_t* big_depth = (uint16_t*)calloc((size_t)big * big, sizeof(uint16_t));
    uint8_t* big_gray = (uint8_t*)calloc((size_t)big * big, 1);
    size_t n_pts = 99;
    REQUIRE_OK(big_depth && big_gray ? SOGMM_OK : SOGMM_E_NOMEM);
    ROW_OUT("R28", fr, FRAME_NEW(big_depth, big_gray, SOGMM_COLOR_GRAY8, big, big), SOGMM_E_LIMIT);
    ROW("R29", test_rgbd_to_points(NULL, 0, &n_pts, big_depth, big_gray, SOGMM_COLOR_GRAY8, big, big, 7000, 7000,
                                        4100, 4100, NULL),
        SOGMM_E_LIMIT);
    EXPECT_TRUE(n_pts == 99);
    free(big_depth);
    free(big_gray);
  }

  /* ---- models from arrays, clone ---- */
  ROW("A1", sogmm_model_from_arrays_f32(NULL, 2, w, mu, cov, 0), SOGMM_E_NULL_ARG);
  ROW_OUT("A2", out, sogmm_model_from_arrays_f32(&out, 2, NULL, mu, cov, 0), SOGMM_E_NULL_ARG);
  ROW_OUT("A3", out, sogmm_model_from_arrays_f32(&out, 2, w, NULL, cov, 0), SOGMM_E_NULL_ARG);
  ROW_OUT("A4", out, sogmm_model_from_arrays_f32(&out, 2, w, mu, NULL, 0), SOGMM_E_NULL_ARG);
  ROW_OUT("A5", out, sogmm_model_from_arrays_f32(&out, 0, w, mu, cov, 0), SOGMM_E_INVALID_DATA);
  memcpy(wbad, w, sizeof w);
  wbad[1] = (float)nan_;
  ROW_OUT("A6", out, sogmm_model_from_arrays_f32(&out, 2, wbad, mu, cov, 0), SOGMM_E_INVALID_DATA);
  memcpy(mubad, mu, sizeof mu);
  mubad[6] = (float)inf_;
  ROW_OUT("A7", out, sogmm_model_from_arrays_f32(&out, 2, w, mubad, cov, 0), SOGMM_E_INVALID_DATA);
  memcpy(covbad, cov, sizeof cov);
  covbad[20] = (float)nan_;
  ROW_OUT("A8", out, sogmm_model_from_arrays_f32(&out, 2, w, mu, covbad, 0), SOGMM_E_INVALID_DATA);
  wbad[0] = 0.5f;
  wbad[1] = 0.6f;
  ROW_OUT("A9", out, sogmm_model_from_arrays_f32(&out, 2, wbad, mu, cov, 0), SOGMM_E_INVALID_DATA);
  wbad[0] = -0.5f;
  wbad[1] = 1.5f;
  ROW_OUT("A10", out, sogmm_model_from_arrays_f32(&out, 2, wbad, mu, cov, 0), SOGMM_E_INVALID_DATA);
  memcpy(covbad, cov, sizeof cov);
  covbad[1] = 0.001f; /* (0, 1) != (1, 0) */
  ROW_OUT("A11", out, sogmm_model_from_arrays_f32(&out, 2, w, mu, covbad, 0), SOGMM_E_INVALID_DATA);
  memcpy(covbad, cov, sizeof cov);
  covbad[16 + 5] = -0.01f; /* negative variance: not positive definite */
  ROW_OUT("A12", out, sogmm_model_from_arrays_f32(&out, 2, w, mu, covbad, 0), SOGMM_E_NUMERIC);
  ROW_OUT("A13", out, sogmm_model_from_arrays_f32(&out, huge, w, mu, cov, 0), SOGMM_E_LIMIT);
  ROW("A14", sogmm_model_clone(NULL, m), SOGMM_E_NULL_ARG);
  ROW_OUT("A15", out, sogmm_model_clone(&out, NULL), SOGMM_E_NULL_ARG);

  /* ---- arrays ---- */
  ROW("Q1", sogmm_model_n_components(NULL, &n_out), SOGMM_E_NULL_ARG);
  ROW("Q2", sogmm_model_n_components(m, NULL), SOGMM_E_NULL_ARG);
  ROW("Q3", sogmm_model_get_weights_f32(NULL, f1, 64), SOGMM_E_NULL_ARG);
  ROW("Q4", sogmm_model_get_weights_f32(m, NULL, 64), SOGMM_E_NULL_ARG);
  ROW("Q5", sogmm_model_get_weights_f32(m, f1, 0), SOGMM_E_BUFFER_TOO_SMALL);
  ROW("Q6", sogmm_model_get_weights_f32(m, f1, 1), SOGMM_E_BUFFER_TOO_SMALL);
  ROW("Q7", sogmm_model_get_means_f32(NULL, f1, 64), SOGMM_E_NULL_ARG);
  ROW("Q8", sogmm_model_get_means_f32(m, NULL, 64), SOGMM_E_NULL_ARG);
  ROW("Q9", sogmm_model_get_means_f32(m, f1, 7), SOGMM_E_BUFFER_TOO_SMALL);
  ROW("Q10", sogmm_model_get_covariances_f32(NULL, f1, 64), SOGMM_E_NULL_ARG);
  ROW("Q11", sogmm_model_get_covariances_f32(m, NULL, 64), SOGMM_E_NULL_ARG);
  ROW("Q12", sogmm_model_get_covariances_f32(m, f1, 31), SOGMM_E_BUFFER_TOO_SMALL);

  /* ---- info, pose, key/values ---- */
  ROW("M1", sogmm_model_get_info_f64(NULL, SOGMM_INFO_FIT_TOL, &f64), SOGMM_E_NULL_ARG);
  ROW("M2", sogmm_model_get_info_f64(m, SOGMM_INFO_FIT_TOL, NULL), SOGMM_E_NULL_ARG);
  ROW("M3", sogmm_model_get_info_f64(m, 12345, &f64), SOGMM_E_INVALID_ARG);
  ROW("M4", sogmm_model_get_info_f64(m, SOGMM_INFO_SUPPORT_SIZE, &f64), SOGMM_E_INVALID_ARG);
  ROW("M5", sogmm_model_get_info_f64(a, SOGMM_INFO_FIT_LOG_LIKELIHOOD, &f64), SOGMM_E_NOT_FOUND);
  ROW("M6", sogmm_model_get_info_f64(m, SOGMM_INFO_CAMERA_FX, &f64), SOGMM_E_NOT_FOUND);
  ROW("M7", sogmm_model_get_info_f64(a, SOGMM_INFO_FIT_SECONDS_EM, &f64), SOGMM_E_NOT_FOUND);
  ROW("M8", sogmm_model_get_info_i64(NULL, SOGMM_INFO_SUPPORT_SIZE, &i64), SOGMM_E_NULL_ARG);
  ROW("M9", sogmm_model_get_info_i64(m, SOGMM_INFO_SUPPORT_SIZE, NULL), SOGMM_E_NULL_ARG);
  ROW("M10", sogmm_model_get_info_i64(m, -1, &i64), SOGMM_E_INVALID_ARG);
  ROW("M11", sogmm_model_get_info_i64(m, SOGMM_INFO_FIT_TOL, &i64), SOGMM_E_INVALID_ARG);
  ROW("M12", sogmm_model_get_info_i64(a, SOGMM_INFO_FIT_ITERATIONS, &i64), SOGMM_E_NOT_FOUND);
  ROW("M13", sogmm_model_get_info_i64(m, SOGMM_INFO_CAMERA_WIDTH, &i64), SOGMM_E_NOT_FOUND);
  ROW("M14", sogmm_model_get_pose(NULL, d1), SOGMM_E_NULL_ARG);
  ROW("M15", sogmm_model_get_pose(m, NULL), SOGMM_E_NULL_ARG);
  ROW("M16", sogmm_model_get_pose(m, d1), SOGMM_E_NOT_FOUND);
  ROW("M17", sogmm_model_set_pose(NULL, pose_ok), SOGMM_E_NULL_ARG);
  ROW("M18", sogmm_model_set_pose(m, NULL), SOGMM_E_NULL_ARG);
  memcpy(pose_bad, pose_ok, sizeof pose_ok);
  pose_bad[3] = nan_;
  ROW("M19", sogmm_model_set_pose(m, pose_bad), SOGMM_E_INVALID_ARG);
  pose_bad[3] = inf_;
  ROW("M20", sogmm_model_set_pose(m, pose_bad), SOGMM_E_INVALID_ARG);
  memcpy(pose_bad, pose_ok, sizeof pose_ok);
  pose_bad[0] = 2.0; /* scale, not a rotation */
  ROW("M21", sogmm_model_set_pose(m, pose_bad), SOGMM_E_INVALID_ARG);
  pose_bad[0] = -1.0; /* reflection */
  ROW("M22", sogmm_model_set_pose(m, pose_bad), SOGMM_E_INVALID_ARG);
  memcpy(pose_bad, pose_ok, sizeof pose_ok);
  pose_bad[12] = 0.5; /* last row not (0, 0, 0, 1) */
  ROW("M23", sogmm_model_set_pose(m, pose_bad), SOGMM_E_INVALID_ARG);
  ROW("M24", sogmm_model_get_pose(m, d1), SOGMM_E_NOT_FOUND); /* rejected poses were not stored */
  ROW("M25", sogmm_model_clear_pose(NULL), SOGMM_E_NULL_ARG);
  ROW("M26", sogmm_model_get_value(NULL, "k", &s1), SOGMM_E_NULL_ARG);
  ROW("M27", sogmm_model_get_value(m, NULL, &s1), SOGMM_E_NULL_ARG);
  ROW("M28", sogmm_model_get_value(m, "k", NULL), SOGMM_E_NULL_ARG);
  ROW("M29", sogmm_model_get_value(m, "absent", &s1), SOGMM_E_NOT_FOUND);
  ROW("M30", sogmm_model_set_value(NULL, "k", "v"), SOGMM_E_NULL_ARG);
  ROW("M31", sogmm_model_set_value(m, NULL, "v"), SOGMM_E_NULL_ARG);
  ROW("M32", sogmm_model_set_value(m, "k", NULL), SOGMM_E_NULL_ARG);
  ROW("M33", sogmm_model_set_value(m, "", "v"), SOGMM_E_INVALID_ARG);
  ROW("M34", sogmm_model_value_count(NULL, &n_out), SOGMM_E_NULL_ARG);
  ROW("M35", sogmm_model_value_count(m, NULL), SOGMM_E_NULL_ARG);
  ROW("M36", sogmm_model_value_at(NULL, 0, &s1, &s2), SOGMM_E_NULL_ARG);
  ROW("M37", sogmm_model_value_at(m, 0, NULL, &s2), SOGMM_E_NULL_ARG);
  ROW("M38", sogmm_model_value_at(m, 0, &s1, NULL), SOGMM_E_NULL_ARG);
  ROW("M39", sogmm_model_value_at(m, 2, &s1, &s2), SOGMM_E_INVALID_ARG); /* the fit recorded 2 pairs (reg_covar_*) */
  ROW("M40", sogmm_model_get_info_f64(m, SOGMM_OPT_BANDWIDTH, &f64), SOGMM_E_INVALID_ARG);
  memcpy(pose_bad, pose_ok, sizeof pose_ok);
  pose_bad[15] = 1.0 + 1e-6; /* the last row is exactly (0, 0, 0, 1) */
  ROW("M41", sogmm_model_set_pose(m, pose_bad), SOGMM_E_INVALID_ARG);
  ROW("M42", sogmm_model_set_value(m, "k\xff", "v"), SOGMM_E_INVALID_ARG);
  ROW("M43", sogmm_model_set_value(m, "k", "\xed\xa0\x80"), SOGMM_E_INVALID_ARG); /* a UTF-16 surrogate */

  /* ---- inference ---- */
  ROW("I1", sogmm_model_sample_f32(NULL, 4, 0, 4, NULL, f1), SOGMM_E_NULL_ARG);
  ROW("I2", sogmm_model_sample_f32(m, 4, 0, 4, NULL, NULL), SOGMM_E_NULL_ARG);
  ROW("I3", sogmm_model_sample_f32(m, 0, 0, 4, NULL, NULL), SOGMM_OK);
  ROW("I4", sogmm_model_sample_f32(m, 4, 0, 2, NULL, f1), SOGMM_E_INVALID_ARG);
  ROW("I5", sogmm_model_sample_f32(m, 4, 0, 5, NULL, f1), SOGMM_E_INVALID_ARG);
  ROW("I6", sogmm_model_sample_f32(m, huge, 0, 4, NULL, f1), SOGMM_E_LIMIT);
  ROW("I7", sogmm_model_regress_gray_f32(NULL, mu, 2, NULL, f1, NULL), SOGMM_E_NULL_ARG);
  ROW("I8", sogmm_model_regress_gray_f32(m, NULL, 2, NULL, f1, NULL), SOGMM_E_NULL_ARG);
  ROW("I9", sogmm_model_regress_gray_f32(m, mu, 2, NULL, NULL, f1), SOGMM_E_NULL_ARG);
  ROW("I10", sogmm_model_regress_gray_f32(m, NULL, 0, NULL, NULL, NULL), SOGMM_OK);
  xyzbad[7] = (float)nan_;
  ROW("I11", sogmm_model_regress_gray_f32(m, xyzbad, 3, NULL, f1, f1 + 8), SOGMM_E_INVALID_DATA);
  xyzbad[7] = (float)-inf_;
  ROW("I12", sogmm_model_regress_gray_f32(m, xyzbad, 3, NULL, f1, NULL), SOGMM_E_INVALID_DATA);
  ROW("I13", sogmm_model_regress_gray_f32(m, mu, huge, NULL, f1, NULL), SOGMM_E_LIMIT);
  ROW("I14", sogmm_model_score_samples_f32(NULL, mu, 2, 4, NULL, d1), SOGMM_E_NULL_ARG);
  ROW("I15", sogmm_model_score_samples_f32(m, NULL, 2, 4, NULL, d1), SOGMM_E_NULL_ARG);
  ROW("I16", sogmm_model_score_samples_f32(m, mu, 2, 4, NULL, NULL), SOGMM_E_NULL_ARG);
  ROW("I17", sogmm_model_score_samples_f32(m, NULL, 0, 4, NULL, NULL), SOGMM_OK);
  ROW("I18", sogmm_model_score_samples_f32(m, mu, 2, 0, NULL, d1), SOGMM_E_INVALID_ARG);
  mubad[6] = (float)-inf_;
  ROW("I19", sogmm_model_score_samples_f32(m, mubad, 2, 4, NULL, d1), SOGMM_E_INVALID_DATA);
  mubad[6] = 0.0f;
  mubad[4] = (float)nan_;
  ROW("I20", sogmm_model_score_samples_f32(m, mubad, 2, 3, NULL, d1), SOGMM_E_INVALID_DATA);
  ROW("I21", sogmm_model_score_samples_f32(m, mu, huge, 4, NULL, d1), SOGMM_E_LIMIT);
  ROW("I22", sogmm_model_merge(NULL, m, a), SOGMM_E_NULL_ARG);
  ROW_OUT("I23", out, sogmm_model_merge(&out, NULL, a), SOGMM_E_NULL_ARG);
  ROW_OUT("I24", out, sogmm_model_merge(&out, m, NULL), SOGMM_E_NULL_ARG);
  ROW("I25", sogmm_model_transform(NULL, m, pose_ok), SOGMM_E_NULL_ARG);
  ROW_OUT("I26", out, sogmm_model_transform(&out, NULL, pose_ok), SOGMM_E_NULL_ARG);
  ROW_OUT("I27", out, sogmm_model_transform(&out, m, NULL), SOGMM_E_NULL_ARG);
  memcpy(pose_bad, pose_ok, sizeof pose_ok);
  pose_bad[7] = nan_;
  ROW_OUT("I28", out, sogmm_model_transform(&out, m, pose_bad), SOGMM_E_INVALID_ARG);
  memcpy(pose_bad, pose_ok, sizeof pose_ok);
  pose_bad[5] = 0.5;
  ROW_OUT("I29", out, sogmm_model_transform(&out, m, pose_bad), SOGMM_E_INVALID_ARG);
  {
    sogmm_model *zero = NULL, *huge_support = NULL;
    REQUIRE_OK(sogmm_model_from_arrays_f32(&zero, 2, w, mu, cov, 0));
    REQUIRE_OK(sogmm_model_from_arrays_f32(&huge_support, 2, w, mu, cov, ((uint64_t)1 << 63) + 1));
    ROW_OUT("I30", out, sogmm_model_merge(&out, a, zero), SOGMM_E_INVALID_ARG); /* support 10 against 0 */
    ROW_OUT("I31", out, sogmm_model_merge(&out, huge_support, huge_support), SOGMM_E_LIMIT);
    sogmm_model_free(zero);
    sogmm_model_free(huge_support);
  }
  memcpy(pose_bad, pose_ok, sizeof pose_ok);
  pose_bad[3] = 1e39; /* moves the means beyond float32 */
  ROW_OUT("I32", out, sogmm_model_transform(&out, m, pose_bad), SOGMM_E_INVALID_ARG);

  /* ---- files and memory ---- */
#ifdef SOGMM_CAPI_HAVE_FORMAT
  {
    static const char garbage[] = "this is not a sogmm file, just some text bytes.....";
    size_t full;
    uint8_t* flipped;
    REQUIRE_OK(sogmm_model_save_to_memory(&buf, m, NULL));
    full = sogmm_buffer_size(buf);
    REQUIRE_OK(write_file(garbage_path, garbage, sizeof garbage) == 0 ? SOGMM_OK : SOGMM_E_IO);
    REQUIRE_OK(write_file(trunc_path, sogmm_buffer_data(buf), full / 2) == 0 ? SOGMM_OK : SOGMM_E_IO);
    ROW("S1", sogmm_model_save(NULL, path, NULL), SOGMM_E_NULL_ARG);
    ROW("S2", sogmm_model_save(m, NULL, NULL), SOGMM_E_NULL_ARG);
    ROW("S3", sogmm_model_save(m, "", NULL), SOGMM_E_IO);
    ROW("S4", sogmm_model_save(m, "/nonexistent-sogmm-dir/x/model.sogmm", NULL), SOGMM_E_IO);
    ROW("S5", sogmm_model_save(m, g_dir, NULL), SOGMM_E_IO); /* a directory */
    ROW("S6", sogmm_model_load(NULL, path, NULL), SOGMM_E_NULL_ARG);
    ROW_OUT("S7", out, sogmm_model_load(&out, NULL, NULL), SOGMM_E_NULL_ARG);
    ROW_OUT("S8", out, sogmm_model_load(&out, "", NULL), SOGMM_E_IO);
    ROW_OUT("S9", out, sogmm_model_load(&out, "/nonexistent-sogmm-dir/model.sogmm", NULL), SOGMM_E_IO);
    ROW_OUT("S10", out, sogmm_model_load(&out, g_dir, NULL), SOGMM_E_IO);
    ROW_OUT("S11", out, sogmm_model_load(&out, garbage_path, NULL), SOGMM_E_FORMAT);
    ROW_OUT("S12", out, sogmm_model_load(&out, trunc_path, NULL), SOGMM_E_FORMAT);
    REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_MAX_DECODED_BYTES, 16));
    REQUIRE_OK(sogmm_model_save(m, path, NULL));
    ROW_OUT("S13", out, sogmm_model_load(&out, path, o), SOGMM_E_LIMIT);
    ROW("S14", sogmm_model_save_to_memory(NULL, m, NULL), SOGMM_E_NULL_ARG);
    ROW_OUT("S15", bout, sogmm_model_save_to_memory(&bout, NULL, NULL), SOGMM_E_NULL_ARG);
    ROW("S16", sogmm_model_load_from_memory(NULL, sogmm_buffer_data(buf), full, NULL), SOGMM_E_NULL_ARG);
    ROW_OUT("S17", out, sogmm_model_load_from_memory(&out, NULL, full, NULL), SOGMM_E_NULL_ARG);
    ROW_OUT("S18", out, sogmm_model_load_from_memory(&out, sogmm_buffer_data(buf), 0, NULL), SOGMM_E_FORMAT);
    ROW_OUT("S19", out, sogmm_model_load_from_memory(&out, garbage, sizeof garbage, NULL), SOGMM_E_FORMAT);
    ROW_OUT("S20", out, sogmm_model_load_from_memory(&out, sogmm_buffer_data(buf), full / 2, NULL),
            SOGMM_E_FORMAT);
    ROW_OUT("S21", out, sogmm_model_load_from_memory(&out, sogmm_buffer_data(buf), full, o), SOGMM_E_LIMIT);
    /* one flipped bit in the middle of the file: checksums catch it */
    flipped = (uint8_t*)malloc(full);
    memcpy(flipped, sogmm_buffer_data(buf), full);
    flipped[full / 2] ^= 0x10;
    ROW_OUT("S22", out, sogmm_model_load_from_memory(&out, flipped, full, NULL), SOGMM_E_FORMAT);
    free(flipped);
    sogmm_buffer_free(buf);
    remove(path);
    remove(garbage_path);
    remove(trunc_path);
  }
#else
  (void)buf, (void)bout, (void)garbage_path, (void)trunc_path;
  printf("test_bad_input: built without the format library; rows S1-S22 not exercised\n");
#endif

  /* ---- never-failing functions accept NULL ---- */
  sogmm_options_free(NULL);
  sogmm_model_free(NULL);
  sogmm_buffer_free(NULL);
  EXPECT_TRUE(sogmm_buffer_data(NULL) == NULL);
  EXPECT_TRUE(sogmm_buffer_size(NULL) == 0);
  EXPECT_TRUE(strcmp(sogmm_status_string(-999), "unknown status") == 0);

  /* fixtures still intact after all the rejected calls */
  REQUIRE_OK(sogmm_model_n_components(m, &n_out));
  EXPECT_TRUE(n_out == 2);

  sogmm_model_free(m);
  sogmm_model_free(a);
  sogmm_options_free(o);
  free(pts);
  free(depth);
  free(gray);
  free(rgb);
  printf("test_bad_input: %d table rows\n", g_rows);
  return test_summary("capi_bad_input");
}
