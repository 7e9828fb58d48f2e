//! `Model`: an owned sogmm_model handle and every operation on it.
use std::ffi::{CStr, CString};
use std::path::Path;
use std::ptr::{self, NonNull};

use sogmm_sys as sys;

use crate::error::{check, Error, Result, Status};
use crate::options::{opt_ptr, Options};
use crate::progress::with_progress;

/// A fitted 4-D GMM (x, y, z, gray) with its metadata. Arrays come out as
/// row-major `Vec`s: weights (M), means (M x 4), covariances (M x 4 x 4).
pub struct Model {
    ptr: NonNull<sys::sogmm_model>,
}

// SAFETY: spec/api.md 1.1 and 6: functions taking a const model (queries,
// inference, merge, transform, clone, save) may run concurrently on one
// handle and are the `&self` methods; set_pose, clear_pose, set_value and
// free need exclusive use, which `&mut self` and `Drop` give. The library
// has no global mutable state, so moving a handle between threads is fine.
unsafe impl Send for Model {}
unsafe impl Sync for Model {}

/// The color image of an RGB-D frame, registered to the depth image.
#[derive(Clone, Copy, Debug)]
pub enum Color<'a> {
    /// width * height bytes, gray 0..255.
    Gray8(&'a [u8]),
    /// width * height * 3 bytes, interleaved R, G, B.
    Rgb8(&'a [u8]),
    /// width * height floats, gray used as given (meant to be in [0, 1]).
    GrayF32(&'a [f32]),
}

/// One RGB-D frame: raw depth (SOGMM_OPT_DEPTH_SCALE units per metre, 0 = no
/// reading), color, size and the full-size pinhole intrinsics.
#[derive(Clone, Copy, Debug)]
pub struct Frame<'a> {
    pub depth: &'a [u16],
    pub color: Color<'a>,
    pub width: u32,
    pub height: u32,
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
}

impl Frame<'_> {
    /// The color pointer and SOGMM_COLOR_* format, after checking every slice
    /// length against width and height (C cannot see them).
    pub(crate) fn color_args(&self) -> Result<(*const u8, i32)> {
        let pixels = len_of(self.width as usize, self.height as usize, "image size")?;
        if self.depth.len() != pixels {
            return Err(invalid(format!(
                "depth has {} values, width * height = {pixels}",
                self.depth.len()
            )));
        }
        let (color, format, got, want): (*const u8, i32, usize, usize) = match self.color {
            Color::Gray8(c) => (c.as_ptr(), sys::SOGMM_COLOR_GRAY8, c.len(), pixels),
            Color::Rgb8(c) => (
                c.as_ptr(),
                sys::SOGMM_COLOR_RGB8,
                c.len(),
                len_of(pixels, 3, "RGB size")?,
            ),
            Color::GrayF32(c) => (c.as_ptr().cast(), sys::SOGMM_COLOR_GRAY_F32, c.len(), pixels),
        };
        if got != want {
            return Err(invalid(format!("color has {got} values, the frame needs {want}")));
        }
        Ok((color, format))
    }

    /// The frame as a C `sogmm_frame` (copied by `sogmm_frame_from_arrays`,
    /// with the intrinsics), freed when the handle drops: what the fit, the
    /// map insert and `to_points` hand to the library.
    pub(crate) fn handle(&self) -> Result<crate::frames::Handle> {
        let (color, format) = self.color_args()?;
        let mut h = crate::frames::Handle(ptr::null_mut());
        // SAFETY: color_args checked the slices against width x height.
        check(unsafe {
            sys::sogmm_frame_from_arrays(
                &mut h.0,
                self.width,
                self.height,
                self.depth.as_ptr(),
                color.cast(),
                format,
            )
        })?;
        // SAFETY: a frame just made.
        check(unsafe { sys::sogmm_frame_set_intrinsics(h.0, self.fx, self.fy, self.cx, self.cy) })?;
        Ok(h)
    }

    /// The points `Model::fit_rgbd` would fit, without fitting: N rows (x, y,
    /// z, gray) in the camera frame (decimation and depth range from
    /// `options`). A frame without a valid pixel gives an empty Vec.
    pub fn to_points(&self, options: Option<&Options>) -> Result<Vec<f32>> {
        let frame = self.handle()?;
        let call = |out: *mut f32, capacity: usize, n: &mut usize| {
            // SAFETY: a valid frame; `out` has `capacity` floats.
            check(unsafe { sys::sogmm_frame_to_points_f32(out, capacity, n, frame.0, opt_ptr(options)) })
        };
        let mut n = 0;
        call(ptr::null_mut(), 0, &mut n)?; // capacity 0: only counts
        let mut points = vec![0.0f32; len_of(n, 4, "points")?];
        call(points.as_mut_ptr(), points.len(), &mut n)?;
        Ok(points)
    }
}

