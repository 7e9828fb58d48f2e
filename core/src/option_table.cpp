// The rows of the option registry (sogmm/options.hpp): one per setting. A
// row names its field once (the accessors), states its rule once (bounds,
// plus a predicate where a hull is not the whole rule) and documents it; the
// default is the field's initialiser.
#include <algorithm>
#include <cmath>
#include <limits>

#include "sogmm/mean_shift.hpp"
#include "sogmm/options.hpp"

namespace sogmm {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::int64_t kI64Max = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kI64Min = std::numeric_limits<std::int64_t>::min();
constexpr std::int64_t kInt32Max = std::numeric_limits<std::int32_t>::max();

bool finite(double v) { return std::isfinite(v); }
bool always_i64(std::int64_t) { return true; }

// An F64 row: the field's accessors (any arithmetic field), bounds, a
// predicate on top of them (`extra`, a lambda without captures).
#define SOGMM_F64_ROW(KEY, FIELD, LO, HI, EXTRA, RANGE, UNIT, DOC)                              \
  OptionSpec {                                                                                  \
    OptionKey::KEY, "SOGMM_OPT_" #KEY, OptionType::F64, LO, HI, 0, 0, RANGE, UNIT, DOC, EXTRA,  \
        nullptr, [](const Settings& s) { return static_cast<double>(s.FIELD); },                \
        [](Settings& s, double v) { s.FIELD = static_cast<decltype(s.FIELD)>(v); }, nullptr, nullptr \
  }
// An I64 row over an integer, bool or enum field.
#define SOGMM_I64_ROW(KEY, FIELD, LO, HI, RANGE, UNIT, DOC)                                           \
  OptionSpec {                                                                                        \
    OptionKey::KEY, "SOGMM_OPT_" #KEY, OptionType::I64, static_cast<double>(LO), static_cast<double>(HI), \
        LO, HI, RANGE, UNIT, DOC, nullptr, always_i64, nullptr, nullptr,                                  \
        [](const Settings& s) { return static_cast<std::int64_t>(s.FIELD); },                            \
        [](Settings& s, std::int64_t v) { s.FIELD = static_cast<decltype(s.FIELD)>(v); }                   \
  }

std::vector<OptionSpec> make_table() {
  std::vector<OptionSpec> t = {
      // ---- fit ----
      SOGMM_F64_ROW(
          BANDWIDTH, fit.bandwidth, 0.0, kInf, bandwidth_is_usable,
          "> 0, finite, with bw^2, (3 bw)^2 and 1 / (2 bw^2) finite and nonzero", "",
          "mean-shift bandwidth over the (range, gray) features: the one SOGMM parameter; it sets the number of components"),
      SOGMM_I64_ROW(N_COMPONENTS, fit.n_components, 0, kI64Max, ">= 0", "components",
                    "0: self-organizing (the mode count picks K); K > 0: a fixed-K fit without the mode count"),
      SOGMM_F64_ROW(TOL, fit.em.tol, 0.0, kInf, finite, ">= 0, finite", "nats per point",
                    "EM stops when the mean log-likelihood per point changes by less than this; 0 runs max_iter iterations"),
      // reg_covar: unset (automatic floors) is SOGMM_REG_COVAR_AUTO (-1).
      OptionSpec{OptionKey::REG_COVAR, "SOGMM_OPT_REG_COVAR", OptionType::F64, -1.0,
                 std::numeric_limits<float>::max(), 0, 0, ">= 0, finite in float32, or SOGMM_REG_COVAR_AUTO (-1)",
                 "data units squared",
                 "added to every covariance diagonal in each M-step; AUTO derives a spatial and a gray floor from "
                 "the data's scales",
                 [](double v) { return v == -1.0 || (std::isfinite(static_cast<float>(v)) && v >= 0); }, nullptr,
                 [](const Settings& s) { return s.fit.em.reg_covar.value_or(-1.0); },
                 [](Settings& s, double v) {
                   if (v == -1.0) s.fit.em.reg_covar.reset();
                   else s.fit.em.reg_covar = v;
                 },
                 nullptr, nullptr},
      SOGMM_I64_ROW(MAX_ITER, fit.em.max_iter, 1, kInt32Max, "[1, 2^31-1]", "iterations",
                    "at most this many EM iterations"),
      SOGMM_I64_ROW(SEED, fit.seed, kI64Min, kI64Max, "any (as a 64-bit unsigned seed)", "",
                    "seeds k-means++: the same seed gives the same model; run r of n_init uses seed + r"),
      // THREADS also sets the queries' team (score, regress, render, map queries).
      OptionSpec{OptionKey::THREADS, "SOGMM_OPT_THREADS", OptionType::I64, 0.0, 4096.0, 0, 4096, "[0, 4096]",
                 "threads", "worker threads of fits and queries; 0 = all available cores; results do not depend on it",
                 nullptr, always_i64, nullptr, nullptr,
                 [](const Settings& s) { return static_cast<std::int64_t>(s.fit.em.threads); },
                 [](Settings& s, std::int64_t v) { s.fit.em.threads = s.query.threads = static_cast<int>(v); }},
      SOGMM_I64_ROW(MODE_COUNTER, fit.mode_counter, 0, 1, "a SOGMM_MODE_COUNTER_* value (0 or 1)", "",
                    "how K is counted: 0 the authors' flat binned mean shift, 1 the paper's Gaussian blurring mean shift"),
      SOGMM_F64_ROW(TRUNCATION_NATS, fit.em.truncation_nats, 0.0, kInf, finite, ">= 0, finite", "nats",
                    "0: exact E-step; > 0: a point skips a component only when its term is provably this far below "
                    "the point's largest"),
      SOGMM_I64_ROW(N_INIT, fit.n_init, 1, kMaxRuns, "[1, 1000]", "runs",
                    "runs of k-means++ then EM (seeds seed + r); the best final likelihood is kept"),
      SOGMM_I64_ROW(DEQUANTISE_DEPTH, fit.dequantise_depth, -1, 1, "SOGMM_DEQUANTISE_AUTO (-1), 0 or 1", "",
                    "the depth-quantisation floor: AUTO is on for points from a depth image, off for arrays"),
      SOGMM_I64_ROW(EM_ACCELERATION, fit.em.acceleration, 0, 1, "0 (plain EM) or 1 (SQUAREM)", "",
                    "0: plain EM; 1: SQUAREM steps (extrapolation along two EM steps, rejected when the "
                    "log-likelihood would fall), fewer iterations to the same tol"),
      // ---- RGB-D back-projection ----
      SOGMM_F64_ROW(DEPTH_SCALE, depth.depth_scale, 0.0, kInf, [](double v) { return v > 0 && std::isfinite(v) && std::isfinite(1.0 / v); },
                    "> 0, finite, 1 / value finite", "raw units per metre",
                    "depth = raw / depth_scale (1000: millimetres; TUM uses 5000)"),
      SOGMM_F64_ROW(DEPTH_MIN, depth.depth_min, 0.0, kInf, finite, ">= 0, finite", "m",
                    "pixels at or nearer than this are invalid (exclusive); must be below DEPTH_MAX"),
      SOGMM_F64_ROW(DEPTH_MAX, depth.depth_max, 0.0, kInf, [](double v) { return v > 0 && std::isfinite(v); },
                    "> 0, finite", "m", "pixels farther than this are invalid (inclusive)"),
      SOGMM_I64_ROW(DECIMATION, depth.decimate, 1, 1024, "[1, 1024]", "pixels", "integer decimation factor d of the image"),
      // ---- writing .sogmm ----
      SOGMM_I64_ROW(ZSTD_LEVEL, write.zstd_level, 1, 22, "[1, 22]", "", "zstd compression level of the arrays"),
      SOGMM_I64_ROW(FLOAT64, write.float64, 0, 1, "0 or 1", "", "1: store the arrays as float64"),
      SOGMM_I64_ROW(COMPRESS, write.compress, 0, 1, "0 or 1", "", "1: zstd-compress the arrays"),
      // ---- reading .sogmm (the cap also bounds writing) ----
      // 0 restores the format library's default cap (kDefaultMaxDecodedBytes).
      OptionSpec{OptionKey::MAX_DECODED_BYTES, "SOGMM_OPT_MAX_DECODED_BYTES", OptionType::I64, 0.0,
                 static_cast<double>(kI64Max), 0, kI64Max, ">= 0; 0 = the default cap (1 GiB)", "bytes",
                 "cap on the arrays' decoded bytes: load refuses a file above it and save a model above it",
                 nullptr, always_i64, nullptr, nullptr,
                 [](const Settings& s) { return static_cast<std::int64_t>(s.read.max_decoded_bytes); },
                 [](Settings& s, std::int64_t v) {
                   const std::uint64_t cap = v == 0 ? format::kDefaultMaxDecodedBytes : static_cast<std::uint64_t>(v);
                   s.read.max_decoded_bytes = s.write.max_decoded_bytes = cap;
                 }},
      SOGMM_I64_ROW(VERIFY_CHECKSUMS, read.verify_checksums, 0, 1, "0 or 1", "",
                    "1: check the CRC-32C of the metadata and of every array"),
      // ---- sampling and queries ----
      SOGMM_F64_ROW(SAMPLE_TRUNCATION, sample.truncation, 0.0, kInf, [](double v) { return v > 0; },
                    "> 0 (+inf = untruncated)", "standard deviations",
                    "each standard-normal coordinate of a sample is truncated to (-value, value)"),
      SOGMM_F64_ROW(QUERY_TRUNCATION_NATS, query.truncation_nats, 0.0, kInf, finite, ">= 0, finite", "nats",
                    "0: exact score and regression; > 0: a component is skipped at a point only when its term is "
                    "provably this far below the point's largest"),
      // ---- incremental map ----
      SOGMM_I64_ROW(MAP_NOVELTY, map.novelty, 0, 1, "0 or 1", "",
                    "1: only points the map does not explain are fitted; 0: every point (append everything)"),
      SOGMM_F64_ROW(MAP_NOVELTY_THRESHOLD, map.novelty_threshold, -kInf, kInf, finite, "finite", "nats (log per m^3)",
                    "a point is novel when its neighbourhood's 3-D log-density is below this"),
      SOGMM_I64_ROW(MAP_BATCH_SIZE, map.batch_size, 1, std::int64_t{1} << 26, "[1, 2^26]", "points",
                    "pending novel points that trigger a fit"),
      SOGMM_I64_ROW(MAP_FUSION, map.fusion, 0, 1, "0 or 1", "", "1: fuse new components into close map components"),
      SOGMM_I64_ROW(MAP_FUSION_METHOD, map.fusion_method, 0, 1, "a SOGMM_FUSION_* value (0 or 1)", "",
                    "the distance of fusion: 0 Hellinger, 1 symmetric KL"),
      SOGMM_F64_ROW(MAP_FUSION_THRESHOLD, map.fusion_threshold, 0.0, kInf, [](double v) { return v > 0 && std::isfinite(v); },
                    "> 0, finite", "the method's unit", "fuse when the distance is below this"),
      SOGMM_I64_ROW(MAP_WARM_START, map.warm_start, 0, 1, "0 or 1", "",
                    "1: each flush's fit starts from the previous flush's model (needs n_init = 1)"),
      SOGMM_F64_ROW(MAP_NOVELTY_BANDWIDTH_SCALE, map.novelty_bandwidth_scale, 0.0, 1.0,
                    [](double v) { return v > 0; }, "in (0, 1]", "",
                    "with novelty on, batches are fitted with the bandwidth times this"),
      SOGMM_F64_ROW(MAP_REVISIT_REFIT_RATIO, map.revisit_refit_ratio, 0.0, kInf,
                    [](double v) { return v == 0 || (std::isfinite(v) && v >= 1); }, "0 (off) or >= 1, finite", "",
                    "a revisited surface is refitted when its points have this many times as many modes as it has "
                    "components"),
      // ---- occupancy and distance to the surface ----
      SOGMM_F64_ROW(OCCUPANCY_SIGMA, occupancy.surface_sigma, 0.0, kInf, [](double v) { return v > 0 && std::isfinite(v); },
                    "> 0, finite", "m",
                    "standard deviation of the true surface along a ray about the depth the map renders there"),
      SOGMM_F64_ROW(OCCUPANCY_THICKNESS, occupancy.thickness, 0.0, kInf, [](double v) { return v > 0 && std::isfinite(v); },
                    "> 0, finite", "m", "a point within this distance of the surface along a ray is occupied"),
      SOGMM_F64_ROW(SURFACE_DISC_SIGMAS, surface.disc_sigmas, 0.0, 10.0, [](double v) { return v > 0; }, "in (0, 10]",
                    "standard deviations",
                    "distance to the surface: each component is the disc of its two largest axes out to this many "
                    "standard deviations"),
      SOGMM_I64_ROW(REGISTRATION_MAX_ITER, registration.max_iter, 1, kInt32Max, "[1, 2^31-1]", "iterations",
                    "registration: EM / Gauss-Newton iterations per coarse-to-fine level"),
      SOGMM_F64_ROW(REGISTRATION_TOL, registration.tol, 0.0, kInf, [](double v) { return v > 0 && std::isfinite(v); },
                    "> 0, finite", "m",
                    "registration: a level ends when a step moves the source by less than this"),
      SOGMM_F64_ROW(REGISTRATION_OUTLIER_RATIO, registration.outlier_ratio, 0.0, 1.0, [](double v) { return v < 1; },
                    "in [0, 1)", "", "registration: prior weight of the uniform outlier term"),
      SOGMM_I64_ROW(REGISTRATION_USE_GRAY, registration.use_gray, 0, 1, "0 or 1", "",
                    "registration: 1 scores gray too (the 4-D joint density), 0 the 3-D marginal"),
      SOGMM_I64_ROW(REGISTRATION_LEVELS, registration.levels, 1, 16, "[1, 16]", "levels",
                    "registration: coarse-to-fine levels; the last uses the model unsmoothed"),
      SOGMM_F64_ROW(REGISTRATION_COARSE_SIGMA, registration.coarse_sigma, 0.0, kInf,
                    [](double v) { return v > 0 && std::isfinite(v); }, "> 0, finite", "m",
                    "registration: smoothing standard deviation of the coarsest level (halved per level)"),
      SOGMM_F64_ROW(REGISTRATION_MIN_INLIER_RATIO, registration.min_inlier_ratio, 0.0, 1.0, finite, "in [0, 1]", "",
                    "registration: below this inlier ratio the status is low fitness"),
      SOGMM_F64_ROW(REGISTRATION_DEGENERACY_RATIO, registration.degeneracy_ratio, 0.0, 1.0,
                    [](double v) { return v < 1; }, "in [0, 1)", "",
                    "registration: directions whose scaled information is below this fraction of the largest are "
                    "unobservable"),
      SOGMM_I64_ROW(REGISTRATION_MIN_POINTS, registration.min_points, 6, kI64Max, ">= 6", "points",
                    "registration: fewer finite source points are an error"),
  };
  return t;
}

#undef SOGMM_F64_ROW
#undef SOGMM_I64_ROW

}  // namespace

const std::vector<OptionSpec>& option_specs() {
  static const std::vector<OptionSpec> table = [] {
    std::vector<OptionSpec> t = make_table();
    std::sort(t.begin(), t.end(), [](const OptionSpec& a, const OptionSpec& b) { return a.key < b.key; });
    return t;
  }();
  return table;
}

}  // namespace sogmm
