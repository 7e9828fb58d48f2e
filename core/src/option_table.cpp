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
          "> 0, finite, with bw^2, (3 bw)^2 and 1 / (2 bw^2) finite and nonzero (about 5.3e-155 to 4.4e153)", "",
          "mean-shift bandwidth over the (range, gray) features: the one SOGMM parameter; it sets the number of components"),
      SOGMM_I64_ROW(N_COMPONENTS, fit.n_components, 0, kI64Max, ">= 0", "components",
                    "0: self-organizing (the mode count picks K); K > 0: a fit of exactly K components (1 <= K <= the number "
                    "of points) without the mode count"),
      SOGMM_F64_ROW(TOL, fit.em.tol, 0.0, kInf, finite, ">= 0, finite", "nats per point",
                    "EM stops when the mean log-likelihood per point changes by less than this; 0 runs MAX_ITER iterations"),
      // reg_covar: unset (automatic floors) is SOGMM_REG_COVAR_AUTO (-1).
      OptionSpec{OptionKey::REG_COVAR, "SOGMM_OPT_REG_COVAR", OptionType::F64, -1.0,
                 std::numeric_limits<float>::max(), 0, 0, ">= 0, finite in float32 (<= 3.4e38: covariances are float32), or SOGMM_REG_COVAR_AUTO (-1)",
                 "data units squared",
                 "a value is added to all four covariance diagonals in each M-step. SOGMM_REG_COVAR_AUTO (-1, the "
                 "default; get returns it while no value is set): one floor on x, y, z and one on gray, derived "
                 "from the data: 1e-6 x 100^k, with 10^k the power of ten nearest the median distance of the points "
                 "from their coordinate-wise median, resp. the smallest one not below the gray range; 1e-6 and 1e-6 "
                 "for a room-sized frame with gray in [0, 1], 1 m^2 for a 1 km scene. The model's fit record holds "
                 "the floors used (FIT_REG_COVAR: the spatial one; key_values reg_covar_gray and reg_covar_source). "
                 "Any other negative value, NaN or inf is refused",
                 [](double v) { return v == -1.0 || (std::isfinite(static_cast<float>(v)) && v >= 0); }, nullptr,
                 [](const Settings& s) { return s.fit.em.reg_covar.value_or(-1.0); },
                 [](Settings& s, double v) {
                   if (v == -1.0) s.fit.em.reg_covar.reset();
                   else s.fit.em.reg_covar = v;
                 },
                 nullptr, nullptr},
      SOGMM_I64_ROW(MAX_ITER, fit.em.max_iter, 1, kInt32Max, "[1, 2^31-1]", "iterations",
                    "at most this many EM iterations"),
      SOGMM_I64_ROW(SEED, fit.seed, kI64Min, kI64Max, "any (the bits of a uint64 seed, cast)", "",
                    "seeds k-means++: the same seed gives the same model; run r of N_INIT uses SEED + r"),
      // THREADS also sets the queries' team (score, regress, render, map queries).
      OptionSpec{OptionKey::THREADS, "SOGMM_OPT_THREADS", OptionType::I64, 0.0, 4096.0, 0, 4096, "[0, 4096]",
                 "threads",
                 "worker threads of fits and queries; 0 = all available cores; a request is capped at 4 x the cores "
                 "(libgomp aborts when it cannot start a thread); results do not depend on it",
                 nullptr, always_i64, nullptr, nullptr,
                 [](const Settings& s) { return static_cast<std::int64_t>(s.fit.em.threads); },
                 [](Settings& s, std::int64_t v) { s.fit.em.threads = s.query.threads = static_cast<int>(v); }},
      SOGMM_I64_ROW(MODE_COUNTER, fit.mode_counter, 0, 1, "a SOGMM_MODE_COUNTER_* value (0 or 1)", "",
                    "how K is counted: SOGMM_MODE_COUNTER_FLAT_BINNED (0) the authors' flat mean shift with bin seeding, "
                    "SOGMM_MODE_COUNTER_GAUSSIAN_BLURRING (1) the paper's Gaussian blurring mean shift"),
      SOGMM_F64_ROW(TRUNCATION_NATS, fit.em.truncation_nats, 0.0, kInf, finite, ">= 0, finite", "nats",
                    "0: exact E-step; > 0: a truncated E-step that skips a component only when it is provably more than "
                    "this many nats below every point's best in a block (25: each skipped term < 1.4e-11)"),
      SOGMM_I64_ROW(N_INIT, fit.n_init, 1, kMaxRuns, "[1, 1000]", "runs",
                    "runs of k-means++ then EM: run r (from 0) is seeded with SEED + r and the run with the highest final "
                    "mean log-likelihood is kept (ties: the earliest); the cost grows linearly"),
      SOGMM_I64_ROW(DEQUANTISE_DEPTH, fit.dequantise_depth, -1, 1, "SOGMM_DEQUANTISE_AUTO (-1), 0 or 1", "",
                    "1: when the camera-frame depth sits on discrete levels (a 16-bit depth image), floor each component's "
                    "variance along its viewing ray at the level's bin variance, so that components do not collapse "
                    "onto single levels (every seed converges; higher likelihood of held-out pixels spread in their "
                    "bins, lower training likelihood); 0: the paper's plain EM; SOGMM_DEQUANTISE_AUTO (-1): 1 for "
                    "the points of sogmm_fit_frame, 0 for points given as arrays"),
      SOGMM_I64_ROW(EM_ACCELERATION, fit.em.acceleration, 0, 1, "0 (plain EM) or 1 (SQUAREM)", "",
                    "0: plain EM; 1: SQUAREM steps (extrapolation along two EM steps, rejected when the "
                    "log-likelihood would fall), fewer iterations to the same tol"),
      SOGMM_F64_ROW(TOL_STANDARD_ERRORS, fit.em.tol_standard_errors, 0.0, kInf, finite, ">= 0, finite",
                    "standard errors",
                    "c > 0: EM also stops when a pass changes the mean log-likelihood by less than c times its standard "
                    "error (the per-point log-likelihoods' standard deviation over sqrt(N), from the same E-step), when "
                    "that exceeds TOL; 0: TOL alone. TOL 0 still runs MAX_ITER iterations"),
      SOGMM_I64_ROW(WARM_MAX_ITER, warm.max_iter, 0, kInt32Max, "[0, 2^31-1]", "iterations",
                    "a warm start (a fit given an initial model) runs at most this many EM iterations while MAX_ITER is "
                    "left at its default (a MAX_ITER set to anything else wins; never more than MAX_ITER); 0: MAX_ITER "
                    "alone; a cold fit, and a warm start that keeps no component or falls back to a cold one, ignore it; "
                    "a map's warm start (MAP_WARM_START) uses the default (why: WarmStartOptions::max_iter)"),
      // ---- RGB-D back-projection ----
      SOGMM_F64_ROW(DEPTH_SCALE, depth.depth_scale, 0.0, kInf, [](double v) { return v > 0 && std::isfinite(v) && std::isfinite(1.0 / v); },
                    "> 0, finite, 1 / value finite", "raw units per metre",
                    "depth = raw / depth_scale (1000: millimetres; TUM uses 5000)"),
      SOGMM_F64_ROW(DEPTH_MIN, depth.depth_min, 0.0, kInf, finite, ">= 0, finite", "m",
                    "pixels at or nearer than this are invalid (exclusive); must be below DEPTH_MAX at fit time"),
      SOGMM_F64_ROW(DEPTH_MAX, depth.depth_max, 0.0, kInf, [](double v) { return v > 0 && std::isfinite(v); },
                    "> 0, finite", "m", "pixels farther than this are invalid (inclusive); must exceed DEPTH_MIN at fit time"),
      SOGMM_I64_ROW(DECIMATION, depth.decimate, 1, 1024, "[1, 1024]", "pixels", "integer decimation factor d of the image; at fit time d <= width and d <= height"),
      // ---- writing .sogmm ----
      SOGMM_I64_ROW(ZSTD_LEVEL, write.zstd_level, 1, 22, "[1, 22]", "", "zstd compression level of the arrays"),
      SOGMM_I64_ROW(FLOAT64, write.float64, 0, 1, "0 or 1", "", "1: store the arrays as float64"),
      SOGMM_I64_ROW(COMPRESS, write.compress, 0, 1, "0 or 1", "", "1: zstd-compress the arrays"),
      SOGMM_F64_ROW(ARRAY_PRECISION, write.component_precision, 0.0, 0.5, finite, "[0, 0.5] (0: off)",
                    "standard deviations",
                    "> 0: store each component as integer codes (format 1.5, spec/format.md 5.7) that move its mean by "
                    "at most this many of its standard deviations and its covariance's eigenvalues, in its own frame, "
                    "by at most this fraction, as MAP_COMPONENT_PRECISION bounds them, and its weight by a factor of at "
                    "most 1 +- 2^-4 before the weights are renormalised: 11-21 bytes a component on "
                    "README section 7's maps instead of 30-40 (why: WriteOptions::component_precision). A model "
                    "read from such a file and saved again keeps its components bit for bit (the writer finds their "
                    "codes), but for a few (1-4%) whose equal eigenvalues leave their axes undetermined, coded anew "
                    "within the bound (spec/format.md 5.7). 0: float arrays, bit-exact"),
      // ---- reading .sogmm (the cap also bounds writing) ----
      // 0 restores the format library's default cap (kDefaultMaxDecodedBytes).
      OptionSpec{OptionKey::MAX_DECODED_BYTES, "SOGMM_OPT_MAX_DECODED_BYTES", OptionType::I64, 0.0,
                 static_cast<double>(kI64Max), 0, kI64Max, ">= 0; 0 = the default cap (1 GiB)", "bytes",
                 "cap on the arrays' decoded bytes: load refuses a file above it and save a model above it (what a "
                 "reader with the default cap would refuse)",
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
                    "0: exact score and regression; > 0: culled ones, which skip a component at a point only when its "
                    "term is provably more than this many nats below the point's largest (as TRUNCATION_NATS for "
                    "the E-step): a score is then at most log(1 + M exp(-nats)) below the exact one"),
      SOGMM_F64_ROW(RENDER_SURFACE_SIGMA, render.surface_sigma, 0.0, kInf, finite, ">= 0, finite", "standard deviations",
                    "renders: 0 shows every mode of the density along a pixel's ray; s > 0 only modes where the "
                    "evidence sum_k exp(-D_k^2 / 2) (D_k the Mahalanobis distance to component k) reaches that of one "
                    "component at s sigma, so a ray grazing a nearer object's components passes on to the surface behind "
                    "(RenderOptions::surface_sigma)"),
      // ---- incremental map ----
      SOGMM_I64_ROW(MAP_NOVELTY, map.novelty, 0, 1, "0 or 1", "",
                    "1: only points the map does not explain are fitted; 0: every point is novel and each insert fits its "
                    "whole frame (append everything)"),
      SOGMM_F64_ROW(MAP_NOVELTY_THRESHOLD, map.novelty_threshold, -kInf, kInf, finite, "finite", "nats (log per m^3)",
                    "a point is novel when its 3-D log-likelihood under the local submap is below this"),
      SOGMM_I64_ROW(MAP_BATCH_SIZE, map.batch_size, 1, std::int64_t{1} << 26, "[1, 2^26]", "points",
                    "pending novel points that trigger a fit"),
      SOGMM_I64_ROW(MAP_FUSION, map.fusion, 0, 1, "0 or 1", "", "1: fuse new components into close map components"),
      SOGMM_I64_ROW(MAP_FUSION_METHOD, map.fusion_method, 0, 1, "a SOGMM_FUSION_* value (0 or 1)", "",
                    "the distance of fusion: SOGMM_FUSION_HELLINGER (0) the Hellinger distance of the 4-D Gaussians, in "
                    "[0, 1]; SOGMM_FUSION_KL (1) the symmetric KL divergence (KL(a||b) + KL(b||a)) / 2, in nats"),
      SOGMM_F64_ROW(MAP_FUSION_THRESHOLD, map.fusion_threshold, 0.0, kInf, [](double v) { return v > 0 && std::isfinite(v); },
                    "> 0, finite", "the method's unit", "fuse when the distance is below this"),
      SOGMM_I64_ROW(MAP_WARM_START, map.warm_start, 0, 1, "0 or 1", "",
                    "1: each batch's fit starts from the previous batch's model moved into its camera (as a warm "
                    "sogmm_fit_points_f32); meant for MAP_NOVELTY 0; needs N_INIT 1"),
      SOGMM_F64_ROW(MAP_NOVELTY_BANDWIDTH_SCALE, map.novelty_bandwidth_scale, 0.0, 1.0,
                    [](double v) { return v > 0; }, "in (0, 1]", "",
                    "with MAP_NOVELTY 1 a batch of novel points is fitted with BANDWIDTH times s + (1 - s) h^2, s this "
                    "scale and h the share of the batch's point pairs from one frame (sum n_f^2 / N^2: 1 for one "
                    "frame), and a revisit refit with BANDWIDTH times s (with MAP_NOVELTY 0 each frame with the "
                    "bandwidth itself; why: MapOptions::novelty_bandwidth_scale)"),
      SOGMM_F64_ROW(MAP_REVISIT_REFIT_RATIO, map.revisit_refit_ratio, 0.0, kInf,
                    [](double v) { return v == 0 || (std::isfinite(v) && v >= 1); }, "0 (off) or >= 1, finite", "",
                    "with MAP_NOVELTY 1, an RGB-D insert refits the map components on its surfaces when its explained "
                    "points they dominate have at least this many times as many modes as they are components: they "
                    "are replaced by a fit of those points plus samples of their mass it does not see (details and "
                    "why: MapOptions::revisit_refit_ratio); 0: off; no refit with N_COMPONENTS > 0 or MAP_WARM_START "
                    "1; a refit counts as a fit (flushed, n_flushes)"),
      SOGMM_F64_ROW(MAP_FREE_SPACE_CARVE, map.free_space_carve, 0.0, 0.5, [](double v) { return v <= 0.5; },
                    "in [0, 0.5]", "share of samples",
                    "with MAP_NOVELTY 1, an RGB-D insert reshapes each map component on its surfaces that has at "
                    "least this share of its 256 samples (rounded up to whole samples: the default is one) where the "
                    "frame sees past them (free space): mean and covariance "
                    "become the moments of its other samples, its weight stays; new components are carved by every "
                    "RGB-D frame inserted since the map was created or loaded, whose depth the map keeps (why: "
                    "MapOptions::free_space_carve); 0: off; not with MAP_WARM_START 1"),
      SOGMM_I64_ROW(MAP_DELTA_HISTORY, map.delta_history, 0, std::int64_t{1} << 62, "[0, 2^62]", "revisions",
                    "how many of its latest revisions a map keeps the changes of, for deltas (sogmm_map_export_delta "
                    "since an older one is refused naming the oldest kept); 0: every revision since it was created or "
                    "loaded (memory grows with every fit)"),
      SOGMM_F64_ROW(MAP_COMPONENT_PRECISION, map.component_precision, 0.0, 0.5, finite, "[0, 0.5] (0: off)",
                    "standard deviations",
                    "each fitted component is rounded before the map stores it so that its mean moves by at most this "
                    "many of its standard deviations and its covariance's eigenvalues, in its own frame, by at most this "
                    "fraction: zero low mantissa bits that deltas and map files compress away (bounds and why: "
                    "MapOptions::component_precision); 0: full float32"),
      // ---- occupancy and distance to the surface ----
      SOGMM_F64_ROW(OCCUPANCY_SIGMA, occupancy.surface_sigma, 0.0, kInf, [](double v) { return v > 0 && std::isfinite(v); },
                    "> 0, finite", "m",
                    "standard deviation of the true surface along a ray about the depth the map renders there"),
      SOGMM_F64_ROW(OCCUPANCY_THICKNESS, occupancy.thickness, 0.0, kInf, [](double v) { return v > 0 && std::isfinite(v); },
                    "> 0, finite", "m", "a point within this distance of the surface along a ray is occupied"),
      SOGMM_F64_ROW(SURFACE_DISC_SIGMAS, surface.disc_sigmas, 0.0, 10.0, [](double v) { return v > 0; }, "in (0, 10]",
                    "standard deviations",
                    "distance to the surface: each component is the disc of its two largest principal axes out to this "
                    "many standard deviations"),
      SOGMM_I64_ROW(REGISTRATION_MAX_ITER, registration.max_iter, 1, kInt32Max, "[1, 2^31-1]", "iterations",
                    "registration: steps (each scores every source point of the level) per coarse-to-fine level"),
      SOGMM_F64_ROW(REGISTRATION_TOL, registration.tol, 0.0, kInf, [](double v) { return v > 0 && std::isfinite(v); },
                    "> 0, finite", "m",
                    "registration: a level ends when a step moves the source by less than this (|t| + |rotation| x RMS "
                    "radius)"),
      SOGMM_F64_ROW(REGISTRATION_OUTLIER_RATIO, registration.outlier_ratio, 0.0, 1.0, [](double v) { return v < 1; },
                    "in [0, 1)", "", "registration: prior weight of the uniform outlier term (over the target's 3-sigma box)"),
      SOGMM_I64_ROW(REGISTRATION_USE_GRAY, registration.use_gray, 0, 1, "0 or 1", "",
                    "registration: 1 scores gray too (the 4-D joint density: gray marginal times the conditional x | "
                    "gray), 0 the 3-D marginal"),
      SOGMM_I64_ROW(REGISTRATION_LEVELS, registration.levels, 1, 16, "[1, 16]", "levels",
                    "registration: coarse-to-fine levels; level l smooths the target by COARSE_SIGMA / 2^l, the last not "
                    "at all"),
      SOGMM_F64_ROW(REGISTRATION_COARSE_SIGMA, registration.coarse_sigma, 0.0, kInf,
                    [](double v) { return v > 0 && std::isfinite(v); }, "> 0, finite", "m",
                    "registration: smoothing standard deviation of the coarsest level (halved per level)"),
      SOGMM_F64_ROW(REGISTRATION_MIN_INLIER_RATIO, registration.min_inlier_ratio, 0.0, 1.0, finite, "in [0, 1]", "",
                    "registration: below this inlier ratio the status is SOGMM_REGISTRATION_LOW_FITNESS"),
      SOGMM_F64_ROW(REGISTRATION_DEGENERACY_RATIO, registration.degeneracy_ratio, 0.0, 1.0,
                    [](double v) { return v < 1; }, "in [0, 1)", "",
                    "registration: directions whose scaled information is below this fraction of the largest are "
                    "unobservable"),
      SOGMM_I64_ROW(REGISTRATION_MIN_POINTS, registration.min_points, 6, kI64Max, ">= 6", "points",
                    "registration: fewer finite source points are SOGMM_E_INVALID_DATA"),
      SOGMM_F64_ROW(REGISTRATION_DEPTH_NOISE, registration.depth_noise, 0.0, 1.0, finite, "[0, 1] (0: off)", "1/m",
                    "registration: a source point's depth error has standard deviation this x z^2 (z its depth in "
                    "the sensor's frame, the source's own), added along its ray to each component's covariance; "
                    "point sources only; 0: off"),
      SOGMM_I64_ROW(TRACKING_ODOMETRY, tracking.odometry, 0, 1, "0 or 1", "",
                    "tracking: 1 registers a frame the map does not accept to the last inserted frame too and inserts "
                    "it when the two agree or the map has too few inliers to judge; 0 inserts only frames the map "
                    "accepts"),
      SOGMM_F64_ROW(TRACKING_MAX_DISAGREEMENT, tracking.max_disagreement, 0.0, kInf,
                    [](double v) { return v > 0 && std::isfinite(v); }, "> 0, finite", "m",
                    "tracking: largest RMS distance between a frame's points at the map's and at the odometry's pose "
                    "for the two to agree"),
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
