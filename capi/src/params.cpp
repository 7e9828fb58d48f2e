// sogmm_options: enum-keyed parameters for fit, RGB-D, write, read, sample.
#include <cstddef>
#include <cstring>
#include <string>
#include <vector>

#include "internal.hpp"
#include "keys.hpp"
#include "sogmm/fit.hpp"

using sogmm_capi::KeyKind;
using sogmm_capi::KeyType;

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
    sogmm_capi::require_out(out);
    *out = new sogmm_options();
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_options_clone(sogmm_options** out, const sogmm_options* src) {
  SOGMM_TRY {
    sogmm_capi::require_out(out);
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
    sogmm::set_option(options->settings, *spec.option, v);
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_options_set_i64(sogmm_options* options, sogmm_key key, int64_t v) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(options, "options");
    const sogmm_capi::KeySpec& spec = sogmm_capi::require_key(key, KeyKind::Option, KeyType::I64, "set");
    sogmm::set_option(options->settings, *spec.option, std::int64_t{v});
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_options_get_f64(const sogmm_options* options, sogmm_key key, double* out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(options, "options");
    sogmm_capi::require_nonnull(out, "out");
    *out = sogmm_capi::require_key(key, KeyKind::Option, KeyType::F64, "get").option->get_f64(options->settings);
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_options_get_i64(const sogmm_options* options, sogmm_key key, int64_t* out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(options, "options");
    sogmm_capi::require_nonnull(out, "out");
    *out = sogmm_capi::require_key(key, KeyKind::Option, KeyType::I64, "get").option->get_i64(options->settings);
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_option_keys(sogmm_key* keys, size_t capacity, size_t* count) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(count, "count");
    const std::vector<sogmm::OptionSpec>& specs = sogmm::option_specs();
    *count = specs.size();
    if (capacity > 0) sogmm_capi::require_nonnull(keys, "keys");
    for (std::size_t i = 0; i < specs.size() && i < capacity; ++i) keys[i] = static_cast<sogmm_key>(specs[i].key);
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_option_get_info(sogmm_key key, sogmm_option_info* out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(out, "out");
    if (out->struct_size < offsetof(sogmm_option_info, doc) + sizeof(out->doc))
      sogmm_capi::fail(SOGMM_E_INVALID_ARG, "out->struct_size " + std::to_string(out->struct_size) +
                                                " is smaller than this library's sogmm_option_info (" +
                                                std::to_string(sizeof(sogmm_option_info)) +
                                                " bytes): set it to sizeof(sogmm_option_info)");
    const sogmm::OptionSpec* spec = sogmm::find_option(key);
    if (!spec) sogmm_capi::fail(SOGMM_E_INVALID_ARG, "unknown option key " + std::to_string(key));
    // Fields past this library's struct are the caller's: only ours are written.
    sogmm_option_info info{};
    info.struct_size = out->struct_size;
    info.key = key;
    info.name = spec->name;
    info.type = spec->type == sogmm::OptionType::F64 ? SOGMM_TYPE_F64 : SOGMM_TYPE_I64;
    if (spec->type == sogmm::OptionType::F64) {
      info.default_f64 = sogmm::default_f64(*spec);
      info.default_i64 = 0;
      info.lower_i64 = info.upper_i64 = 0;
    } else {
      info.default_i64 = sogmm::default_i64(*spec);
      info.default_f64 = static_cast<double>(info.default_i64);
      info.lower_i64 = spec->lower_i64;
      info.upper_i64 = spec->upper_i64;
    }
    info.lower_f64 = spec->lower;
    info.upper_f64 = spec->upper;
    info.range = spec->range;
    info.unit = spec->unit;
    info.doc = spec->doc;
    std::memcpy(out, &info, sizeof(info));
  }
  SOGMM_CATCH
}

}  // extern "C"
