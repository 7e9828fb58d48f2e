/*
 * sogmm.h - the stable C API of SOGMM (Self-Organizing Gaussian Mixture
 * Models for RGB-D frames). This is the only public header of libsogmm.
 *
 * It is C99 and compiles as C and as C++. Every symbol and constant starts
 * with sogmm_ / SOGMM_. The full reference, with the bad-input table and the
 * thread-safety rules, is spec/api.md.
 *
 * Conventions (apply to every function unless its comment says otherwise)
 * ---------------------------------------------------------------------
 * - Handles (sogmm_model, sogmm_options, sogmm_buffer, sogmm_map, sogmm_frame,
 *   sogmm_trajectory) are opaque. A function
 *   that creates a handle takes its out-pointer FIRST; on failure it stores
 *   NULL there (when the out-pointer itself is not NULL). The caller owns
 *   every created handle and releases it with the matching *_free function.
 *   Every *_free function accepts NULL and then does nothing.
 * - Fallible functions return sogmm_status: SOGMM_OK (0) or a negative
 *   SOGMM_E_* code. Out-parameters and output arrays are written only on
 *   success, with two documented exceptions: the NULL stored into a handle
 *   out-pointer on failure, and the count that sogmm_frame_to_points_f32
 *   reports with SOGMM_E_BUFFER_TOO_SMALL.
 * - A call whose result would not be finite (a transform moving a mean beyond
 *   float32, intrinsics that back-project to infinity) fails at that call.
 * - Input arrays and strings belong to the caller. They are read only during
 *   the call and copied if kept (nothing the caller passes is retained).
 * - Output arrays are allocated by the caller, row-major, with the element
 *   type in the function name (_f32 = float, _f64 = double).
 * - Points are (x, y, z, gray) rows: metres in the model's frame, gray in
 *   [0, 1]. Covariances are always full, symmetric 4 x 4, row-major.
 * - Pointers returned by the library (const char*, const uint8_t*) are owned
 *   by the library; how long they stay valid is stated per function.
 * - No function aborts the process on bad input, and no C++ exception ever
 *   leaves the library.
 * - Thread safety: distinct handles may be used from different threads at
 *   the same time. Functions taking a const handle only read it and may run
 *   concurrently on the same handle; a function taking a non-const handle
 *   needs exclusive use of that handle. A map (sogmm_map) checks this
 *   itself: a call that would break the rule, from another thread or from
 *   the progress callback of a call on that map, returns SOGMM_E_BUSY
 *   ("map busy: ...") at once instead of racing or waiting. Other handles do
 *   not check. sogmm_last_error is per thread.
 */
#ifndef SOGMM_SOGMM_H
#define SOGMM_SOGMM_H

#include <stddef.h>
#include <stdint.h>

/* ---- export / deprecation macros -------------------------------------- */
#if defined(_WIN32) || defined(__CYGWIN__)
#  if defined(SOGMM_BUILDING_LIBRARY)
#    define SOGMM_API __declspec(dllexport)
#  elif defined(SOGMM_STATIC)
#    define SOGMM_API
#  else
#    define SOGMM_API __declspec(dllimport)
#  endif
#elif defined(__GNUC__) && __GNUC__ >= 4
#  define SOGMM_API __attribute__((visibility("default")))
#else
#  define SOGMM_API
#endif

#if defined(__GNUC__) || defined(__clang__)
#  define SOGMM_DEPRECATED(msg) __attribute__((deprecated(msg)))
#elif defined(_MSC_VER)
#  define SOGMM_DEPRECATED(msg) __declspec(deprecated(msg))
#else
#  define SOGMM_DEPRECATED(msg)
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ---- versions --------------------------------------------------------- */
/* Compile-time version of this header. SOGMM_VERSION_NUMBER is
 * MAJOR * 10000 + MINOR * 100 + PATCH. Compare with sogmm_version_number()
 * at run time to detect a header/library mismatch. */
#define SOGMM_VERSION_MAJOR 0
#define SOGMM_VERSION_MINOR 1
#define SOGMM_VERSION_PATCH 0
#define SOGMM_VERSION_NUMBER \
  (SOGMM_VERSION_MAJOR * 10000 + SOGMM_VERSION_MINOR * 100 + SOGMM_VERSION_PATCH)
#define SOGMM_VERSION_STRING "0.1.0"
/* ABI version: bumped only on an incompatible change of this API. The shared
 * library's SONAME is libsogmm.so.<SOGMM_ABI_VERSION>. Bindings that load the
 * library dynamically must check sogmm_abi_version() == the value they were
 * written for. */
#define SOGMM_ABI_VERSION 2

/* Runtime version of the loaded library, same encoding as
 * SOGMM_VERSION_NUMBER. Never fails. */
SOGMM_API uint32_t sogmm_version_number(void);
/* "MAJOR.MINOR.PATCH" of the loaded library; static storage. Never NULL. */
SOGMM_API const char* sogmm_version_string(void);
/* SOGMM_ABI_VERSION of the loaded library. Never fails. */
SOGMM_API uint32_t sogmm_abi_version(void);

/* ---- status codes ----------------------------------------------------- */
/* Fixed width for FFI. Codes are frozen; new codes are only ever appended
 * (next free negative number). Treat any unknown negative code as failure. */
typedef int32_t sogmm_status;

#define SOGMM_OK 0
#define SOGMM_E_NULL_ARG (-1)         /* a required pointer argument is NULL */
#define SOGMM_E_INVALID_ARG (-2)      /* a scalar parameter is out of range, or an unknown key */
#define SOGMM_E_INVALID_DATA (-3)     /* array contents unusable: empty, NaN/Inf, broken model */
#define SOGMM_E_NUMERIC (-4)          /* numerical failure: covariance not SPD, NaN result */
#define SOGMM_E_IO (-5)               /* a file could not be opened, read or written */
#define SOGMM_E_FORMAT (-6)           /* bytes are not a valid / supported .sogmm document (or, for
                                       * sogmm_frame_read/decode, PNG or JPEG image: corrupt, truncated) */
#define SOGMM_E_LIMIT (-7)            /* a size limit is exceeded (decoded size, size overflow, more than
                                       * 2^26 points or 2^16 components in a fit) */
#define SOGMM_E_NOMEM (-8)            /* memory allocation failed */
#define SOGMM_E_BUFFER_TOO_SMALL (-9) /* a caller's output capacity is too small */
#define SOGMM_E_NOT_FOUND (-10)       /* the requested value is not present (unknown metadata) */
#define SOGMM_E_INTERNAL (-11)        /* unexpected internal error (a bug: please report) */
#define SOGMM_E_CANCELLED (-12)       /* the progress callback returned non-zero (sogmm_progress_fn) */
#define SOGMM_E_BUSY (-13)            /* map busy: another call is using the map (another thread's, or the
                                       * call whose progress callback made this one; sogmm_map_*) */

/* Static, never-NULL description of a status, e.g. "invalid argument".
 * Unknown codes give "unknown status". */
SOGMM_API const char* sogmm_status_string(sogmm_status status);

/* Message of the last failure on the calling thread, naming what was wrong.
 * Every status-returning function clears it on entry (so it is "" after a
 * success) and sets it on failure. Never NULL; owned by the library; valid
 * until the next sogmm_* call on the same thread. */
SOGMM_API const char* sogmm_last_error(void);

/* ---- opaque handles --------------------------------------------------- */
typedef struct sogmm_model sogmm_model;     /* a fitted 4-D GMM + metadata */
typedef struct sogmm_options sogmm_options; /* enum-keyed parameters for fit, save, load, sample */
typedef struct sogmm_buffer sogmm_buffer;   /* bytes produced by the library */
typedef struct sogmm_map sogmm_map;         /* an incremental world map (sogmm_map_*) */
typedef struct sogmm_frame sogmm_frame;     /* an RGB-D frame: pixels and intrinsics (sogmm_frame_*) */
typedef struct sogmm_trajectory sogmm_trajectory; /* camera poses read from a Redwood .log file */

/* ---- options ---------------------------------------------------------- */
/* Key of a parameter (SOGMM_OPT_*, below 10000), of a model's information
 * (SOGMM_INFO_*, 10000 to 19999) or of a map's statistics (SOGMM_MAP_*, 20000
 * and up): the ranges are disjoint, so no number is two keys. Each key has one type: set/get an option with the _f64 or _i64
 * function named in its comment; the other one, an info key or an unknown
 * key returns SOGMM_E_INVALID_ARG with a message naming the key (and the
 * function to use). Values outside the stated range are rejected by the
 * setter with SOGMM_E_INVALID_ARG and leave the handle unchanged. Functions
 * ignore keys that do not concern them. Passing NULL where a
 * `const sogmm_options*` is expected means "all defaults". */
typedef int32_t sogmm_key;

/* BEGIN GENERATED option keys (tools/options/regenerate.py, from core/src/option_table.cpp) */
/* Fit (mode count + k-means++ + EM). Read by sogmm_fit_points_f32, sogmm_fit_frame and each
 * batch of a map. */
/* Mean-shift bandwidth over the (range, gray) features: the one SOGMM parameter; it sets the
 * number of components.
 * f64, > 0, finite, with bw^2, (3 bw)^2 and 1 / (2 bw^2) finite and nonzero (about 5.3e-155 to
 * 4.4e153); default 0.02. */
#define SOGMM_OPT_BANDWIDTH 100
/* 0: self-organizing (the mode count picks K); K > 0: a fit of exactly K components (1 <= K <=
 * the number of points) without the mode count.
 * i64 (components), >= 0; default 0. */
#define SOGMM_OPT_N_COMPONENTS 101
/* EM stops when the mean log-likelihood per point changes by less than this; 0 runs MAX_ITER
 * iterations.
 * f64 (nats per point), >= 0, finite; default 0.001. */
#define SOGMM_OPT_TOL 102
/* A value is added to all four covariance diagonals in each M-step. SOGMM_REG_COVAR_AUTO (-1,
 * the default; get returns it while no value is set): one floor on x, y, z and one on gray,
 * derived from the data: 1e-6 x 100^k, with 10^k the power of ten nearest the median distance of
 * the points from their coordinate-wise median, resp. the smallest one not below the gray range;
 * 1e-6 and 1e-6 for a room-sized frame with gray in [0, 1], 1 m^2 for a 1 km scene. The model's
 * fit record holds the floors used (FIT_REG_COVAR: the spatial one; key_values reg_covar_gray
 * and reg_covar_source). Any other negative value, NaN or inf is refused.
 * f64 (data units squared), >= 0, finite in float32 (<= 3.4e38: covariances are float32), or
 * SOGMM_REG_COVAR_AUTO (-1); default -1. */
#define SOGMM_OPT_REG_COVAR 103
/* At most this many EM iterations.
 * i64 (iterations), [1, 2^31-1]; default 100. */
#define SOGMM_OPT_MAX_ITER 104
/* Seeds k-means++: the same seed gives the same model; run r of N_INIT uses SEED + r.
 * i64, any (the bits of a uint64 seed, cast); default 0. */
#define SOGMM_OPT_SEED 105
/* Worker threads of fits and queries; 0 = all available cores; a request is capped at 4 x the
 * cores (libgomp aborts when it cannot start a thread); results do not depend on it.
 * i64 (threads), [0, 4096]; default 0. */
#define SOGMM_OPT_THREADS 106
/* How K is counted: SOGMM_MODE_COUNTER_FLAT_BINNED (0) the authors' flat mean shift with bin
 * seeding, SOGMM_MODE_COUNTER_GAUSSIAN_BLURRING (1) the paper's Gaussian blurring mean shift.
 * i64, a SOGMM_MODE_COUNTER_* value (0 or 1); default 0. */
#define SOGMM_OPT_MODE_COUNTER 107
/* 0: exact E-step; > 0: a truncated E-step that skips a component only when it is provably more
 * than this many nats below every point's best in a block (25: each skipped term < 1.4e-11).
 * f64 (nats), >= 0, finite; default 0. */
#define SOGMM_OPT_TRUNCATION_NATS 108
/* Runs of k-means++ then EM: run r (from 0) is seeded with SEED + r and the run with the highest
 * final mean log-likelihood is kept (ties: the earliest); the cost grows linearly.
 * i64 (runs), [1, 1000]; default 1. */
