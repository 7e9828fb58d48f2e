/* The frame reader (sogmm_frame_*), sogmm_fit_frame, sogmm_map_insert_frame
 * and the .log trajectories (sogmm_trajectory_*) of the C API.
 *
 * The PNGs are built here byte by byte (filter 0 rows in a stored zlib
 * block), so the pixels the library must return are known exactly.
 * Usage: sogmm_capi_test_frame <scratch-dir> */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sogmm/sogmm.h"
#include "test_util.h"

static char g_dir[512] = ".";

static uint32_t crc32_of(const uint8_t* p, size_t n) {
  uint32_t c = 0xFFFFFFFFu;
  size_t i;
  int k;
  for (i = 0; i < n; ++i) {
    c ^= p[i];
    for (k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
  }
  return ~c;
}

static void put32(uint8_t* p, uint32_t v) {
  p[0] = (uint8_t)(v >> 24);
  p[1] = (uint8_t)(v >> 16);
  p[2] = (uint8_t)(v >> 8);
  p[3] = (uint8_t)v;
}

/* Appends a chunk to `out` at *n (room checked by the caller's sizing). */
static void chunk(uint8_t* out, size_t* n, const char* type, const uint8_t* data, uint32_t len) {
  put32(out + *n, len);
  memcpy(out + *n + 4, type, 4);
  if (len) memcpy(out + *n + 8, data, len);
  put32(out + *n + 8 + len, crc32_of(out + *n + 4, len + 4));
  *n += 12 + len;
}

/* A gray PNG of w x h samples of `bits` (8 or 16) bits, values from `v8` or
 * `v16`; returns a malloc'd buffer and its size (rows < 64 KiB in total). */
static uint8_t* gray_png(uint32_t w, uint32_t h, int bits, const uint8_t* v8, const uint16_t* v16, size_t* size) {
  const size_t row = (size_t)w * (bits / 8), raw_n = (row + 1) * h;
  uint8_t* raw = (uint8_t*)malloc(raw_n);
  uint8_t* z = (uint8_t*)malloc(raw_n + 11);
  uint8_t* out = (uint8_t*)malloc(raw_n + 100);
  uint8_t ihdr[13];
  uint32_t a = 1, b = 0, x, y;
  size_t i, n = 8;
  if (!raw || !z || !out || raw_n > 65535) exit(2);
  for (y = 0; y < h; ++y) {
    uint8_t* r = raw + y * (row + 1);
    r[0] = 0;
    for (x = 0; x < w; ++x) {
      size_t k = (size_t)y * w + x;
      if (bits == 16) {
        r[1 + 2 * x] = (uint8_t)(v16[k] >> 8);
        r[2 + 2 * x] = (uint8_t)(v16[k] & 0xFF);
      } else {
        r[1 + x] = v8[k];
      }
    }
  }
  for (i = 0; i < raw_n; ++i) {
    a = (a + raw[i]) % 65521u;
    b = (b + a) % 65521u;
  }
  z[0] = 0x78, z[1] = 0x01, z[2] = 0x01;
  z[3] = (uint8_t)(raw_n & 0xFF), z[4] = (uint8_t)(raw_n >> 8);
  z[5] = (uint8_t)(~raw_n & 0xFF), z[6] = (uint8_t)((~raw_n >> 8) & 0xFF);
  memcpy(z + 7, raw, raw_n);
  put32(z + 7 + raw_n, (b << 16) | a);
  memcpy(out, "\x89PNG\r\n\x1a\n", 8);
  put32(ihdr, w);
  put32(ihdr + 4, h);
  ihdr[8] = (uint8_t)bits, ihdr[9] = 0, ihdr[10] = 0, ihdr[11] = 0, ihdr[12] = 0;
  chunk(out, &n, "IHDR", ihdr, 13);
  chunk(out, &n, "IDAT", z, (uint32_t)(raw_n + 11));
  chunk(out, &n, "IEND", NULL, 0);
  free(raw);
  free(z);
  *size = n;
  return out;
}

static void path_of(char* out, size_t cap, const char* name) { snprintf(out, cap, "%s/%s", g_dir, name); }

/* Weights and means of a model, for bitwise comparisons (malloc'd; *k set). */
static float* params_of(const sogmm_model* m, size_t* k) {
  float* p;
  if (sogmm_model_n_components(m, k) != SOGMM_OK) exit(2);
  p = (float*)malloc(sizeof(float) * 5 * *k);
  if (!p || sogmm_model_get_weights_f32(m, p, *k) != SOGMM_OK ||
      sogmm_model_get_means_f32(m, p + *k, 4 * *k) != SOGMM_OK)
    exit(2);
  return p;
}

static void test_frames(void) {
  const uint32_t w = 64, h = 48;
  const double pose[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  uint16_t* depth;
  uint8_t *gray, *rgb;
  size_t dn, gn, sn, k1, k2;
  uint8_t *dpng, *gpng, *small;
  char dpath[600], gpath[600], spath[600];
  sogmm_frame *f = NULL, *g = NULL, *bad = (sogmm_frame*)1;
  sogmm_options* o = NULL;
  sogmm_model *m1 = NULL, *m2 = NULL, *bad_model = NULL;
  sogmm_map *map1 = NULL, *map2 = NULL;
  float *p1, *p2;

  make_frame(w, h, &depth, &gray, &rgb);
  dpng = gray_png(w, h, 16, NULL, depth, &dn);
  gpng = gray_png(w, h, 8, gray, NULL, &gn);
  small = gray_png(w, h - 1, 8, gray, NULL, &sn);
  path_of(dpath, sizeof dpath, "frame_depth.png");
  path_of(gpath, sizeof gpath, "frame_gray.png");
  path_of(spath, sizeof spath, "frame_small.png");
  if (write_file(dpath, dpng, dn) || write_file(gpath, gpng, gn) || write_file(spath, small, sn)) exit(2);

  /* The files' pixels, from a path and from memory. */
  REQUIRE_OK(sogmm_frame_read(&f, dpath, gpath));
  EXPECT_TRUE(sogmm_frame_width(f) == w && sogmm_frame_height(f) == h);
  EXPECT_TRUE(memcmp(sogmm_frame_depth(f), depth, (size_t)w * h * 2) == 0);
  EXPECT_TRUE(sogmm_frame_color_format(f) == SOGMM_COLOR_GRAY8);
  EXPECT_TRUE(memcmp(sogmm_frame_color(f), gray, (size_t)w * h) == 0);
  REQUIRE_OK(sogmm_frame_decode(&g, dpng, dn, NULL, 0));
  EXPECT_TRUE(memcmp(sogmm_frame_depth(g), depth, (size_t)w * h * 2) == 0);
  EXPECT_TRUE(sogmm_frame_color(g) == NULL && sogmm_frame_color_format(g) == 0);

  /* Fit and insert: bitwise what a frame made from the same pixels gives. */
  REQUIRE_OK(sogmm_options_create(&o));
  REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_BANDWIDTH, 0.05));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_SEED, 3));
  EXPECT_STATUS(sogmm_fit_frame(&m1, f, o), SOGMM_E_INVALID_ARG); /* no intrinsics yet */
  EXPECT_TRUE(m1 == NULL && strstr(sogmm_last_error(), "sogmm_frame_set_intrinsics") != NULL);
  REQUIRE_OK(sogmm_frame_set_intrinsics(f, 60.0, 60.0, 31.5, 23.5));
  REQUIRE_OK(sogmm_fit_frame(&m1, f, o));
  REQUIRE_OK(test_fit_rgbd(&m2, depth, gray, SOGMM_COLOR_GRAY8, w, h, 60.0, 60.0, 31.5, 23.5, o));
  p1 = params_of(m1, &k1);
  p2 = params_of(m2, &k2);
  EXPECT_TRUE(k1 == k2 && k1 >= 2 && memcmp(p1, p2, sizeof(float) * 5 * k1) == 0);
  free(p1);
  free(p2);
  sogmm_model_free(m1);
  sogmm_model_free(m2);
  m1 = m2 = NULL;

  REQUIRE_OK(sogmm_map_create(&map1, o));
  REQUIRE_OK(sogmm_map_create(&map2, o));
  REQUIRE_OK(sogmm_map_insert_frame(map1, f, pose));
  REQUIRE_OK(test_map_insert_rgbd(map2, depth, gray, SOGMM_COLOR_GRAY8, w, h, 60.0, 60.0, 31.5, 23.5, pose));
  REQUIRE_OK(sogmm_map_flush(map1));
  REQUIRE_OK(sogmm_map_flush(map2));
  REQUIRE_OK(sogmm_map_export(&m1, map1, NULL));
  REQUIRE_OK(sogmm_map_export(&m2, map2, NULL));
  p1 = params_of(m1, &k1);
  p2 = params_of(m2, &k2);
  EXPECT_TRUE(k1 == k2 && memcmp(p1, p2, sizeof(float) * 5 * k1) == 0);
  free(p1);
  free(p2);
  EXPECT_STATUS(sogmm_map_insert_frame(map1, g, pose), SOGMM_E_INVALID_ARG); /* g has no intrinsics */
  EXPECT_STATUS(sogmm_map_insert_frame(map1, NULL, pose), SOGMM_E_NULL_ARG);

  /* Bad input: named, classified, out-pointer reset. */
  EXPECT_STATUS(sogmm_frame_read(&bad, NULL, gpath), SOGMM_E_NULL_ARG);
  EXPECT_TRUE(bad == NULL);
  EXPECT_STATUS(sogmm_frame_read(&bad, "/nonexistent/d.png", NULL), SOGMM_E_IO);
  EXPECT_TRUE(strstr(sogmm_last_error(), "/nonexistent/d.png") != NULL);
  EXPECT_STATUS(sogmm_frame_read(&bad, dpath, spath), SOGMM_E_INVALID_DATA); /* sizes differ */
  EXPECT_TRUE(strstr(sogmm_last_error(), "different sizes") != NULL);
  EXPECT_STATUS(sogmm_frame_read(&bad, gpath, NULL), SOGMM_OK); /* an 8-bit gray PNG is a depth image too, widened */
  sogmm_frame_free(bad);
  bad = NULL;
  EXPECT_STATUS(sogmm_frame_decode(&bad, dpng, dn / 2, NULL, 0), SOGMM_E_FORMAT);
  EXPECT_STATUS(sogmm_frame_decode(&bad, "not an image", 12, NULL, 0), SOGMM_E_FORMAT);
  EXPECT_STATUS(sogmm_frame_decode(&bad, dpng, dn, gpng, gn - 20), SOGMM_E_FORMAT);
  EXPECT_STATUS(sogmm_fit_frame(&bad_model, NULL, o), SOGMM_E_NULL_ARG);
  EXPECT_TRUE(bad_model == NULL); /* a refused call resets the out-pointer (m2 still holds a model) */
  EXPECT_STATUS(sogmm_frame_set_intrinsics(NULL, 1, 1, 0, 0), SOGMM_E_NULL_ARG);
  EXPECT_TRUE(sogmm_frame_width(NULL) == 0 && sogmm_frame_height(NULL) == 0 && sogmm_frame_depth(NULL) == NULL &&
              sogmm_frame_color(NULL) == NULL && sogmm_frame_color_format(NULL) == 0);
  sogmm_frame_free(NULL);

  sogmm_model_free(m1);
  sogmm_model_free(m2);
  sogmm_map_free(map1);
  sogmm_map_free(map2);
  sogmm_options_free(o);
  sogmm_frame_free(f);
  sogmm_frame_free(g);
  free(dpng);
  free(gpng);
  free(small);
  free(depth);
  free(gray);
  free(rgb);
}