pub(crate) fn invalid(msg: String) -> Error {
    Error::new(Status::InvalidArg, msg)
}

/// Number of `cols`-wide rows in `data`, refusing a ragged slice.
pub(crate) fn rows(data: &[f32], cols: usize, what: &str) -> Result<usize> {
    if data.len() % cols != 0 {
        return Err(invalid(format!(
            "{what} has {} floats, not a multiple of {cols}",
            data.len()
        )));
    }
    Ok(data.len() / cols)
}

/// `dims` as a row width, refusing anything but 3 or 4.
pub(crate) fn dims_ok(dims: i32) -> Result<usize> {
    if dims == 3 || dims == 4 {
        Ok(dims as usize)
    } else {
        Err(invalid(format!("dims must be 3 or 4, got {dims}")))
    }
}

pub(crate) fn len_of(n: usize, per: usize, what: &str) -> Result<usize> {
    n.checked_mul(per)
        .ok_or_else(|| Error::new(Status::Limit, format!("{what}: {n} x {per} overflows usize")))
}

fn c_string(s: &str, what: &str) -> Result<CString> {
    CString::new(s).map_err(|_| invalid(format!("{what} contains a NUL byte")))
}

pub(crate) fn c_path(p: &Path) -> Result<CString> {
    use std::os::unix::ffi::OsStrExt;
    CString::new(p.as_os_str().as_bytes()).map_err(|_| invalid(format!("path {p:?} contains a NUL byte")))
}

/// Copies a library-owned string (valid until the model is next mutated,
/// which `&self` rules out meanwhile).
fn owned(p: *const sys::c_char) -> String {
    // SAFETY: the library returned a valid NUL-terminated string.
    unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
}

impl Model {
    /// Runs a C constructor taking an out-pointer first.
    pub(crate) fn make(f: impl FnOnce(*mut *mut sys::sogmm_model) -> i32) -> Result<Model> {
        crate::ensure_abi()?;
        let mut out = ptr::null_mut();
        check(f(&mut out))?;
        Ok(Model {
            ptr: NonNull::new(out).expect("libsogmm returned OK and a NULL model"),
        })
    }

    pub(crate) fn raw(&self) -> *const sys::sogmm_model {
        self.ptr.as_ptr()
    }

    /// Fits a model to n points: `points` holds n rows (x, y, z, gray).
    /// Uses the fit keys of `options` (None = defaults; `n_components` fixes
    /// K). Their progress closure (`OptionsBuilder::on_progress`) gets the
    /// reports; `ControlFlow::Break(())` cancels: `Err` with
    /// `Status::Cancelled` and no model, within about 50 ms.
    pub fn fit(points: &[f32], options: Option<&Options>) -> Result<Model> {
        Model::fit_points(points, None, options)
    }