#define SOGMM_OPT_N_INIT 109
/* 1: when the camera-frame depth sits on discrete levels (a 16-bit depth image), floor each
 * component's variance along its viewing ray at the level's bin variance, so that components do
 * not collapse onto single levels (every seed converges; higher likelihood of held-out pixels
 * spread in their bins, lower training likelihood); 0: the paper's plain EM;
 * SOGMM_DEQUANTISE_AUTO (-1): 1 for the points of sogmm_fit_frame, 0 for points given as arrays.
 * i64, SOGMM_DEQUANTISE_AUTO (-1), 0 or 1; default -1. */
#define SOGMM_OPT_DEQUANTISE_DEPTH 110
/* 0: plain EM; 1: SQUAREM steps (extrapolation along two EM steps, rejected when the
 * log-likelihood would fall), fewer iterations to the same tol.
 * i64, 0 (plain EM) or 1 (SQUAREM); default 0. */
#define SOGMM_OPT_EM_ACCELERATION 111
/* C > 0: EM also stops when a pass changes the mean log-likelihood by less than c times its
 * standard error (the per-point log-likelihoods' standard deviation over sqrt(N), from the same
 * E-step), when that exceeds TOL; 0: TOL alone. TOL 0 still runs MAX_ITER iterations.
 * f64 (standard errors), >= 0, finite; default 0. */
#define SOGMM_OPT_TOL_STANDARD_ERRORS 131
/* A warm start (a fit given an initial model) runs at most this many EM iterations while
 * MAX_ITER is left at its default (a MAX_ITER set to anything else wins; never more than
 * MAX_ITER); 0: MAX_ITER alone; a cold fit, and a warm start that keeps no component or falls
 * back to a cold one, ignore it; a map's warm start (MAP_WARM_START) uses the default (why:
 * WarmStartOptions::max_iter).
 * i64 (iterations), [0, 2^31-1]; default 8. */
#define SOGMM_OPT_WARM_MAX_ITER 145

/* RGB-D back-projection. Read by sogmm_fit_frame, sogmm_map_insert_frame,
 * sogmm_frame_to_points_f32. */
/* Depth = raw / depth_scale (1000: millimetres; TUM uses 5000).
 * f64 (raw units per metre), > 0, finite, 1 / value finite; default 1000. */
#define SOGMM_OPT_DEPTH_SCALE 200
/* Pixels at or nearer than this are invalid (exclusive); must be below DEPTH_MAX at fit time.
 * f64 (m), >= 0, finite; default 0.1. */
#define SOGMM_OPT_DEPTH_MIN 201
/* Pixels farther than this are invalid (inclusive); must exceed DEPTH_MIN at fit time.
 * f64 (m), > 0, finite; default 3. */
#define SOGMM_OPT_DEPTH_MAX 202
/* Integer decimation factor d of the image; at fit time d <= width and d <= height.
 * i64 (pixels), [1, 1024]; default 1. */
#define SOGMM_OPT_DECIMATION 203

/* Writing .sogmm. Read by sogmm_model_save, sogmm_model_save_to_memory, sogmm_map_save. */
/* Zstd compression level of the arrays.
 * i64, [1, 22]; default 19. */
#define SOGMM_OPT_ZSTD_LEVEL 300
/* 1: store the arrays as float64.
 * i64, 0 or 1; default 0. */
#define SOGMM_OPT_FLOAT64 301
/* 1: zstd-compress the arrays.
 * i64, 0 or 1; default 1. */
#define SOGMM_OPT_COMPRESS 302
/* > 0: store each component as integer codes (format 1.5, spec/format.md 5.7) that move its mean
 * by at most this many of its standard deviations and its covariance's eigenvalues, in its own
 * frame, by at most this fraction, as MAP_COMPONENT_PRECISION bounds them, and its weight by a
 * factor of at most 1 +- 2^-4 before the weights are renormalised: 11-21 bytes a component on
 * README section 7's maps instead of 30-40 (why: WriteOptions::component_precision). A model
 * read from such a file and saved again keeps its components bit for bit (the writer finds their
 * codes), but for a few (1-4%) whose equal eigenvalues leave their axes undetermined, coded anew
 * within the bound (spec/format.md 5.7). 0: float arrays, bit-exact.
 * f64 (standard deviations), [0, 0.5] (0: off); default 0. */
#define SOGMM_OPT_ARRAY_PRECISION 303

/* Reading .sogmm. Read by sogmm_model_load, sogmm_model_load_from_memory, sogmm_map_load;
 * MAX_DECODED_BYTES also the saves. */
/* Cap on the arrays' decoded bytes: load refuses a file above it and save a model above it (what
 * a reader with the default cap would refuse).
 * i64 (bytes), >= 0; 0 = the default cap (1 GiB); default 1073741824. */
#define SOGMM_OPT_MAX_DECODED_BYTES 400
/* 1: check the CRC-32C of the metadata and of every array.
 * i64, 0 or 1; default 1. */
#define SOGMM_OPT_VERIFY_CHECKSUMS 401

/* Sampling and queries. Read by sogmm_model_sample_f32 (SAMPLE_TRUNCATION); the model's score
 * and regression and the map queries (QUERY_TRUNCATION_NATS, and THREADS for the team). */
/* Each standard-normal coordinate of a sample is truncated to (-value, value).
 * f64 (standard deviations), > 0 (+inf = untruncated); default 2.5. */
#define SOGMM_OPT_SAMPLE_TRUNCATION 500
/* 0: exact score and regression; > 0: culled ones, which skip a component at a point only when
 * its term is provably more than this many nats below the point's largest (as TRUNCATION_NATS
 * for the E-step): a score is then at most log(1 + M exp(-nats)) below the exact one.
 * f64 (nats), >= 0, finite; default 0. */
#define SOGMM_OPT_QUERY_TRUNCATION_NATS 501
/* Renders: 0 shows every mode of the density along a pixel's ray; s > 0 only modes where the
 * evidence sum_k exp(-D_k^2 / 2) (D_k the Mahalanobis distance to component k) reaches that of
 * one component at s sigma, so a ray grazing a nearer object's components passes on to the
 * surface behind (RenderOptions::surface_sigma).
 * f64 (standard deviations), >= 0, finite; default 0. */
#define SOGMM_OPT_RENDER_SURFACE_SIGMA 502

/* Incremental map. Read by sogmm_map_create, sogmm_map_load; a map also reads the fit keys (each
 * batch's fit; THREADS also runs the novelty test) and the RGB-D keys (sogmm_map_insert_frame). */
/* 1: only points the map does not explain are fitted; 0: every point is novel and each insert
 * fits its whole frame (append everything).
 * i64, 0 or 1; default 1. */
#define SOGMM_OPT_MAP_NOVELTY 600
/* A point is novel when its 3-D log-likelihood under the local submap is below this.
 * f64 (nats (log per m^3)), finite; default 3. */
#define SOGMM_OPT_MAP_NOVELTY_THRESHOLD 601
/* Pending novel points that trigger a fit.
 * i64 (points), [1, 2^26]; default 12288. */
#define SOGMM_OPT_MAP_BATCH_SIZE 602
/* 1: fuse new components into close map components.
 * i64, 0 or 1; default 0. */
#define SOGMM_OPT_MAP_FUSION 603
/* The distance of fusion: SOGMM_FUSION_HELLINGER (0) the Hellinger distance of the 4-D
 * Gaussians, in [0, 1]; SOGMM_FUSION_KL (1) the symmetric KL divergence (KL(a||b) + KL(b||a)) /
 * 2, in nats.
 * i64, a SOGMM_FUSION_* value (0 or 1); default 0. */
#define SOGMM_OPT_MAP_FUSION_METHOD 604
/* Fuse when the distance is below this.
 * f64 (the method's unit), > 0, finite; default 0.3. */
#define SOGMM_OPT_MAP_FUSION_THRESHOLD 605
/* 1: each batch's fit starts from the previous batch's model moved into its camera (as a warm
 * sogmm_fit_points_f32); meant for MAP_NOVELTY 0; needs N_INIT 1.
 * i64, 0 or 1; default 0. */
#define SOGMM_OPT_MAP_WARM_START 606
/* With MAP_NOVELTY 1 a batch of novel points is fitted with BANDWIDTH times s + (1 - s) h^2, s
 * this scale and h the share of the batch's point pairs from one frame (sum n_f^2 / N^2: 1 for
 * one frame), and a revisit refit with BANDWIDTH times s (with MAP_NOVELTY 0 each frame with the
 * bandwidth itself; why: MapOptions::novelty_bandwidth_scale).
 * f64, in (0, 1]; default 0.7. */
#define SOGMM_OPT_MAP_NOVELTY_BANDWIDTH_SCALE 607
/* With MAP_NOVELTY 1, an RGB-D insert refits the map components on its surfaces when its
 * explained points they dominate have at least this many times as many modes as they are
 * components: they are replaced by a fit of those points plus samples of their mass it does not
 * see (details and why: MapOptions::revisit_refit_ratio); 0: off; no refit with N_COMPONENTS > 0
 * or MAP_WARM_START 1; a refit counts as a fit (flushed, n_flushes).
 * f64, 0 (off) or >= 1, finite; default 1.25. */
#define SOGMM_OPT_MAP_REVISIT_REFIT_RATIO 608
/* How many of its latest revisions a map keeps the changes of, for deltas
 * (sogmm_map_export_delta since an older one is refused naming the oldest kept); 0: every
 * revision since it was created or loaded (memory grows with every fit).
 * i64 (revisions), [0, 2^62]; default 0. */
#define SOGMM_OPT_MAP_DELTA_HISTORY 609
/* With MAP_NOVELTY 1, an RGB-D insert reshapes each map component on its surfaces that has at
 * least this share of its 256 samples (rounded up to whole samples: the default is one) where
 * the frame sees past them (free space): mean and covariance become the moments of its other
 * samples, its weight stays; new components are carved by every RGB-D frame inserted since the
 * map was created or loaded, whose depth the map keeps (why: MapOptions::free_space_carve); 0:
 * off; not with MAP_WARM_START 1.
 * f64 (share of samples), in [0, 0.5]; default 0.002. */
#define SOGMM_OPT_MAP_FREE_SPACE_CARVE 620
/* Each fitted component is rounded before the map stores it so that its mean moves by at most
 * this many of its standard deviations and its covariance's eigenvalues, in its own frame, by at
 * most this fraction: zero low mantissa bits that deltas and map files compress away (bounds and
 * why: MapOptions::component_precision); 0: full float32.
 * f64 (standard deviations), [0, 0.5] (0: off); default 0. */
#define SOGMM_OPT_MAP_COMPONENT_PRECISION 630

/* Occupancy and distance to the surface. Read by sogmm_map_occupancy_f32,
 * sogmm_model_surface_distance_f32, sogmm_map_surface_distance_f32. */
/* Standard deviation of the true surface along a ray about the depth the map renders there.
 * f64 (m), > 0, finite; default 0.01. */
#define SOGMM_OPT_OCCUPANCY_SIGMA 700
/* A point within this distance of the surface along a ray is occupied.
 * f64 (m), > 0, finite; default 0.02. */
#define SOGMM_OPT_OCCUPANCY_THICKNESS 701
/* Distance to the surface: each component is the disc of its two largest principal axes out to
 * this many standard deviations.
 * f64 (standard deviations), in (0, 10]; default 2. */
#define SOGMM_OPT_SURFACE_DISC_SIGMAS 702

/* Registration. Read by sogmm_register_points_f32 and sogmm_register_model. */
/* Registration: steps (each scores every source point of the level) per coarse-to-fine level.
 * i64 (iterations), [1, 2^31-1]; default 30. */
#define SOGMM_OPT_REGISTRATION_MAX_ITER 800
/* Registration: a level ends when a step moves the source by less than this (|t| + |rotation| x
 * RMS radius).
 * f64 (m), > 0, finite; default 0.0001. */
#define SOGMM_OPT_REGISTRATION_TOL 801
/* Registration: prior weight of the uniform outlier term (over the target's 3-sigma box).
 * f64, in [0, 1); default 0.1. */
#define SOGMM_OPT_REGISTRATION_OUTLIER_RATIO 802
/* Registration: 1 scores gray too (the 4-D joint density: gray marginal times the conditional x
 * | gray), 0 the 3-D marginal.
 * i64, 0 or 1; default 1. */