static void test_trajectories(void) {
  const double c = cos(0.4), s = sin(0.4);
  const double poses[32] = {c, -s, 0, 1.0 / 3.0, s, c, 0, -2, 0, 0, 1, 1e-9, 0, 0, 0, 1,
                            1, 0, 0, 4, 0, c, -s, 5, 0, s, c, 6, 0, 0, 0, 1};
  double scaled[16];
  char path[600], before[64], after[64];
  sogmm_trajectory *t = NULL, *bad = (sogmm_trajectory*)1;
  FILE* fp;
  path_of(path, sizeof path, "trajectory.log");
  REQUIRE_OK(sogmm_trajectory_write(path, poses, 2));
  REQUIRE_OK(sogmm_trajectory_read(&t, path));
  EXPECT_TRUE(sogmm_trajectory_size(t) == 2);
  EXPECT_TRUE(sogmm_trajectory_ids(t)[0] == 0 && sogmm_trajectory_ids(t)[1] == 1);
  EXPECT_TRUE(memcmp(sogmm_trajectory_poses(t), poses, sizeof poses) == 0); /* 17 digits: bitwise */
  sogmm_trajectory_free(t);

  /* A refused write leaves the file as it was. */
  memcpy(scaled, poses, sizeof scaled);
  scaled[0] = 2.0;
  fp = fopen(path, "rb");
  if (!fp || !fgets(before, sizeof before, fp)) exit(2);
  fclose(fp);
  EXPECT_STATUS(sogmm_trajectory_write(path, scaled, 1), SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(strstr(sogmm_last_error(), "pose 0") != NULL);
  EXPECT_STATUS(sogmm_trajectory_write(path, poses, 0), SOGMM_E_INVALID_ARG);
  EXPECT_STATUS(sogmm_trajectory_write(path, NULL, 1), SOGMM_E_NULL_ARG);
  EXPECT_STATUS(sogmm_trajectory_write(NULL, poses, 1), SOGMM_E_NULL_ARG);
  fp = fopen(path, "rb");
  if (!fp || !fgets(after, sizeof after, fp)) exit(2);
  fclose(fp);
  EXPECT_TRUE(strcmp(before, after) == 0 && strcmp(before, "0 1 2\n") == 0);

  if (write_file(path, "0 0 1\n1 0 0 0\n0 1 0 0\n", 22)) exit(2);
  EXPECT_STATUS(sogmm_trajectory_read(&bad, path), SOGMM_E_INVALID_DATA);
  EXPECT_TRUE(bad == NULL && strstr(sogmm_last_error(), "trajectory.log:3: truncated") != NULL);
  EXPECT_STATUS(sogmm_trajectory_read(&bad, g_dir), SOGMM_E_IO); /* a folder */
  EXPECT_TRUE(sogmm_trajectory_size(NULL) == 0 && sogmm_trajectory_poses(NULL) == NULL &&
              sogmm_trajectory_ids(NULL) == NULL);
  sogmm_trajectory_free(NULL);
}

/* Frames from arrays: the arrays are copied (the accessors give them back
 * after the caller's copies change), a frame without a colour image fits
 * bitwise as one with gray 0 everywhere (its documented meaning), float gray
 * keeps its layout, and a refused frame leaves the out-pointer NULL. */
static void test_frames_from_arrays(void) {
  const uint32_t w = 64, h = 48;
  uint16_t *depth = NULL;
  uint8_t *gray = NULL, *rgb = NULL, *zeros = (uint8_t*)calloc((size_t)w * h, 1);
  float* grayf = (float*)malloc((size_t)w * h * sizeof(float));
  sogmm_frame *bare = NULL, *zero = NULL, *ff = NULL, *bad = (sogmm_frame*)&g_dir;
  sogmm_model *m1 = NULL, *m2 = NULL;
  sogmm_options* o = NULL;
  size_t k1 = 0, k2 = 0, i;
  float *p1, *p2;
  make_frame(w, h, &depth, &gray, &rgb);
  for (i = 0; i < (size_t)w * h; ++i) grayf[i] = gray[i] / 255.0f;
  REQUIRE_OK(sogmm_frame_from_arrays(&bare, w, h, depth, NULL, 0));
  REQUIRE_OK(sogmm_frame_from_arrays(&zero, w, h, depth, zeros, SOGMM_COLOR_GRAY8));
  REQUIRE_OK(sogmm_frame_from_arrays(&ff, w, h, depth, grayf, SOGMM_COLOR_GRAY_F32));
  depth[5] ^= 0x55;
  EXPECT_TRUE(sogmm_frame_width(bare) == w && sogmm_frame_height(bare) == h);
  EXPECT_TRUE(sogmm_frame_depth(bare)[5] == (uint16_t)(depth[5] ^ 0x55)); /* a copy */
  depth[5] ^= 0x55;
  EXPECT_TRUE(sogmm_frame_color(bare) == NULL && sogmm_frame_color_format(bare) == 0);
  EXPECT_TRUE(sogmm_frame_color_format(ff) == SOGMM_COLOR_GRAY_F32);
  EXPECT_TRUE(memcmp(sogmm_frame_color(ff), grayf, (size_t)w * h * sizeof(float)) == 0);
  REQUIRE_OK(sogmm_options_create(&o));
  REQUIRE_OK(sogmm_options_set_f64(o, SOGMM_OPT_BANDWIDTH, 0.05));
  REQUIRE_OK(sogmm_options_set_i64(o, SOGMM_OPT_SEED, 3));
  REQUIRE_OK(sogmm_frame_set_intrinsics(bare, 60.0, 60.0, 31.5, 23.5));
  REQUIRE_OK(sogmm_frame_set_intrinsics(zero, 60.0, 60.0, 31.5, 23.5));
  REQUIRE_OK(sogmm_fit_frame(&m1, bare, o));
  REQUIRE_OK(sogmm_fit_frame(&m2, zero, o));
  p1 = params_of(m1, &k1);
  p2 = params_of(m2, &k2);
  EXPECT_TRUE(k1 == k2 && k1 >= 1 && memcmp(p1, p2, sizeof(float) * 5 * k1) == 0);
  free(p1);
  free(p2);
  EXPECT_STATUS(sogmm_frame_from_arrays(&bad, w, h, depth, NULL, SOGMM_COLOR_GRAY8), SOGMM_E_NULL_ARG);
  EXPECT_TRUE(bad == NULL && strstr(sogmm_last_error(), "color is NULL") != NULL);
  EXPECT_STATUS(sogmm_frame_from_arrays(NULL, w, h, depth, gray, SOGMM_COLOR_GRAY8), SOGMM_E_NULL_ARG);
  sogmm_model_free(m1);
  sogmm_model_free(m2);
  sogmm_frame_free(bare);
  sogmm_frame_free(zero);
  sogmm_frame_free(ff);
  sogmm_options_free(o);
  free(depth);
  free(gray);
  free(rgb);
  free(zeros);
  free(grayf);
}

int main(int argc, char** argv) {
  if (argc > 1) snprintf(g_dir, sizeof g_dir, "%s", argv[1]);
  test_frames();
  test_frames_from_arrays();
  test_trajectories();
  return test_summary("capi_frame");
}
