//! `Options` (an owned sogmm_options handle) and its builder.
use std::ops::ControlFlow;
use std::ptr::{self, NonNull};

use sogmm_sys as sys;

use crate::error::{check, Result};
use crate::progress::{Progress, ProgressHook};

/// Enum-keyed parameters for fit, save, load and sample (sogmm_options).
/// Ranges are checked by the library: the setter (or `OptionsBuilder::build`)
/// fails with `Status::InvalidArg` and a message naming the key.
pub struct Options {
    ptr: NonNull<sys::sogmm_options>,
    /// Go-between for `set_progress`; installed per call (progress.rs).
    progress: Option<ProgressHook>,
}

// SAFETY: spec/api.md 1.1: distinct handles never interfere; functions taking
// a const handle (the getters, and every call reading options) may run
// concurrently, and those are exactly the `&self` methods; setters and free
// need exclusive use, which `&mut self` and `Drop` guarantee.
unsafe impl Send for Options {}
unsafe impl Sync for Options {}

/// Mean-shift variant of the mode count (SOGMM_OPT_MODE_COUNTER).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModeCounter {
    /// The authors' flat mean shift with bin seeding (default).
    FlatBinned,
    /// The paper's Gaussian blurring mean shift.
    GaussianBlurring,
}

/// How a map's fusion measures two components (SOGMM_OPT_MAP_FUSION_METHOD).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FusionMethod {
    /// Hellinger distance, in [0, 1] (default).
    Hellinger,
    /// Symmetric Kullback-Leibler divergence, in nats.
    Kl,
}

impl Options {
    /// Every default.
    pub fn new() -> Result<Options> {
        crate::ensure_abi()?;
        let mut out = ptr::null_mut();
        // SAFETY: `out` is a valid out-pointer.
        check(unsafe { sys::sogmm_options_create(&mut out) })?;
        Ok(Options {
            ptr: NonNull::new(out).expect("sogmm_options_create returned OK and NULL"),
            progress: None,
        })
    }

    /// A builder collecting keys; `build` applies them in order.
    pub fn builder() -> OptionsBuilder {
        OptionsBuilder::default()
    }

    pub fn set_f64(&mut self, key: i32, value: f64) -> Result<()> {
        // SAFETY: valid handle, exclusive through &mut self.
        check(unsafe { sys::sogmm_options_set_f64(self.ptr.as_ptr(), key, value) })
    }

    pub fn set_i64(&mut self, key: i32, value: i64) -> Result<()> {
        // SAFETY: as set_f64.
        check(unsafe { sys::sogmm_options_set_i64(self.ptr.as_ptr(), key, value) })
    }

    pub fn get_f64(&self, key: i32) -> Result<f64> {
        let mut v = 0.0;
        // SAFETY: valid handle; `v` is a valid out-pointer.
        check(unsafe { sys::sogmm_options_get_f64(self.ptr.as_ptr(), key, &mut v) })?;
        Ok(v)
    }

    pub fn get_i64(&self, key: i32) -> Result<i64> {
        let mut v = 0;
        // SAFETY: as get_f64.
        check(unsafe { sys::sogmm_options_get_i64(self.ptr.as_ptr(), key, &mut v) })?;
        Ok(v)
    }

    /// Makes every call given these options report its progress to `f` (see
    /// `Progress`); `ControlFlow::Break(())` cancels the call. A map keeps the
    /// closure of the options it was created with for its inserts and
    /// flushes. Clones share the closure.
    pub fn set_progress(&mut self, f: impl FnMut(Progress) -> ControlFlow<()> + Send + 'static) {
        self.progress = Some(ProgressHook::new(f));
    }

    pub(crate) fn progress(&self) -> Option<&ProgressHook> {
        self.progress.as_ref()
    }

    /// Deep copy (sogmm_options_clone; the progress closure is shared); fails
    /// only when memory runs out.
    pub fn try_clone(&self) -> Result<Options> {
        let mut out = ptr::null_mut();
        // SAFETY: valid handle and out-pointer.
        check(unsafe { sys::sogmm_options_clone(&mut out, self.ptr.as_ptr()) })?;
        Ok(Options {
            ptr: NonNull::new(out).expect("sogmm_options_clone returned OK and NULL"),
            progress: self.progress.clone(),
        })
    }

    pub(crate) fn as_ptr(&self) -> *const sys::sogmm_options {
        self.ptr.as_ptr()
    }
}

/// The C pointer of optional options: NULL means "all defaults".
pub(crate) fn opt_ptr(o: Option<&Options>) -> *const sys::sogmm_options {
    o.map_or(ptr::null(), Options::as_ptr)
}

owned_handle!(Options, sys::sogmm_options_free, clone: "sogmm options");

impl std::fmt::Debug for Options {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Options").finish_non_exhaustive()
    }
}

