// sogmm_options: enum-keyed parameters for fit, RGB-D, write, read, sample.
#include <cmath>
#include <string>

#include "internal.hpp"
#include "sogmm/fit.hpp"

namespace {

using sogmm_capi::fail;

enum class KeyType { None, F64, I64 };

KeyType key_type(sogmm_key key) {
  switch (key) {
    case SOGMM_OPT_BANDWIDTH:
    case SOGMM_OPT_TOL:
    case SOGMM_OPT_REG_COVAR:
    case SOGMM_OPT_DEPTH_SCALE:
    case SOGMM_OPT_DEPTH_MIN:
    case SOGMM_OPT_DEPTH_MAX:
    case SOGMM_OPT_SAMPLE_TRUNCATION:
    case SOGMM_OPT_TRUNCATION_NATS:
      return KeyType::F64;
    case SOGMM_OPT_N_COMPONENTS:
    case SOGMM_OPT_MAX_ITER:
    case SOGMM_OPT_SEED:
    case SOGMM_OPT_THREADS:
    case SOGMM_OPT_N_INIT:
    case SOGMM_OPT_MODE_COUNTER:
    case SOGMM_OPT_DECIMATION:
    case SOGMM_OPT_ZSTD_LEVEL:
    case SOGMM_OPT_FLOAT64:
    case SOGMM_OPT_COMPRESS:
    case SOGMM_OPT_MAX_DECODED_BYTES:
    case SOGMM_OPT_VERIFY_CHECKSUMS:
      return KeyType::I64;
    default:
      return KeyType::None;
  }
}

void require_type(sogmm_key key, KeyType wanted) {
  const KeyType t = key_type(key);
  if (t == KeyType::None) fail(SOGMM_E_INVALID_ARG, "unknown option key " + std::to_string(key));
  if (t != wanted)
    fail(SOGMM_E_INVALID_ARG, "option key " + std::to_string(key) + " is " +
                                  (t == KeyType::F64 ? "f64: use sogmm_options_*_f64"
                                                     : "i64: use sogmm_options_*_i64"));
}

void out_of_range(sogmm_key key, const std::string& value, const char* range) {
  fail(SOGMM_E_INVALID_ARG,
       "option key " + std::to_string(key) + ": value " + value + " out of range (" + range + ")");
}

void check_i64(sogmm_key key, std::int64_t v, std::int64_t lo, std::int64_t hi, const char* range) {
  if (v < lo || v > hi) out_of_range(key, std::to_string(v), range);
}

void check_f64(sogmm_key key, double v, bool ok, const char* range) {
  if (std::isnan(v) || !ok) out_of_range(key, std::to_string(v), range);
}

double* f64_slot(sogmm_options& o, sogmm_key key) {
  switch (key) {
    case SOGMM_OPT_BANDWIDTH: return &o.bandwidth;
    case SOGMM_OPT_TOL: return &o.tol;
    case SOGMM_OPT_REG_COVAR: return &o.reg_covar;
    case SOGMM_OPT_DEPTH_SCALE: return &o.depth_scale;
    case SOGMM_OPT_DEPTH_MIN: return &o.depth_min;
    case SOGMM_OPT_DEPTH_MAX: return &o.depth_max;
    case SOGMM_OPT_SAMPLE_TRUNCATION: return &o.sample_truncation;
    case SOGMM_OPT_TRUNCATION_NATS: return &o.truncation_nats;
    default: return nullptr;
  }
}

std::int64_t* i64_slot(sogmm_options& o, sogmm_key key) {
  switch (key) {
    case SOGMM_OPT_N_COMPONENTS: return &o.n_components;
    case SOGMM_OPT_MAX_ITER: return &o.max_iter;
    case SOGMM_OPT_SEED: return &o.seed;
    case SOGMM_OPT_THREADS: return &o.threads;
    case SOGMM_OPT_N_INIT: return &o.n_init;
    case SOGMM_OPT_MODE_COUNTER: return &o.mode_counter;
    case SOGMM_OPT_DECIMATION: return &o.decimation;
    case SOGMM_OPT_ZSTD_LEVEL: return &o.zstd_level;
    case SOGMM_OPT_FLOAT64: return &o.float64;
    case SOGMM_OPT_COMPRESS: return &o.compress;
    case SOGMM_OPT_MAX_DECODED_BYTES: return &o.max_decoded_bytes;
    case SOGMM_OPT_VERIFY_CHECKSUMS: return &o.verify_checksums;
    default: return nullptr;
  }
}

}  // namespace

