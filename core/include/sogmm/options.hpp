// The one option registry of the library. Every setting a user can make,
// from C (sogmm_options_set_*), Python, Rust, Go or the CLI, is one field of
// Settings below plus one row of the table behind option_specs(): its key,
// name, type, accepted values, unit and meaning. The default of a setting is
// the value its field is initialised with, read from a default Settings and
// never written again: the C API's options handle stores a Settings, its
// introspection call (sogmm_option_info) reports the table, and the copies
// that cannot read it at run time (sogmm.h's SOGMM_OPT_* macros and their
// documentation, spec/api.md's option tables, the Rust, Python and Go key
// constants) are generated from it (tools/options/regenerate.py; ctest
// options_registry fails while one is stale).
//
// Adding an option: a field in the struct it belongs to (with its default
// and doc comment), a key below, and a row in core/src/option_table.cpp;
// then `cmake --build build --target sogmm-option-mirrors &&
// python3 tools/options/regenerate.py`.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sogmm/camera.hpp"
#include "sogmm/file_options.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/map.hpp"
#include "sogmm/map_tracking.hpp"
#include "sogmm/occupancy.hpp"
#include "sogmm/registration.hpp"
#include "sogmm/render.hpp"
#include "sogmm/surface_distance.hpp"
#include "sogmm/warm_start.hpp"