#[derive(Clone, Copy, Debug)]
enum Value {
    F64(f64),
    I64(i64),
}

/// Collects option values; `build()` creates the handle and sets them in
/// order, returning the library's error for the first value it refuses.
/// Validation stays in the C library, the one place that knows the ranges.
#[derive(Clone, Debug, Default)]
#[must_use]
pub struct OptionsBuilder {
    values: Vec<(i32, Value)>,
    progress: Option<ProgressHook>,
}

macro_rules! setters {
    ($($(#[$doc:meta])* $name:ident($t:ty) => $key:ident as $kind:ident $conv:expr;)*) => {
        $($(#[$doc])* pub fn $name(self, v: $t) -> Self {
            #[allow(clippy::redundant_closure_call)]
            let value = ($conv)(v);
            self.$kind(sys::$key, value)
        })*
    };
}

impl OptionsBuilder {
    /// Any f64 key, e.g. an experimental one.
    pub fn f64(mut self, key: i32, v: f64) -> Self {
        self.values.push((key, Value::F64(v)));
        self
    }

    /// Any i64 key.
    pub fn i64(mut self, key: i32, v: i64) -> Self {
        self.values.push((key, Value::I64(v)));
        self
    }

    /// The progress closure of the options (`Options::set_progress`).
    pub fn on_progress(mut self, f: impl FnMut(Progress) -> ControlFlow<()> + Send + 'static) -> Self {
        self.progress = Some(ProgressHook::new(f));
        self
    }

    setters! {
        /// Mean-shift bandwidth (default 0.02).
        bandwidth(f64) => SOGMM_OPT_BANDWIDTH as f64 |v| v;
        /// Fixed K; 0 = self-organizing (default).
        n_components(i64) => SOGMM_OPT_N_COMPONENTS as i64 |v| v;
        /// EM stop tolerance (default 1e-3).
        tol(f64) => SOGMM_OPT_TOL as f64 |v| v;
        /// Added to all four covariance diagonals; default automatic floors from the
        /// data (sogmm_sys::SOGMM_REG_COVAR_AUTO, which restores them).
        reg_covar(f64) => SOGMM_OPT_REG_COVAR as f64 |v| v;
        /// EM iterations at most (default 100).
        max_iter(i64) => SOGMM_OPT_MAX_ITER as i64 |v| v;
        /// k-means++ seed (default 0); the u64's bits, as the header says.
        seed(u64) => SOGMM_OPT_SEED as i64 |v: u64| v as i64;
        /// Worker threads of a fit, and of the queries given these options
        /// (`Queryable`: the same bits for any count); 0 = all cores (default).
        threads(i64) => SOGMM_OPT_THREADS as i64 |v| v;
        /// Mode-count variant.
        mode_counter(ModeCounter) => SOGMM_OPT_MODE_COUNTER as i64 |m| match m {
            ModeCounter::FlatBinned => sys::SOGMM_MODE_COUNTER_FLAT_BINNED,
            ModeCounter::GaussianBlurring => sys::SOGMM_MODE_COUNTER_GAUSSIAN_BLURRING,
        };
        /// Truncated E-step margin in nats; 0 = exact (default).
        truncation_nats(f64) => SOGMM_OPT_TRUNCATION_NATS as f64 |v| v;
        /// c > 0: EM also stops when a pass changes the mean log-likelihood by
        /// less than c of its standard error (the per-point log-likelihoods'
        /// spread over sqrt(N)); 0 = tol alone (default).
        tol_standard_errors(f64) => SOGMM_OPT_TOL_STANDARD_ERRORS as f64 |v| v;
        /// Runs of k-means++ + EM (default 1).
        n_init(i64) => SOGMM_OPT_N_INIT as i64 |v| v;
        /// Forces the depth-quantisation floor on or off; the default
        /// (sogmm_sys::SOGMM_DEQUANTISE_AUTO) floors RGB-D frames and not arrays.
        dequantise_depth(bool) => SOGMM_OPT_DEQUANTISE_DEPTH as i64 i64::from;
        /// SQUAREM-accelerated EM (true) or plain EM (false, default); see
        /// SOGMM_OPT_EM_ACCELERATION in sogmm.h.
        squarem(bool) => SOGMM_OPT_EM_ACCELERATION as i64 i64::from;
        /// Raw depth units per metre (default 1000).
        depth_scale(f64) => SOGMM_OPT_DEPTH_SCALE as f64 |v| v;
        /// Nearest valid depth in metres, exclusive (default 0.1).
        depth_min(f64) => SOGMM_OPT_DEPTH_MIN as f64 |v| v;
        /// Farthest valid depth in metres, inclusive (default 3.0).
        depth_max(f64) => SOGMM_OPT_DEPTH_MAX as f64 |v| v;
        /// Integer image decimation (default 1).
        decimation(i64) => SOGMM_OPT_DECIMATION as i64 |v| v;
        /// zstd level of saved arrays (default 19).
        zstd_level(i64) => SOGMM_OPT_ZSTD_LEVEL as i64 |v| v;
        /// Store arrays as float64 (default false).
        float64(bool) => SOGMM_OPT_FLOAT64 as i64 i64::from;
        /// Compress arrays (default true).
        compress(bool) => SOGMM_OPT_COMPRESS as i64 i64::from;
        /// Saves: > 0 stores each component as integer codes that move its mean
        /// by at most this many of its own standard deviations (format 1.5;
        /// bounds: SOGMM_OPT_ARRAY_PRECISION in sogmm.h); 0 = float arrays,
        /// bit-exact (default); outside [0, 0.5]: `build` fails with
        /// `Status::InvalidArg`.
        array_precision(f64) => SOGMM_OPT_ARRAY_PRECISION as f64 |v| v;
        /// Cap on the arrays' decoded bytes when loading, and when saving (a model
        /// above it is refused: raise it on both sides); 0 = the format's 1 GiB.
        max_decoded_bytes(i64) => SOGMM_OPT_MAX_DECODED_BYTES as i64 |v| v;
        /// Verify checksums when loading (default true).
        verify_checksums(bool) => SOGMM_OPT_VERIFY_CHECKSUMS as i64 i64::from;
        /// Sampling truncation in standard deviations (default 2.5; may be inf).
        sample_truncation(f64) => SOGMM_OPT_SAMPLE_TRUNCATION as f64 |v| v;
        /// Culled queries (`Queryable::score_samples`, `regress_gray`): 0 = exact
        /// (default); > 0 skips a component at a point only when its term is
        /// provably more than this many nats below the point's largest, so a
        /// score is at most ln(1 + M e^-nats) below the exact one. Negative or
        /// not finite: `build` fails with `Status::InvalidArg`.
        query_truncation_nats(f64) => SOGMM_OPT_QUERY_TRUNCATION_NATS as f64 |v| v;
        /// Renders (`Queryable::render`): 0 = every mode along a ray is a
        /// surface (default); s > 0 = only modes with the evidence of one
        /// component at s sigma, so a ray grazing a nearer object's components
        /// shows the surface behind. Negative or not finite: `build` fails
        /// with `Status::InvalidArg`.
        render_surface_sigma(f64) => SOGMM_OPT_RENDER_SURFACE_SIGMA as f64 |v| v;
        /// Map: test each point's novelty (default true; false = append everything).
        map_novelty(bool) => SOGMM_OPT_MAP_NOVELTY as i64 i64::from;
        /// Map: points with a 3-D log-likelihood below this (nats) are novel (default 3.0).
        map_novelty_threshold(f64) => SOGMM_OPT_MAP_NOVELTY_THRESHOLD as f64 |v| v;
        /// Map: s in (0, 1] (default 0.7): with novelty on, a batch of novel
        /// points is fitted with the bandwidth times s + (1 - s) h^2, h the
        /// share of its point pairs from one frame (1 for a batch of one
        /// frame), and a revisit refit with the bandwidth times s; outside:
        /// `build` fails with `Status::InvalidArg`.
        map_novelty_bandwidth_scale(f64) => SOGMM_OPT_MAP_NOVELTY_BANDWIDTH_SCALE as f64 |v| v;
        /// Map: the free-space carve, in [0, 0.5] (default 0.002, one of the
        /// 256 samples; 0 = off): an RGB-D insert reshapes a map component
        /// when at least this share of its samples lies where the frame sees
        /// past it; outside: `build` fails with `Status::InvalidArg`.
        map_free_space_carve(f64) => SOGMM_OPT_MAP_FREE_SPACE_CARVE as f64 |v| v;
        /// Map: every fitted component is rounded before the map stores it, so
        /// that its mean moves by at most this many of its own standard
        /// deviations and its covariance's eigenvalues by at most this fraction
        /// (default 0 = off; smaller deltas); outside the range: `build` fails
        /// with `Status::InvalidArg`.
        map_component_precision(f64) => SOGMM_OPT_MAP_COMPONENT_PRECISION as f64 |v| v;
        /// Map: an RGB-D insert whose explained points have at least this many
        /// times as many modes as the map has components on its surfaces
        /// replaces those components by a fit of its points plus samples of
        /// their unseen mass (not with a fixed K or a warm start); 0 (off) or
        /// >= 1 (default 1.25); else `build` fails with `Status::InvalidArg`.
        map_revisit_refit_ratio(f64) => SOGMM_OPT_MAP_REVISIT_REFIT_RATIO as f64 |v| v;
        /// Map: pending novel points that trigger a fit (default 12288).
        map_batch_size(i64) => SOGMM_OPT_MAP_BATCH_SIZE as i64 |v| v;
        /// Map: fuse new components into close ones (default false).
        map_fusion(bool) => SOGMM_OPT_MAP_FUSION as i64 i64::from;
        /// Map: the fusion distance.
        map_fusion_method(FusionMethod) => SOGMM_OPT_MAP_FUSION_METHOD as i64 |m| match m {
            FusionMethod::Hellinger => sys::SOGMM_FUSION_HELLINGER,
            FusionMethod::Kl => sys::SOGMM_FUSION_KL,
        };
        /// Map: fuse below this distance (Hellinger in [0, 1] or KL in nats; default 0.3).
        map_fusion_threshold(f64) => SOGMM_OPT_MAP_FUSION_THRESHOLD as f64 |v| v;
        /// Map: warm-start each batch's fit from the previous one (default false; needs n_init 1).
        map_warm_start(bool) => SOGMM_OPT_MAP_WARM_START as i64 i64::from;
        /// Map: keep the changes of only the last N revisions for
        /// `Map::export_delta` (default 0: all of them); an export from an
        /// older revision then fails with `Status::InvalidArg` naming the
        /// oldest kept. Negative: `build` fails with `Status::InvalidArg`.
        map_delta_history(i64) => SOGMM_OPT_MAP_DELTA_HISTORY as i64 |v| v;
    }

    pub fn build(&self) -> Result<Options> {
        let mut o = Options::new()?;
        o.progress = self.progress.clone();
        for &(key, v) in &self.values {
            match v {
                Value::F64(x) => o.set_f64(key, x)?,
                Value::I64(x) => o.set_i64(key, x)?,
            }
        }
        Ok(o)
    }
}

/// The value type and accepted values of an option key.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OptionValues {
    /// An f64 key: its default and the closed hull of its accepted values.
    F64 { default: f64, lower: f64, upper: f64 },
    /// An i64 key: its default and its accepted range.
    I64 { default: i64, lower: i64, upper: i64 },
}

/// What the library's option registry says of one key (sogmm_option_get_info):
/// the single source of every option's default and range.
#[derive(Clone, Debug, PartialEq)]
pub struct OptionInfo {
    /// The key.
    pub key: i32,
    /// The C macro's name, e.g. "SOGMM_OPT_BANDWIDTH".
    pub name: &'static str,
    /// Type, default and bounds.
    pub values: OptionValues,
    /// The whole rule in words (the bounds are its hull).
    pub range: &'static str,
    /// Unit ("" when dimensionless).
    pub unit: &'static str,
    /// What the option does.
    pub doc: &'static str,
}

fn static_str(p: *const sys::c_char) -> &'static str {
    // SAFETY: the library's strings are static, NUL-terminated ASCII.
    unsafe { std::ffi::CStr::from_ptr(p) }.to_str().unwrap_or("")
}

