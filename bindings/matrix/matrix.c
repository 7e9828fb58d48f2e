/* matrix.c - the C participant of the cross-language matrix test
 * (bindings/matrix/run_matrix.py describes the protocol; the Python, Rust and
 * Go participants do exactly the same calls).
 *
 *   matrix write <points.f32> <out.sogmm>
 *       fit the raw little-endian (x, y, z, gray) float32 rows with
 *       bandwidth 0.05, seed 16, 1 thread, and save with default options.
 *   matrix read <in.sogmm> <query.f32> <out.bin>
 *       load, then write weights, means, covariances, 256 samples (seed
 *       2024, dims 4), gray regression mean and variance at the query's
 *       (x, y, z) rows (float32), and their 3-D log-density (float64), all
 *       little-endian, concatenated.
 *   matrix frame <depth.png> <color image> <out.sogmm>
 *       read the RGB-D frame with the library's reader (sogmm_frame_read),
 *       fit it with intrinsics fx = fy = 525, cx = 319.5, cy = 239.5,
 *       bandwidth 0.05, seed 16, 1 thread, decimation 2 (sogmm_fit_frame),
 *       and save with default options.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sogmm/sogmm.h"

#define N_SAMPLES 256
#define SAMPLE_SEED 2024

static int fail(const char* what, sogmm_status st) {
  fprintf(stderr, "matrix.c: %s: %s (%d): %s\n", what, sogmm_status_string(st), (int)st, sogmm_last_error());
  return 1;
}

/* Reads a whole file of float32 into *out (malloc'd), returning the count. */
static long read_floats(const char* path, float** out) {
  FILE* f = fopen(path, "rb");
  long n;
  if (!f) return -1;
  fseek(f, 0, SEEK_END);
  n = ftell(f) / (long)sizeof(float);
  fseek(f, 0, SEEK_SET);
  *out = (float*)malloc((size_t)n * sizeof(float) + 1);
  if (!*out || fread(*out, sizeof(float), (size_t)n, f) != (size_t)n) n = -1;
  fclose(f);
  return n;
}

/* The protocol's fit options in a new *o: bandwidth 0.05, seed 16, one
 * thread, and `decimation` when > 0. 0, or fail()'s code naming the step. */
static int protocol_options(sogmm_options** o, int64_t decimation) {
  sogmm_status st;
  if ((st = sogmm_options_create(o)) != SOGMM_OK) return fail("options", st);
  if ((st = sogmm_options_set_f64(*o, SOGMM_OPT_BANDWIDTH, 0.05)) != SOGMM_OK) return fail("bandwidth", st);
  if ((st = sogmm_options_set_i64(*o, SOGMM_OPT_SEED, 16)) != SOGMM_OK) return fail("seed", st);
  if ((st = sogmm_options_set_i64(*o, SOGMM_OPT_THREADS, 1)) != SOGMM_OK) return fail("threads", st);
  if (decimation > 0 && (st = sogmm_options_set_i64(*o, SOGMM_OPT_DECIMATION, decimation)) != SOGMM_OK)
    return fail("decimation", st);
  return 0;
}

static int write_model(const char* points_path, const char* out_path) {
  float* pts = NULL;
  sogmm_options* o = NULL;
  sogmm_model* m = NULL;
  sogmm_status st;
  int rc = 1;
  long n = read_floats(points_path, &pts);
  if (n < 0) {
    fprintf(stderr, "matrix.c: cannot read %s\n", points_path);
    return 1;
  }
  if ((rc = protocol_options(&o, 0)) == 0) {
    if ((st = sogmm_fit_points_f32(&m, pts, (size_t)n / 4, NULL, o)) != SOGMM_OK) rc = fail("fit", st);
    else if ((st = sogmm_model_save(m, out_path, NULL)) != SOGMM_OK) rc = fail("save", st);
  }
  sogmm_model_free(m);
  sogmm_options_free(o);
  free(pts);
  return rc;
}

