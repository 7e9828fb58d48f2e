// The key table behind require_key(): one row per SOGMM_OPT_* and SOGMM_INFO_*.
#include "keys.hpp"

namespace sogmm_capi {
namespace {

constexpr KeyKind O = KeyKind::Option, N = KeyKind::Info;
constexpr KeyType F = KeyType::F64, I = KeyType::I64;

#define SOGMM_F64_OPTION(key, field) {key, #key, O, F, &sogmm_options::field, nullptr}
#define SOGMM_I64_OPTION(key, field) {key, #key, O, I, nullptr, &sogmm_options::field}
#define SOGMM_INFO(key, type) {key, #key, N, type, nullptr, nullptr}

const KeySpec kKeys[] = {
    SOGMM_F64_OPTION(SOGMM_OPT_BANDWIDTH, bandwidth),
    SOGMM_I64_OPTION(SOGMM_OPT_N_COMPONENTS, n_components),
    SOGMM_F64_OPTION(SOGMM_OPT_TOL, tol),
    SOGMM_F64_OPTION(SOGMM_OPT_REG_COVAR, reg_covar),
    SOGMM_I64_OPTION(SOGMM_OPT_MAX_ITER, max_iter),
    SOGMM_I64_OPTION(SOGMM_OPT_SEED, seed),
    SOGMM_I64_OPTION(SOGMM_OPT_THREADS, threads),
    SOGMM_I64_OPTION(SOGMM_OPT_MODE_COUNTER, mode_counter),
    SOGMM_F64_OPTION(SOGMM_OPT_TRUNCATION_NATS, truncation_nats),
    SOGMM_I64_OPTION(SOGMM_OPT_N_INIT, n_init),
    SOGMM_I64_OPTION(SOGMM_OPT_DEQUANTISE_DEPTH, dequantise_depth),
    SOGMM_F64_OPTION(SOGMM_OPT_DEPTH_SCALE, depth_scale),
    SOGMM_F64_OPTION(SOGMM_OPT_DEPTH_MIN, depth_min),
    SOGMM_F64_OPTION(SOGMM_OPT_DEPTH_MAX, depth_max),
    SOGMM_I64_OPTION(SOGMM_OPT_DECIMATION, decimation),
    SOGMM_I64_OPTION(SOGMM_OPT_ZSTD_LEVEL, zstd_level),
    SOGMM_I64_OPTION(SOGMM_OPT_FLOAT64, float64),
    SOGMM_I64_OPTION(SOGMM_OPT_COMPRESS, compress),
    SOGMM_I64_OPTION(SOGMM_OPT_MAX_DECODED_BYTES, max_decoded_bytes),
    SOGMM_I64_OPTION(SOGMM_OPT_VERIFY_CHECKSUMS, verify_checksums),
    SOGMM_F64_OPTION(SOGMM_OPT_SAMPLE_TRUNCATION, sample_truncation),
    SOGMM_F64_OPTION(SOGMM_OPT_QUERY_TRUNCATION_NATS, query_truncation_nats),
    SOGMM_I64_OPTION(SOGMM_OPT_MAP_NOVELTY, map_novelty),
    SOGMM_F64_OPTION(SOGMM_OPT_MAP_NOVELTY_THRESHOLD, map_novelty_threshold),
    SOGMM_F64_OPTION(SOGMM_OPT_MAP_NOVELTY_BANDWIDTH_SCALE, map_novelty_bandwidth_scale),
    SOGMM_F64_OPTION(SOGMM_OPT_MAP_REVISIT_REFIT_RATIO, map_revisit_refit_ratio),
    SOGMM_I64_OPTION(SOGMM_OPT_MAP_BATCH_SIZE, map_batch_size),
    SOGMM_I64_OPTION(SOGMM_OPT_MAP_FUSION, map_fusion),
    SOGMM_I64_OPTION(SOGMM_OPT_MAP_FUSION_METHOD, map_fusion_method),
    SOGMM_F64_OPTION(SOGMM_OPT_MAP_FUSION_THRESHOLD, map_fusion_threshold),
    SOGMM_I64_OPTION(SOGMM_OPT_MAP_WARM_START, map_warm_start),
    SOGMM_INFO(SOGMM_INFO_SUPPORT_SIZE, I),
    SOGMM_INFO(SOGMM_INFO_CREATED_UNIX_MS, I),
    SOGMM_INFO(SOGMM_INFO_FIT_ITERATIONS, I),
    SOGMM_INFO(SOGMM_INFO_FIT_CONVERGED, I),
    SOGMM_INFO(SOGMM_INFO_FIT_LOG_LIKELIHOOD, F),
    SOGMM_INFO(SOGMM_INFO_FIT_BANDWIDTH, F),
    SOGMM_INFO(SOGMM_INFO_FIT_N_COMPONENTS_REQUESTED, I),
    SOGMM_INFO(SOGMM_INFO_FIT_TOL, F),
    SOGMM_INFO(SOGMM_INFO_FIT_REG_COVAR, F),
    SOGMM_INFO(SOGMM_INFO_FIT_MAX_ITER, I),
    SOGMM_INFO(SOGMM_INFO_FIT_SEED, I),
    SOGMM_INFO(SOGMM_INFO_FIT_N_POINTS, I),
    SOGMM_INFO(SOGMM_INFO_FIT_SECONDS_MODE_COUNT, F),
    SOGMM_INFO(SOGMM_INFO_FIT_SECONDS_SEEDING, F),
    SOGMM_INFO(SOGMM_INFO_FIT_SECONDS_EM, F),
    SOGMM_INFO(SOGMM_INFO_FIT_SECONDS_TOTAL, F),
    SOGMM_INFO(SOGMM_INFO_FIT_N_INIT, I),
    SOGMM_INFO(SOGMM_INFO_FIT_RUN, I),
    SOGMM_INFO(SOGMM_INFO_CAMERA_WIDTH, I),
    SOGMM_INFO(SOGMM_INFO_CAMERA_HEIGHT, I),
    SOGMM_INFO(SOGMM_INFO_CAMERA_FX, F),
    SOGMM_INFO(SOGMM_INFO_CAMERA_FY, F),
    SOGMM_INFO(SOGMM_INFO_CAMERA_CX, F),
    SOGMM_INFO(SOGMM_INFO_CAMERA_CY, F),
    SOGMM_INFO(SOGMM_INFO_CAMERA_DECIMATION, I),
    SOGMM_INFO(SOGMM_INFO_CAMERA_DEPTH_SCALE, F),
    SOGMM_INFO(SOGMM_INFO_CAMERA_DEPTH_MIN, F),
    SOGMM_INFO(SOGMM_INFO_CAMERA_DEPTH_MAX, F),
};

#undef SOGMM_F64_OPTION
#undef SOGMM_I64_OPTION
#undef SOGMM_INFO

const KeySpec* find_key(sogmm_key key) {
  for (const KeySpec& k : kKeys) {
    if (k.key == key) return &k;
  }
  return nullptr;
}

const char* type_name(KeyType t) { return t == KeyType::F64 ? "f64" : "i64"; }

// The function that takes a key of this kind and type.
std::string function_for(KeyKind kind, KeyType type, const char* verb) {
  return kind == KeyKind::Option ? std::string("sogmm_options_") + verb + "_" + type_name(type)
                                 : std::string("sogmm_model_") + verb + "_info_" + type_name(type);
}

}  // namespace

std::string key_label(sogmm_key key) {
  const KeySpec* k = find_key(key);
  return k ? std::to_string(key) + " (" + k->name + ")" : std::to_string(key);
}

const KeySpec& require_key(sogmm_key key, KeyKind kind, KeyType type, const char* verb) {
  const char* const wanted = kind == KeyKind::Option ? "option" : "info";
  const KeySpec* k = find_key(key);
  if (k == nullptr) fail(SOGMM_E_INVALID_ARG, std::string("unknown ") + wanted + " key " + std::to_string(key));
  if (k->kind != kind) {
    fail(SOGMM_E_INVALID_ARG, "key " + key_label(key) + " is " + (k->kind == KeyKind::Option ? "an option" : "an info") +
                                  " key, not " + (kind == KeyKind::Option ? "an option" : "an info") +
                                  " key: use " + function_for(k->kind, k->type, verb));
  }
  if (k->type != type) {
    fail(SOGMM_E_INVALID_ARG, std::string(wanted) + " key " + key_label(key) + " is " + type_name(k->type) +
                                  ": use " + function_for(k->kind, k->type, verb));
  }
  return *k;
}

}  // namespace sogmm_capi