#define SOGMM_OPT_REGISTRATION_USE_GRAY 803
/* Registration: coarse-to-fine levels; level l smooths the target by COARSE_SIGMA / 2^l, the
 * last not at all.
 * i64 (levels), [1, 16]; default 3. */
#define SOGMM_OPT_REGISTRATION_LEVELS 804
/* Registration: smoothing standard deviation of the coarsest level (halved per level).
 * f64 (m), > 0, finite; default 0.04. */
#define SOGMM_OPT_REGISTRATION_COARSE_SIGMA 805
/* Registration: below this inlier ratio the status is SOGMM_REGISTRATION_LOW_FITNESS.
 * f64, in [0, 1]; default 0.5. */
#define SOGMM_OPT_REGISTRATION_MIN_INLIER_RATIO 806
/* Registration: directions whose scaled information is below this fraction of the largest are
 * unobservable.
 * f64, in [0, 1); default 0.001. */
#define SOGMM_OPT_REGISTRATION_DEGENERACY_RATIO 807
/* Registration: fewer finite source points are SOGMM_E_INVALID_DATA.
 * i64 (points), >= 6; default 100. */
#define SOGMM_OPT_REGISTRATION_MIN_POINTS 808
/* Registration: a source point's depth error has standard deviation this x z^2 (z its depth in
 * the sensor's frame, the source's own), added along its ray to each component's covariance;
 * point sources only; 0: off.
 * f64 (1/m), [0, 1] (0: off); default 0. */
#define SOGMM_OPT_REGISTRATION_DEPTH_NOISE 809
/* Tracking: 1 registers a frame the map does not accept to the last inserted frame too and
 * inserts it when the two agree or the map has too few inliers to judge; 0 inserts only frames
 * the map accepts.
 * i64, 0 or 1; default 1. */
#define SOGMM_OPT_TRACKING_ODOMETRY 810
/* Tracking: largest RMS distance between a frame's points at the map's and at the odometry's
 * pose for the two to agree.
 * f64 (m), > 0, finite; default 0.02. */
#define SOGMM_OPT_TRACKING_MAX_DISAGREEMENT 811
/* END GENERATED option keys */

/* Named values of option keys. */
/* SOGMM_OPT_REG_COVAR: floors from the data's scales; get returns it while no value is set. */
#define SOGMM_REG_COVAR_AUTO (-1.0)
/* SOGMM_OPT_DEQUANTISE_DEPTH: on for the points of an RGB-D frame, off for arrays. */
#define SOGMM_DEQUANTISE_AUTO (-1)
/* SOGMM_OPT_MODE_COUNTER: */
#define SOGMM_MODE_COUNTER_FLAT_BINNED 0       /* the authors' flat mean shift with bin seeding */
#define SOGMM_MODE_COUNTER_GAUSSIAN_BLURRING 1 /* the paper's Gaussian blurring mean shift */
/* SOGMM_OPT_MAP_FUSION_METHOD: */
#define SOGMM_FUSION_HELLINGER 0 /* Hellinger distance of the 4-D Gaussians, in [0, 1] */
#define SOGMM_FUSION_KL 1        /* symmetric KL divergence (KL(a||b) + KL(b||a)) / 2, nats */

/* Option keys 1000 to 9999 are experimental and may change in any release. */

/* Creates an options handle holding every default. Caller frees it. */
SOGMM_API sogmm_status sogmm_options_create(sogmm_options** out);
/* Deep copy of `src`. Caller frees it. */
SOGMM_API sogmm_status sogmm_options_clone(sogmm_options** out, const sogmm_options* src);
/* Releases `options`. NULL is a no-op. */
SOGMM_API void sogmm_options_free(sogmm_options* options);
SOGMM_API sogmm_status sogmm_options_set_f64(sogmm_options* options, sogmm_key key, double value);
SOGMM_API sogmm_status sogmm_options_set_i64(sogmm_options* options, sogmm_key key, int64_t value);
SOGMM_API sogmm_status sogmm_options_get_f64(const sogmm_options* options, sogmm_key key, double* out);
SOGMM_API sogmm_status sogmm_options_get_i64(const sogmm_options* options, sogmm_key key, int64_t* out);

/* ---- option introspection --------------------------------------------- */
/* The library's option registry, which every binding and tool reads its
 * defaults and ranges from (as zstd's ZSTD_cParam_getBounds). */
#define SOGMM_TYPE_F64 0 /* set/get with sogmm_options_*_f64 */
#define SOGMM_TYPE_I64 1 /* set/get with sogmm_options_*_i64 */

/* What the library knows of one option key. The caller sets struct_size to
 * sizeof(sogmm_option_info) before the call; later versions only append
 * fields, and write only the first struct_size bytes. Strings are static
 * (never freed, valid for the process's lifetime). */
typedef struct sogmm_option_info {
  size_t struct_size;  /* in: sizeof(sogmm_option_info) as the caller knows it */
  sogmm_key key;       /* the key asked for */
  int32_t type;        /* SOGMM_TYPE_F64 or SOGMM_TYPE_I64 */
  const char* name;    /* the macro's name, e.g. "SOGMM_OPT_BANDWIDTH" */
  double default_f64;  /* the default (for an I64 key: the default as a double) */
  double lower_f64;    /* smallest accepted value (closed; may be -inf); for I64 keys the I64 bound as a double */
  double upper_f64;    /* largest accepted value (closed; may be +inf) */
  int64_t default_i64; /* I64 keys: the default; F64 keys: 0 */
  int64_t lower_i64;   /* I64 keys: smallest accepted value; F64 keys: 0 */
  int64_t upper_i64;   /* I64 keys: largest accepted value; F64 keys: 0 */
  const char* range;   /* the whole rule in words, e.g. "> 0, finite" (the bounds are its hull:
                        * a value inside them may still be refused, as a sentinel outside them accepted) */
  const char* unit;    /* e.g. "m", "nats"; "" when dimensionless */
  const char* doc;     /* what the option does (the text this header documents the key with) */
} sogmm_option_info;

/* Fills `*out` for `key`. SOGMM_E_INVALID_ARG for an unknown key (info keys
 * included) or a struct_size below this version's first struct. */
SOGMM_API sogmm_status sogmm_option_get_info(sogmm_key key, sogmm_option_info* out);
/* Every option key, in increasing order: writes min(capacity, count) keys
 * to `keys` (may be NULL when capacity is 0) and the number of keys to
 * `*count`. */
SOGMM_API sogmm_status sogmm_option_keys(sogmm_key* keys, size_t capacity, size_t* count);

/* ---- progress and cancel ---------------------------------------------- */
/* Stages reported to a progress callback. New stages are only appended:
 * pass unknown numbers through. `step` counts work done in the stage,
 * `total` is 0 when unknown. */
#define SOGMM_STAGE_MODE_COUNT 1 /* mean shift; step/total: seeds (flat) or iterations (blurring) */
#define SOGMM_STAGE_SEEDING 2    /* k-means++; step/total: components seeded / K */
#define SOGMM_STAGE_EM 3         /* EM; step: iterations done (0 at the start), total: max_iter;
                                  * log_likelihood: mean per point of the last iteration's E-step */
#define SOGMM_STAGE_RUN 4        /* SOGMM_OPT_N_INIT > 1 only: run `step` (from 1) of `total` starts;
                                  * log_likelihood: the best final value of the runs before (0 at first) */
#define SOGMM_STAGE_SAMPLING 5   /* sogmm_model_sample_f32; step/total: points drawn / requested */
#define SOGMM_STAGE_SCORING 6    /* sogmm_*_score_samples_f32*; step/total: points scored / requested
                                  * (the last report has step = total) */
#define SOGMM_STAGE_REGRESSION 7 /* sogmm_*_regress_gray_f32*; step/total as SCORING */
#define SOGMM_STAGE_RENDERING 8  /* sogmm_*_render_f32; step/total: image rows done / height */
#define SOGMM_STAGE_REGISTRATION 9 /* sogmm_register_points_f32; step: iterations done, total: levels x
                                    * max_iter; the mean log-likelihood of the last iteration */

/* Progress callback. Return 0 to continue; any non-zero value cancels: the
 * call stops within one report interval, frees everything it allocated,
 * writes no output (handle out-pointers get NULL, output arrays are left
 * untouched) and returns SOGMM_E_CANCELLED, with a last-error message naming
 * the stage. Thread: called only on the thread that called the sogmm_*
 * function, inside that call, one call at a time (never on a worker thread,
 * never after the call returned), so it may use thread-affine state (the
 * Python GIL and signal handling, a thread-local error). Cadence: at the start
 * of each stage, after each EM iteration, and during long loops at most about
 * 20 ms apart (plus one work chunk, a few milliseconds), so that a cancel
 * takes effect within about 50 ms. Within a stage, `step` never decreases.
 * The interval is timed from the callback's return: a slow callback slows
 * the call by its own time only, and the call's worker threads sleep while
 * they wait for it. Rules: return quickly; never throw, longjmp or unwind out
 * of it. A sogmm_* function called from the callback runs without a
 * callback (a nested fit reports to nothing, whatever its options say) and
 * overwrites the thread's last error; a call on the map whose call is
 * running the callback returns SOGMM_E_BUSY (sogmm_map_free refuses it).
 * Results never depend on the callback (only whether the call finishes). */
typedef int32_t (*sogmm_progress_fn)(int32_t stage, uint64_t step, uint64_t total, double log_likelihood,
                                     void* user_data);

/* Sets the progress callback of `options` (fn = NULL removes it); user_data
 * is passed through and not owned. sogmm_options_clone copies the pair.
 * Called by sogmm_fit_points_f32, sogmm_fit_frame (from the mode count on),
 * sogmm_model_sample_f32, sogmm_model_regress_gray_f32,
 * sogmm_model_score_samples_f32 and the map queries sogmm_map_score_samples_f32,
 * sogmm_map_regress_gray_f32 and sogmm_map_sample_f32 (which then write into
 * a temporary buffer: as much memory again as their output); the map's
 * inserts and flushes use the callback of sogmm_map_set_progress. Other
 * functions ignore it. Bindings set it on a private clone for one call. */
SOGMM_API sogmm_status sogmm_options_set_progress(sogmm_options* options, sogmm_progress_fn fn, void* user_data);

/* ---- fitting ---------------------------------------------------------- */
/* Fits a model to n points (x, y, z, gray): `points` holds n * 4 floats.
 * Uses the fit keys of `options` (NULL = defaults). With
 * SOGMM_OPT_N_COMPONENTS = K > 0 the mode count is skipped and the model has
 * exactly K components (fixed K). The model records the fit report and the
 * fit parameters (see SOGMM_INFO_*). Errors: n == 0 or NaN/Inf ->
 * SOGMM_E_INVALID_DATA; K > n -> SOGMM_E_INVALID_ARG.
 *
 * `initial` NULL: a cold fit. Otherwise a warm start: the fit starts from
 * `initial`, a model of an earlier, overlapping cloud already moved into these
 * points' frame (e.g. the previous frame's model moved by the relative pose
 * with sogmm_model_transform). Self-organizing (SOGMM_OPT_N_COMPONENTS = 0):
 * components of `initial` whose responsibility mass on the well-explained
 * points is below 0.5 points are removed; points more than 10 nats below the
 * median log-likelihood under `initial` are novel, and the mode count
 * (SOGMM_OPT_BANDWIDTH) and k-means++ (SOGMM_OPT_SEED) on the novel points
 * only add that many new components; EM then runs from kept + new, at most
 * SOGMM_OPT_WARM_MAX_ITER iterations while SOGMM_OPT_MAX_ITER is left at its
 * default (with N_COMPONENTS = K too; a cold fallback runs MAX_ITER). When
 * `initial` explains the points badly (fewer than half of them: the median
 * point's log-likelihood more than 10 nats below the mean log-likelihood
 * `initial` gives its own samples, e.g. a start far from the points), it is
 * dropped and the fit is a cold one (every point novel). With
 * N_COMPONENTS = K > 0, EM runs from `initial` as given, which must have K
 * components. `initial` is not modified and may be freed afterwards. Warm
 * start errors: SOGMM_OPT_N_INIT != 1 or K != the initial model's size ->
 * SOGMM_E_INVALID_ARG. */
SOGMM_API sogmm_status sogmm_fit_points_f32(sogmm_model** out, const float* points, size_t n,
                                            const sogmm_model* initial, const sogmm_options* options);


