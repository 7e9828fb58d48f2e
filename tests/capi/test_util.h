/* Helpers shared by the plain-C tests of the C API: a tiny check framework
 * and synthetic data (a seeded 4-D cluster cloud and an RGB-D frame). */
#ifndef SOGMM_TEST_UTIL_H
#define SOGMM_TEST_UTIL_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sogmm/sogmm.h"

static int g_failures = 0;
static int g_checks = 0;

/* Checks that `expr` (a sogmm_status) equals `expected`; prints the
 * last-error message on a mismatch. */
#define EXPECT_STATUS(expr, expected)                                                         \
  do {                                                                                        \
    sogmm_status s_ = (expr);                                                                 \
    ++g_checks;                                                                               \
    if (s_ != (expected)) {                                                                   \
      ++g_failures;                                                                           \
      fprintf(stderr, "%s:%d: %s\n  returned %d (%s), expected %d (%s); last error: %s\n",    \
              __FILE__, __LINE__, #expr, (int)s_, sogmm_status_string(s_), (int)(expected),   \
              sogmm_status_string(expected), sogmm_last_error());                             \
    }                                                                                         \
  } while (0)

#define EXPECT_OK(expr) EXPECT_STATUS(expr, SOGMM_OK)

#define EXPECT_TRUE(cond)                                                                     \
  do {                                                                                        \
    ++g_checks;                                                                               \
    if (!(cond)) {                                                                            \
      ++g_failures;                                                                           \
      fprintf(stderr, "%s:%d: expected %s\n", __FILE__, __LINE__, #cond);                     \
    }                                                                                         \
  } while (0)

#define EXPECT_NEAR(a, b, tol) EXPECT_TRUE(fabs((double)(a) - (double)(b)) <= (tol))

/* Fatal check: stops the test (the rest depends on it). */
#define REQUIRE_OK(expr)                                                                      \
  do {                                                                                        \
    sogmm_status s_ = (expr);                                                                 \
    ++g_checks;                                                                               \
    if (s_ != SOGMM_OK) {                                                                     \
      fprintf(stderr, "%s:%d: %s failed: %d (%s): %s\n", __FILE__, __LINE__, #expr, (int)s_, \
              sogmm_status_string(s_), sogmm_last_error());                                   \
      exit(1);                                                                                \
    }                                                                                         \
  } while (0)

static inline int test_summary(const char* name) {
  if (g_failures) {
    fprintf(stderr, "%s: %d of %d checks FAILED\n", name, g_failures, g_checks);
    return 1;
  }
  printf("%s: all %d checks passed\n", name, g_checks);
  return 0;
}

/* splitmix64-style generator: deterministic everywhere. */
static inline uint64_t test_rng_next(uint64_t* state) {
  uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
static inline double test_rng_uniform(uint64_t* state) {
  return (double)(test_rng_next(state) >> 11) * (1.0 / 9007199254740992.0);
}
static inline double test_rng_normal(uint64_t* state) {
  double u1, u2;
  do u1 = test_rng_uniform(state); while (u1 <= 0.0);
  u2 = test_rng_uniform(state);
  return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

/* The three cluster centres (x, y, z, gray) used by make_clusters. */
static const float k_centres[3][4] = {
    {0.0f, 0.0f, 1.0f, 0.2f}, {0.5f, 0.0f, 1.5f, 0.5f}, {0.0f, 0.5f, 2.0f, 0.8f}};

/* n points (n * 4 floats, caller frees) in three tight, well separated
 * Gaussian clusters, point i in cluster i % 3. */
static inline float* make_clusters(size_t n, uint64_t seed) {
  float* p = (float*)malloc(n * 4 * sizeof(float));
  size_t i;
  int d;
  if (!p) exit(2);
  for (i = 0; i < n; ++i) {
    const float* c = k_centres[i % 3];
    for (d = 0; d < 4; ++d) p[4 * i + d] = c[d] + (float)(0.02 * test_rng_normal(&seed));
  }
  return p;
}

/* A w x h frame of a tilted plane (depth in millimetres, 1.0 m to 1.6 m
 * across the image) with a gray / color pattern of three bands. Invalid
 * (zero) depth in the first column. Caller frees the three buffers. */
static inline void make_frame(uint32_t w, uint32_t h, uint16_t** depth, uint8_t** gray, uint8_t** rgb) {
  uint32_t u, v;
  *depth = (uint16_t*)malloc((size_t)w * h * sizeof(uint16_t));
  *gray = (uint8_t*)malloc((size_t)w * h);
  *rgb = (uint8_t*)malloc((size_t)w * h * 3);
  if (!*depth || !*gray || !*rgb) exit(2);
  for (v = 0; v < h; ++v) {
    for (u = 0; u < w; ++u) {
      size_t i = (size_t)v * w + u;
      uint8_t g = (uint8_t)(u < w / 3 ? 40 : (u < 2 * w / 3 ? 128 : 220));
      (*depth)[i] = (uint16_t)(u == 0 ? 0 : 1000 + (600 * u) / w);
      (*gray)[i] = g;
      (*rgb)[3 * i + 0] = g;
      (*rgb)[3 * i + 1] = g;
      (*rgb)[3 * i + 2] = g;
    }
  }
}

/* Writes `size` bytes to `path`; returns 0 on success. */
static inline int write_file(const char* path, const void* data, size_t size) {
  FILE* f = fopen(path, "wb");
  if (!f) return -1;
  if (size && fwrite(data, 1, size, f) != size) {
    fclose(f);
    return -1;
  }
  return fclose(f) == 0 ? 0 : -1;
}

/* A map's totals and what one insert did, read key by key
 * (sogmm_map_get_i64, sogmm_map_frame_get_i64/_f64/_pose) into one struct
 * for the tests to compare; returns the first status that is not SOGMM_OK. */
typedef struct test_map_stats {
  uint64_t n_components, n_pending, n_frames, n_flushes, n_fused, n_refits;
} test_map_stats;
typedef struct test_frame_stats {
  uint64_t n_points, n_novel, n_components, n_replaced;
  int flushed;
  double ms_novelty, ms_fit, ms_merge, pose[16];
} test_frame_stats;

static inline sogmm_status test_map_get_stats(const sogmm_map* map, test_map_stats* out) {
  const sogmm_key keys[6] = {SOGMM_MAP_N_COMPONENTS, SOGMM_MAP_N_PENDING, SOGMM_MAP_N_FRAMES,
                             SOGMM_MAP_N_FLUSHES,    SOGMM_MAP_N_FUSED,   SOGMM_MAP_N_REFITS};
  uint64_t* fields[6] = {&out->n_components, &out->n_pending, &out->n_frames,
                         &out->n_flushes,    &out->n_fused,   &out->n_refits};
  int i;
  for (i = 0; i < 6; ++i) {
    int64_t v = -1;
    const sogmm_status s = sogmm_map_get_i64(map, keys[i], &v);
    if (s != SOGMM_OK) return s;
    *fields[i] = (uint64_t)v;
  }
  return SOGMM_OK;
}

static inline sogmm_status test_map_get_frame_stats(const sogmm_map* map, uint64_t frame, test_frame_stats* out) {
  const sogmm_key ikeys[5] = {SOGMM_MAP_FRAME_N_POINTS, SOGMM_MAP_FRAME_N_NOVEL, SOGMM_MAP_FRAME_N_COMPONENTS,
                              SOGMM_MAP_FRAME_N_REPLACED, SOGMM_MAP_FRAME_FLUSHED};
  const sogmm_key fkeys[3] = {SOGMM_MAP_FRAME_MS_NOVELTY, SOGMM_MAP_FRAME_MS_FIT, SOGMM_MAP_FRAME_MS_MERGE};
  int64_t iv[5];
  double* fv[3] = {&out->ms_novelty, &out->ms_fit, &out->ms_merge};
  sogmm_status s;
  int i;
  for (i = 0; i < 5; ++i)
    if ((s = sogmm_map_frame_get_i64(map, frame, ikeys[i], &iv[i])) != SOGMM_OK) return s;
  for (i = 0; i < 3; ++i)
    if ((s = sogmm_map_frame_get_f64(map, frame, fkeys[i], fv[i])) != SOGMM_OK) return s;
  out->n_points = (uint64_t)iv[0];
  out->n_novel = (uint64_t)iv[1];
  out->n_components = (uint64_t)iv[2];
  out->n_replaced = (uint64_t)iv[3];
  out->flushed = (int)iv[4];
  return sogmm_map_frame_get_pose(map, frame, out->pose);
}

/* A frame from arrays with its intrinsics (sogmm_frame_from_arrays +
 * sogmm_frame_set_intrinsics), for the tests that give a frame as the
 * arrays and scalars the RGB-D calls took before the frame handle: NULL and
 * the status in *status (when not NULL) if the frame is refused. */
static inline sogmm_frame* test_frame(const uint16_t* depth, const void* color, int32_t color_format, uint32_t w,
                                      uint32_t h, double fx, double fy, double cx, double cy, sogmm_status* status) {
  sogmm_frame* f = NULL;
  sogmm_status s = sogmm_frame_from_arrays(&f, w, h, depth, color, color_format);
  if (s == SOGMM_OK) s = sogmm_frame_set_intrinsics(f, fx, fy, cx, cy);
  if (status) *status = s;
  return f;
}

/* The body of the three wrappers below: `call` (a status expression on the
 * frame f) run on test_frame(...) of the wrapper's own arguments; the frame
 * is freed and the first status that is not SOGMM_OK returned. */
#define ON_TEST_FRAME(call)                                                            \
  do {                                                                                 \
    sogmm_status s_;                                                                   \
    sogmm_frame* f = test_frame(depth, color, color_format, w, h, fx, fy, cx, cy, &s_); \
    if (s_ == SOGMM_OK) s_ = (call);                                                   \
    sogmm_frame_free(f);                                                               \
    return s_;                                                                         \
  } while (0)

/* sogmm_fit_frame, sogmm_map_insert_frame and sogmm_frame_to_points_f32 on
 * test_frame(...): the first status that is not SOGMM_OK. */
static inline sogmm_status test_fit_rgbd(sogmm_model** out, const uint16_t* depth, const void* color,
                                         int32_t color_format, uint32_t w, uint32_t h, double fx, double fy,
                                         double cx, double cy, const sogmm_options* options) {
  ON_TEST_FRAME(sogmm_fit_frame(out, f, options));
}

static inline sogmm_status test_map_insert_rgbd(sogmm_map* map, const uint16_t* depth, const void* color,
                                                int32_t color_format, uint32_t w, uint32_t h, double fx, double fy,
                                                double cx, double cy, const double* pose) {
  ON_TEST_FRAME(sogmm_map_insert_frame(map, f, pose));
}

static inline sogmm_status test_rgbd_to_points(float* out, size_t capacity, size_t* n_points, const uint16_t* depth,
                                               const void* color, int32_t color_format, uint32_t w, uint32_t h,
                                               double fx, double fy, double cx, double cy,
                                               const sogmm_options* options) {
  ON_TEST_FRAME(sogmm_frame_to_points_f32(out, capacity, n_points, f, options));
}

/* A fixed-K fit: sogmm_fit_points_f32 with SOGMM_OPT_N_COMPONENTS = k on a
 * copy of `options` (NULL = defaults); the first status that is not SOGMM_OK. */
static inline sogmm_status test_fit_fixed_k(sogmm_model** out, const float* points, size_t n, size_t k,
                                            const sogmm_options* options) {
  sogmm_options* o = NULL;
  sogmm_status s = options ? sogmm_options_clone(&o, options) : sogmm_options_create(&o);
  if (s == SOGMM_OK) s = sogmm_options_set_i64(o, SOGMM_OPT_N_COMPONENTS, (int64_t)k);
  if (s == SOGMM_OK) s = sogmm_fit_points_f32(out, points, n, NULL, o);
  sogmm_options_free(o);
  return s;
}

#endif /* SOGMM_TEST_UTIL_H */
