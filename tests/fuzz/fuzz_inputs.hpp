// What the call-sequence targets (fuzz_api, fuzz_map) share: the status and
// handle checks every call goes through, and the readers that turn input
// bytes into hostile arguments (doubles, point clouds, poses). The byte
// layout each reader consumes is part of the committed seeds: change it and
// the seeds (make_*_seeds.py) must be rewritten.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "fuzz_model_check.hpp"
#include "fuzz_util.hpp"
#include "sogmm/sogmm.h"

namespace sogmm_fuzz {

/// Every status is documented (OK, or a code from SOGMM_E_NULL_ARG down to
/// `lowest`: SOGMM_E_INTERNAL for calls without callbacks or map handles,
/// SOGMM_E_BUSY with them), an error carries a message, and INTERNAL (a bug)
/// never comes.
inline void check_status(sogmm_status s, sogmm_status lowest = SOGMM_E_INTERNAL) {
  if (std::getenv("SOGMM_FUZZ_TRACE")) std::fprintf(stderr, "  status %d %s\n", s, s ? sogmm_last_error() : "");
  FUZZ_CHECK(s == SOGMM_OK || (s <= SOGMM_E_NULL_ARG && s >= lowest));
  FUZZ_CHECK(s != SOGMM_E_INTERNAL);
  if (s != SOGMM_OK) FUZZ_CHECK(sogmm_last_error()[0] != '\0');
}

/// A model-creating call: on error *out is NULL; on success the model is valid.
inline void check_created(sogmm_status s, sogmm_model* out, sogmm_status lowest = SOGMM_E_INTERNAL) {
  check_status(s, lowest);
  if (s == SOGMM_OK) {
    FUZZ_CHECK(out != nullptr);
    check_model(out);
  } else {
    FUZZ_CHECK(out == nullptr);
  }
}

/// Options for work, created on first use: one thread (the fuzzer is
/// single-threaded), small EM budgets, the fastest compression; whatever a
/// program set since, kept within those bounds, so that a step stays cheap.
inline sogmm_options* bound_work(sogmm_options*& o) {
  if (!o) {
    FUZZ_CHECK(sogmm_options_create(&o) == SOGMM_OK);
    FUZZ_CHECK(sogmm_options_set_i64(o, SOGMM_OPT_MAX_ITER, 4) == SOGMM_OK);
    FUZZ_CHECK(sogmm_options_set_i64(o, SOGMM_OPT_ZSTD_LEVEL, 1) == SOGMM_OK);
  }
  FUZZ_CHECK(sogmm_options_set_i64(o, SOGMM_OPT_THREADS, 1) == SOGMM_OK);
  std::int64_t v = 0;
  if (sogmm_options_get_i64(o, SOGMM_OPT_MAX_ITER, &v) == SOGMM_OK && v > 8)
    FUZZ_CHECK(sogmm_options_set_i64(o, SOGMM_OPT_MAX_ITER, 8) == SOGMM_OK);
  if (sogmm_options_get_i64(o, SOGMM_OPT_N_INIT, &v) == SOGMM_OK && v > 2)
    FUZZ_CHECK(sogmm_options_set_i64(o, SOGMM_OPT_N_INIT, 2) == SOGMM_OK);
  if (sogmm_options_get_i64(o, SOGMM_OPT_ZSTD_LEVEL, &v) == SOGMM_OK && v > 3)
    FUZZ_CHECK(sogmm_options_set_i64(o, SOGMM_OPT_ZSTD_LEVEL, 3) == SOGMM_OK);
  return o;
}

// A double from the input: either a raw bit pattern (NaN, Inf, denormals, huge)
// or a tame value in [-8, 8) in steps of 1/16, chosen by one bit.
inline double take_double(Reader& in) {
  const std::uint8_t how = in.take<std::uint8_t>();
  if (how & 1) return in.take<double>();
  return (static_cast<int>(in.take<std::uint8_t>()) - 128) / 16.0;
}

inline float take_float(Reader& in) { return static_cast<float>(take_double(in)); }

// n points (x, y, z, gray): mostly a tame cloud around a plane, so that fits
// reach EM; the input bytes perturb it.
inline std::vector<float> take_points(Reader& in, std::size_t n) {
  std::vector<float> p(4 * n + 4);
  const std::uint8_t raw = in.take<std::uint8_t>();
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t b = in.take<std::uint8_t>();
    p[4 * i + 0] = static_cast<float>(i % 13) * 0.05f + (b & 7) * 1e-3f;
    p[4 * i + 1] = static_cast<float>(i / 13) * 0.05f + ((b >> 3) & 7) * 1e-3f;
    p[4 * i + 2] = 1.0f + (b >> 6) * 0.01f;
    p[4 * i + 3] = static_cast<float>(b) / 255.0f;
  }
  // Raw overrides: a few values straight from the input (NaN, Inf, huge).
  for (int r = 0; r < (raw & 3) && n > 0; ++r) {
    const std::size_t at = in.take<std::uint16_t>() % (4 * n);
    p[at] = in.take<float>();
  }
  return p;
}

// A pose: a rotation from a (possibly unnormalised) quaternion plus a
// translation, or 16 raw doubles.
inline std::array<double, 16> take_pose(Reader& in) {
  std::array<double, 16> t{};
  if (in.take<std::uint8_t>() & 1) {
    for (double& v : t) v = take_double(in);
    return t;
  }
  double q[4];
  for (double& v : q) v = (static_cast<int>(in.take<std::uint8_t>()) - 128) / 64.0;
  double nq = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (nq == 0) nq = q[0] = 1;
  for (double& v : q) v /= nq;
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  const double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                       2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                       2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) t[4 * i + j] = r[3 * i + j];
    t[4 * i + 3] = take_double(in);
  }
  t[15] = 1;
  return t;
}

/// One kind of step of a program: its name (for SOGMM_FUZZ_TRACE) and what
/// it does with the state and the bytes that follow its opcode.
template <typename State>
struct Step {
  const char* name;
  void (*run)(State&, Reader&);
};

/// Runs the program in `in`: at most `max_steps` steps, each an opcode byte
/// (modulo the number of step kinds) and the step's bytes, with `after`
/// checking the state after every step. SOGMM_FUZZ_TRACE=1 prints the steps
/// (to read a finding).
template <typename State, std::size_t N>
void run_program(Reader& in, State& st, int max_steps, const Step<State> (&steps)[N], void (*after)(const State&)) {
  static const bool trace = std::getenv("SOGMM_FUZZ_TRACE") != nullptr;
  for (int step = 0; step < max_steps && in.remaining() > 0; ++step) {
    const Step<State>& s = steps[in.take<std::uint8_t>() % N];
    if (trace) std::fprintf(stderr, "step %d: %s\n", step, s.name);
    s.run(st, in);
    after(st);
  }
}

}  // namespace sogmm_fuzz
