// The option, info and map statistic keys of the C API: number, name, kind and type of each,
// and the argument check every keyed function starts with. Never installed.
#pragma once

#include <cstdint>
#include <string>

#include "internal.hpp"
#include "sogmm/options.hpp"

namespace sogmm_capi {

/// Whether a key names a parameter (sogmm_options_*), a model's information
/// (sogmm_model_get_info_*), a map's totals (sogmm_map_get_i64) or what one
/// map insert did (sogmm_map_frame_get_*). The numbers are disjoint: options
/// are below 10000, info keys 10000 to 19999, map keys 20000 and up.
enum class KeyKind { Option, Info, MapStat, FrameStat };
/// The value type of a key.
enum class KeyType { F64, I64 };

/// A key of either kind. Option keys come from the core's option registry
/// (sogmm/options.hpp), whose row (`option`) holds their rule, default and
/// storage; info and map keys are listed in keys.cpp.
struct KeySpec {
  sogmm_key key;
  const char* name;  ///< the macro, e.g. "SOGMM_OPT_BANDWIDTH"
  KeyKind kind;
  KeyType type;
  const sogmm::OptionSpec* option;  ///< the registry row (option keys only)
};

/// The spec of `key` of `kind` and `type`. Otherwise SOGMM_E_INVALID_ARG with
/// a message naming the key and, for a known key of the wrong kind or type,
/// the function that takes it. `verb` is "set" or "get" for options (it names
/// the function to use instead); ignored for info keys.
const KeySpec& require_key(sogmm_key key, KeyKind kind, KeyType type, const char* verb);

/// "100 (SOGMM_OPT_BANDWIDTH)", or the bare number of an unknown key.
std::string key_label(sogmm_key key);

}  // namespace sogmm_capi