/* ---- RGB-D frames ---------------------------------------------------- */
/* A frame holds the depth image, the colour image (or none) and the camera
 * intrinsics: the one descriptor of an RGB-D image that sogmm_fit_frame,
 * sogmm_map_insert_frame and sogmm_frame_to_points_f32 take. It is made from
 * arrays in memory (sogmm_frame_from_arrays) or from image files, which the
 * library decodes itself (sogmm_frame_read, sogmm_frame_decode: libpng,
 * libjpeg-turbo with fixed settings, accurate integer IDCT, no gamma), so
 * every language gets the same pixels, and with the same options the same
 * model, from the same files. */

/* Layout of a frame's colour image (sogmm_frame_from_arrays,
 * sogmm_frame_color_format). */
#define SOGMM_COLOR_GRAY8 1    /* width * height bytes, gray 0..255 */
#define SOGMM_COLOR_RGB8 2     /* width * height * 3 bytes, interleaved R, G, B */
#define SOGMM_COLOR_GRAY_F32 3 /* width * height native floats, gray used as given (meant to be in
                                * [0, 1], e.g. a normalised thermal image); any alignment.
                                * Non-finite -> INVALID_DATA where the frame is used */

/* Makes a frame from arrays (copied; the caller keeps them): `depth` holds
 * width * height uint16 values (raw units, SOGMM_OPT_DEPTH_SCALE per metre,
 * 0 = no reading), `color` the registered image in `color_format`
 * (SOGMM_COLOR_*), both row-major and contiguous. color = NULL with
 * color_format = 0: no colour image (gray 0 when fitted). The frame has no
 * intrinsics yet (sogmm_frame_set_intrinsics). Errors: out or depth NULL, or
 * color NULL with a non-zero color_format -> SOGMM_E_NULL_ARG; width/height 0
 * or > INT32_MAX, unknown color_format -> SOGMM_E_INVALID_ARG; more than 2^26
 * pixels (the frame reader's limit, checked before anything is copied) ->
 * SOGMM_E_LIMIT. */
SOGMM_API sogmm_status sogmm_frame_from_arrays(sogmm_frame** out, uint32_t width, uint32_t height,
                                               const uint16_t* depth, const void* color, int32_t color_format);

/* Reads a frame from a depth PNG (one channel, 16-bit; 8-bit is widened with
 * the same values) and a colour PNG or JPEG (8-bit gray -> SOGMM_COLOR_GRAY8,
 * RGB or palette -> SOGMM_COLOR_RGB8; an alpha channel is dropped; 1/2/4-bit
 * gray expanded to 8). `color_path` NULL = no colour image (gray 0 when
 * fitted). The frame has no intrinsics yet (sogmm_frame_set_intrinsics).
 * Errors: a path NULL -> SOGMM_E_NULL_ARG; a file that cannot be read or is
 * not a regular file (a FIFO is refused, never waited on) -> SOGMM_E_IO; not
 * a PNG/JPEG, truncated or corrupt (a JPEG warning counts as corrupt) ->
 * SOGMM_E_FORMAT; a depth image with colour, alpha or another bit depth, a
 * JPEG depth image, 16-bit or CMYK colour, images of different sizes ->
 * SOGMM_E_INVALID_DATA; an image of more than 2^26 pixels (checked from its
 * header, before the pixels are allocated) -> SOGMM_E_LIMIT. Messages name
 * the file. */
SOGMM_API sogmm_status sogmm_frame_read(sogmm_frame** out, const char* depth_path, const char* color_path);
/* As sogmm_frame_read from the files' bytes in memory (`color_data` NULL =
 * no colour image; messages name the images "depth" and "color"). */
SOGMM_API sogmm_status sogmm_frame_decode(sogmm_frame** out, const void* depth_data, size_t depth_size,
                                          const void* color_data, size_t color_size);
/* Releases `frame`. NULL is a no-op. */
SOGMM_API void sogmm_frame_free(sogmm_frame* frame);
/* Width and height of the frame in pixels (0 for NULL). Never fail. */
SOGMM_API uint32_t sogmm_frame_width(const sogmm_frame* frame);
SOGMM_API uint32_t sogmm_frame_height(const sogmm_frame* frame);
/* The depth pixels: width * height raw uint16 values, row-major (NULL for
 * NULL). Owned by the frame, valid until sogmm_frame_free. Never fails. */
SOGMM_API const uint16_t* sogmm_frame_depth(const sogmm_frame* frame);
/* The colour bytes in the layout of sogmm_frame_color_format, row-major;
 * NULL without a colour image (or for NULL).
 * Owned by the frame, valid until sogmm_frame_free. Never fails. */
SOGMM_API const uint8_t* sogmm_frame_color(const sogmm_frame* frame);
/* SOGMM_COLOR_GRAY8 or SOGMM_COLOR_RGB8 (from files; also
 * SOGMM_COLOR_GRAY_F32 from arrays); 0 without a colour image (or for NULL).
 * Never fails. */
SOGMM_API int32_t sogmm_frame_color_format(const sogmm_frame* frame);
/* Sets the intrinsics of the full-size images (pixels). They are checked
 * where the frame is used (fx, fy > 0, all finite). Errors: frame NULL ->
 * SOGMM_E_NULL_ARG. */
SOGMM_API sogmm_status sogmm_frame_set_intrinsics(sogmm_frame* frame, double fx, double fy, double cx, double cy);

/* Fits a model to one RGB-D frame. Decimation and the valid depth range come
 * from `options` (NULL = defaults); the fit keys as sogmm_fit_points_f32.
 * The model records the camera (SOGMM_INFO_CAMERA_*). Errors: frame or out
 * NULL -> SOGMM_E_NULL_ARG; no intrinsics set, bad intrinsics (including fx,
 * fy, cx, cy, depth scale and range that would back-project a pixel beyond
 * the float32 range), bad depth range, a decimation larger than a side ->
 * SOGMM_E_INVALID_ARG; a decimated image of more than 2^26 pixels ->
 * SOGMM_E_LIMIT; no valid pixel or a non-finite float gray ->
 * SOGMM_E_INVALID_DATA. */
SOGMM_API sogmm_status sogmm_fit_frame(sogmm_model** out, const sogmm_frame* frame, const sogmm_options* options);

/* The points sogmm_fit_frame fits, without fitting: the valid pixels of the
 * decimated frame, row by row, as N rows (x, y, z, gray) of float32 in the
 * camera frame (x right, y down, z forward, metres): z = depth / scale,
 * x = (u - cx/d) z / (fx/d), y = (v - cy/d) z / (fy/d) on the decimated
 * pixel grid. Options and errors as sogmm_fit_frame, except that a frame
 * without a valid pixel gives N = 0 and SOGMM_OK. *n_points (required)
 * receives N. `out` has room for `capacity` floats and must hold 4 N, else
 * SOGMM_E_BUFFER_TOO_SMALL, which still sets *n_points to N (the size to
 * allocate); on any other error neither *n_points nor `out` is written.
 * out = NULL with capacity 0 only queries N. */
SOGMM_API sogmm_status sogmm_frame_to_points_f32(float* out, size_t capacity, size_t* n_points,
                                                 const sogmm_frame* frame, const sogmm_options* options);

/* ---- models from arrays, copies, release ------------------------------ */
/* Builds a model from m components: `weights` (m floats, >= 0, summing to 1
 * within 1e-4), `means` (m * 4) and `covariances` (m * 16, symmetric
 * positive definite 4 x 4). `support_size` is the number of points the model
 * stands for (weights merges; 0 = unknown). The arrays are copied.
 * Errors: m == 0, NaN/Inf, bad weights, asymmetric covariance ->
 * SOGMM_E_INVALID_DATA; covariance not positive definite -> SOGMM_E_NUMERIC. */
SOGMM_API sogmm_status sogmm_model_from_arrays_f32(sogmm_model** out, size_t m, const float* weights,
                                                   const float* means, const float* covariances,
                                                   uint64_t support_size);
/* Deep copy of `model` including its metadata. */
SOGMM_API sogmm_status sogmm_model_clone(sogmm_model** out, const sogmm_model* model);
/* Releases `model`. NULL is a no-op. */
SOGMM_API void sogmm_model_free(sogmm_model* model);

/* ---- arrays ----------------------------------------------------------- */
/* Number of components M (always >= 1 for a valid handle). */
SOGMM_API sogmm_status sogmm_model_n_components(const sogmm_model* model, size_t* out);
/* Copy the M weights / M x 4 means / M x 4 x 4 covariances into `out`, which
 * has room for `capacity` floats; capacity must be >= M, 4 M, 16 M
 * respectively, else SOGMM_E_BUFFER_TOO_SMALL. */
SOGMM_API sogmm_status sogmm_model_get_weights_f32(const sogmm_model* model, float* out, size_t capacity);
SOGMM_API sogmm_status sogmm_model_get_means_f32(const sogmm_model* model, float* out, size_t capacity);
SOGMM_API sogmm_status sogmm_model_get_covariances_f32(const sogmm_model* model, float* out,
                                                       size_t capacity);

/* ---- fit report and metadata ------------------------------------------ */
/* Read-only information keys (10000 and up, disjoint from the option keys);
 * types as with options: the getter of the other type, an option key or an
 * unknown key -> SOGMM_E_INVALID_ARG naming the key. A value that the model
 * does not have returns SOGMM_E_NOT_FOUND (e.g. the fit report of a model
 * built from arrays, or the timings of a loaded model). */
#define SOGMM_INFO_SUPPORT_SIZE 10001    /* i64: points the model stands for (always present): the uint64's
                                          * bits (cast), as for the seed */
#define SOGMM_INFO_CREATED_UNIX_MS 10002 /* i64: creation time, ms since 1970 UTC (0 = unknown) */
/* Fit report and parameters: present for fitted models and files that store them. */
#define SOGMM_INFO_FIT_ITERATIONS 10100     /* i64: EM iterations run */
#define SOGMM_INFO_FIT_CONVERGED 10101      /* i64: 1 if EM stopped on the tolerance */
#define SOGMM_INFO_FIT_LOG_LIKELIHOOD 10102 /* f64: final mean log-likelihood per point */
#define SOGMM_INFO_FIT_BANDWIDTH 10103      /* f64: bandwidth (0 for a fixed-K fit) */
#define SOGMM_INFO_FIT_N_COMPONENTS_REQUESTED 10104 /* i64: K of a fixed-K fit, 0 = self-organizing */
#define SOGMM_INFO_FIT_TOL 10105            /* f64 */
#define SOGMM_INFO_FIT_REG_COVAR 10106      /* f64 */
#define SOGMM_INFO_FIT_MAX_ITER 10107       /* i64 */
#define SOGMM_INFO_FIT_SEED 10108           /* i64: the uint64 seed's bits: the k-means++ seed of the kept
                                           * run (SEED + run), so a fit with this seed and N_INIT 1
                                           * reproduces the model */
/* Timings: present only for a model fitted in this process (not stored in files). */
#define SOGMM_INFO_FIT_N_POINTS 10150              /* i64: points given to the fit */
#define SOGMM_INFO_FIT_SECONDS_MODE_COUNT 10151    /* f64 */
#define SOGMM_INFO_FIT_SECONDS_SEEDING 10152       /* f64 */
#define SOGMM_INFO_FIT_SECONDS_EM 10153            /* f64 */
#define SOGMM_INFO_FIT_SECONDS_TOTAL 10154         /* f64 */
#define SOGMM_INFO_FIT_N_INIT 10155                /* i64: runs made (SOGMM_OPT_N_INIT) */
#define SOGMM_INFO_FIT_RUN 10156                   /* i64: which run was kept, from 0 */
/* Camera the points came from: present for sogmm_fit_frame models and files that store it. */
#define SOGMM_INFO_CAMERA_WIDTH 10200       /* i64: full-size image width, pixels */
#define SOGMM_INFO_CAMERA_HEIGHT 10201      /* i64 */
#define SOGMM_INFO_CAMERA_FX 10202          /* f64 */
#define SOGMM_INFO_CAMERA_FY 10203          /* f64 */
#define SOGMM_INFO_CAMERA_CX 10204          /* f64 */
#define SOGMM_INFO_CAMERA_CY 10205          /* f64 */
#define SOGMM_INFO_CAMERA_DECIMATION 10206  /* i64 */
#define SOGMM_INFO_CAMERA_DEPTH_SCALE 10207 /* f64 */
#define SOGMM_INFO_CAMERA_DEPTH_MIN 10208   /* f64 */
#define SOGMM_INFO_CAMERA_DEPTH_MAX 10209   /* f64 */

