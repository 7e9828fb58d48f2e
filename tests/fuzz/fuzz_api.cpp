// Fuzz target: random sequences of public C API calls with random arguments.
//
// The input is a program: each step is one opcode byte followed by the bytes
// that step consumes (see the switch below). The state is a few model slots,
// two options handles and one buffer, so that calls combine: a model that a
// merge made is transformed, saved, loaded, sampled, merged again ...
//
// Invariants checked after every call (a violation aborts, which libFuzzer
// records as a crash):
// - no call crashes, hangs or aborts (ASan/UBSan and libFuzzer's timeout);
// - a status is either SOGMM_OK or one of the documented negative codes, and
//   on error sogmm_last_error() is a non-empty message;
// - a call that creates a handle leaves *out == NULL on error;
// - every model handle that exists is valid: M >= 1, finite weights >= 0
//   summing to 1 within 1e-4, finite means and covariances (no NaN/Inf model);
// - what save_to_memory writes, load_from_memory reads back with the same
//   arrays bit for bit (the writer never writes what the reader rejects);
// - inference outputs are finite where the inputs are (score may be -inf).
// Sizes are kept small (at most a few hundred points), except deliberate
// huge counts that must be refused before anything is read.
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "fuzz_inputs.hpp"
#include "fuzz_model_check.hpp"
#include "../hardening/capi_calls.hpp"
#include "fuzz_util.hpp"
#include "sogmm/sogmm.h"

