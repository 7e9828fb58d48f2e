// The key table behind require_key(): one row per SOGMM_OPT_* and SOGMM_INFO_*.
#include "keys.hpp"

#include <iterator>
#include <vector>

namespace sogmm_capi {
namespace {

constexpr KeyKind O = KeyKind::Option, N = KeyKind::Info;
constexpr KeyType F = KeyType::F64, I = KeyType::I64;

#define SOGMM_INFO(key, type) {key, #key, N, type, nullptr}

// The info keys (SOGMM_INFO_*): a model's information, not settings.
const KeySpec kInfoKeys[] = {
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

#undef SOGMM_INFO

// Every key: the registry's options, then the info keys.
const std::vector<KeySpec>& all_keys() {
  static const std::vector<KeySpec> keys = [] {
    std::vector<KeySpec> k;
    for (const sogmm::OptionSpec& o : sogmm::option_specs())
      k.push_back({static_cast<sogmm_key>(o.key), o.name, O, o.type == sogmm::OptionType::F64 ? F : I, &o});
    k.insert(k.end(), std::begin(kInfoKeys), std::end(kInfoKeys));
    return k;
  }();
  return keys;
}

const KeySpec* find_key(sogmm_key key) {
  for (const KeySpec& k : all_keys()) {
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
