//! Raw declarations of libsogmm's C API, written by hand from
//! `capi/include/sogmm/sogmm.h` (no bindgen: the header is small and plain C99,
//! and a hand-written file keeps the toolchain light). The documentation of
//! every item is in the header and in spec/api.md; the safe API is the `sogmm`
//! crate.
//!
//! `tests/header_drift.rs` parses sogmm.h and fails when a prototype or a
//! constant here differs from it (name, argument count, argument or return
//! types, value). Keep the declarations in the header's order.
#![no_std]
#![allow(non_camel_case_types)]

pub use core::ffi::{c_char, c_void};

/// Declares the opaque handle types of the C API, each with its doc
/// comment: zero-sized, only ever behind a pointer, and (through the
/// PhantomData) neither Send, Sync nor Unpin, as the Rustonomicon advises
/// for opaque FFI structs.
macro_rules! opaque_handles {
    ($($(#[$doc:meta])* $name:ident;)*) => {
        $(
            $(#[$doc])*
            #[repr(C)]
            pub struct $name {
                _opaque: [u8; 0],
                _pin: core::marker::PhantomData<(*mut u8, core::marker::PhantomPinned)>,
            }
        )*
    };
}

opaque_handles! {
    /// Opaque handle: a fitted 4-D GMM plus metadata.
    sogmm_model;
    /// Opaque handle: enum-keyed parameters for fit, save, load, sample.
    sogmm_options;
    /// Opaque handle: bytes produced by the library.
    sogmm_buffer;
    /// Opaque handle: an incremental world map (sogmm_map_*).
    sogmm_map;
    /// Opaque handle: an RGB-D frame read from image files (sogmm_frame_*).
    sogmm_frame;
    /// Opaque handle: camera poses read from a Redwood .log file (sogmm_trajectory_*).
    sogmm_trajectory;
}

pub type sogmm_status = i32;
pub type sogmm_key = i32;
/// Progress callback: (stage, step, total, log_likelihood, user_data) -> 0 to
/// continue, non-zero to cancel. Called only on the calling thread.
pub type sogmm_progress_fn =
    Option<unsafe extern "C" fn(stage: i32, step: u64, total: u64, log_likelihood: f64, user_data: *mut c_void) -> i32>;

// ---- versions -------------------------------------------------------------
pub const SOGMM_VERSION_MAJOR: u32 = 0;
pub const SOGMM_VERSION_MINOR: u32 = 1;
pub const SOGMM_VERSION_PATCH: u32 = 0;
pub const SOGMM_VERSION_STRING: &str = "0.1.0";
pub const SOGMM_ABI_VERSION: u32 = 2;

// ---- status codes ---------------------------------------------------------
pub const SOGMM_OK: sogmm_status = 0;
pub const SOGMM_E_NULL_ARG: sogmm_status = -1;
pub const SOGMM_E_INVALID_ARG: sogmm_status = -2;
pub const SOGMM_E_INVALID_DATA: sogmm_status = -3;
pub const SOGMM_E_NUMERIC: sogmm_status = -4;
pub const SOGMM_E_IO: sogmm_status = -5;
pub const SOGMM_E_FORMAT: sogmm_status = -6;
pub const SOGMM_E_LIMIT: sogmm_status = -7;
pub const SOGMM_E_NOMEM: sogmm_status = -8;
pub const SOGMM_E_BUFFER_TOO_SMALL: sogmm_status = -9;
pub const SOGMM_E_NOT_FOUND: sogmm_status = -10;
pub const SOGMM_E_INTERNAL: sogmm_status = -11;
pub const SOGMM_E_CANCELLED: sogmm_status = -12;
pub const SOGMM_E_BUSY: sogmm_status = -13;

// ---- option keys ----------------------------------------------------------
// BEGIN GENERATED option keys (tools/options/regenerate.py, from core/src/option_table.cpp)
pub const SOGMM_OPT_BANDWIDTH: sogmm_key = 100;
pub const SOGMM_OPT_N_COMPONENTS: sogmm_key = 101;
pub const SOGMM_OPT_TOL: sogmm_key = 102;
pub const SOGMM_OPT_REG_COVAR: sogmm_key = 103;
pub const SOGMM_OPT_MAX_ITER: sogmm_key = 104;
pub const SOGMM_OPT_SEED: sogmm_key = 105;
pub const SOGMM_OPT_THREADS: sogmm_key = 106;
pub const SOGMM_OPT_MODE_COUNTER: sogmm_key = 107;
pub const SOGMM_OPT_TRUNCATION_NATS: sogmm_key = 108;
pub const SOGMM_OPT_N_INIT: sogmm_key = 109;
pub const SOGMM_OPT_DEQUANTISE_DEPTH: sogmm_key = 110;
pub const SOGMM_OPT_EM_ACCELERATION: sogmm_key = 111;
pub const SOGMM_OPT_TOL_STANDARD_ERRORS: sogmm_key = 131;
pub const SOGMM_OPT_WARM_MAX_ITER: sogmm_key = 145;
pub const SOGMM_OPT_DEPTH_SCALE: sogmm_key = 200;
pub const SOGMM_OPT_DEPTH_MIN: sogmm_key = 201;
pub const SOGMM_OPT_DEPTH_MAX: sogmm_key = 202;
pub const SOGMM_OPT_DECIMATION: sogmm_key = 203;
pub const SOGMM_OPT_ZSTD_LEVEL: sogmm_key = 300;
pub const SOGMM_OPT_FLOAT64: sogmm_key = 301;
pub const SOGMM_OPT_COMPRESS: sogmm_key = 302;
pub const SOGMM_OPT_ARRAY_PRECISION: sogmm_key = 303;
pub const SOGMM_OPT_MAX_DECODED_BYTES: sogmm_key = 400;
pub const SOGMM_OPT_VERIFY_CHECKSUMS: sogmm_key = 401;
pub const SOGMM_OPT_SAMPLE_TRUNCATION: sogmm_key = 500;
pub const SOGMM_OPT_QUERY_TRUNCATION_NATS: sogmm_key = 501;
pub const SOGMM_OPT_RENDER_SURFACE_SIGMA: sogmm_key = 502;
pub const SOGMM_OPT_MAP_NOVELTY: sogmm_key = 600;
pub const SOGMM_OPT_MAP_NOVELTY_THRESHOLD: sogmm_key = 601;
pub const SOGMM_OPT_MAP_BATCH_SIZE: sogmm_key = 602;
pub const SOGMM_OPT_MAP_FUSION: sogmm_key = 603;
pub const SOGMM_OPT_MAP_FUSION_METHOD: sogmm_key = 604;
pub const SOGMM_OPT_MAP_FUSION_THRESHOLD: sogmm_key = 605;
pub const SOGMM_OPT_MAP_WARM_START: sogmm_key = 606;
pub const SOGMM_OPT_MAP_NOVELTY_BANDWIDTH_SCALE: sogmm_key = 607;
pub const SOGMM_OPT_MAP_REVISIT_REFIT_RATIO: sogmm_key = 608;
pub const SOGMM_OPT_MAP_DELTA_HISTORY: sogmm_key = 609;
pub const SOGMM_OPT_MAP_FREE_SPACE_CARVE: sogmm_key = 620;
pub const SOGMM_OPT_MAP_COMPONENT_PRECISION: sogmm_key = 630;
pub const SOGMM_OPT_OCCUPANCY_SIGMA: sogmm_key = 700;
pub const SOGMM_OPT_OCCUPANCY_THICKNESS: sogmm_key = 701;
pub const SOGMM_OPT_SURFACE_DISC_SIGMAS: sogmm_key = 702;
pub const SOGMM_OPT_REGISTRATION_MAX_ITER: sogmm_key = 800;
pub const SOGMM_OPT_REGISTRATION_TOL: sogmm_key = 801;
pub const SOGMM_OPT_REGISTRATION_OUTLIER_RATIO: sogmm_key = 802;
pub const SOGMM_OPT_REGISTRATION_USE_GRAY: sogmm_key = 803;
pub const SOGMM_OPT_REGISTRATION_LEVELS: sogmm_key = 804;
pub const SOGMM_OPT_REGISTRATION_COARSE_SIGMA: sogmm_key = 805;
pub const SOGMM_OPT_REGISTRATION_MIN_INLIER_RATIO: sogmm_key = 806;
pub const SOGMM_OPT_REGISTRATION_DEGENERACY_RATIO: sogmm_key = 807;
pub const SOGMM_OPT_REGISTRATION_MIN_POINTS: sogmm_key = 808;
pub const SOGMM_OPT_REGISTRATION_DEPTH_NOISE: sogmm_key = 809;
pub const SOGMM_OPT_TRACKING_ODOMETRY: sogmm_key = 810;
pub const SOGMM_OPT_TRACKING_MAX_DISAGREEMENT: sogmm_key = 811;
// END GENERATED option keys
// ---- named values of option keys -------------------------------------------
/// f64 value of SOGMM_OPT_REG_COVAR (its default): floors from the data's scales (see sogmm.h).
pub const SOGMM_REG_COVAR_AUTO: f64 = -1.0;
/// i64 value of SOGMM_OPT_DEQUANTISE_DEPTH (its default): on for RGB-D frames, off for arrays.
pub const SOGMM_DEQUANTISE_AUTO: i64 = -1;
pub const SOGMM_MODE_COUNTER_FLAT_BINNED: i64 = 0;
pub const SOGMM_MODE_COUNTER_GAUSSIAN_BLURRING: i64 = 1;
pub const SOGMM_REGISTRATION_CONVERGED: i32 = 0;
pub const SOGMM_REGISTRATION_NOT_CONVERGED: i32 = 1;
pub const SOGMM_REGISTRATION_LOW_FITNESS: i32 = 2;
pub const SOGMM_REGISTRATION_DEGENERATE: i32 = 3;
pub const SOGMM_FUSION_HELLINGER: i64 = 0;
pub const SOGMM_FUSION_KL: i64 = 1;

// ---- progress stages --------------------------------------------------------
pub const SOGMM_STAGE_MODE_COUNT: i32 = 1;
pub const SOGMM_STAGE_SEEDING: i32 = 2;
pub const SOGMM_STAGE_EM: i32 = 3;
pub const SOGMM_STAGE_RUN: i32 = 4;
pub const SOGMM_STAGE_SAMPLING: i32 = 5;
pub const SOGMM_STAGE_SCORING: i32 = 6;
pub const SOGMM_STAGE_REGRESSION: i32 = 7;
pub const SOGMM_STAGE_RENDERING: i32 = 8;
pub const SOGMM_STAGE_REGISTRATION: i32 = 9;
pub const SOGMM_OCCUPANCY_FREE: u8 = 0;
pub const SOGMM_OCCUPANCY_OCCUPIED: u8 = 1;
pub const SOGMM_OCCUPANCY_UNKNOWN: u8 = 2;

/// The largest width * height a render takes (2^26).
pub const SOGMM_MAX_RENDER_PIXELS: usize = 67108864;

// ---- color formats --------------------------------------------------------
pub const SOGMM_COLOR_GRAY8: i32 = 1;
pub const SOGMM_COLOR_RGB8: i32 = 2;
pub const SOGMM_COLOR_GRAY_F32: i32 = 3;

// ---- information keys -----------------------------------------------------
pub const SOGMM_INFO_SUPPORT_SIZE: sogmm_key = 10001;
pub const SOGMM_INFO_CREATED_UNIX_MS: sogmm_key = 10002;
pub const SOGMM_INFO_FIT_ITERATIONS: sogmm_key = 10100;
pub const SOGMM_INFO_FIT_CONVERGED: sogmm_key = 10101;
pub const SOGMM_INFO_FIT_LOG_LIKELIHOOD: sogmm_key = 10102;
pub const SOGMM_INFO_FIT_BANDWIDTH: sogmm_key = 10103;
pub const SOGMM_INFO_FIT_N_COMPONENTS_REQUESTED: sogmm_key = 10104;
pub const SOGMM_INFO_FIT_TOL: sogmm_key = 10105;
pub const SOGMM_INFO_FIT_REG_COVAR: sogmm_key = 10106;
pub const SOGMM_INFO_FIT_MAX_ITER: sogmm_key = 10107;
pub const SOGMM_INFO_FIT_SEED: sogmm_key = 10108;
pub const SOGMM_INFO_FIT_N_POINTS: sogmm_key = 10150;
pub const SOGMM_INFO_FIT_SECONDS_MODE_COUNT: sogmm_key = 10151;
pub const SOGMM_INFO_FIT_SECONDS_SEEDING: sogmm_key = 10152;
pub const SOGMM_INFO_FIT_SECONDS_EM: sogmm_key = 10153;
pub const SOGMM_INFO_FIT_SECONDS_TOTAL: sogmm_key = 10154;
pub const SOGMM_INFO_FIT_N_INIT: sogmm_key = 10155;
pub const SOGMM_INFO_FIT_RUN: sogmm_key = 10156;
pub const SOGMM_INFO_CAMERA_WIDTH: sogmm_key = 10200;
pub const SOGMM_INFO_CAMERA_HEIGHT: sogmm_key = 10201;
pub const SOGMM_INFO_CAMERA_FX: sogmm_key = 10202;
pub const SOGMM_INFO_CAMERA_FY: sogmm_key = 10203;
pub const SOGMM_INFO_CAMERA_CX: sogmm_key = 10204;
pub const SOGMM_INFO_CAMERA_CY: sogmm_key = 10205;
pub const SOGMM_INFO_CAMERA_DECIMATION: sogmm_key = 10206;
pub const SOGMM_INFO_CAMERA_DEPTH_SCALE: sogmm_key = 10207;
pub const SOGMM_INFO_CAMERA_DEPTH_MIN: sogmm_key = 10208;
pub const SOGMM_INFO_CAMERA_DEPTH_MAX: sogmm_key = 10209;

// Map statistic keys (sogmm_map_get_i64, sogmm_map_frame_get_i64 / _f64).
pub const SOGMM_MAP_N_COMPONENTS: sogmm_key = 20000;
pub const SOGMM_MAP_N_PENDING: sogmm_key = 20001;
pub const SOGMM_MAP_N_FRAMES: sogmm_key = 20002;
pub const SOGMM_MAP_N_FLUSHES: sogmm_key = 20003;
pub const SOGMM_MAP_N_FUSED: sogmm_key = 20004;
pub const SOGMM_MAP_N_REFITS: sogmm_key = 20005;
pub const SOGMM_MAP_REVISION: sogmm_key = 20006;
pub const SOGMM_MAP_FRAME_N_POINTS: sogmm_key = 20100;
pub const SOGMM_MAP_FRAME_N_NOVEL: sogmm_key = 20101;
pub const SOGMM_MAP_FRAME_N_COMPONENTS: sogmm_key = 20102;
pub const SOGMM_MAP_FRAME_FLUSHED: sogmm_key = 20103;
pub const SOGMM_MAP_FRAME_N_REPLACED: sogmm_key = 20104;
pub const SOGMM_MAP_FRAME_MS_NOVELTY: sogmm_key = 20150;
pub const SOGMM_MAP_FRAME_MS_FIT: sogmm_key = 20151;
pub const SOGMM_MAP_FRAME_MS_MERGE: sogmm_key = 20152;

/// SOGMM_TYPE_F64 / SOGMM_TYPE_I64 (sogmm_option_info.type).
pub const SOGMM_TYPE_F64: i32 = 0;
pub const SOGMM_TYPE_I64: i32 = 1;

/// The figures of one registration (sogmm_register_points_f32,
/// sogmm_register_model). Set
/// `struct_size` to `size_of::<sogmm_registration_info>()` before the call.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct sogmm_registration_info {
    pub struct_size: usize,
    pub status: i32,
    pub iterations: i32,
    pub log_likelihood: f64,
    pub inlier_ratio: f64,
    pub rmse: f64,
    pub information: [f64; 36],
    pub unobservable: i32,
    pub eigen_ratio: f64,
}

/// What the library's option registry says of one key (sogmm_option_get_info).
/// Set `struct_size` to `size_of::<sogmm_option_info>()` before the call.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct sogmm_option_info {
    pub struct_size: usize,
    pub key: sogmm_key,
    pub type_: i32,
    pub name: *const c_char,
    pub default_f64: f64,
    pub lower_f64: f64,
    pub upper_f64: f64,
    pub default_i64: i64,
    pub lower_i64: i64,
    pub upper_i64: i64,
    pub range: *const c_char,
    pub unit: *const c_char,
    pub doc: *const c_char,
}

extern "C" {
    pub fn sogmm_version_number() -> u32;
    pub fn sogmm_version_string() -> *const c_char;
    pub fn sogmm_abi_version() -> u32;
    pub fn sogmm_status_string(status: sogmm_status) -> *const c_char;
    pub fn sogmm_last_error() -> *const c_char;
    pub fn sogmm_options_create(out: *mut *mut sogmm_options) -> sogmm_status;
    pub fn sogmm_options_clone(out: *mut *mut sogmm_options, src: *const sogmm_options) -> sogmm_status;
    pub fn sogmm_options_free(options: *mut sogmm_options);
    pub fn sogmm_options_set_f64(options: *mut sogmm_options, key: sogmm_key, value: f64) -> sogmm_status;
    pub fn sogmm_options_set_i64(options: *mut sogmm_options, key: sogmm_key, value: i64) -> sogmm_status;
    pub fn sogmm_options_get_f64(options: *const sogmm_options, key: sogmm_key, out: *mut f64) -> sogmm_status;
    pub fn sogmm_options_get_i64(options: *const sogmm_options, key: sogmm_key, out: *mut i64) -> sogmm_status;
    pub fn sogmm_option_get_info(key: sogmm_key, out: *mut sogmm_option_info) -> sogmm_status;
    pub fn sogmm_option_keys(keys: *mut sogmm_key, capacity: usize, count: *mut usize) -> sogmm_status;
    pub fn sogmm_options_set_progress(
        options: *mut sogmm_options,
        fn_: sogmm_progress_fn,
        user_data: *mut c_void,
    ) -> sogmm_status;
    pub fn sogmm_model_from_arrays_f32(
        out: *mut *mut sogmm_model,
        m: usize,
        weights: *const f32,
        means: *const f32,
        covariances: *const f32,
        support_size: u64,
    ) -> sogmm_status;
    pub fn sogmm_model_clone(out: *mut *mut sogmm_model, model: *const sogmm_model) -> sogmm_status;
    pub fn sogmm_model_free(model: *mut sogmm_model);
    pub fn sogmm_model_n_components(model: *const sogmm_model, out: *mut usize) -> sogmm_status;
    pub fn sogmm_model_get_weights_f32(model: *const sogmm_model, out: *mut f32, capacity: usize) -> sogmm_status;
    pub fn sogmm_model_get_means_f32(model: *const sogmm_model, out: *mut f32, capacity: usize) -> sogmm_status;
    pub fn sogmm_model_get_covariances_f32(model: *const sogmm_model, out: *mut f32, capacity: usize) -> sogmm_status;
    pub fn sogmm_model_get_info_f64(model: *const sogmm_model, key: sogmm_key, out: *mut f64) -> sogmm_status;
    pub fn sogmm_model_get_info_i64(model: *const sogmm_model, key: sogmm_key, out: *mut i64) -> sogmm_status;
    pub fn sogmm_model_set_info_f64(model: *mut sogmm_model, key: sogmm_key, value: f64) -> sogmm_status;
    pub fn sogmm_model_set_info_i64(model: *mut sogmm_model, key: sogmm_key, value: i64) -> sogmm_status;
    pub fn sogmm_model_get_pose(model: *const sogmm_model, pose_out: *mut f64) -> sogmm_status;
    pub fn sogmm_model_set_pose(model: *mut sogmm_model, pose: *const f64) -> sogmm_status;
    pub fn sogmm_model_clear_pose(model: *mut sogmm_model) -> sogmm_status;
    pub fn sogmm_model_get_value(
        model: *const sogmm_model,
        key: *const c_char,
        value_out: *mut *const c_char,
    ) -> sogmm_status;
    pub fn sogmm_model_set_value(model: *mut sogmm_model, key: *const c_char, value: *const c_char) -> sogmm_status;
    pub fn sogmm_model_value_count(model: *const sogmm_model, out: *mut usize) -> sogmm_status;
    pub fn sogmm_model_value_at(
        model: *const sogmm_model,
        index: usize,
        key_out: *mut *const c_char,
        value_out: *mut *const c_char,
    ) -> sogmm_status;
    pub fn sogmm_model_sample_f32(
        model: *const sogmm_model,
        n: usize,
        seed: u64,
        dims: i32,
        options: *const sogmm_options,
        out: *mut f32,
    ) -> sogmm_status;
    pub fn sogmm_model_regress_gray_f32(
        model: *const sogmm_model,
        xyz: *const f32,
        n: usize,
        options: *const sogmm_options,
        mean_out: *mut f32,
        variance_out: *mut f32,
    ) -> sogmm_status;
    pub fn sogmm_model_score_samples_f32(
        model: *const sogmm_model,
        points: *const f32,
        n: usize,
        dims: i32,
        options: *const sogmm_options,
        out: *mut f64,
    ) -> sogmm_status;
    pub fn sogmm_psnr_images_f32(
        truth: *const f32,
        estimate: *const f32,
        pixels: usize,
        data_range: f64,
        psnr_out: *mut f64,
        psnr_paper_out: *mut f64,
    ) -> sogmm_status;
    pub fn sogmm_model_merge(out: *mut *mut sogmm_model, a: *const sogmm_model, b: *const sogmm_model) -> sogmm_status;
    pub fn sogmm_model_transform(
        out: *mut *mut sogmm_model,
        model: *const sogmm_model,
        pose: *const f64,
    ) -> sogmm_status;
    pub fn sogmm_model_save(
        model: *const sogmm_model,
        path: *const c_char,
        options: *const sogmm_options,
    ) -> sogmm_status;
    pub fn sogmm_model_load(
        out: *mut *mut sogmm_model,
        path: *const c_char,
        options: *const sogmm_options,
    ) -> sogmm_status;
    pub fn sogmm_model_save_to_memory(
        out: *mut *mut sogmm_buffer,
        model: *const sogmm_model,
        options: *const sogmm_options,
    ) -> sogmm_status;
    pub fn sogmm_model_load_from_memory(
        out: *mut *mut sogmm_model,
        data: *const c_void,
        size: usize,
        options: *const sogmm_options,
    ) -> sogmm_status;
    pub fn sogmm_map_create(out: *mut *mut sogmm_map, options: *const sogmm_options) -> sogmm_status;
    pub fn sogmm_map_free(map: *mut sogmm_map);
    pub fn sogmm_map_insert_points_f32(
        map: *mut sogmm_map,
        points: *const f32,
        n: usize,
        pose: *const f64,
    ) -> sogmm_status;
    pub fn sogmm_map_insert_frame(map: *mut sogmm_map, frame: *const sogmm_frame, pose: *const f64) -> sogmm_status;
    pub fn sogmm_map_flush(map: *mut sogmm_map) -> sogmm_status;
    pub fn sogmm_map_discard_pending(map: *mut sogmm_map, dropped: *mut u64) -> sogmm_status;
    pub fn sogmm_map_set_progress(map: *mut sogmm_map, fn_: sogmm_progress_fn, user_data: *mut c_void) -> sogmm_status;
    pub fn sogmm_map_get_i64(map: *const sogmm_map, key: sogmm_key, out: *mut i64) -> sogmm_status;
    pub fn sogmm_map_frame_get_i64(map: *const sogmm_map, frame: u64, key: sogmm_key, out: *mut i64) -> sogmm_status;
    pub fn sogmm_map_frame_get_f64(map: *const sogmm_map, frame: u64, key: sogmm_key, out: *mut f64) -> sogmm_status;
    pub fn sogmm_map_frame_get_pose(map: *const sogmm_map, frame: u64, pose_out: *mut f64) -> sogmm_status;
    pub fn sogmm_map_get_origin(map: *const sogmm_map, origin_out: *mut f64) -> sogmm_status;
    pub fn sogmm_map_set_origin(map: *mut sogmm_map, origin: *const f64) -> sogmm_status;
    pub fn sogmm_map_export(out: *mut *mut sogmm_model, map: *const sogmm_map, box_: *const f32) -> sogmm_status;
    pub fn sogmm_map_score_samples_f32(
        map: *const sogmm_map,
        points: *const f32,
        n: usize,
        dims: i32,
        options: *const sogmm_options,
        out: *mut f64,
    ) -> sogmm_status;
    pub fn sogmm_map_regress_gray_f32(
        map: *const sogmm_map,
        xyz: *const f32,
        n: usize,
        options: *const sogmm_options,
        mean_out: *mut f32,
        variance_out: *mut f32,
    ) -> sogmm_status;
    pub fn sogmm_map_sample_f32(
        map: *const sogmm_map,
        n: usize,
        seed: u64,
        dims: i32,
        options: *const sogmm_options,
        out: *mut f32,
    ) -> sogmm_status;
    pub fn sogmm_model_render_f32(
        model: *const sogmm_model,
        width: u32,
        height: u32,
        fx: f64,
        fy: f64,
        cx: f64,
        cy: f64,
        camera_to_world: *const f64,
        options: *const sogmm_options,
        depth_out: *mut f32,
        gray_out: *mut f32,
        variance_out: *mut f32,
    ) -> sogmm_status;
    pub fn sogmm_map_occupancy_f32(
        map: *const sogmm_map,
        xyz: *const f32,
        n: usize,
        options: *const sogmm_options,
        probability_out: *mut f64,
        state_out: *mut u8,
    ) -> sogmm_status;
    pub fn sogmm_register_points_f32(
        target: *const sogmm_model,
        points: *const f32,
        n: usize,
        init: *const f64,
        options: *const sogmm_options,
        pose_out: *mut f64,
        info_out: *mut sogmm_registration_info,
    ) -> sogmm_status;
    pub fn sogmm_register_model(
        target: *const sogmm_model,
        source: *const sogmm_model,
        init: *const f64,
        options: *const sogmm_options,
        pose_out: *mut f64,
        info_out: *mut sogmm_registration_info,
    ) -> sogmm_status;
    pub fn sogmm_map_track_frame(
        map: *mut sogmm_map,
        frame: *const sogmm_frame,
        guess: *const f64,
        pose_out: *mut f64,
        inserted_out: *mut i32,
        info_out: *mut sogmm_registration_info,
    ) -> sogmm_status;
    pub fn sogmm_model_surface_distance_f32(
        model: *const sogmm_model,
        xyz: *const f32,
        n: usize,
        options: *const sogmm_options,
        distance_out: *mut f64,
        gradient_out: *mut f64,
    ) -> sogmm_status;
    pub fn sogmm_map_surface_distance_f32(
        map: *const sogmm_map,
        xyz: *const f32,
        n: usize,
        options: *const sogmm_options,
        distance_out: *mut f64,
        gradient_out: *mut f64,
    ) -> sogmm_status;
    pub fn sogmm_model_collision_probability(
        model: *const sogmm_model,
        centers: *const f64,
        shapes: *const f64,
        n: usize,
        options: *const sogmm_options,
        out: *mut f64,
    ) -> sogmm_status;
    pub fn sogmm_map_collision_probability(
        map: *const sogmm_map,
        centers: *const f64,
        shapes: *const f64,
        n: usize,
        options: *const sogmm_options,
        out: *mut f64,
    ) -> sogmm_status;
    pub fn sogmm_map_render_f32(
        map: *const sogmm_map,
        width: u32,
        height: u32,
        fx: f64,
        fy: f64,
        cx: f64,
        cy: f64,
        camera_to_world: *const f64,
        options: *const sogmm_options,
        depth_out: *mut f32,
        gray_out: *mut f32,
        variance_out: *mut f32,
    ) -> sogmm_status;
    pub fn sogmm_map_save(map: *const sogmm_map, path: *const c_char, options: *const sogmm_options) -> sogmm_status;
    pub fn sogmm_map_load(out: *mut *mut sogmm_map, path: *const c_char, options: *const sogmm_options)
        -> sogmm_status;
    pub fn sogmm_map_export_delta(
        map: *const sogmm_map,
        since_revision: u64,
        options: *const sogmm_options,
        out: *mut c_void,
        capacity: usize,
        size: *mut usize,
    ) -> sogmm_status;
    pub fn sogmm_map_apply_delta(
        map: *mut sogmm_map,
        data: *const c_void,
        size: usize,
        options: *const sogmm_options,
    ) -> sogmm_status;
    pub fn sogmm_map_merge_map(
        map: *mut sogmm_map,
        other: *const sogmm_map,
        other_to_map: *const f64,
        stats_out: *mut u64,
    ) -> sogmm_status;
    pub fn sogmm_fit_points_f32(
        out: *mut *mut sogmm_model,
        points: *const f32,
        n: usize,
        initial: *const sogmm_model,
        options: *const sogmm_options,
    ) -> sogmm_status;
    pub fn sogmm_frame_from_arrays(
        out: *mut *mut sogmm_frame,
        width: u32,
        height: u32,
        depth: *const u16,
        color: *const c_void,
        color_format: i32,
    ) -> sogmm_status;
    pub fn sogmm_frame_to_points_f32(
        out: *mut f32,
        capacity: usize,
        n_points: *mut usize,
        frame: *const sogmm_frame,
        options: *const sogmm_options,
    ) -> sogmm_status;
    pub fn sogmm_frame_read(
        out: *mut *mut sogmm_frame,
        depth_path: *const c_char,
        color_path: *const c_char,
    ) -> sogmm_status;
    pub fn sogmm_frame_decode(
        out: *mut *mut sogmm_frame,
        depth_data: *const c_void,
        depth_size: usize,
        color_data: *const c_void,
        color_size: usize,
    ) -> sogmm_status;
    pub fn sogmm_frame_free(frame: *mut sogmm_frame);
    pub fn sogmm_frame_width(frame: *const sogmm_frame) -> u32;
    pub fn sogmm_frame_height(frame: *const sogmm_frame) -> u32;
    pub fn sogmm_frame_depth(frame: *const sogmm_frame) -> *const u16;
    pub fn sogmm_frame_color(frame: *const sogmm_frame) -> *const u8;
    pub fn sogmm_frame_color_format(frame: *const sogmm_frame) -> i32;
    pub fn sogmm_frame_set_intrinsics(frame: *mut sogmm_frame, fx: f64, fy: f64, cx: f64, cy: f64) -> sogmm_status;
    pub fn sogmm_fit_frame(
        out: *mut *mut sogmm_model,
        frame: *const sogmm_frame,
        options: *const sogmm_options,
    ) -> sogmm_status;
    pub fn sogmm_trajectory_read(out: *mut *mut sogmm_trajectory, path: *const c_char) -> sogmm_status;
    pub fn sogmm_trajectory_free(trajectory: *mut sogmm_trajectory);
    pub fn sogmm_trajectory_size(trajectory: *const sogmm_trajectory) -> usize;
    pub fn sogmm_trajectory_poses(trajectory: *const sogmm_trajectory) -> *const f64;
    pub fn sogmm_trajectory_ids(trajectory: *const sogmm_trajectory) -> *const i64;
    pub fn sogmm_trajectory_write(path: *const c_char, poses: *const f64, n: usize) -> sogmm_status;
    pub fn sogmm_buffer_data(buffer: *const sogmm_buffer) -> *const u8;
    pub fn sogmm_buffer_size(buffer: *const sogmm_buffer) -> usize;
    pub fn sogmm_buffer_free(buffer: *mut sogmm_buffer);
}