namespace sogmm {

/// How sample() draws.
struct SampleOptions {
  /// Each standard-normal coordinate is truncated to (-truncation,
  /// truncation); infinity = untruncated.
  double truncation = kDefaultSampleTruncation;
};

/// Every user setting, composed of the core's option structs. A map's fit
/// and back-projection are `fit` and `depth` (map.fit and map.depth are not
/// read here; map_options() fills them).
struct Settings {
  FitOptions fit;
  /// A warm start's rule (fits given an initial model); only its pass cap
  /// is a setting (WARM_MAX_ITER).
  WarmStartOptions warm;
  DepthOptions depth;
  format::WriteOptions write;
  format::ReadOptions read;
  SampleOptions sample;
  QueryOptions query;
  MapOptions map;
  OccupancyOptions occupancy;
  SurfaceDistanceOptions surface;
  RegistrationOptions registration;
  TrackingOptions tracking;
  /// Renders: only surface_sigma is a setting here; a render's depth range
  /// is `depth` and its threads `query.threads` (one setting each).
  RenderOptions render;
};

/// The MapOptions of `s`: s.map with s.fit and s.depth. Throws as
/// validate(MapOptions) (e.g. depth_min >= depth_max).
MapOptions map_options(const Settings& s);

/// The key of each setting: the numbers and (after SOGMM_OPT_) the names of
/// sogmm.h's SOGMM_OPT_* (stable; grouped by hundreds: fit, RGB-D, write,
/// read, sample and query, map, occupancy and distance, registration and tracking).
enum class OptionKey : int {
  BANDWIDTH = 100,
  N_COMPONENTS = 101,
  TOL = 102,
  REG_COVAR = 103,
  MAX_ITER = 104,
  SEED = 105,
  THREADS = 106,
  MODE_COUNTER = 107,
  TRUNCATION_NATS = 108,
  N_INIT = 109,
  DEQUANTISE_DEPTH = 110,
  EM_ACCELERATION = 111,
  TOL_STANDARD_ERRORS = 131,
  WARM_MAX_ITER = 145,
  DEPTH_SCALE = 200,
  DEPTH_MIN = 201,
  DEPTH_MAX = 202,
  DECIMATION = 203,
  ZSTD_LEVEL = 300,
  FLOAT64 = 301,
  COMPRESS = 302,
  ARRAY_PRECISION = 303,
  MAX_DECODED_BYTES = 400,
  VERIFY_CHECKSUMS = 401,
  SAMPLE_TRUNCATION = 500,
  QUERY_TRUNCATION_NATS = 501,
  RENDER_SURFACE_SIGMA = 502,
  MAP_NOVELTY = 600,
  MAP_NOVELTY_THRESHOLD = 601,
  MAP_BATCH_SIZE = 602,
  MAP_FUSION = 603,
  MAP_FUSION_METHOD = 604,
  MAP_FUSION_THRESHOLD = 605,
  MAP_WARM_START = 606,
  MAP_NOVELTY_BANDWIDTH_SCALE = 607,
  MAP_REVISIT_REFIT_RATIO = 608,
  MAP_DELTA_HISTORY = 609,
  MAP_FREE_SPACE_CARVE = 620,
  MAP_COMPONENT_PRECISION = 630,
  OCCUPANCY_SIGMA = 700,
  OCCUPANCY_THICKNESS = 701,
  SURFACE_DISC_SIGMAS = 702,
  REGISTRATION_MAX_ITER = 800,
  REGISTRATION_TOL = 801,
  REGISTRATION_OUTLIER_RATIO = 802,
  REGISTRATION_USE_GRAY = 803,
  REGISTRATION_LEVELS = 804,
  REGISTRATION_COARSE_SIGMA = 805,
  REGISTRATION_MIN_INLIER_RATIO = 806,
  REGISTRATION_DEGENERACY_RATIO = 807,
  REGISTRATION_MIN_POINTS = 808,
  REGISTRATION_DEPTH_NOISE = 809,
  TRACKING_ODOMETRY = 810,
  TRACKING_MAX_DISAGREEMENT = 811,
};

/// The value type of a setting (sogmm.h: SOGMM_TYPE_F64 = 0, SOGMM_TYPE_I64 = 1).
enum class OptionType : int { F64 = 0, I64 = 1 };

/// One row of the registry. Bounds are the closed hull of the accepted values
/// (for an F64 row also the I64 pair, rounded inward; for an I64 row the F64
/// pair is the I64 one as doubles); `accepts` adds what a hull cannot say
/// (a sentinel, a derived finiteness), `range` says the whole rule in words.
struct OptionSpec {
  OptionKey key;
  const char* name;   ///< the C macro, e.g. "SOGMM_OPT_BANDWIDTH"
  OptionType type;
  double lower;       ///< F64 rows: smallest accepted value (may be -inf)
  double upper;       ///< F64 rows: largest accepted value (may be +inf)
  std::int64_t lower_i64;  ///< I64 rows: smallest accepted value
  std::int64_t upper_i64;  ///< I64 rows: largest accepted value
  const char* range;  ///< the accepted values in words, e.g. "> 0, finite"
  const char* unit;   ///< e.g. "m", "nats", "" when dimensionless
  const char* doc;    ///< what the setting does, complete: sogmm.h and spec/api.md document the key with it
  bool (*accepts_f64)(double);        ///< F64 rows: the whole rule
  bool (*accepts_i64)(std::int64_t);  ///< I64 rows: the whole rule
  double (*get_f64)(const Settings&);
  void (*set_f64)(Settings&, double);
  std::int64_t (*get_i64)(const Settings&);
  void (*set_i64)(Settings&, std::int64_t);
};

/// Every row, in key order.
const std::vector<OptionSpec>& option_specs();

/// The row of `key`, or nullptr.
const OptionSpec* find_option(int key);

/// The default of a row: its value in a default Settings.
double default_f64(const OptionSpec& spec);
std::int64_t default_i64(const OptionSpec& spec);

/// Sets one setting after checking it against its row. Throws
/// Error(InvalidArgument) "option key 102 (SOGMM_OPT_TOL): value -1 out of
/// range (>= 0, finite)" when the value is not accepted.
void set_option(Settings& settings, const OptionSpec& spec, double value);
void set_option(Settings& settings, const OptionSpec& spec, std::int64_t value);

/// Throws Error(InvalidArgument) naming `name` and the rule of `key`'s row
/// unless the row accepts `value`: the one check of a setting, for the core's
/// own validate() functions as for the C API's setters.
void require_option(OptionKey key, double value, const std::string& name);
void require_option(OptionKey key, std::int64_t value, const std::string& name);

}  // namespace sogmm