namespace {

constexpr int kSlots = 4;
constexpr std::size_t kMaxPoints = 192;
constexpr int kMaxSteps = 48;
constexpr std::size_t kMaxMergedComponents = 4096;

struct State {
  std::array<sogmm_model*, kSlots> models{};
  std::array<sogmm_options*, 2> options{};
  sogmm_buffer* buffer = nullptr;
  ~State() {
    for (auto* m : models) sogmm_model_free(m);
    for (auto* o : options) sogmm_options_free(o);
    sogmm_buffer_free(buffer);
  }
};

using sogmm_fuzz::check_created;
using sogmm_fuzz::check_model;
using sogmm_fuzz::check_status;
using sogmm_fuzz::take_double;
using sogmm_fuzz::take_float;
using sogmm_fuzz::take_points;
using sogmm_fuzz::take_pose;

void put(State& st, int slot, sogmm_model* m) {
  if (std::getenv("SOGMM_FUZZ_TRACE")) std::fprintf(stderr, "  -> model in slot %d\n", slot);
  sogmm_model_free(st.models[slot]);
  st.models[slot] = m;
}

std::string take_string(sogmm_fuzz::Reader& in) {
  const std::size_t len = in.take<std::uint8_t>() % 24;
  std::string s;
  for (std::size_t i = 0; i < len; ++i) {
    const char c = static_cast<char>(in.take<std::uint8_t>());
    if (c == '\0') break;
    s.push_back(c);
  }
  return s;
}

// Keys the setters and getters are tried with: every documented option and
// info key, plus whatever 32-bit value the input gives.
sogmm_key take_key(sogmm_fuzz::Reader& in) {
  static const sogmm_key known[] = {
      SOGMM_OPT_BANDWIDTH, SOGMM_OPT_N_COMPONENTS, SOGMM_OPT_TOL, SOGMM_OPT_REG_COVAR, SOGMM_OPT_MAX_ITER,
      SOGMM_OPT_SEED, SOGMM_OPT_THREADS, SOGMM_OPT_MODE_COUNTER, SOGMM_OPT_TRUNCATION_NATS, SOGMM_OPT_N_INIT,
      SOGMM_OPT_DEPTH_SCALE, SOGMM_OPT_DEPTH_MIN, SOGMM_OPT_DEPTH_MAX, SOGMM_OPT_DECIMATION,
      SOGMM_OPT_ZSTD_LEVEL, SOGMM_OPT_FLOAT64, SOGMM_OPT_COMPRESS, SOGMM_OPT_MAX_DECODED_BYTES,
      SOGMM_OPT_VERIFY_CHECKSUMS, SOGMM_OPT_SAMPLE_TRUNCATION, SOGMM_INFO_SUPPORT_SIZE,
      SOGMM_INFO_CREATED_UNIX_MS, SOGMM_INFO_FIT_ITERATIONS, SOGMM_INFO_FIT_LOG_LIKELIHOOD,
      SOGMM_INFO_FIT_SEED, SOGMM_INFO_FIT_SECONDS_TOTAL, SOGMM_INFO_CAMERA_FX, SOGMM_INFO_CAMERA_DECIMATION};
  const std::uint8_t b = in.take<std::uint8_t>();
  if (b < sizeof(known) / sizeof(known[0])) return known[b];
  return in.take<sogmm_key>();
}

// The program's two options handles, bounded for work (bound_work).
sogmm_options* work_options(State& st, std::uint8_t which) {
  return sogmm_fuzz::bound_work(st.options[which & 1]);
}

void step_set_option(State& st, sogmm_fuzz::Reader& in) {
  sogmm_options* o = work_options(st, in.take<std::uint8_t>());
  const sogmm_key key = take_key(in);
  const std::uint8_t kind = in.take<std::uint8_t>();
  if (kind & 1) {
    const double v = take_double(in);
    double before = 0, after = 0;
    const sogmm_status had = sogmm_options_get_f64(o, key, &before);
    const sogmm_status s = sogmm_options_set_f64(o, key, v);
    check_status(s);
    // A refused value leaves the option as it was.
    if (s != SOGMM_OK && had == SOGMM_OK) {
      FUZZ_CHECK(sogmm_options_get_f64(o, key, &after) == SOGMM_OK);
      FUZZ_CHECK(std::memcmp(&before, &after, sizeof before) == 0);
    }
    if (s == SOGMM_OK) {
      FUZZ_CHECK(sogmm_options_get_f64(o, key, &after) == SOGMM_OK);
      FUZZ_CHECK(std::memcmp(&v, &after, sizeof v) == 0);
    }
  } else {
    const std::int64_t v = (kind & 2) ? in.take<std::int64_t>() : static_cast<std::int8_t>(in.take<std::uint8_t>());
    const sogmm_status s = sogmm_options_set_i64(o, key, v);
    check_status(s);
    std::int64_t after = 0;
    if (s == SOGMM_OK) {
      FUZZ_CHECK(sogmm_options_get_i64(o, key, &after) == SOGMM_OK);
      // An accepted value reads back as set, but for the documented "0 = the
      // default cap" of SOGMM_OPT_MAX_DECODED_BYTES (sogmm.h): it reads back
      // as the registry's default.
      sogmm_option_info info{};
      info.struct_size = sizeof info;
      const bool zero_means_default = key == SOGMM_OPT_MAX_DECODED_BYTES && v == 0 &&
                                      sogmm_option_get_info(key, &info) == SOGMM_OK;
      FUZZ_CHECK(after == (zero_means_default ? info.default_i64 : v));
    }
  }
}

void step_fit(State& st, sogmm_fuzz::Reader& in) {
  const int slot = in.take<std::uint8_t>() % kSlots;
  sogmm_options* o = work_options(st, in.take<std::uint8_t>());
  const std::uint8_t how = in.take<std::uint8_t>();
  const std::size_t n = in.take<std::uint8_t>() % kMaxPoints;
  const std::vector<float> pts = take_points(in, n);
  sogmm_model* m = reinterpret_cast<sogmm_model*>(1);
  sogmm_status s;
  if (how & 1) {
    const std::size_t k = (how >> 1) % 9;
    s = sogmm_test::fit_fixed_k(&m, pts.data(), n, k, o);
  } else {
    // The mode count can find many components in a small noisy cloud: a larger bandwidth keeps steps cheap.
    double bw = 0.02;
    if (sogmm_options_get_f64(o, SOGMM_OPT_BANDWIDTH, &bw) == SOGMM_OK && bw < 0.01)
      FUZZ_CHECK(sogmm_options_set_f64(o, SOGMM_OPT_BANDWIDTH, 0.01) == SOGMM_OK);
    s = sogmm_fit_points_f32(&m, pts.data(), n, nullptr, o);
  }
  check_created(s, m);
  if (s == SOGMM_OK) put(st, slot, m);
}

void step_from_arrays(State& st, sogmm_fuzz::Reader& in) {
  const int slot = in.take<std::uint8_t>() % kSlots;
  const std::size_t m = 1 + in.take<std::uint8_t>() % 6;
  std::vector<float> w(m), mu(4 * m), cov(16 * m);
  const std::uint8_t raw = in.take<std::uint8_t>();
  for (std::size_t k = 0; k < m; ++k) {
    w[k] = 1.0f / static_cast<float>(m);
    for (int i = 0; i < 4; ++i) mu[4 * k + i] = take_float(in);
    // A diagonal-dominant SPD start, perturbed symmetrically by the input.
    for (int i = 0; i < 4; ++i) cov[16 * k + 5 * i] = 1e-2f + std::fabs(take_float(in));
    const int i = in.take<std::uint8_t>() % 4, j = (i + 1) % 4;
    const float off = take_float(in) * 1e-3f;
    cov[16 * k + 4 * i + j] = cov[16 * k + 4 * j + i] = off;
  }
  // Raw overrides anywhere (NaN, negative weights, asymmetric covariances ...).
  for (int r = 0; r < (raw & 7); ++r) {
    const std::uint16_t at = in.take<std::uint16_t>();
    const float v = in.take<float>();
    switch (at % 3) {
      case 0: w[at / 3 % m] = v; break;
      case 1: mu[at / 3 % (4 * m)] = v; break;
      default: cov[at / 3 % (16 * m)] = v; break;
    }
  }
  const std::uint64_t support = (raw & 8) ? in.take<std::uint64_t>() : in.take<std::uint8_t>();
  sogmm_model* out = reinterpret_cast<sogmm_model*>(1);
  const sogmm_status s = sogmm_model_from_arrays_f32(&out, m, w.data(), mu.data(), cov.data(), support);
  check_created(s, out);
  if (s == SOGMM_OK) put(st, slot, out);
}

void step_info(State& st, sogmm_fuzz::Reader& in) {
  const sogmm_model* m = st.models[in.take<std::uint8_t>() % kSlots];
  const sogmm_key key = take_key(in);
  double f = 0;
  std::int64_t i = 0;
  check_status(sogmm_model_get_info_f64(m, key, &f));
  check_status(sogmm_model_get_info_i64(m, key, &i));
  std::size_t count = 0;
  if (m && sogmm_model_value_count(m, &count) == SOGMM_OK) {
    for (std::size_t k = 0; k <= count; ++k) {
      const char *key_out = nullptr, *value_out = nullptr;
      const sogmm_status s = sogmm_model_value_at(m, k, &key_out, &value_out);
      check_status(s);
      FUZZ_CHECK((s == SOGMM_OK) == (k < count));
      if (s == SOGMM_OK) FUZZ_CHECK(key_out && value_out && key_out[0] != '\0');
    }
  }
}

void step_metadata(State& st, sogmm_fuzz::Reader& in) {
  sogmm_model* m = st.models[in.take<std::uint8_t>() % kSlots];
  const std::string key = take_string(in), value = take_string(in);
  const sogmm_status s = sogmm_model_set_value(m, key.c_str(), value.c_str());
  check_status(s);
  if (s == SOGMM_OK) {
    const char* got = nullptr;
    FUZZ_CHECK(sogmm_model_get_value(m, key.c_str(), &got) == SOGMM_OK);
    FUZZ_CHECK(got && value == got);
  }
}

void step_pose(State& st, sogmm_fuzz::Reader& in) {
  const int slot = in.take<std::uint8_t>() % kSlots;
  const std::uint8_t what = in.take<std::uint8_t>();
  const std::array<double, 16> pose = take_pose(in);
  sogmm_model* m = st.models[slot];
  switch (what % 4) {
    case 0: check_status(sogmm_model_set_pose(m, pose.data())); break;
    case 1: {
      double got[16];
      check_status(sogmm_model_get_pose(m, got));
      break;
    }
    case 2: check_status(sogmm_model_clear_pose(m)); break;
    default: {
      sogmm_model* out = reinterpret_cast<sogmm_model*>(1);
      const sogmm_status s = sogmm_model_transform(&out, m, pose.data());
      check_created(s, out);
      if (s == SOGMM_OK) put(st, (slot + 1) % kSlots, out);
    }
  }
}

void step_inference(State& st, sogmm_fuzz::Reader& in) {
  const sogmm_model* m = st.models[in.take<std::uint8_t>() % kSlots];
  const std::uint8_t what = in.take<std::uint8_t>();
  const bool huge = (what & 0x80) != 0;
  const std::size_t n = huge ? SIZE_MAX / 2 : in.take<std::uint8_t>() % kMaxPoints;
  const std::size_t n_alloc = huge ? 1 : n;
  switch (what % 3) {
    case 0: {
      const int32_t dims = (what & 8) ? 3 : (what & 16) ? in.take<std::int32_t>() : 4;
      sogmm_options* o = work_options(st, what >> 5);
      std::vector<float> out(4 * n_alloc + 4, 12345.0f);
      const sogmm_status s = sogmm_model_sample_f32(m, n, in.take<std::uint64_t>(), dims, o, out.data());
      check_status(s);
      FUZZ_CHECK(!(huge && s == SOGMM_OK));
      if (s == SOGMM_OK)
        for (std::size_t i = 0; i < n * static_cast<std::size_t>(dims); ++i) FUZZ_CHECK(std::isfinite(out[i]));
      break;
    }
    case 1: {
      const std::vector<float> xyz = take_points(in, n_alloc);  // 4 floats a point: room for 3
      std::vector<float> mean(n_alloc + 1), var(n_alloc + 1);
      const sogmm_status s = sogmm_model_regress_gray_f32(m, xyz.data(), n, nullptr, mean.data(), (what & 8) ? nullptr : var.data());
      check_status(s);
      FUZZ_CHECK(!(huge && s == SOGMM_OK));
      if (s == SOGMM_OK)
        for (std::size_t i = 0; i < n; ++i) FUZZ_CHECK(std::isfinite(mean[i]) && ((what & 8) || var[i] >= 0));
      break;
    }
    default: {
      const int32_t dims = (what & 8) ? 3 : 4;
      const std::vector<float> pts = take_points(in, n_alloc);
      std::vector<double> out(n_alloc + 1);
      const sogmm_status s = sogmm_model_score_samples_f32(m, pts.data(), n, dims, nullptr, out.data());
      check_status(s);
      FUZZ_CHECK(!(huge && s == SOGMM_OK));
      if (s == SOGMM_OK)
        for (std::size_t i = 0; i < n; ++i) FUZZ_CHECK(!std::isnan(out[i]) && out[i] != INFINITY);
    }
  }
}

void step_merge(State& st, sogmm_fuzz::Reader& in) {
  const int a = in.take<std::uint8_t>() % kSlots, b = in.take<std::uint8_t>() % kSlots;
  // Merging a model with itself doubles it: a program of merges alone would
  // reach millions of components, legitimately (maps grow), but slowly. Keep
  // each input cheap.
  std::size_t ma = 0, mb = 0;
  if (st.models[a] && st.models[b] && sogmm_model_n_components(st.models[a], &ma) == SOGMM_OK &&
      sogmm_model_n_components(st.models[b], &mb) == SOGMM_OK && ma + mb > kMaxMergedComponents)
    return;
  sogmm_model* out = reinterpret_cast<sogmm_model*>(1);
  const sogmm_status s = sogmm_model_merge(&out, st.models[a], st.models[b]);
  check_created(s, out);
  if (s == SOGMM_OK) put(st, in.take<std::uint8_t>() % kSlots, out);
}

std::vector<float> arrays_of(const sogmm_model* m) {
  std::size_t k = 0;
  FUZZ_CHECK(sogmm_model_n_components(m, &k) == SOGMM_OK);
  std::vector<float> a(21 * k);
  FUZZ_CHECK(sogmm_model_get_weights_f32(m, a.data(), k) == SOGMM_OK);
  FUZZ_CHECK(sogmm_model_get_means_f32(m, a.data() + k, 4 * k) == SOGMM_OK);
  FUZZ_CHECK(sogmm_model_get_covariances_f32(m, a.data() + 5 * k, 16 * k) == SOGMM_OK);
  return a;
}

// What a reader returns for the arrays of arrays_of(): every covariance
// replaced by its symmetric part, (a_ij + a_ji) / 2 rounded to float32
// (spec/format.md 5.1; the identity on a bit-symmetric matrix).
std::vector<float> as_read(std::vector<float> a) {
  const std::size_t k = a.size() / 21;
  for (std::size_t c = 0; c < k; ++c) {
    float* m = a.data() + 5 * k + 16 * c;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        m[4 * i + j] = m[4 * j + i] = static_cast<float>((double{m[4 * i + j]} + m[4 * j + i]) / 2.0);
  }
  return a;
}

void step_roundtrip(State& st, sogmm_fuzz::Reader& in) {
  const int slot = in.take<std::uint8_t>() % kSlots;
  const std::uint8_t what = in.take<std::uint8_t>();
  sogmm_options* o = work_options(st, what);
  const sogmm_model* m = st.models[slot];
  sogmm_buffer* buf = reinterpret_cast<sogmm_buffer*>(1);
  const sogmm_status s = sogmm_model_save_to_memory(&buf, m, o);
  check_status(s);
  if (s != SOGMM_OK) {
    FUZZ_CHECK(buf == nullptr);
    // A valid model is always writable (options only choose the encoding),
    // unless its arrays exceed a decoded-size cap the program set on `o`
    // (the writer keeps to the cap a reader with `o` would apply).
    std::int64_t cap = 0;
    FUZZ_CHECK(m == nullptr || (s == SOGMM_E_LIMIT && o != nullptr &&
                                sogmm_options_get_i64(o, SOGMM_OPT_MAX_DECODED_BYTES, &cap) == SOGMM_OK && cap > 0));
    return;
  }
  // Read back with default read options (the program may have set a tiny decoded-size cap on `o`).
  sogmm_model* back = reinterpret_cast<sogmm_model*>(1);
  const sogmm_status r = sogmm_model_load_from_memory(&back, sogmm_buffer_data(buf), sogmm_buffer_size(buf), nullptr);
  check_created(r, back);
  FUZZ_CHECK(r == SOGMM_OK);
  const std::vector<float> before = as_read(arrays_of(m)), after = arrays_of(back);
  FUZZ_CHECK(before.size() == after.size());
  FUZZ_CHECK(std::memcmp(before.data(), after.data(), before.size() * sizeof(float)) == 0);
  sogmm_model_free(back);
  sogmm_buffer_free(st.buffer);
  st.buffer = buf;
}

void step_load_bytes(State& st, sogmm_fuzz::Reader& in) {
  const int slot = in.take<std::uint8_t>() % kSlots;
  const std::uint8_t what = in.take<std::uint8_t>();
  std::vector<std::uint8_t> bytes;
  if (st.buffer && (what & 1)) {
    // The last saved file with a few bytes flipped.
    bytes.assign(sogmm_buffer_data(st.buffer), sogmm_buffer_data(st.buffer) + sogmm_buffer_size(st.buffer));
    for (int r = 0; r < 1 + (what >> 1) % 4 && !bytes.empty(); ++r) {
      const std::uint16_t at = in.take<std::uint16_t>();
      bytes[at % bytes.size()] ^= in.take<std::uint8_t>() | 1;
    }
  } else {
    const std::size_t len = in.take<std::uint8_t>();
    for (std::size_t i = 0; i < len; ++i) bytes.push_back(in.take<std::uint8_t>());
  }
  sogmm_model* m = reinterpret_cast<sogmm_model*>(1);
  const sogmm_status s =
      sogmm_model_load_from_memory(&m, bytes.empty() ? nullptr : bytes.data(), bytes.size(), nullptr);
  check_created(s, m);
  if (s == SOGMM_OK) put(st, slot, m);
}

void step_rgbd(State& st, sogmm_fuzz::Reader& in) {
  const int slot = in.take<std::uint8_t>() % kSlots;
  const std::uint8_t what = in.take<std::uint8_t>();
  const std::uint32_t w = 1 + in.take<std::uint8_t>() % 24, h = 1 + in.take<std::uint8_t>() % 24;
  const int32_t format = (what & 4) ? static_cast<int32_t>(in.take<std::uint8_t>() % 5) : SOGMM_COLOR_GRAY8;
  std::vector<std::uint16_t> depth(w * h);
  std::vector<std::uint8_t> color(w * h * 4 + 4);  // room for every format
  for (std::size_t i = 0; i < depth.size(); ++i) {
    const std::uint8_t b = in.take<std::uint8_t>();
    depth[i] = b == 0 ? 0 : static_cast<std::uint16_t>(900 + 4 * b);
    color[i] = b;
  }
  const double fx = (what & 8) ? take_double(in) : 20.0, fy = (what & 16) ? take_double(in) : 20.0;
  const double cx = (what & 32) ? take_double(in) : w / 2.0, cy = (what & 64) ? take_double(in) : h / 2.0;
  sogmm_options* o = work_options(st, what);
  // The frame from the arrays (format 0: no colour image when `what` & 128).
  sogmm_frame* frame = reinterpret_cast<sogmm_frame*>(1);
  const sogmm_status made = sogmm_frame_from_arrays(&frame, w, h, depth.data(),
                                                    (format == 0 && (what & 128)) ? nullptr : color.data(), format);
  check_status(made);
  if (made != SOGMM_OK) {
    FUZZ_CHECK(frame == nullptr);
    return;
  }
  FUZZ_CHECK(sogmm_frame_set_intrinsics(frame, fx, fy, cx, cy) == SOGMM_OK);
  if (what & 1) {
    std::size_t n_points = 777;
    std::vector<float> out(4 * w * h + 4, 12345.0f);
    const std::size_t capacity = (what & 2) ? out.size() : in.take<std::uint8_t>();
    const sogmm_status s = sogmm_frame_to_points_f32(out.data(), capacity, &n_points, frame, o);
    check_status(s);
    if (s == SOGMM_OK) {
      FUZZ_CHECK(n_points <= static_cast<std::size_t>(w) * h);
      for (std::size_t i = 0; i < 4 * n_points; ++i) FUZZ_CHECK(std::isfinite(out[i]));
    }
  } else {
    double bw = 0.02;
    if (sogmm_options_get_f64(o, SOGMM_OPT_BANDWIDTH, &bw) == SOGMM_OK && bw < 0.01)
      FUZZ_CHECK(sogmm_options_set_f64(o, SOGMM_OPT_BANDWIDTH, 0.01) == SOGMM_OK);
    sogmm_model* m = reinterpret_cast<sogmm_model*>(1);
    const sogmm_status s = sogmm_fit_frame(&m, frame, o);
    check_created(s, m);
    if (s == SOGMM_OK) put(st, slot, m);
  }
  sogmm_frame_free(frame);
}

void step_misc(State& st, sogmm_fuzz::Reader& in) {
  const std::uint8_t what = in.take<std::uint8_t>();
  const int slot = what % kSlots;
  switch ((what >> 2) % 4) {
    case 0: FUZZ_CHECK(sogmm_status_string(in.take<std::int32_t>()) != nullptr); break;
    case 1: {
      sogmm_model* out = reinterpret_cast<sogmm_model*>(1);
      const sogmm_status s = sogmm_model_clone(&out, st.models[slot]);
      check_created(s, out);
      if (s == SOGMM_OK) put(st, (slot + 1) % kSlots, out);
      break;
    }
    case 2: put(st, slot, nullptr); break;
    default: {
      sogmm_options* copy = reinterpret_cast<sogmm_options*>(1);
      const sogmm_status s = sogmm_options_clone(&copy, st.options[what & 1]);
      check_status(s);
      if (s == SOGMM_OK) {
        sogmm_options_free(st.options[(what >> 4) & 1]);
        st.options[(what >> 4) & 1] = copy;
      } else {
        FUZZ_CHECK(copy == nullptr);
      }
    }
  }
}

// After every step: every model that exists is valid.
void check_models(const State& st) {
  for (const sogmm_model* m : st.models)
    if (m) check_model(m);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const sogmm_fuzz::Step<State> steps[] = {
      {"set_option", step_set_option}, {"fit", step_fit},           {"from_arrays", step_from_arrays},
      {"info", step_info},             {"metadata", step_metadata}, {"pose", step_pose},
      {"inference", step_inference},   {"merge", step_merge},       {"roundtrip", step_roundtrip},
      {"load_bytes", step_load_bytes}, {"rgbd", step_rgbd},         {"misc", step_misc}};
  sogmm_fuzz::Reader in(data, size);
  State st;
  sogmm_fuzz::run_program(in, st, kMaxSteps, steps, check_models);
  return 0;
}