    /// sogmm_fit_points_f32: cold (`initial` None) or warm, with the options' progress.
    fn fit_points(points: &[f32], initial: Option<&Model>, options: Option<&Options>) -> Result<Model> {
        let n = rows(points, 4, "points")?;
        crate::ensure_abi()?;
        let initial = initial.map_or(ptr::null(), Model::raw);
        with_progress(options, |o| {
            // SAFETY: `points` holds n * 4 floats and `initial` is a valid handle or NULL, both only read
            // during the call.
            Model::make(|out| unsafe { sys::sogmm_fit_points_f32(out, points.as_ptr(), n, initial, o) })
        })
    }

    /// Warm start: fits n points starting from `initial`, a model of an
    /// earlier, overlapping cloud already moved into these points' frame
    /// (e.g. the previous frame's model moved with `transform`). Self-
    /// organizing: components `initial` no longer explains are dropped and
    /// new ones are added for the novel points; with SOGMM_OPT_N_COMPONENTS
    /// = K, EM runs from `initial` as given (K must be its size). Needs
    /// n_init 1. `initial` is not changed. Progress and cancel as `fit`.
    pub fn fit_warm(points: &[f32], initial: &Model, options: Option<&Options>) -> Result<Model> {
        Model::fit_points(points, Some(initial), options)
    }

    /// Fits one RGB-D frame; decimation and depth range come from `options`;
    /// progress and cancel as `fit`.
    pub fn fit_rgbd(frame: &Frame<'_>, options: Option<&Options>) -> Result<Model> {
        let h = frame.handle()?;
        crate::ensure_abi()?;
        // SAFETY: a valid frame; `o` valid options or NULL.
        with_progress(options, |o| {
            Model::make(|out| unsafe { sys::sogmm_fit_frame(out, h.0, o) })
        })
    }

    /// Builds a model from M weights, M x 4 means and M x 4 x 4 covariances
    /// (copied). `support_size` = points it stands for (0 = unknown).
    pub fn from_arrays(weights: &[f32], means: &[f32], covariances: &[f32], support_size: u64) -> Result<Model> {
        let m = weights.len();
        if means.len() != len_of(m, 4, "means")? || covariances.len() != len_of(m, 16, "covariances")? {
            return Err(invalid(format!(
                "{m} weights need {} means and {} covariance floats, got {} and {}",
                m.saturating_mul(4),
                m.saturating_mul(16),
                means.len(),
                covariances.len()
            )));
        }
        // SAFETY: lengths checked above.
        Model::make(|out| unsafe {
            sys::sogmm_model_from_arrays_f32(
                out,
                m,
                weights.as_ptr(),
                means.as_ptr(),
                covariances.as_ptr(),
                support_size,
            )
        })
    }

    /// Reads a .sogmm file (read keys of `options` apply).
    pub fn load(path: impl AsRef<Path>, options: Option<&Options>) -> Result<Model> {
        let p = c_path(path.as_ref())?;
        // SAFETY: NUL-terminated path.
        Model::make(|out| unsafe { sys::sogmm_model_load(out, p.as_ptr(), opt_ptr(options)) })
    }

    /// Reads a model from the bytes of a .sogmm file.
    pub fn from_bytes(data: &[u8], options: Option<&Options>) -> Result<Model> {
        // SAFETY: `data` holds data.len() bytes.
        Model::make(|out| unsafe {
            sys::sogmm_model_load_from_memory(out, data.as_ptr().cast(), data.len(), opt_ptr(options))
        })
    }

    /// Deep copy including metadata; fails only when memory runs out.
    pub fn try_clone(&self) -> Result<Model> {
        // SAFETY: valid handle.
        Model::make(|out| unsafe { sys::sogmm_model_clone(out, self.raw()) })
    }

    /// Number of components M (>= 1).
    pub fn n_components(&self) -> usize {
        let mut m = 0;
        // SAFETY: valid handle; cannot fail for one.
        check(unsafe { sys::sogmm_model_n_components(self.raw(), &mut m) }).expect("n_components of a valid model");
        m
    }