static int fit_frame(const char* depth_path, const char* color_path, const char* out_path) {
  sogmm_frame* frame = NULL;
  sogmm_options* o = NULL;
  sogmm_model* m = NULL;
  sogmm_status st;
  int rc = 1;
  if ((st = sogmm_frame_read(&frame, depth_path, color_path)) != SOGMM_OK) rc = fail("frame_read", st);
  else if ((st = sogmm_frame_set_intrinsics(frame, 525.0, 525.0, 319.5, 239.5)) != SOGMM_OK) rc = fail("intrinsics", st);
  else if ((rc = protocol_options(&o, 2)) == 0) {
    if ((st = sogmm_fit_frame(&m, frame, o)) != SOGMM_OK) rc = fail("fit_frame", st);
    else if ((st = sogmm_model_save(m, out_path, NULL)) != SOGMM_OK) rc = fail("save", st);
  }
  sogmm_model_free(m);
  sogmm_options_free(o);
  sogmm_frame_free(frame);
  return rc;
}

static int read_model(const char* model_path, const char* query_path, const char* out_path) {
  float *q = NULL, *buf = NULL;
  double* score = NULL;
  sogmm_model* m = NULL;
  size_t k = 0, nq;
  sogmm_status st;
  FILE* out = NULL;
  int rc = 1;
  long nf = read_floats(query_path, &q);
  if (nf < 0) {
    fprintf(stderr, "matrix.c: cannot read %s\n", query_path);
    return 1;
  }
  nq = (size_t)nf / 3;
  if ((st = sogmm_model_load(&m, model_path, NULL)) != SOGMM_OK) { rc = fail("load", st); goto done; }
  if ((st = sogmm_model_n_components(m, &k)) != SOGMM_OK) { rc = fail("n_components", st); goto done; }
  /* One buffer large enough for every float32 array, reused in turn. */
  buf = (float*)malloc(sizeof(float) * (16 * k + 4 * N_SAMPLES + 2 * nq + 1));
  score = (double*)malloc(sizeof(double) * (nq + 1));
  out = fopen(out_path, "wb");
  if (!buf || !score || !out) goto done;
  if ((st = sogmm_model_get_weights_f32(m, buf, k)) != SOGMM_OK) { rc = fail("weights", st); goto done; }
  fwrite(buf, sizeof(float), k, out);
  if ((st = sogmm_model_get_means_f32(m, buf, 4 * k)) != SOGMM_OK) { rc = fail("means", st); goto done; }
  fwrite(buf, sizeof(float), 4 * k, out);
  if ((st = sogmm_model_get_covariances_f32(m, buf, 16 * k)) != SOGMM_OK) { rc = fail("covariances", st); goto done; }
  fwrite(buf, sizeof(float), 16 * k, out);
  if ((st = sogmm_model_sample_f32(m, N_SAMPLES, SAMPLE_SEED, 4, NULL, buf)) != SOGMM_OK) { rc = fail("sample", st); goto done; }
  fwrite(buf, sizeof(float), 4 * N_SAMPLES, out);
  if ((st = sogmm_model_regress_gray_f32(m, q, nq, NULL, buf, buf + nq)) != SOGMM_OK) { rc = fail("regress", st); goto done; }
  fwrite(buf, sizeof(float), 2 * nq, out);
  if ((st = sogmm_model_score_samples_f32(m, q, nq, 3, NULL, score)) != SOGMM_OK) { rc = fail("score", st); goto done; }
  fwrite(score, sizeof(double), nq, out);
  rc = ferror(out) ? 1 : 0;
done:
  if (out && fclose(out) != 0) rc = 1;
  sogmm_model_free(m);
  free(buf);
  free(score);
  free(q);
  return rc;
}

int main(int argc, char** argv) {
  const uint16_t one = 1;
  if (*(const uint8_t*)&one != 1) {
    fprintf(stderr, "matrix.c: the dump format is little-endian; this machine is not\n");
    return 1;
  }
  if (argc == 4 && strcmp(argv[1], "write") == 0) return write_model(argv[2], argv[3]);
  if (argc == 5 && strcmp(argv[1], "read") == 0) return read_model(argv[2], argv[3], argv[4]);
  if (argc == 5 && strcmp(argv[1], "frame") == 0) return fit_frame(argv[2], argv[3], argv[4]);
  fprintf(stderr,
          "usage: %s write <points.f32> <out.sogmm> | read <in.sogmm> <query.f32> <out.bin> | "
          "frame <depth.png> <color> <out.sogmm>\n",
          argv[0]);
  return 2;
}