SOGMM_API sogmm_status sogmm_model_get_info_f64(const sogmm_model* model, sogmm_key key, double* out);
SOGMM_API sogmm_status sogmm_model_get_info_i64(const sogmm_model* model, sogmm_key key, int64_t* out);
/* Sets an information key that .sogmm files store: the fit record
 * (SOGMM_INFO_FIT_ITERATIONS to SOGMM_INFO_FIT_SEED) or the camera
 * (SOGMM_INFO_CAMERA_*), e.g. to give a model rebuilt from arrays the
 * provenance of the fits it came from. A model without that record gets one
 * holding the format's defaults (spec/format.md 4.2) before the key is set.
 * Types as with get. Errors (SOGMM_E_INVALID_ARG naming the key, the model
 * unchanged): a key not stored in files (support size, creation time,
 * timings), a non-finite double, FIT_CONVERGED not 0 or 1, a negative
 * N_COMPONENTS_REQUESTED, an int32 field out of range, CAMERA_WIDTH/HEIGHT
 * < 0, CAMERA_DECIMATION < 1. FIT_SEED takes the uint64's bits (cast). */
SOGMM_API sogmm_status sogmm_model_set_info_f64(sogmm_model* model, sogmm_key key, double value);
SOGMM_API sogmm_status sogmm_model_set_info_i64(sogmm_model* model, sogmm_key key, int64_t value);

/* Pose of the model's frame in the world: 16 doubles, row-major 4 x 4 rigid
 * transform [R t; 0 0 0 1] (camera-to-world for a fitted frame).
 * get: SOGMM_E_NOT_FOUND if no pose is set. set: copies `pose`; it must be
 * finite and rigid (every entry of R^T R within 1e-3 of I, det R > 0, last
 * row exactly 0 0 0 1: the rule of sogmm_model_transform and of .sogmm files),
 * else SOGMM_E_INVALID_ARG. clear: removes the pose. */
SOGMM_API sogmm_status sogmm_model_get_pose(const sogmm_model* model, double* pose_out);
SOGMM_API sogmm_status sogmm_model_set_pose(sogmm_model* model, const double* pose);
SOGMM_API sogmm_status sogmm_model_clear_pose(sogmm_model* model);

/* Free-form key/value metadata (UTF-8 strings, NUL-terminated, stored in
 * .sogmm files). get: *value_out points to the library-owned value, valid
 * until `model` is next modified or freed; SOGMM_E_NOT_FOUND if absent; a
 * key that repeats (files may hold repeated keys) gives its first pair.
 * set: adds the pair or replaces the value of the first pair with that key;
 * an empty key or a key or value that is not valid UTF-8 is
 * SOGMM_E_INVALID_ARG. count / at: enumerate all pairs in order; index >=
 * count is SOGMM_E_INVALID_ARG; pointers as for get. */
SOGMM_API sogmm_status sogmm_model_get_value(const sogmm_model* model, const char* key,
                                             const char** value_out);
SOGMM_API sogmm_status sogmm_model_set_value(sogmm_model* model, const char* key, const char* value);
SOGMM_API sogmm_status sogmm_model_value_count(const sogmm_model* model, size_t* out);
SOGMM_API sogmm_status sogmm_model_value_at(const sogmm_model* model, size_t index, const char** key_out,
                                            const char** value_out);

/* ---- inference -------------------------------------------------------- */
/* Draws n points, written as n rows of `dims` floats (dims = 4: x, y, z,
 * gray; dims = 3: x, y, z, the spatial marginal) into `out` (n * dims
 * floats), grouped by component. Same seed, same samples. Truncation from
 * SOGMM_OPT_SAMPLE_TRUNCATION (NULL options = 2.5). n == 0 writes nothing
 * (out may then be NULL). */
SOGMM_API sogmm_status sogmm_model_sample_f32(const sogmm_model* model, size_t n, uint64_t seed,
                                              int32_t dims, const sogmm_options* options, float* out);

/* Expected gray at n 3-D points (`xyz`: n * 3 floats) into `mean_out` (n
 * floats) and, if `variance_out` is not NULL, the conditional variance (n
 * floats). Far from every component (beyond about 6.5 standard deviations)
 * both fall back smoothly to the mixture's prior gray and total gray
 * variance (sogmm::regress_gray, core/include/sogmm/inference.hpp). n == 0
 * writes nothing (pointers may then be NULL). NaN/Inf input ->
 * SOGMM_E_INVALID_DATA. Query options below. */
SOGMM_API sogmm_status sogmm_model_regress_gray_f32(const sogmm_model* model, const float* xyz, size_t n,
                                                    const sogmm_options* options, float* mean_out,
                                                    float* variance_out);

/* Log-density of n points under the model into `out` (n doubles). dims = 4:
 * rows of (x, y, z, gray), joint density; dims = 3: rows of (x, y, z), the
 * marginal over gray. n == 0 writes nothing. NaN/Inf input ->
 * SOGMM_E_INVALID_DATA. Query options below. */
SOGMM_API sogmm_status sogmm_model_score_samples_f32(const sogmm_model* model, const float* points,
                                                     size_t n, int32_t dims, const sogmm_options* options,
                                                     double* out);

/* The query options of sogmm_model_regress_gray_f32 and
 * sogmm_model_score_samples_f32 (NULL = defaults):
 * - SOGMM_OPT_THREADS: worker threads; the answers are bitwise the same for
 *   any count;
 * - SOGMM_OPT_QUERY_TRUNCATION_NATS: 0 = exact (default); > 0 culls (a
 *   component is skipped at a point only when its term is provably more than
 *   that many nats below the point's largest);
 * - the progress callback (sogmm_options_set_progress; SOGMM_STAGE_REGRESSION,
 *   SOGMM_STAGE_SCORING): the same bits; a cancel returns SOGMM_E_CANCELLED
 *   with the outputs untouched (they are then written through a temporary
 *   buffer: as much memory again as the output). */

/* PSNR of a gray image `estimate` against `truth` (`pixels` floats each;
 * -1 marks an empty pixel, e.g. a rendering of the model against the
 * frame's gray, as `sogmm eval` draws them). *psnr_out receives the honest
 * figure: 10 log10(data_range^2 / MSE) over the pixels valid in `truth`
 * (>= 0), with data_range 1 for gray in [0, 1], any other peak for other
 * data, or 0 for the actual range of the valid truth pixels (max - min).
 * *psnr_paper_out (may be NULL) receives the paper-compatible figure, which
 * keeps the authors' evaluation whatever data_range is: range 2 and every
 * pixel counted, the empty ones as perfect. Identical images give +infinity;
 * images that differ on a valid pixel always give a finite figure, for any
 * finite data_range (e.g. 1e300: computed as 20 log10(data_range) -
 * 10 log10(MSE), so data_range^2 never overflows).
 * Errors: NULL truth/estimate/psnr_out -> SOGMM_E_NULL_ARG; data_range
 * negative or not finite -> SOGMM_E_INVALID_ARG; NaN/Inf pixels, no valid
 * truth pixel, or data_range 0 on a constant truth that is not matched
 * exactly -> SOGMM_E_INVALID_DATA. */
SOGMM_API sogmm_status sogmm_psnr_images_f32(const float* truth, const float* estimate, size_t pixels,
                                             double data_range, double* psnr_out, double* psnr_paper_out);

/* New model with the components of a and b, weights re-weighted by support
 * size; support size a + b. Both must be in the same frame (key
 * "coordinate_frame": absent or "camera", or "world"), else
 * SOGMM_E_INVALID_ARG. Metadata as spec/format.md section 2.2: key/values
 * "coordinate_frame" (when "world") and "merged_fits" (fits of a + fits of
 * b; a model without it counts 1); the fit report when both have one with
 * the same settings (n_iter summed, converged if both, log-likelihood
 * weighted by support size), else none; the camera when both are equal; no
 * pose; other key/values are not kept. a may equal b. Support size 0
 * means unknown: if both are 0 the models count equally; if only one is 0 ->
 * SOGMM_E_INVALID_ARG (weighing a known count against an unknown one would be
 * a guess; rebuild that model with its support size). a + b overflowing
 * uint64 -> SOGMM_E_LIMIT. */
SOGMM_API sogmm_status sogmm_model_merge(sogmm_model** out, const sogmm_model* a, const sogmm_model* b);

/* New model = `model` moved by the rigid transform `pose` (16 doubles,
 * row-major [R t; 0 1], rules as sogmm_model_set_pose): means -> R mu + t,
 * spatial covariance blocks rotated (each rounded to the float32 matrix
 * nearest it that is positive definite, as a fit stores its own, so any valid
 * model moves to a valid one). Metadata is copied; a stored pose P
 * becomes P * pose^-1 so that the result still maps to the same world. A
 * moved mean or covariance (or the new pose) that is not finite ->
 * SOGMM_E_INVALID_ARG. */
SOGMM_API sogmm_status sogmm_model_transform(sogmm_model** out, const sogmm_model* model,
                                             const double* pose);

/* ---- rendering ---------------------------------------------------------- */
/* The largest image a render takes (width * height), checked before anything
 * is allocated: the limit of a frame's back-projection (2^26). */
#define SOGMM_MAX_RENDER_PIXELS 67108864
/* Renders what `model` shows from a pinhole camera (sogmm::render,
 * core/include/sogmm/render.hpp): for each pixel of a width x height image
 * with intrinsics fx, fy (> 0), cx, cy (all finite), the first surface along
 * the pixel's ray: the nearest mode, at camera depth z in (SOGMM_OPT_DEPTH_MIN,
 * SOGMM_OPT_DEPTH_MAX], of the model's spatial density along the ray, reached
 * by 1-D mean shift from every component peak on the ray that lies within
 * 3 standard deviations of its component; then the gray regressed at that
 * point (sogmm_model_regress_gray_f32) and its variance.
 * `camera_to_world` (16 doubles, row-major [R t; 0 0 0 1], rules as
 * sogmm_model_set_pose; NULL = identity, the model in the camera's frame)
 * places the camera in the model's frame. Outputs, row-major, width * height
 * floats each, written only on success: `depth_out` (camera z, metres),
 * `gray_out` and, if not NULL, `variance_out`. A pixel with nothing to show
 * (no component near its ray, or no surface in the depth range) is NaN in
 * all three (0 would be a valid gray, and a depth 0 a point at the camera).
 * `options` (NULL = defaults): SOGMM_OPT_DEPTH_MIN / _MAX (default 0.1 and
 * 3 m), SOGMM_OPT_RENDER_SURFACE_SIGMA (default 0: every mode is a surface;
 * s > 0: only modes with the evidence of one component at s sigma, so a ray
 * grazing a nearer object's components shows the surface behind),
 * SOGMM_OPT_THREADS (the images are bitwise the same for any count) and
 * the progress callback (SOGMM_STAGE_RENDERING; a cancel returns
 * SOGMM_E_CANCELLED with the outputs untouched). Moving model and pose
 * together by one rigid transform renders the same images (up to rounding).
 * Errors (the image size before the output pointers): width or height 0 or
 * > INT32_MAX ->
 * SOGMM_E_INVALID_ARG; model, depth_out or gray_out NULL ->
 * SOGMM_E_NULL_ARG; bad intrinsics, a pose that is not rigid,
 * DEPTH_MIN >= DEPTH_MAX -> SOGMM_E_INVALID_ARG; more than
 * SOGMM_MAX_RENDER_PIXELS pixels -> SOGMM_E_LIMIT. */
SOGMM_API sogmm_status sogmm_model_render_f32(const sogmm_model* model, uint32_t width, uint32_t height, double fx,
                                              double fy, double cx, double cy, const double* camera_to_world,
                                              const sogmm_options* options, float* depth_out, float* gray_out,
                                              float* variance_out);