namespace sogmm_capi {
const sogmm_options& default_options() {
  static const sogmm_options defaults{};
  return defaults;
}
}  // namespace sogmm_capi

extern "C" {

SOGMM_API sogmm_status sogmm_options_create(sogmm_options** out) {
  SOGMM_TRY {
    sogmm_capi::reset_out(out);
    sogmm_capi::require_nonnull(out, "out");
    *out = new sogmm_options();
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_options_clone(sogmm_options** out, const sogmm_options* src) {
  SOGMM_TRY {
    sogmm_capi::reset_out(out);
    sogmm_capi::require_nonnull(out, "out");
    sogmm_capi::require_nonnull(src, "src");
    *out = new sogmm_options(*src);
  }
  SOGMM_CATCH
}

SOGMM_API void sogmm_options_free(sogmm_options* options) { delete options; }

SOGMM_API sogmm_status sogmm_options_set_f64(sogmm_options* options, sogmm_key key, double v) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(options, "options");
    require_type(key, KeyType::F64);
    switch (key) {
      case SOGMM_OPT_BANDWIDTH: check_f64(key, v, std::isfinite(v) && v > 0, "> 0, finite"); break;
      case SOGMM_OPT_TOL: check_f64(key, v, std::isfinite(v) && v > 0, "> 0, finite"); break;
      case SOGMM_OPT_REG_COVAR: check_f64(key, v, std::isfinite(v) && v >= 0, ">= 0, finite"); break;
      case SOGMM_OPT_DEPTH_SCALE: check_f64(key, v, std::isfinite(v) && v > 0, "> 0, finite"); break;
      case SOGMM_OPT_DEPTH_MIN: check_f64(key, v, std::isfinite(v) && v >= 0, ">= 0, finite"); break;
      case SOGMM_OPT_DEPTH_MAX: check_f64(key, v, std::isfinite(v) && v > 0, "> 0, finite"); break;
      case SOGMM_OPT_SAMPLE_TRUNCATION: check_f64(key, v, v > 0, "> 0"); break;
      case SOGMM_OPT_TRUNCATION_NATS: check_f64(key, v, std::isfinite(v) && v >= 0, ">= 0, finite"); break;
      default: break;
    }
    *f64_slot(*options, key) = v;
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_options_set_i64(sogmm_options* options, sogmm_key key, int64_t v) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(options, "options");
    require_type(key, KeyType::I64);
    constexpr std::int64_t kInt32Max = 2147483647;
    constexpr std::int64_t kI64Max = std::numeric_limits<std::int64_t>::max();
    switch (key) {
      case SOGMM_OPT_N_COMPONENTS: check_i64(key, v, 0, kI64Max, ">= 0"); break;
      case SOGMM_OPT_MAX_ITER: check_i64(key, v, 1, kInt32Max, "[1, 2^31-1]"); break;
      case SOGMM_OPT_SEED: break;
      case SOGMM_OPT_THREADS: check_i64(key, v, 0, 4096, "[0, 4096]"); break;
      case SOGMM_OPT_N_INIT: check_i64(key, v, 1, sogmm::kMaxRuns, "[1, 1000]"); break;
      case SOGMM_OPT_MODE_COUNTER: check_i64(key, v, 0, 1, "a SOGMM_MODE_COUNTER_* value"); break;
      case SOGMM_OPT_DECIMATION: check_i64(key, v, 1, 1024, "[1, 1024]"); break;
      case SOGMM_OPT_ZSTD_LEVEL: check_i64(key, v, 1, 22, "[1, 22]"); break;
      case SOGMM_OPT_FLOAT64:
      case SOGMM_OPT_COMPRESS:
      case SOGMM_OPT_VERIFY_CHECKSUMS: check_i64(key, v, 0, 1, "0 or 1"); break;
      case SOGMM_OPT_MAX_DECODED_BYTES: check_i64(key, v, 0, kI64Max, ">= 0"); break;
      default: break;
    }
    *i64_slot(*options, key) = v;
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_options_get_f64(const sogmm_options* options, sogmm_key key, double* out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(options, "options");
    sogmm_capi::require_nonnull(out, "out");
    require_type(key, KeyType::F64);
    *out = *f64_slot(const_cast<sogmm_options&>(*options), key);
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_options_get_i64(const sogmm_options* options, sogmm_key key, int64_t* out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(options, "options");
    sogmm_capi::require_nonnull(out, "out");
    require_type(key, KeyType::I64);
    *out = *i64_slot(const_cast<sogmm_options&>(*options), key);
  }
  SOGMM_CATCH
}

}  // extern "C"
