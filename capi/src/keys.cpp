// The key table behind require_key(): one row per SOGMM_OPT_*, SOGMM_INFO_* and SOGMM_MAP_*.
#include "keys.hpp"

#include <cstring>
#include <iterator>
#include <vector>

namespace sogmm_capi {
namespace {

constexpr KeyKind O = KeyKind::Option, N = KeyKind::Info, M = KeyKind::MapStat, R = KeyKind::FrameStat;
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

#define SOGMM_MAP_KEY(key, kind, type) {key, #key, kind, type, nullptr}

// The map statistic keys (SOGMM_MAP_*): totals, then what one insert did.
const KeySpec kMapKeys[] = {
    SOGMM_MAP_KEY(SOGMM_MAP_N_COMPONENTS, M, I),
    SOGMM_MAP_KEY(SOGMM_MAP_N_PENDING, M, I),
    SOGMM_MAP_KEY(SOGMM_MAP_N_FRAMES, M, I),
    SOGMM_MAP_KEY(SOGMM_MAP_N_FLUSHES, M, I),
    SOGMM_MAP_KEY(SOGMM_MAP_N_FUSED, M, I),
    SOGMM_MAP_KEY(SOGMM_MAP_N_REFITS, M, I),
    SOGMM_MAP_KEY(SOGMM_MAP_REVISION, M, I),
    SOGMM_MAP_KEY(SOGMM_MAP_FRAME_N_POINTS, R, I),
    SOGMM_MAP_KEY(SOGMM_MAP_FRAME_N_NOVEL, R, I),
    SOGMM_MAP_KEY(SOGMM_MAP_FRAME_N_COMPONENTS, R, I),
    SOGMM_MAP_KEY(SOGMM_MAP_FRAME_FLUSHED, R, I),
    SOGMM_MAP_KEY(SOGMM_MAP_FRAME_N_REPLACED, R, I),
    SOGMM_MAP_KEY(SOGMM_MAP_FRAME_MS_NOVELTY, R, F),
    SOGMM_MAP_KEY(SOGMM_MAP_FRAME_MS_FIT, R, F),
    SOGMM_MAP_KEY(SOGMM_MAP_FRAME_MS_MERGE, R, F),
};

#undef SOGMM_MAP_KEY

// Every key: the registry's options, then the info and map keys.
const std::vector<KeySpec>& all_keys() {
  static const std::vector<KeySpec> keys = [] {
    std::vector<KeySpec> k;
    for (const sogmm::OptionSpec& o : sogmm::option_specs())
      k.push_back({static_cast<sogmm_key>(o.key), o.name, O, o.type == sogmm::OptionType::F64 ? F : I, &o});
    k.insert(k.end(), std::begin(kInfoKeys), std::end(kInfoKeys));
    k.insert(k.end(), std::begin(kMapKeys), std::end(kMapKeys));
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

// "option", "info", "map", "map frame": as in "unknown info key 7".
const char* kind_noun(KeyKind kind) {
  switch (kind) {
    case KeyKind::Option: return "option";
    case KeyKind::Info: return "info";
    case KeyKind::MapStat: return "map";
    case KeyKind::FrameStat: return "map frame";
  }
  return "unknown";
}

// The noun with its article, as in "key K is an info key".
std::string kind_name(KeyKind kind) {
  const char* noun = kind_noun(kind);
  return (std::strchr("aeiou", noun[0]) != nullptr ? "an " : "a ") + std::string(noun);
}

// The function that takes a key of this kind and type (the map keys are
// read-only, so `verb` only matters for options and info keys).
std::string function_for(KeyKind kind, KeyType type, const char* verb) {
  switch (kind) {
    case KeyKind::Option: return std::string("sogmm_options_") + verb + "_" + type_name(type);
    case KeyKind::Info: return std::string("sogmm_model_") + verb + "_info_" + type_name(type);
    case KeyKind::MapStat: return std::string("sogmm_map_get_") + type_name(type);
    case KeyKind::FrameStat: return std::string("sogmm_map_frame_get_") + type_name(type);
  }
  return "";
}

}  // namespace

std::string key_label(sogmm_key key) {
  const KeySpec* k = find_key(key);
  return k ? std::to_string(key) + " (" + k->name + ")" : std::to_string(key);
}

const KeySpec& require_key(sogmm_key key, KeyKind kind, KeyType type, const char* verb) {
  const std::string wanted = kind_noun(kind);
  const KeySpec* k = find_key(key);
  if (k == nullptr) fail(SOGMM_E_INVALID_ARG, "unknown " + wanted + " key " + std::to_string(key));
  if (k->kind != kind) {
    fail(SOGMM_E_INVALID_ARG, "key " + key_label(key) + " is " + kind_name(k->kind) + " key, not " + kind_name(kind) +
                                  " key: use " + function_for(k->kind, k->type, verb));
  }
  if (k->type != type) {
    fail(SOGMM_E_INVALID_ARG, wanted + " key " + key_label(key) + " is " + type_name(k->type) +
                                  ": use " + function_for(k->kind, k->type, verb));
  }
  return *k;
}

}  // namespace sogmm_capi