    fn array(
        &self,
        per: usize,
        get: unsafe extern "C" fn(*const sys::sogmm_model, *mut f32, usize) -> i32,
    ) -> Result<Vec<f32>> {
        let mut v = vec![0.0f32; len_of(self.n_components(), per, "array")?];
        // SAFETY: `v` has room for v.len() floats, the capacity passed.
        check(unsafe { get(self.raw(), v.as_mut_ptr(), v.len()) })?;
        Ok(v)
    }

    /// The M weights.
    pub fn weights(&self) -> Result<Vec<f32>> {
        self.array(1, sys::sogmm_model_get_weights_f32)
    }

    /// The M x 4 means, row-major.
    pub fn means(&self) -> Result<Vec<f32>> {
        self.array(4, sys::sogmm_model_get_means_f32)
    }

    /// The M x 4 x 4 covariances, row-major.
    pub fn covariances(&self) -> Result<Vec<f32>> {
        self.array(16, sys::sogmm_model_get_covariances_f32)
    }

    /// An f64 SOGMM_INFO_* value; `None` when the model does not have it.
    pub fn info_f64(&self, key: i32) -> Result<Option<f64>> {
        let mut v = 0.0;
        // SAFETY: valid handle and out-pointer.
        not_found_is_none(
            check(unsafe { sys::sogmm_model_get_info_f64(self.raw(), key, &mut v) }),
            v,
        )
    }

    /// An i64 SOGMM_INFO_* value; `None` when the model does not have it.
    pub fn info_i64(&self, key: i32) -> Result<Option<i64>> {
        let mut v = 0;
        // SAFETY: valid handle and out-pointer.
        not_found_is_none(
            check(unsafe { sys::sogmm_model_get_info_i64(self.raw(), key, &mut v) }),
            v,
        )
    }

    /// Sets an f64 SOGMM_INFO_* key that .sogmm files store (the fit record,
    /// SOGMM_INFO_FIT_*, or the camera, SOGMM_INFO_CAMERA_*), e.g. to give a
    /// model rebuilt with `from_arrays` the provenance of its fit; a model
    /// without that record gets one with the format's defaults first. A key
    /// files do not store, or a value the format cannot hold (non-finite),
    /// is `Status::InvalidArg` naming the key, the model unchanged.
    pub fn set_info_f64(&mut self, key: i32, value: f64) -> Result<()> {
        // SAFETY: exclusive through &mut self.
        check(unsafe { sys::sogmm_model_set_info_f64(self.ptr.as_ptr(), key, value) })
    }

    /// As `set_info_f64` for i64 keys (FIT_CONVERGED 0 or 1, int32 fields in
    /// range, CAMERA_DECIMATION >= 1, ...; FIT_SEED takes the u64's bits).
    pub fn set_info_i64(&mut self, key: i32, value: i64) -> Result<()> {
        // SAFETY: exclusive through &mut self.
        check(unsafe { sys::sogmm_model_set_info_i64(self.ptr.as_ptr(), key, value) })
    }

    /// The 4 x 4 row-major pose of the model's frame, if set.
    pub fn pose(&self) -> Result<Option<[f64; 16]>> {
        let mut p = [0.0; 16];
        // SAFETY: room for 16 doubles.
        not_found_is_none(
            check(unsafe { sys::sogmm_model_get_pose(self.raw(), p.as_mut_ptr()) }),
            p,
        )
    }

    /// Sets the pose (must be a finite rigid transform).
    pub fn set_pose(&mut self, pose: &[f64; 16]) -> Result<()> {
        // SAFETY: exclusive through &mut self; 16 doubles.
        check(unsafe { sys::sogmm_model_set_pose(self.ptr.as_ptr(), pose.as_ptr()) })
    }

    pub fn clear_pose(&mut self) -> Result<()> {
        // SAFETY: exclusive through &mut self.
        check(unsafe { sys::sogmm_model_clear_pose(self.ptr.as_ptr()) })
    }

