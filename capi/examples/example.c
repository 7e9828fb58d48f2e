/* example.c - a complete use of the SOGMM C API from plain C99.
 *
 * Builds a synthetic RGB-D frame (a tilted plane with three gray bands),
 * fits a self-organizing GMM to it, prints the fit report, samples the
 * model, regresses gray at a few points, and round-trips the model through
 * a .sogmm file. Every call is checked; failures print the status and the
 * thread's last-error message.
 *
 * Build: cc -std=c99 example.c $(pkg-config --cflags --libs sogmm) -lm
 * Run:   ./example [scratch-dir]
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "sogmm/sogmm.h"

/* Evaluates a sogmm_* call; on failure prints why and jumps to `done`. */
#define TRY(call)                                                                     \
  do {                                                                                \
    sogmm_status st_ = (call);                                                        \
    if (st_ != SOGMM_OK) {                                                            \
      fprintf(stderr, "%s failed: %s (%d): %s\n", #call, sogmm_status_string(st_),    \
              (int)st_, sogmm_last_error());                                          \
      goto done;                                                                      \
    }                                                                                 \
  } while (0)

int main(int argc, char** argv) {
  const uint32_t width = 160, height = 120;
  const char* dir = argc > 1 ? argv[1] : ".";
  char path[1024];
  uint16_t* depth = NULL;
  uint8_t* gray = NULL;
  sogmm_options* options = NULL;
  sogmm_model* model = NULL;
  sogmm_frame* frame = NULL;
  sogmm_model* loaded = NULL;
  float* samples = NULL;
  size_t m = 0, loaded_m = 0, i;
  int64_t iterations = 0, converged = 0, support = 0;
  double loglik = 0, seconds = 0;
  /* Two points on the plane: pixel column 20 (dark band) and 140 (bright
   * band) of the centre row, back-projected with the camera below. */
  float xyz[6] = {-0.4516f, 0.0f, 1.0625f, 0.6207f, 0.0f, 1.4375f};
  float g[2], var[2];
  int exit_code = 1;
  uint32_t u, v;

  /* The header and the loaded library must agree. */
  if (sogmm_abi_version() != SOGMM_ABI_VERSION) {
    fprintf(stderr, "libsogmm ABI %u, header ABI %d\n", (unsigned)sogmm_abi_version(), SOGMM_ABI_VERSION);
    return 1;
  }
  printf("libsogmm %s (ABI %u)\n", sogmm_version_string(), (unsigned)sogmm_abi_version());

  /* A synthetic frame: depth in millimetres, 8-bit gray. */
  depth = (uint16_t*)malloc((size_t)width * height * sizeof *depth);
  gray = (uint8_t*)malloc((size_t)width * height);
  if (!depth || !gray) goto done;
  for (v = 0; v < height; ++v)
    for (u = 0; u < width; ++u) {
      depth[(size_t)v * width + u] = (uint16_t)(1000 + 500 * u / width);
      gray[(size_t)v * width + u] = (uint8_t)(u < width / 3 ? 30 : (u < 2 * width / 3 ? 120 : 230));
    }

  /* Parameters: enum keys, no struct to mirror. */
  TRY(sogmm_options_create(&options));
  TRY(sogmm_options_set_f64(options, SOGMM_OPT_BANDWIDTH, 0.05));
  TRY(sogmm_options_set_i64(options, SOGMM_OPT_DECIMATION, 4));
  TRY(sogmm_options_set_i64(options, SOGMM_OPT_SEED, 1));

  /* The frame: the arrays (copied) and the camera's intrinsics. */
  TRY(sogmm_frame_from_arrays(&frame, width, height, depth, gray, SOGMM_COLOR_GRAY8));
  TRY(sogmm_frame_set_intrinsics(frame, 140.0, 140.0, 79.5, 59.5));
  TRY(sogmm_fit_frame(&model, frame, options));
  TRY(sogmm_model_n_components(model, &m));
  TRY(sogmm_model_get_info_i64(model, SOGMM_INFO_FIT_ITERATIONS, &iterations));
  TRY(sogmm_model_get_info_i64(model, SOGMM_INFO_FIT_CONVERGED, &converged));
  TRY(sogmm_model_get_info_i64(model, SOGMM_INFO_SUPPORT_SIZE, &support));
  TRY(sogmm_model_get_info_f64(model, SOGMM_INFO_FIT_LOG_LIKELIHOOD, &loglik));
  TRY(sogmm_model_get_info_f64(model, SOGMM_INFO_FIT_SECONDS_TOTAL, &seconds));
  printf("fit: %zu components from %lld points, %lld EM iterations (%s), "
         "mean log-likelihood %.3f, %.3f s\n",
         m, (long long)support, (long long)iterations, converged ? "converged" : "not converged",
         loglik, seconds);

  /* Sample 1000 points (x, y, z, gray). */
  samples = (float*)malloc(1000 * 4 * sizeof *samples);
  if (!samples) goto done;
  TRY(sogmm_model_sample_f32(model, 1000, 42, 4, NULL, samples));
  printf("first sample: (%.3f, %.3f, %.3f, gray %.3f)\n", samples[0], samples[1], samples[2], samples[3]);

  /* Expected gray and its variance at two 3-D points. */
  TRY(sogmm_model_regress_gray_f32(model, xyz, 2, NULL, g, var));
  for (i = 0; i < 2; ++i)
    printf("gray at (%.2f, %.2f, %.2f): %.3f (variance %.5f)\n", xyz[3 * i], xyz[3 * i + 1],
           xyz[3 * i + 2], g[i], var[i]);

  /* Metadata and a .sogmm round trip. */
  TRY(sogmm_model_set_value(model, "example", "synthetic plane"));
  snprintf(path, sizeof path, "%s/example.sogmm", dir);
  TRY(sogmm_model_save(model, path, NULL));
  TRY(sogmm_model_load(&loaded, path, NULL));
  TRY(sogmm_model_n_components(loaded, &loaded_m));
  printf("saved and reloaded %s: %zu components\n", path, loaded_m);
  remove(path);
  exit_code = loaded_m == m ? 0 : 1;

done:
  /* Every free function accepts NULL. */
  sogmm_model_free(loaded);
  sogmm_model_free(model);
  sogmm_frame_free(frame);
  sogmm_options_free(options);
  free(samples);
  free(depth);
  free(gray);
  return exit_code;
}