/* ---- .sogmm files and memory ------------------------------------------ */
/* Writes `model` to `path` atomically (a temporary file in the same
 * directory renamed into place: on failure the previous file, if any, is
 * untouched). A symbolic link is written through: its final target is
 * replaced and the link kept. The file gets the permission bits of the file
 * it replaces (never set-user-ID, set-group-ID or sticky bits), or 0666 minus
 * the umask. Write keys of `options` apply. Errors: metadata too large for a
 * .sogmm file (2^31 - 1 bytes; 100 000 tables: 99 994 to 99 996 key/value pairs),
 * or arrays decoding to more bytes than SOGMM_OPT_MAX_DECODED_BYTES (default
 * 1 GiB: the cap of a default reader; about 17.9 million float32 components)
 * -> SOGMM_E_LIMIT, checked before anything is written; cannot write, or the
 * path names something other than a regular file -> SOGMM_E_IO. */
SOGMM_API sogmm_status sogmm_model_save(const sogmm_model* model, const char* path,
                                        const sogmm_options* options);
/* Reads a model from `path`. Read keys of `options` apply. Errors: cannot
 * open/read, or not a regular file (a FIFO, device or directory is refused
 * at once, never waited on) -> SOGMM_E_IO; not a valid .sogmm ->
 * SOGMM_E_FORMAT; checksum or content invalid -> SOGMM_E_FORMAT /
 * SOGMM_E_INVALID_DATA / SOGMM_E_NUMERIC; decoded size above the cap ->
 * SOGMM_E_LIMIT. */
SOGMM_API sogmm_status sogmm_model_load(sogmm_model** out, const char* path, const sogmm_options* options);
/* Serialises `model` into a new buffer (the bytes of a .sogmm file).
 * Errors as sogmm_model_save without SOGMM_E_IO. */
SOGMM_API sogmm_status sogmm_model_save_to_memory(sogmm_buffer** out, const sogmm_model* model,
                                                  const sogmm_options* options);
/* Reads a model from `size` bytes at `data` (copied as needed). Errors as
 * sogmm_model_load without SOGMM_E_IO; size == 0 -> SOGMM_E_FORMAT. */
SOGMM_API sogmm_status sogmm_model_load_from_memory(sogmm_model** out, const void* data, size_t size,
                                                    const sogmm_options* options);

/* ---- incremental map -------------------------------------------------- */
/* A world-frame map that grows only where the scene is new (issue 18; the
 * algorithm is documented in core/include/sogmm/map.hpp). Each insert scores
 * the frame's points, moved to the world by the camera-to-world `pose` (16
 * doubles, row-major rigid [R t; 0 0 0 1], rules as sogmm_model_set_pose),
 * with the 3-D log-likelihood of the map's local submap; points below
 * SOGMM_OPT_MAP_NOVELTY_THRESHOLD are pending, and once
 * SOGMM_OPT_MAP_BATCH_SIZE points are pending they are fitted and merged in
 * the world frame (optionally fused). With novelty and fusion off the map is
 * exactly the merge of every frame's own fit moved by its pose.
 *
 * Use guard: the calls taking a non-const map (inserts, flush,
 * set_progress) need it alone; the calls taking a const map (statistics,
 * export, save, queries) share it. A call that finds the map otherwise
 * taken, by another thread or because it is made from the progress callback
 * of a call on the same map, returns SOGMM_E_BUSY at once with the message
 * "map busy: <function> cannot run while ..." and changes nothing (it never
 * waits, so a callback cannot deadlock). This check comes right after the map
 * NULL check. */

/* Creates an empty map with the map, fit and RGB-D keys of `options` (NULL =
 * defaults). A depth range with DEPTH_MIN >= DEPTH_MAX -> SOGMM_E_INVALID_ARG. */
SOGMM_API sogmm_status sogmm_map_create(sogmm_map** out, const sogmm_options* options);
/* Releases `map`. NULL is a no-op. Call it once no call uses the map: a
 * free while another call on it runs (on another thread, or from that call's
 * progress callback) does not free it and sets the thread's last error to
 * "map busy: ..." (SOGMM_E_BUSY); free it after that call returns. Like any
 * free, it must not race a call that has not started yet: a handle is freed
 * by its last user. */
SOGMM_API void sogmm_map_free(sogmm_map* map);

/* Inserts a frame of n points (x, y, z, gray; n * 4 floats) in the camera
 * frame with its camera-to-world `pose`. Errors (the map is unchanged):
 * n == 0 or NaN/Inf -> SOGMM_E_INVALID_DATA; pose not finite or not rigid ->
 * SOGMM_E_INVALID_ARG; n > 2^26 -> SOGMM_E_LIMIT. An insert commits only
 * points a flush can fit; it refuses: a point beyond float32 range after the
 * pose -> SOGMM_E_INVALID_ARG; with SOGMM_OPT_N_COMPONENTS = K > 0, a fit it
 * would trigger on fewer than K points -> SOGMM_E_INVALID_ARG; else a batch
 * (the pending points and this frame's new ones, in this frame's camera
 * frame) whose range or gray values span more than 1e8 batch bandwidths
 * (SOGMM_OPT_BANDWIDTH, with novelty on times the batch's scale from
 * SOGMM_OPT_MAP_NOVELTY_BANDWIDTH_SCALE), the rule a fit of those points at that bandwidth applies ->
 * SOGMM_E_LIMIT (e.g. a pose far from the pending frames': flush first). A
 * fit this insert triggers that fails anyway or is cancelled
 * (sogmm_map_set_progress) -> its status, and the insert is undone: the map
 * is as before the call (the frame is not recorded, its points are not
 * pending), so the call can be retried. */
SOGMM_API sogmm_status sogmm_map_insert_points_f32(sogmm_map* map, const float* points, size_t n,
                                                   const double* pose);
/* Inserts `frame` (its pixels and intrinsics; decimation and depth range
 * from the options the map was created with) with its camera-to-world
 * `pose`. The first RGB-D frame fixes the camera: a frame of another size or
 * other intrinsics -> SOGMM_E_INVALID_ARG; a frame without a valid pixel ->
 * SOGMM_E_INVALID_DATA; frame NULL -> SOGMM_E_NULL_ARG; other errors as
 * sogmm_fit_frame and sogmm_map_insert_points_f32. */
SOGMM_API sogmm_status sogmm_map_insert_frame(sogmm_map* map, const sogmm_frame* frame, const double* pose);
/* Fits the pending points now (no-op when none are pending). A failed or
 * cancelled fit leaves the map and the pending points unchanged. */
SOGMM_API sogmm_status sogmm_map_flush(sogmm_map* map);
/* Drops the points pending for a fit (they never become components) and
 * writes how many there were into *dropped (may be NULL). The frames stay
 * recorded, and so does the camera the first RGB-D frame fixed. The way out
 * when a flush keeps failing (e.g. cancelled, or a numeric failure) and the
 * map cannot be saved. Needs exclusive use of the map, like an insert. */
SOGMM_API sogmm_status sogmm_map_discard_pending(sogmm_map* map, uint64_t* dropped);
/* Sets the progress callback of the fits that later inserts and flushes of
 * `map` run (fn = NULL removes it; rules of sogmm_progress_fn; user_data is
 * passed through and not owned). A non-zero return cancels the fit: the call
 * returns SOGMM_E_CANCELLED and the map is as before it. sogmm_map_create and
 * sogmm_map_load start with the callback of their options (none by
 * default). An insert that runs no fit calls no callback. Needs exclusive
 * use of the map, like an insert. */
SOGMM_API sogmm_status sogmm_map_set_progress(sogmm_map* map, sogmm_progress_fn fn, void* user_data);

/* Statistics of a map, by key (20000 and up, disjoint from the option and
 * info keys), so that a later version can add one without changing a type.
 * Types as with options: the getter of the other type, a key of another kind
 * or an unknown key -> SOGMM_E_INVALID_ARG naming the key. */

