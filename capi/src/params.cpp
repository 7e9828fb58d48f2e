// sogmm_options: enum-keyed parameters for fit, RGB-D, write, read, sample.
#include <cmath>
#include <string>

#include "internal.hpp"
#include "keys.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/fit.hpp"

namespace {

using sogmm_capi::fail;
using sogmm_capi::KeyKind;
using sogmm_capi::KeyType;

void out_of_range(sogmm_key key, const std::string& value, const char* range) {
  fail(SOGMM_E_INVALID_ARG,
       "option key " + sogmm_capi::key_label(key) + ": value " + value + " out of range (" + range + ")");
}

void check_i64(sogmm_key key, std::int64_t v, std::int64_t lo, std::int64_t hi, const char* range) {
  if (v < lo || v > hi) out_of_range(key, std::to_string(v), range);
}

void check_f64(sogmm_key key, double v, bool ok, const char* range) {
  if (std::isnan(v) || !ok) out_of_range(key, sogmm::checked::exact(v), range);
}

}  // namespace

// The C stages are the core's numbers (documented as stable there).
static_assert(static_cast<int>(sogmm::Stage::ModeCount) == SOGMM_STAGE_MODE_COUNT);
static_assert(static_cast<int>(sogmm::Stage::Seeding) == SOGMM_STAGE_SEEDING);
static_assert(static_cast<int>(sogmm::Stage::Em) == SOGMM_STAGE_EM);
static_assert(static_cast<int>(sogmm::Stage::Run) == SOGMM_STAGE_RUN);
static_assert(static_cast<int>(sogmm::Stage::Sampling) == SOGMM_STAGE_SAMPLING);

namespace sogmm_capi {
sogmm::ProgressSink progress_sink(const sogmm_options& o) {
  if (!o.progress) return {};
  return [fn = o.progress, user_data = o.progress_user_data](const sogmm::Progress& p) {
    return fn(static_cast<std::int32_t>(p.stage), p.step, p.total, p.log_likelihood, user_data) != 0;
  };
}

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

SOGMM_API sogmm_status sogmm_options_set_progress(sogmm_options* options, sogmm_progress_fn fn, void* user_data) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(options, "options");
    options->progress = fn;
    options->progress_user_data = fn ? user_data : nullptr;
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_options_set_f64(sogmm_options* options, sogmm_key key, double v) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(options, "options");
    const sogmm_capi::KeySpec& spec = sogmm_capi::require_key(key, KeyKind::Option, KeyType::F64, "set");
    switch (key) {
      case SOGMM_OPT_BANDWIDTH:
        check_f64(key, v, sogmm::bandwidth_is_usable(v), "> 0, finite, with bw^2, (3 bw)^2 and 1 / (2 bw^2) finite and nonzero");
        break;
      case SOGMM_OPT_TOL: check_f64(key, v, std::isfinite(v) && v > 0, "> 0, finite"); break;
      case SOGMM_OPT_REG_COVAR:
        // Added to float32 covariances: must be a finite float32 itself;
        // the sentinel SOGMM_REG_COVAR_AUTO (-1) restores the automatic floors.
        check_f64(key, v, v == SOGMM_REG_COVAR_AUTO || (std::isfinite(static_cast<float>(v)) && v >= 0),
                  ">= 0, finite in float32, or SOGMM_REG_COVAR_AUTO (-1)");
        break;
      case SOGMM_OPT_DEPTH_SCALE:
        // Depth is raw / scale, computed as raw * (1 / scale).
        check_f64(key, v, std::isfinite(v) && v > 0 && std::isfinite(1.0 / v), "> 0, finite, 1 / value finite");
        break;
      case SOGMM_OPT_DEPTH_MIN: check_f64(key, v, std::isfinite(v) && v >= 0, ">= 0, finite"); break;
      case SOGMM_OPT_DEPTH_MAX: check_f64(key, v, std::isfinite(v) && v > 0, "> 0, finite"); break;
      case SOGMM_OPT_SAMPLE_TRUNCATION: check_f64(key, v, v > 0, "> 0"); break;
      case SOGMM_OPT_TRUNCATION_NATS:
      case SOGMM_OPT_QUERY_TRUNCATION_NATS: check_f64(key, v, std::isfinite(v) && v >= 0, ">= 0, finite"); break;
      case SOGMM_OPT_MAP_NOVELTY_THRESHOLD: check_f64(key, v, std::isfinite(v), "finite"); break;
      case SOGMM_OPT_MAP_NOVELTY_BANDWIDTH_SCALE: check_f64(key, v, v > 0 && v <= 1, "in (0, 1]"); break;
      case SOGMM_OPT_MAP_REVISIT_REFIT_RATIO:
        check_f64(key, v, v == 0 || (std::isfinite(v) && v >= 1), "0 (off) or >= 1, finite");
        break;
      case SOGMM_OPT_MAP_FUSION_THRESHOLD: check_f64(key, v, std::isfinite(v) && v > 0, "> 0, finite"); break;
      default: break;
    }
    options->*spec.f64 = v;
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_options_set_i64(sogmm_options* options, sogmm_key key, int64_t v) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(options, "options");
    const sogmm_capi::KeySpec& spec = sogmm_capi::require_key(key, KeyKind::Option, KeyType::I64, "set");
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
      case SOGMM_OPT_DEQUANTISE_DEPTH:
        check_i64(key, v, SOGMM_DEQUANTISE_AUTO, 1, "SOGMM_DEQUANTISE_AUTO (-1), 0 or 1");
        break;
      case SOGMM_OPT_FLOAT64:
      case SOGMM_OPT_COMPRESS:
      case SOGMM_OPT_VERIFY_CHECKSUMS:
      case SOGMM_OPT_MAP_NOVELTY:
      case SOGMM_OPT_MAP_WARM_START:
      case SOGMM_OPT_MAP_FUSION: check_i64(key, v, 0, 1, "0 or 1"); break;
      case SOGMM_OPT_MAP_BATCH_SIZE: check_i64(key, v, 1, std::int64_t{1} << 26, "[1, 2^26]"); break;
      case SOGMM_OPT_MAP_FUSION_METHOD: check_i64(key, v, 0, 1, "a SOGMM_FUSION_* value"); break;
      case SOGMM_OPT_MAX_DECODED_BYTES: check_i64(key, v, 0, kI64Max, ">= 0"); break;
      default: break;
    }
    options->*spec.i64 = v;
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_options_get_f64(const sogmm_options* options, sogmm_key key, double* out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(options, "options");
    sogmm_capi::require_nonnull(out, "out");
    *out = options->*sogmm_capi::require_key(key, KeyKind::Option, KeyType::F64, "get").f64;
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_options_get_i64(const sogmm_options* options, sogmm_key key, int64_t* out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(options, "options");
    sogmm_capi::require_nonnull(out, "out");
    *out = options->*sogmm_capi::require_key(key, KeyKind::Option, KeyType::I64, "get").i64;
  }
  SOGMM_CATCH
}

}  // extern "C"