    /// The value of a metadata key (its first pair), if present.
    pub fn value(&self, key: &str) -> Result<Option<String>> {
        let k = c_string(key, "key")?;
        let mut v = ptr::null();
        // SAFETY: NUL-terminated key; `v` is copied before any mutation.
        let r = check(unsafe { sys::sogmm_model_get_value(self.raw(), k.as_ptr(), &mut v) });
        Ok(not_found_is_none(r, ())?.map(|()| owned(v)))
    }

    /// Adds a key/value pair or replaces the value of the first pair with that key.
    pub fn set_value(&mut self, key: &str, value: &str) -> Result<()> {
        let (k, v) = (c_string(key, "key")?, c_string(value, "value")?);
        // SAFETY: exclusive through &mut self; NUL-terminated strings.
        check(unsafe { sys::sogmm_model_set_value(self.ptr.as_ptr(), k.as_ptr(), v.as_ptr()) })
    }

    /// Every metadata pair, in order.
    pub fn values(&self) -> Result<Vec<(String, String)>> {
        let mut n = 0;
        // SAFETY: valid handle and out-pointer.
        check(unsafe { sys::sogmm_model_value_count(self.raw(), &mut n) })?;
        (0..n)
            .map(|i| {
                let (mut k, mut v) = (ptr::null(), ptr::null());
                // SAFETY: i < count; pointers copied at once.
                check(unsafe { sys::sogmm_model_value_at(self.raw(), i, &mut k, &mut v) })?;
                Ok((owned(k), owned(v)))
            })
            .collect()
    }

    /// A new model with the components of both, weighted by support size.
    pub fn merge(&self, other: &Model) -> Result<Model> {
        // SAFETY: both handles valid; const use only.
        Model::make(|out| unsafe { sys::sogmm_model_merge(out, self.raw(), other.raw()) })
    }

    /// A new model moved by a rigid 4 x 4 row-major transform.
    pub fn transform(&self, pose: &[f64; 16]) -> Result<Model> {
        // SAFETY: 16 doubles.
        Model::make(|out| unsafe { sys::sogmm_model_transform(out, self.raw(), pose.as_ptr()) })
    }

    /// Writes a .sogmm file atomically (write keys of `options` apply).
    pub fn save(&self, path: impl AsRef<Path>, options: Option<&Options>) -> Result<()> {
        let p = c_path(path.as_ref())?;
        // SAFETY: NUL-terminated path; const use of the model.
        check(unsafe { sys::sogmm_model_save(self.raw(), p.as_ptr(), opt_ptr(options)) })
    }

    /// The bytes of a .sogmm file.
    pub fn to_bytes(&self, options: Option<&Options>) -> Result<Vec<u8>> {
        let mut buf = ptr::null_mut();
        // SAFETY: valid out-pointer.
        check(unsafe { sys::sogmm_model_save_to_memory(&mut buf, self.raw(), opt_ptr(options)) })?;
        // SAFETY: the buffer owns size bytes at data until freed just below.
        let bytes = unsafe {
            let (data, size) = (sys::sogmm_buffer_data(buf), sys::sogmm_buffer_size(buf));
            let v = std::slice::from_raw_parts(data, size).to_vec();
            sys::sogmm_buffer_free(buf);
            v
        };
        Ok(bytes)
    }
}

/// `Ok(Some(value))` on success, `Ok(None)` for SOGMM_E_NOT_FOUND.
fn not_found_is_none<T>(r: Result<()>, value: T) -> Result<Option<T>> {
    match r {
        Ok(()) => Ok(Some(value)),
        Err(e) if e.status() == Status::NotFound => Ok(None),
        Err(e) => Err(e),
    }
}

owned_handle!(Model, sys::sogmm_model_free, clone: "a sogmm model");

impl std::fmt::Debug for Model {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Model")
            .field("n_components", &self.n_components())
            .finish_non_exhaustive()
    }
}