/* Totals of the map (sogmm_map_get_i64). */
#define SOGMM_MAP_N_COMPONENTS 20000 /* i64: components in the map */
#define SOGMM_MAP_N_PENDING 20001    /* i64: novel points waiting for a fit */
#define SOGMM_MAP_N_FRAMES 20002     /* i64: frames inserted (a loaded map counts the frames of its file) */
#define SOGMM_MAP_N_FLUSHES 20003    /* i64: fits run by this handle (batches and revisit refits) */
#define SOGMM_MAP_N_FUSED 20004      /* i64: new components fused into existing ones instead of appended */
#define SOGMM_MAP_N_REFITS 20005     /* i64: revisit refits run by this handle (also in N_FLUSHES) */
#define SOGMM_MAP_REVISION 20006     /* i64: the map's revision: 0 when created, +1 for every insert, flush
                                      * that fitted or delta that changed it (a delta sets the sender's);
                                      * a failed call keeps it. Saved with the map (spec/format.md 2.3) */
SOGMM_API sogmm_status sogmm_map_get_i64(const sogmm_map* map, sogmm_key key, int64_t* out);

/* What the insert of frame `frame` did (insertion order, from 0;
 * sogmm_map_frame_get_i64 / _f64). Frames of a loaded map have zero times
 * and no refit. frame >= SOGMM_MAP_N_FRAMES -> SOGMM_E_INVALID_ARG. */
#define SOGMM_MAP_FRAME_N_POINTS 20100     /* i64: points of the frame */
#define SOGMM_MAP_FRAME_N_NOVEL 20101      /* i64: of which novel */
#define SOGMM_MAP_FRAME_N_COMPONENTS 20102 /* i64: map components after the insert */
#define SOGMM_MAP_FRAME_FLUSHED 20103      /* i64: 1 if the insert ran a fit (a flush or a revisit refit), else 0 */
#define SOGMM_MAP_FRAME_N_REPLACED 20104   /* i64: components its revisit refit replaced
                                            * (SOGMM_OPT_MAP_REVISIT_REFIT_RATIO); 0 when none ran */
#define SOGMM_MAP_FRAME_MS_NOVELTY 20150   /* f64: novelty test, milliseconds */
#define SOGMM_MAP_FRAME_MS_FIT 20151       /* f64: fits run by the insert (a refit's with its check) */
#define SOGMM_MAP_FRAME_MS_MERGE 20152     /* f64: transform, merge, fusion and index update run by the insert */
SOGMM_API sogmm_status sogmm_map_frame_get_i64(const sogmm_map* map, uint64_t frame, sogmm_key key, int64_t* out);
SOGMM_API sogmm_status sogmm_map_frame_get_f64(const sogmm_map* map, uint64_t frame, sogmm_key key, double* out);
/* The camera-to-world pose given with frame `frame` into `pose_out` (16
 * doubles, row-major). frame >= SOGMM_MAP_N_FRAMES -> SOGMM_E_INVALID_ARG. */
SOGMM_API sogmm_status sogmm_map_frame_get_pose(const sogmm_map* map, uint64_t frame, double* pose_out);

/* The map's origin (anchor) into origin_out (3 doubles: x, y, z in the world
 * frame, metres). The map holds its components relative to it, so that far
 * from the world origin (geo-referenced poses: 1000 km out a float32
 * coordinate moves in steps of 6.25 cm) they keep room-scale resolution;
 * every computation with a pose is in double relative to it. By default the
 * first frame's translation rounded to a multiple of 1 km per axis (0 for a
 * map that starts within 500 m of the world origin, which is held and saved
 * as before origins existed); a loaded map's comes from its file's pose
 * (spec/format.md 2.3.1). World-frame exports and queries convert at the
 * boundary. 0 0 0 for a map before its first insert unless set. */
SOGMM_API sogmm_status sogmm_map_get_origin(const sogmm_map* map, double* origin_out);
/* Declares the map's origin (3 doubles, world frame, metres; e.g. a site's
 * surveyed point, so that the maps of one site share it) instead of the
 * first frame's. Only before the first insert: a map with a frame or a
 * component -> SOGMM_E_INVALID_ARG; a NaN/Inf entry or one beyond float32
 * range -> SOGMM_E_INVALID_ARG naming the axis. Needs exclusive use of the
 * map, like an insert. */
SOGMM_API sogmm_status sogmm_map_set_origin(sogmm_map* map, const double* origin);

/* New world-frame model (key "coordinate_frame" = "world") of the whole map
 * (`box` NULL) or of the components whose 3-sigma box meets `box` (6 floats:
 * x_min, y_min, z_min, x_max, y_max, z_max; weights renormalised over them).
 * Score, sample and regress in the world frame with the sogmm_model_*
 * functions on it. Errors: an empty map or no component in the box ->
 * SOGMM_E_INVALID_DATA; a box with min > max or NaN/Inf ->
 * SOGMM_E_INVALID_ARG. Pending points are not in it. */
SOGMM_API sogmm_status sogmm_map_export(sogmm_model** out, const sogmm_map* map, const float* box);

/* World-frame queries on the map, without exporting it. Each writes exactly
 * (bitwise) what the same sogmm_model_* query writes on sogmm_map_export(map,
 * NULL): they run on the map's model itself (core/include/sogmm/map_queries.hpp
 * says why not on the component index). Pending points are not in the map.
 * `options` (NULL = defaults) gives the progress callback
 * (sogmm_options_set_progress; SOGMM_STAGE_SCORING, _REGRESSION, _SAMPLING)
 * and, for sampling, SOGMM_OPT_SAMPLE_TRUNCATION; a cancel returns
 * SOGMM_E_CANCELLED with the outputs untouched. Errors, checked in this
 * order: map NULL -> SOGMM_E_NULL_ARG; dims not 3 or 4 ->
 * SOGMM_E_INVALID_ARG; a map without components (nothing flushed yet) ->
 * SOGMM_E_INVALID_DATA; then n == 0 writes nothing and succeeds (arrays may
 * be NULL); an input or output array NULL -> SOGMM_E_NULL_ARG; n * dims
 * overflowing size_t -> SOGMM_E_LIMIT; NaN/Inf input -> SOGMM_E_INVALID_DATA.
 * Const on the map: any number of threads may query one map at once. */

/* Log-density of n world points (dims = 4: rows of x, y, z, gray, joint;
 * dims = 3: rows of x, y, z, marginal over gray) into `out` (n doubles), as
 * sogmm_model_score_samples_f32. */
SOGMM_API sogmm_status sogmm_map_score_samples_f32(const sogmm_map* map, const float* points, size_t n,
                                                   int32_t dims, const sogmm_options* options, double* out);
/* Expected gray at n world points (`xyz`: n * 3 floats) into `mean_out` (n
 * floats) and, if `variance_out` is not NULL, its variance (n floats), as
 * sogmm_model_regress_gray_f32. */
SOGMM_API sogmm_status sogmm_map_regress_gray_f32(const sogmm_map* map, const float* xyz, size_t n,
                                                  const sogmm_options* options, float* mean_out,
                                                  float* variance_out);
/* Draws n world points into `out` (n * dims floats, grouped by component),
 * as sogmm_model_sample_f32: same seed, same samples. */
SOGMM_API sogmm_status sogmm_map_sample_f32(const sogmm_map* map, size_t n, uint64_t seed, int32_t dims,
                                            const sogmm_options* options, float* out);

/* Renders the map from a camera-to-world pose (world frame; NULL =
 * identity), exactly (bitwise) as sogmm_model_render_f32 on
 * sogmm_map_export(map, NULL). Arguments and errors as that function; a map
 * without components -> SOGMM_E_INVALID_DATA. */
SOGMM_API sogmm_status sogmm_map_render_f32(const sogmm_map* map, uint32_t width, uint32_t height, double fx,
                                            double fy, double cx, double cy, const double* camera_to_world,
                                            const sogmm_options* options, float* depth_out, float* gray_out,
                                            float* variance_out);

/* Writes the map as a world-frame .sogmm file, atomically as
 * sogmm_model_save (write keys of `options` apply), with the provenance keys
 * "map_frames" and "map_options" (spec/format.md section 2.3). Errors as
 * sogmm_model_save; points pending (call sogmm_map_flush first) or an empty
 * map -> SOGMM_E_INVALID_ARG / SOGMM_E_INVALID_DATA. */
SOGMM_API sogmm_status sogmm_map_save(const sogmm_map* map, const char* path, const sogmm_options* options);
/* Reads a map saved by sogmm_map_save (or any world-frame .sogmm model: then
 * without frame provenance). Read keys of `options` apply, and its map, fit
 * and RGB-D keys govern later inserts (NULL = defaults). Errors as
 * sogmm_model_load; a camera-frame model or a model of support size 0
 * (unknown: a flush could not weigh it against new points) ->
 * SOGMM_E_INVALID_ARG; malformed "map_frames" (a count with a sign
 * included) -> SOGMM_E_FORMAT. */
SOGMM_API sogmm_status sogmm_map_load(sogmm_map** out, const char* path, const sogmm_options* options);

/* Map deltas (spec/format.md section 2.5): what changed in a map since one
 * of its revisions (SOGMM_MAP_REVISION), so that a receiver that applies
 * them in order holds a bitwise equal map (weights, means, covariances,
 * support size, frame provenance) without the whole map being resent.
 *
 * Writes the delta file from revision `since_revision` to the map's current
 * one into `out` (room for `capacity` bytes) and its size to *size. out =
 * NULL with capacity 0 only queries the size; capacity below the size ->
 * SOGMM_E_BUFFER_TOO_SMALL with *size set (nothing written). Pending points
 * are not in a delta. Write keys of `options` apply (NULL = defaults). A
 * revision the map holds no changes from (before it was created or loaded,
 * after its current one, or, for a receiver, inside a delta it received) ->
 * SOGMM_E_INVALID_ARG naming the range. The map keeps the changes of its
 * last SOGMM_OPT_MAP_DELTA_HISTORY revisions (default 0: every revision,
 * so every explicit component it ever fitted: the cost of exporting from
 * any revision); a revision before those -> SOGMM_E_INVALID_ARG naming the
 * oldest kept. */
SOGMM_API sogmm_status sogmm_map_export_delta(const sogmm_map* map, uint64_t since_revision,
                                              const sogmm_options* options, void* out, size_t capacity,
                                              size_t* size);
/* Applies a delta of `size` bytes from `data` (read keys of `options`
 * apply). Refused with the map unchanged (its revision included): a file
 * that is not a valid delta (SOGMM_E_FORMAT and the other errors of
 * sogmm_model_load_from_memory; a model file -> SOGMM_E_FORMAT
 * "not_a_delta"); another map's delta, unless `map` is new (revision 0, no
 * frame, no component: it then takes the sender's identity) ->
 * SOGMM_E_INVALID_ARG; a delta that does not start at the map's revision (a
 * gap, a duplicate, out of order) -> SOGMM_E_INVALID_ARG naming both
 * revisions; points pending -> SOGMM_E_INVALID_ARG; steps that do not fit
 * the map or a result that differs from the sender's digest ->
 * SOGMM_E_FORMAT. Needs exclusive use of the map, like an insert. */
SOGMM_API sogmm_status sogmm_map_apply_delta(sogmm_map* map, const void* data, size_t size,
                                             const sogmm_options* options);

/* Merges the map `other` into `map` (two robots, one map):
 * `other_to_map` (16 doubles, row-major) is the rigid transform of the other
 * map's world frame into this map's. Where both maps hold the same surface
 * the sharper view wins instead of both being stacked: each of the other
 * map's components that `map` already explains at least as sharply (the
 * novelty test's local 3-D log-density at 4 of its 7 test points: its mean
 * and +-1 sigma along its spatial axes; ties to `map`) is left out, then
 * each of `map`'s components that the other's kept components explain more
 * sharply is removed; kept components keep their mass in points. The other
 * map's frame provenance is appended (poses moved into this world). A map
 * with no origin yet takes the other's, moved. One revision
 * (SOGMM_MAP_REVISION + 1): its delta (sogmm_map_export_delta) carries it.
 * Into an empty map it gives the other map's components (bitwise for the
 * identity); with a copy of itself it adds none. `stats_out` (NULL or 5
 * uint64): this map's components kept, removed; the other's added, left
 * out; frame lines added. Errors (the map unchanged): map, other or
 * other_to_map NULL -> SOGMM_E_NULL_ARG; other == map ->
 * SOGMM_E_INVALID_ARG; points pending in either map (flush first) or a pose
 * not finite or not rigid -> SOGMM_E_INVALID_ARG; the other map without
 * components -> SOGMM_E_INVALID_DATA; both maps with a camera and different
 * ones, or a component moved beyond float32 -> SOGMM_E_INVALID_ARG. Needs
 * exclusive use of `map` (like an insert) and shared use of `other` (like an
 * export): either in use by another call -> SOGMM_E_BUSY. */
SOGMM_API sogmm_status sogmm_map_merge_map(sogmm_map* map, const sogmm_map* other, const double* other_to_map,
                                           uint64_t* stats_out);

/* ---- trajectories (Redwood .log) -------------------------------------- */
/* A .log file holds, per frame, a header line "i j n" and four lines of a
 * row-major 4 x 4 camera-to-world matrix. Blank lines are skipped. */

/* Reads a .log file. Errors: path NULL -> SOGMM_E_NULL_ARG; cannot read, or
 * not a regular file (a FIFO is refused, never waited on) -> SOGMM_E_IO;
 * larger than 1 GiB -> SOGMM_E_LIMIT; a header that is not three integers, a
 * truncated matrix, a missing or non-finite number, a pose that is not rigid
 * (the rule of sogmm_model_set_pose), no pose at all -> SOGMM_E_INVALID_DATA
 * with the message naming the file and line. */
SOGMM_API sogmm_status sogmm_trajectory_read(sogmm_trajectory** out, const char* path);
/* Releases `trajectory`. NULL is a no-op. */
SOGMM_API void sogmm_trajectory_free(sogmm_trajectory* trajectory);
/* Number of poses (blocks), >= 1 for a read trajectory; 0 for NULL. Never fails. */
SOGMM_API size_t sogmm_trajectory_size(const sogmm_trajectory* trajectory);
/* The poses: size * 16 doubles, pose k at 16 k, in file order (NULL for
 * NULL). Owned by the trajectory, valid until sogmm_trajectory_free. */
SOGMM_API const double* sogmm_trajectory_poses(const sogmm_trajectory* trajectory);
/* The frame ids: size values, ids[k] the first number of block k's header,
 * the frame the pose belongs to (NULL for NULL). Owned as the poses. */
SOGMM_API const int64_t* sogmm_trajectory_ids(const sogmm_trajectory* trajectory);
/* Writes n poses (n * 16 doubles, row-major) as a .log file: block k with
 * the header "k k+1 n" and 17 significant digits (read back bitwise),
 * atomically as sogmm_model_save (on failure the previous file is
 * untouched). Errors: path NULL, or poses NULL with n > 0 ->
 * SOGMM_E_NULL_ARG; n == 0, a non-finite or non-rigid pose ->
 * SOGMM_E_INVALID_ARG (nothing written); cannot write -> SOGMM_E_IO. */
SOGMM_API sogmm_status sogmm_trajectory_write(const char* path, const double* poses, size_t n);
/* ---- occupancy and distance to the surface (issue 31) ----------------- */
/* States written by sogmm_map_occupancy_f32. */
#define SOGMM_OCCUPANCY_FREE 0
#define SOGMM_OCCUPANCY_OCCUPIED 1
#define SOGMM_OCCUPANCY_UNKNOWN 2

/* P(occupied) of n world points (`xyz`: n * 3 floats) into `probability_out`
 * (n doubles in [0, 1]; 0.5 = unknown) and, if `state_out` is not NULL,
 * their state (n bytes, SOGMM_OCCUPANCY_*), from what the map's own frames
 * see: each frame whose view (the map's camera record, its depth range)
 * holds a point renders the map there (as sogmm_map_render_f32); a point
 * before the first rendered surface is free, one within
 * SOGMM_OPT_OCCUPANCY_THICKNESS of it occupied, one behind it or seen by no
 * frame unknown, with the surface uncertain by SOGMM_OPT_OCCUPANCY_SIGMA
 * (formula: spec/api.md, "Occupancy"). A map without frames, without a
 * camera record (points-only inserts) or without components answers
 * unknown everywhere (it observed nothing). Keys: SOGMM_OPT_OCCUPANCY_*,
 * SOGMM_OPT_THREADS; the progress callback sees the renders
 * (SOGMM_STAGE_RENDERING) and then SOGMM_STAGE_SCORING over the points, and
 * may cancel (outputs then untouched). n == 0 writes nothing. Errors: NULL
 * map, xyz or probability_out -> SOGMM_E_NULL_ARG; NaN/Inf in xyz ->
 * SOGMM_E_INVALID_DATA (nothing written). */
SOGMM_API sogmm_status sogmm_map_occupancy_f32(const sogmm_map* map, const float* xyz, size_t n,
                                               const sogmm_options* options, double* probability_out,
                                               uint8_t* state_out);

/* Unsigned distance (metres) of n points (`xyz`: n * 3 floats, the model's
 * frame) to the model's surface into `distance_out` (n doubles) and, if
 * `gradient_out` is not NULL, the distance's gradient (n * 3 doubles: unit
 * vectors pointing away from the nearest surface point). The surface is the
 * union of the components' discs (the two largest principal axes out to
 * SOGMM_OPT_SURFACE_DISC_SIGMAS standard deviations; why:
 * core/include/sogmm/surface_distance.hpp); the search is exact. Keys:
 * SOGMM_OPT_SURFACE_DISC_SIGMAS, SOGMM_OPT_THREADS; progress as
 * sogmm_map_occupancy_f32 (SOGMM_STAGE_SCORING). n == 0 writes nothing.
 * Errors: NULL model, xyz or distance_out -> SOGMM_E_NULL_ARG; NaN/Inf in
 * xyz or a model without components -> SOGMM_E_INVALID_DATA. */
SOGMM_API sogmm_status sogmm_model_surface_distance_f32(const sogmm_model* model, const float* xyz, size_t n,
                                                        const sogmm_options* options, double* distance_out,
                                                        double* gradient_out);
/* The same for a map (world frame); an empty map -> SOGMM_E_INVALID_DATA. */
SOGMM_API sogmm_status sogmm_map_surface_distance_f32(const sogmm_map* map, const float* xyz, size_t n,
                                                      const sogmm_options* options, double* distance_out,
                                                      double* gradient_out);
/* Probability that each of n ellipsoidal robots touches the model's surface:
 * robot i is {x : (x - c)^T S^-1 (x - c) <= 1} with centre c = centers[3i..]
 * and shape S = shapes[9i..] (row-major, symmetric positive definite; a
 * sphere of radius r is r^2 I). Each component's disc (as
 * sogmm_model_surface_distance_f32) is a surface patch uncertain along its
 * normal by the component's smallest standard deviation sigma_k; the patch
 * touches the robot with probability Phi(-clearance / sigma_k) and the
 * answer is the largest over the patches (formula and why:
 * core/include/sogmm/collision.hpp): 1/2 at contact, falling with the
 * clearance. Writes n doubles in [0, 1] to `out`. Keys:
 * SOGMM_OPT_SURFACE_DISC_SIGMAS, SOGMM_OPT_THREADS; progress
 * SOGMM_STAGE_SCORING. Errors: NULL handle, centers, shapes or out ->
 * SOGMM_E_NULL_ARG; a non-finite centre or a model without components ->
 * SOGMM_E_INVALID_DATA; a shape that is not finite, symmetric and positive
 * definite (e.g. a negative radius) -> SOGMM_E_INVALID_ARG naming the robot. */
SOGMM_API sogmm_status sogmm_model_collision_probability(const sogmm_model* model, const double* centers,
                                                         const double* shapes, size_t n,
                                                         const sogmm_options* options, double* out);
/* The same for a map (world frame); an empty map -> SOGMM_E_INVALID_DATA. */
SOGMM_API sogmm_status sogmm_map_collision_probability(const sogmm_map* map, const double* centers,
                                                       const double* shapes, size_t n,
                                                       const sogmm_options* options, double* out);

/* ---- registration ----------------------------------------------------- */
/* How a registration ended (sogmm_registration_info.status). */
#define SOGMM_REGISTRATION_CONVERGED 0     /* the last level converged; fitness and observability fine */
#define SOGMM_REGISTRATION_NOT_CONVERGED 1 /* the last level hit REGISTRATION_MAX_ITER, or no source
                                            * point came near the target: the pose is not an estimate */
#define SOGMM_REGISTRATION_LOW_FITNESS 2   /* converged, but the inlier ratio is below
                                            * REGISTRATION_MIN_INLIER_RATIO: likely a wrong pose */
#define SOGMM_REGISTRATION_DEGENERATE 3    /* converged, but `unobservable` directions are not
                                            * constrained by the scene (e.g. a single plane) */

/* The figures of one registration. The caller sets struct_size to
 * sizeof(sogmm_registration_info); later versions only append fields and
 * write only the first struct_size bytes. */
typedef struct sogmm_registration_info {
  size_t struct_size;     /* in: sizeof(sogmm_registration_info) as the caller knows it */
  int32_t status;         /* SOGMM_REGISTRATION_* */
  int32_t iterations;     /* steps (Newton or EM / Gauss-Newton), summed over the levels */
  double log_likelihood;  /* mean log-likelihood per source point at the pose (model plus outlier term) */
  double inlier_ratio;    /* fraction of points the mixture explains better than the outlier term */
  double rmse;            /* Mahalanobis RMS of the inliers per dimension (about 1 when they fit) */
  double information[36]; /* observed information (negative Hessian of the log-likelihood), row-major
                           * 6 x 6 over x -> x + w x x + v, (w_x, w_y, w_z, v_x, v_y, v_z) in radians and
                           * metres about the target frame's origin; near-zero eigenvalues are the
                           * unobservable directions */
  int32_t unobservable;   /* number of unobservable directions (0 to 6; REGISTRATION_DEGENERACY_RATIO) */
  double eigen_ratio;     /* smallest / largest eigenvalue of the information with rotations scaled by
                           * the source's RMS radius (0 to 1) */
} sogmm_registration_info;

/* The rigid pose that best explains n source points (`points`: rows of x,
 * y, z, gray float32, in their own frame) under the model `target`:
 * pose_out (row-major 4 x 4) maps source points into the target's frame.
 * It maximises the points' log-likelihood under the target's 4-D density
 * (REGISTRATION_USE_GRAY 1, the default; 0: its 3-D marginal) mixed with a uniform
 * outlier term, by Newton steps on the observed information (EM / Gauss-Newton
 * steps where it leaves a direction unconstrained) coarse to fine (formula and why:
 * core/include/sogmm/registration.hpp), from `init` (a rigid 4 x 4 pose;
 * NULL = identity). Always check info_out->status: pose_out is the last
 * iterate, an estimate only with SOGMM_REGISTRATION_CONVERGED (and, along
 * the observable directions, DEGENERATE). Keys: SOGMM_OPT_REGISTRATION_*,
 * SOGMM_OPT_THREADS (changes no result); progress SOGMM_STAGE_REGISTRATION;
 * a cancel leaves the outputs untouched. Errors: NULL target, points,
 * pose_out or info_out -> SOGMM_E_NULL_ARG; info_out->struct_size too small,
 * a non-rigid or non-finite init -> SOGMM_E_INVALID_ARG; fewer than
 * REGISTRATION_MIN_POINTS points or a non-finite point ->
 * SOGMM_E_INVALID_DATA naming it. Nothing is written on error.
 * The model keeps the target this call prepares (each level's smoothed
 * components, boxes and index: about half a kilobyte per component and
 * level, freed with the model) for its next registration with the same
 * REGISTRATION_LEVELS, _COARSE_SIGMA, _OUTLIER_RATIO and _USE_GRAY, so
 * frames localised one after another in one model pay that preparation
 * once (about a fifth of a d = 5 frame's CPU against 3,000 components).
 * The answers are the same bits either way, and concurrent calls on one
 * model stay safe (the kept target is guarded). */
SOGMM_API sogmm_status sogmm_register_points_f32(const sogmm_model* target, const float* points, size_t n,
                                                 const double* init, const sogmm_options* options,
                                                 double* pose_out, sogmm_registration_info* info_out);

/* The rigid pose that best explains the model `source` (a fit of a frame,
 * in its own frame) under the model `target`: distribution-to-distribution
 * (D2D) registration. Each source component is scored by the closed-form
 * overlap of its Gaussian, moved by the pose, with each target component
 * (formula: core/include/sogmm/registration.hpp, register_model; each
 * step holds the source covariances at the current rotation, as GICP does),
 * counted as many times as the points it stands for (weight x support size,
 * a support size of 0 taken as the number of components); the
 * outlier term, levels, options, outputs, status and progress are those of
 * sogmm_register_points_f32, the figures per point stood for. A source of a
 * few hundred components registers in a fraction of its points' time.
 * Errors: NULL target, source, pose_out or info_out -> SOGMM_E_NULL_ARG;
 * info_out->struct_size too small, a non-rigid or non-finite init ->
 * SOGMM_E_INVALID_ARG; a source without components or standing for fewer
 * than REGISTRATION_MIN_POINTS points -> SOGMM_E_INVALID_DATA. Nothing is
 * written on error. The target model keeps its prepared target as in
 * sogmm_register_points_f32 (one kept target serves both calls). */
SOGMM_API sogmm_status sogmm_register_model(const sogmm_model* target, const sogmm_model* source,
                                            const double* init, const sogmm_options* options, double* pose_out,
                                            sogmm_registration_info* info_out);

/* Tracking: inserts an RGB-D `frame` into `map` at the camera-to-world pose
 * that registration to the map finds (sogmm_register_points_f32's method,
 * with the map's creation options: SOGMM_OPT_REGISTRATION_*,
 * SOGMM_OPT_THREADS; progress and cancel through the map's callback), so
 * that a stream without poses still gives a map. Start: `guess` (a rigid
 * row-major 4 x 4 camera-to-world pose), or with NULL the constant-velocity
 * prediction from the map's last two frames (frames assumed evenly spaced:
 * a caller that skips frames passes its own guess). The map's first frame
 * (no component, nothing pending) is inserted at the guess (NULL: the
 * identity) without registration. The target is the map's components and
 * its pending points; only the frame's points that some inserted frame saw
 * are registered (placed by the guess, at least 8 pixels inside that frame's
 * image through this frame's intrinsics), or all of them when those are
 * fewer than half, and all of them once more when the frame would otherwise
 * not be inserted (the map's edge pulled points in new space back and the
 * pose lagged behind the motion);
 * pending points are flushed first when the map has no
 * component, or when the frame would not be inserted (then it registers
 * again). The frame is inserted when the registration's status is
 * SOGMM_REGISTRATION_CONVERGED, or, with SOGMM_OPT_REGISTRATION_USE_GRAY and
 * SOGMM_OPT_TRACKING_ODOMETRY (both default 1), when its registration to the
 * last frame this call inserted into the map (odometry) converged and
 * either agrees with the map's pose (SOGMM_OPT_TRACKING_MAX_DISAGREEMENT:
 * then at the map's pose when its status is DEGENERATE, else at the
 * odometry's) or the map has fewer inliers than
 * SOGMM_OPT_REGISTRATION_MIN_INLIER_RATIO (at the odometry's); rule and
 * why: core/include/sogmm/map_tracking.hpp. Otherwise the call still
 * returns SOGMM_OK, *inserted_out is 0, info_out says why, and the map
 * keeps only the flush it may have run. Outputs (each may be NULL):
 * pose_out (16 doubles) the pose used or the map registration's last
 * iterate, inserted_out 1/0, info_out the map registration's figures
 * (struct_size set by the caller; for the first frame status CONVERGED
 * and iterations 0). Errors: NULL map or
 * frame -> SOGMM_E_NULL_ARG; a non-rigid guess, info_out->struct_size too
 * small -> SOGMM_E_INVALID_ARG; fewer than REGISTRATION_MIN_POINTS valid
 * pixels -> SOGMM_E_INVALID_DATA; a busy map -> SOGMM_E_BUSY; otherwise as
 * sogmm_map_insert_frame and sogmm_map_flush. */
SOGMM_API sogmm_status sogmm_map_track_frame(sogmm_map* map, const sogmm_frame* frame, const double* guess,
                                             double* pose_out, int32_t* inserted_out,
                                             sogmm_registration_info* info_out);

/* ---- buffers ---------------------------------------------------------- */
/* Bytes of a buffer: owned by the buffer, valid until sogmm_buffer_free.
 * NULL buffer -> NULL / 0. These never fail and do not touch
 * sogmm_last_error. */
SOGMM_API const uint8_t* sogmm_buffer_data(const sogmm_buffer* buffer);
SOGMM_API size_t sogmm_buffer_size(const sogmm_buffer* buffer);
/* Releases `buffer` and its bytes. NULL is a no-op. */
SOGMM_API void sogmm_buffer_free(sogmm_buffer* buffer);

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* SOGMM_SOGMM_H */
