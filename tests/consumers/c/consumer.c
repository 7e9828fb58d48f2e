/* A program outside this repository using the installed C library (ctest
 * consumer_c, tests/consumers/consumer_c.sh): two cubes of 64 points, 1 m
 * apart, one dark (gray 0.2) and one bright (0.8), are fitted, saved, loaded
 * and queried. With a bandwidth of 0.05 m, far below the 1 m gap and above
 * the cubes' 0.03 m size, mean shift finds exactly two modes, and the gray
 * regressed at each cube's centre is that cube's gray.
 * Exit 0 only if all of that holds. Usage: consumer <scratch-dir> */
#include <math.h>
#include <stdio.h>

#include "sogmm/sogmm.h"

#define CHECK(call)                                                                   \
  do {                                                                                \
    sogmm_status st_ = (call);                                                        \
    if (st_ != SOGMM_OK) {                                                            \
      fprintf(stderr, "%s: %s: %s\n", #call, sogmm_status_string(st_), sogmm_last_error()); \
      return 1;                                                                       \
    }                                                                                 \
  } while (0)

int main(int argc, char** argv) {
  float points[128 * 4];
  const float centre_x[2] = {0.0f, 1.0f}, cube_gray[2] = {0.2f, 0.8f};
  const float centres[6] = {0.015f, 0.015f, 1.015f, 1.015f, 0.015f, 1.015f};
  float gray[2], variance[2];
  char path[1024];
  size_t n = 0, fitted = 0, loaded_m = 0;
  int c, i, j, k;
  sogmm_options* options = NULL;
  sogmm_model* model = NULL;
  sogmm_model* loaded = NULL;

  if (argc != 2) {
    fprintf(stderr, "usage: consumer <scratch-dir>\n");
    return 2;
  }
  for (c = 0; c < 2; ++c)
    for (i = 0; i < 4; ++i)
      for (j = 0; j < 4; ++j)
        for (k = 0; k < 4; ++k, ++n) {
          points[4 * n + 0] = centre_x[c] + 0.01f * (float)i;
          points[4 * n + 1] = 0.01f * (float)j;
          points[4 * n + 2] = 1.0f + 0.01f * (float)k;
          points[4 * n + 3] = cube_gray[c];
        }

  CHECK(sogmm_options_create(&options));
  CHECK(sogmm_options_set_f64(options, SOGMM_OPT_BANDWIDTH, 0.05));
  CHECK(sogmm_options_set_i64(options, SOGMM_OPT_SEED, 1));
  CHECK(sogmm_fit_points_f32(&model, points, n, NULL, options));
  CHECK(sogmm_model_n_components(model, &fitted));

  snprintf(path, sizeof path, "%s/consumer_c.sogmm", argv[1]);
  CHECK(sogmm_model_save(model, path, NULL));
  CHECK(sogmm_model_load(&loaded, path, NULL));
  CHECK(sogmm_model_n_components(loaded, &loaded_m));
  CHECK(sogmm_model_regress_gray_f32(loaded, centres, 2, NULL, gray, variance));
  printf("libsogmm %s: %zu components fitted, %zu loaded from %s, gray %.3f and %.3f\n",
         sogmm_version_string(), fitted, loaded_m, path, gray[0], gray[1]);

  sogmm_model_free(loaded);
  sogmm_model_free(model);
  sogmm_options_free(options);
  if (fitted != 2 || loaded_m != 2 || fabsf(gray[0] - 0.2f) > 0.01f || fabsf(gray[1] - 0.8f) > 0.01f) {
    fprintf(stderr, "wrong result: expected 2 components and gray 0.2 / 0.8\n");
    return 1;
  }
  return 0;
}