/// The registry's row of `key`; `Status::InvalidArg` for an unknown key.
pub fn option_info(key: i32) -> Result<OptionInfo> {
    let mut raw = sys::sogmm_option_info {
        struct_size: std::mem::size_of::<sys::sogmm_option_info>(),
        key: 0,
        type_: 0,
        name: ptr::null(),
        default_f64: 0.0,
        lower_f64: 0.0,
        upper_f64: 0.0,
        default_i64: 0,
        lower_i64: 0,
        upper_i64: 0,
        range: ptr::null(),
        unit: ptr::null(),
        doc: ptr::null(),
    };
    // SAFETY: `raw` is a valid, writable sogmm_option_info with its size set.
    check(unsafe { sys::sogmm_option_get_info(key, &mut raw) })?;
    let values = if raw.type_ == sys::SOGMM_TYPE_F64 {
        OptionValues::F64 {
            default: raw.default_f64,
            lower: raw.lower_f64,
            upper: raw.upper_f64,
        }
    } else {
        OptionValues::I64 {
            default: raw.default_i64,
            lower: raw.lower_i64,
            upper: raw.upper_i64,
        }
    };
    Ok(OptionInfo {
        key,
        name: static_str(raw.name),
        values,
        range: static_str(raw.range),
        unit: static_str(raw.unit),
        doc: static_str(raw.doc),
    })
}

/// Every option key of the library, in increasing order.
pub fn option_keys() -> Result<Vec<i32>> {
    let mut count = 0usize;
    // SAFETY: capacity 0 with a null array only asks for the count.
    check(unsafe { sys::sogmm_option_keys(ptr::null_mut(), 0, &mut count) })?;
    let mut keys = vec![0i32; count];
    // SAFETY: `keys` holds `count` writable keys.
    check(unsafe { sys::sogmm_option_keys(keys.as_mut_ptr(), keys.len(), &mut count) })?;
    keys.truncate(count);
    Ok(keys)
}
