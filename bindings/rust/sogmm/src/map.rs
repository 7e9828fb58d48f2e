//! `Map`: an owned sogmm_map handle, the incremental world map of posed
//! frames (core/include/sogmm/map.hpp): only the points the map does not yet
//! explain are fitted and merged in the world frame.
use std::ops::ControlFlow;
use std::path::Path;
use std::ptr::{self, NonNull};

use sogmm_sys as sys;

use crate::error::{check, Result};
use crate::model::{c_path, dims_ok, len_of, regress_with, rows, score_with, Frame, Model};
use crate::options::{opt_ptr, Options};
use crate::progress::{with_map_progress, with_progress, Progress};
use crate::render::{render_into, Camera, Rendered};

/// A row-major 4 x 4 rigid camera-to-world transform [R t; 0 0 0 1].
pub type Pose = [f64; 16];

/// Totals of a map.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MapStats {
    /// Components in the map.
    pub n_components: u64,
    /// Novel points waiting for a fit (not in the map yet).
    pub n_pending: u64,
    /// Frames inserted (a loaded map counts the frames of its file).
    pub n_frames: u64,
    /// Fits run by this handle.
    pub n_flushes: u64,
    /// New components fused into existing ones instead of appended.
    pub n_fused: u64,
    /// Revisit refits run by this handle (also counted in `n_flushes`).
    pub n_refits: u64,
}

/// What one insert did (frames of a loaded map have zero times).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MapFrameStats {
    pub n_points: u64,
    pub n_novel: u64,
    /// Map components after the insert.
    pub n_components: u64,
    /// The insert ran a fit.
    pub flushed: bool,
    pub ms_novelty: f64,
    pub ms_fit: f64,
    pub ms_merge: f64,
    /// Map components this insert's revisit refit replaced (0: none ran).
    pub n_replaced: u64,
    /// The camera-to-world pose given with the frame.
    pub pose: Pose,
}

/// An incremental world map. Inserting needs `&mut self`; the queries
/// (`stats`, `export`, `score_samples`, `regress_gray`, `sample`, `save`)
/// take `&self` and may run on many threads at once.
///
/// The C library refuses a call on a map that another call is using
/// (SOGMM_E_BUSY, "map busy"); here the borrow rules already forbid it, so
/// `Status::Busy` never comes from safe code. A progress closure cannot reach
/// the map whose insert runs it:
///
/// ```compile_fail
/// let mut map = sogmm::Map::new(None).unwrap();
/// map.flush_with_progress(|_| {
///     let _ = map.stats(); // error[E0502]: `map` is already borrowed as mutable
///     std::ops::ControlFlow::Continue(())
/// })
/// .unwrap();
/// ```
///
/// and dropping it from another thread while an insert runs needs the map
/// by value, which the insert's `&mut` borrow prevents.
pub struct Map {
    ptr: NonNull<sys::sogmm_map>,
}

// SAFETY: sogmm.h: functions taking a const map may run concurrently on one
// handle (the `&self` methods); inserts, flushes and sogmm_map_set_progress
// need exclusive use, which `&mut self` and `Drop` give. The map has no
// thread affinity, so moving it between threads is fine.
unsafe impl Send for Map {}
unsafe impl Sync for Map {}

impl Map {
    fn make(f: impl FnOnce(*mut *mut sys::sogmm_map) -> i32) -> Result<Map> {
        crate::ensure_abi()?;
        let mut out = ptr::null_mut();
        check(f(&mut out))?;
        Ok(Map {
            ptr: NonNull::new(out).expect("libsogmm returned OK and a NULL map"),
        })
    }

    pub(crate) fn raw(&self) -> *const sys::sogmm_map {
        self.ptr.as_ptr()
    }

    /// An empty map with the map, fit and RGB-D keys of `options` (None =
    /// defaults: novelty 3.0 nats, batches of 12,288 points, no fusion).
    pub fn new(options: Option<&Options>) -> Result<Map> {
        // SAFETY: valid out-pointer; options a valid handle or NULL.
        Map::make(|out| unsafe { sys::sogmm_map_create(out, opt_ptr(options)) })
    }

    /// Reads a map file written by `save` (or any world-frame model, without
    /// frame provenance); the keys of `options` govern later inserts.
    pub fn load(path: impl AsRef<Path>, options: Option<&Options>) -> Result<Map> {
        let p = c_path(path.as_ref())?;
        // SAFETY: NUL-terminated path.
        Map::make(|out| unsafe { sys::sogmm_map_load(out, p.as_ptr(), opt_ptr(options)) })
    }

    /// Inserts n points (rows of x, y, z, gray) in the camera frame with the
    /// frame's camera-to-world pose. A failed insert leaves the map as it was.
    pub fn insert_points(&mut self, points: &[f32], pose: &Pose) -> Result<()> {
        let n = rows(points, 4, "points")?;
        // SAFETY: exclusive through &mut self; n * 4 floats and 16 doubles.
        check(unsafe { sys::sogmm_map_insert_points_f32(self.ptr.as_ptr(), points.as_ptr(), n, pose.as_ptr()) })
    }

    /// Inserts an RGB-D frame (decimation and depth range from the map's
    /// options) with its camera-to-world pose. The first frame fixes the camera.
    pub fn insert_frame(&mut self, frame: &Frame<'_>, pose: &Pose) -> Result<()> {
        let h = frame.handle()?;
        // SAFETY: exclusive through &mut self; a valid frame and 16 doubles.
        check(unsafe { sys::sogmm_map_insert_frame(self.ptr.as_ptr(), h.0, pose.as_ptr()) })
    }

    /// Fits the pending points now (nothing when none are pending).
    pub fn flush(&mut self) -> Result<()> {
        // SAFETY: exclusive through &mut self.
        check(unsafe { sys::sogmm_map_flush(self.ptr.as_ptr()) })
    }

    /// Drops the points pending for a fit (they never become components) and
    /// returns how many there were. The frames stay recorded. The way out when
    /// a flush keeps failing and the map cannot be saved.
    pub fn discard_pending(&mut self) -> Result<u64> {
        let mut dropped = 0u64;
        // SAFETY: exclusive through &mut self; `dropped` outlives the call.
        check(unsafe { sys::sogmm_map_discard_pending(self.ptr.as_ptr(), &mut dropped) })?;
        Ok(dropped)
    }

    /// As `insert_points`, reporting the fit it may run to `on_progress`
    /// (see `Model::fit_with_progress`). `ControlFlow::Break(())` or a panic
    /// cancels: `Err` with `Status::Cancelled` (the panic resumes) and the
    /// map as before the call.
    pub fn insert_points_with_progress(
        &mut self,
        points: &[f32],
        pose: &Pose,
        on_progress: impl FnMut(Progress) -> ControlFlow<()>,
    ) -> Result<()> {
        let map = self.ptr.as_ptr();
        with_map_progress(map, on_progress, || self.insert_points(points, pose))
    }

    /// As `insert_frame`, with progress and cancel as `insert_points_with_progress`.
    pub fn insert_frame_with_progress(
        &mut self,
        frame: &Frame<'_>,
        pose: &Pose,
        on_progress: impl FnMut(Progress) -> ControlFlow<()>,
    ) -> Result<()> {
        let map = self.ptr.as_ptr();
        with_map_progress(map, on_progress, || self.insert_frame(frame, pose))
    }

    /// As `flush`, with progress and cancel; a cancelled flush keeps the
    /// pending points.
    pub fn flush_with_progress(&mut self, on_progress: impl FnMut(Progress) -> ControlFlow<()>) -> Result<()> {
        let map = self.ptr.as_ptr();
        with_map_progress(map, on_progress, || self.flush())
    }

    /// The map's totals (read key by key, `sogmm_map_get_i64`).
    pub fn stats(&self) -> Result<MapStats> {
        let get = |key| -> Result<u64> {
            let mut v = 0i64;
            // SAFETY: valid handle and out-pointer.
            check(unsafe { sys::sogmm_map_get_i64(self.raw(), key, &mut v) })?;
            Ok(v as u64)
        };
        Ok(MapStats {
            n_components: get(sys::SOGMM_MAP_N_COMPONENTS)?,
            n_pending: get(sys::SOGMM_MAP_N_PENDING)?,
            n_frames: get(sys::SOGMM_MAP_N_FRAMES)?,
            n_flushes: get(sys::SOGMM_MAP_N_FLUSHES)?,
            n_fused: get(sys::SOGMM_MAP_N_FUSED)?,
            n_refits: get(sys::SOGMM_MAP_N_REFITS)?,
        })
    }

    /// The map's origin (anchor; world x, y, z in metres): the map holds its
    /// components relative to it, so that far from the world origin
    /// (geo-referenced poses) they keep room-scale resolution. By default the
    /// first frame's translation rounded to 1 km per axis (0 near the world
    /// origin); a loaded map's comes from its file (`sogmm_map_get_origin`).
    pub fn origin(&self) -> Result<[f64; 3]> {
        let mut out = [0f64; 3];
        // SAFETY: valid handle; `out` has room for the 3 doubles written.
        check(unsafe { sys::sogmm_map_get_origin(self.raw(), out.as_mut_ptr()) })?;
        Ok(out)
    }

    /// Declares the origin (finite, within float32 range) instead of the
    /// first frame's; only before the first insert, else `Err` with
    /// `Status::InvalidArg` (`sogmm_map_set_origin`).
    pub fn set_origin(&mut self, origin: [f64; 3]) -> Result<()> {
        // SAFETY: exclusive through &mut self; 3 doubles.
        check(unsafe { sys::sogmm_map_set_origin(self.ptr.as_ptr(), origin.as_ptr()) })
    }

    /// What the insert of frame `frame` (insertion order, from 0) did (read
    /// key by key, `sogmm_map_frame_get_*`).
    pub fn frame_stats(&self, frame: u64) -> Result<MapFrameStats> {
        let int = |key| -> Result<u64> {
            let mut v = 0i64;
            // SAFETY: valid handle and out-pointer.
            check(unsafe { sys::sogmm_map_frame_get_i64(self.raw(), frame, key, &mut v) })?;
            Ok(v as u64)
        };
        let float = |key| -> Result<f64> {
            let mut v = 0f64;
            // SAFETY: valid handle and out-pointer.
            check(unsafe { sys::sogmm_map_frame_get_f64(self.raw(), frame, key, &mut v) })?;
            Ok(v)
        };
        let mut pose = [0f64; 16];
        // SAFETY: valid handle; `pose` has room for the 16 doubles written.
        check(unsafe { sys::sogmm_map_frame_get_pose(self.raw(), frame, pose.as_mut_ptr()) })?;
        Ok(MapFrameStats {
            n_points: int(sys::SOGMM_MAP_FRAME_N_POINTS)?,
            n_novel: int(sys::SOGMM_MAP_FRAME_N_NOVEL)?,
            n_components: int(sys::SOGMM_MAP_FRAME_N_COMPONENTS)?,
            flushed: int(sys::SOGMM_MAP_FRAME_FLUSHED)? != 0,
            ms_novelty: float(sys::SOGMM_MAP_FRAME_MS_NOVELTY)?,
            ms_fit: float(sys::SOGMM_MAP_FRAME_MS_FIT)?,
            ms_merge: float(sys::SOGMM_MAP_FRAME_MS_MERGE)?,
            n_replaced: int(sys::SOGMM_MAP_FRAME_N_REPLACED)?,
            pose,
        })
    }

    /// The whole map as a world-frame model.
    pub fn export(&self) -> Result<Model> {
        // SAFETY: valid handles; NULL box = everything.
        Model::make(|out| unsafe { sys::sogmm_map_export(out, self.raw(), ptr::null()) })
    }

    /// The components whose 3-sigma box meets `bounds` (x_min, y_min, z_min,
    /// x_max, y_max, z_max), weights renormalised over them.
    pub fn export_box(&self, bounds: &[f32; 6]) -> Result<Model> {
        // SAFETY: valid handles; 6 floats.
        Model::make(|out| unsafe { sys::sogmm_map_export(out, self.raw(), bounds.as_ptr()) })
    }

    /// Log-density of world points (rows of `dims` floats; 4: joint, 3:
    /// marginal over gray), bitwise what `export()?.score_samples` gives,
    /// without the copy.
    pub fn score_samples(&self, points: &[f32], dims: i32) -> Result<Vec<f64>> {
        self.score_raw(points, dims, opt_ptr(None))
    }

    /// As `score_samples`, with the threads and culling of `options` (as
    /// `Model::score_samples_with`).
    pub fn score_samples_with(&self, points: &[f32], dims: i32, options: Option<&Options>) -> Result<Vec<f64>> {
        self.score_raw(points, dims, opt_ptr(options))
    }

    /// As `score_samples_with` (threads and culling of `options`), reporting
    /// `Stage::Scoring` and cancellable.
    pub fn score_samples_with_progress(
        &self,
        points: &[f32],
        dims: i32,
        options: Option<&Options>,
        on_progress: impl FnMut(Progress) -> ControlFlow<()>,
    ) -> Result<Vec<f64>> {
        with_progress(options, on_progress, |o| self.score_raw(points, dims, o))
    }

    fn score_raw(&self, points: &[f32], dims: i32, o: *const sys::sogmm_options) -> Result<Vec<f64>> {
        // SAFETY: score_with passes n rows and n doubles of room; `o` valid or NULL.
        score_with(points, dims, |n, out| unsafe {
            sys::sogmm_map_score_samples_f32(self.raw(), points.as_ptr(), n, dims, o, out)
        })
    }

    /// Expected gray and its variance at world points (`xyz`: rows of 3).
    pub fn regress_gray(&self, xyz: &[f32]) -> Result<(Vec<f32>, Vec<f32>)> {
        self.regress_raw(xyz, opt_ptr(None))
    }

    /// As `regress_gray`, with the threads and culling of `options` (as
    /// `Model::regress_gray_with`).
    pub fn regress_gray_with(&self, xyz: &[f32], options: Option<&Options>) -> Result<(Vec<f32>, Vec<f32>)> {
        self.regress_raw(xyz, opt_ptr(options))
    }

    /// As `regress_gray_with` (threads and culling of `options`), reporting
    /// `Stage::Regression` and cancellable.
    pub fn regress_gray_with_progress(
        &self,
        xyz: &[f32],
        options: Option<&Options>,
        on_progress: impl FnMut(Progress) -> ControlFlow<()>,
    ) -> Result<(Vec<f32>, Vec<f32>)> {
        with_progress(options, on_progress, |o| self.regress_raw(xyz, o))
    }

    fn regress_raw(&self, xyz: &[f32], o: *const sys::sogmm_options) -> Result<(Vec<f32>, Vec<f32>)> {
        // SAFETY: regress_with passes n rows and n floats of room in each output; `o` valid or NULL.
        regress_with(xyz, |n, mean, var| unsafe {
            sys::sogmm_map_regress_gray_f32(self.raw(), xyz.as_ptr(), n, o, mean, var)
        })
    }

    /// The map seen from `camera` at the camera-to-world `pose`: the same
    /// bits as `self.export()?.render(...)` (see `Model::render`).
    pub fn render(&self, camera: &Camera, pose: Option<&Pose>, options: Option<&Options>) -> Result<Rendered> {
        self.render_raw(camera, pose, opt_ptr(options))
    }

    /// As `render`, reporting `Stage::Rendering` and cancellable.
    pub fn render_with_progress(
        &self,
        camera: &Camera,
        pose: Option<&Pose>,
        options: Option<&Options>,
        on_progress: impl FnMut(Progress) -> ControlFlow<()>,
    ) -> Result<Rendered> {
        with_progress(options, on_progress, |o| self.render_raw(camera, pose, o))
    }

    fn render_raw(&self, camera: &Camera, pose: Option<&Pose>, o: *const sys::sogmm_options) -> Result<Rendered> {
        render_into(sys::sogmm_map_render_f32, self.raw(), camera, pose, o)
    }

    /// Draws n world points (rows of `dims` floats, grouped by component);
    /// `options` gives SOGMM_OPT_SAMPLE_TRUNCATION (None = 2.5).
    pub fn sample(&self, n: usize, seed: u64, dims: i32, options: Option<&Options>) -> Result<Vec<f32>> {
        self.sample_raw(n, seed, dims, opt_ptr(options))
    }

    /// As `sample`, reporting `Stage::Sampling` and cancellable.
    pub fn sample_with_progress(
        &self,
        n: usize,
        seed: u64,
        dims: i32,
        options: Option<&Options>,
        on_progress: impl FnMut(Progress) -> ControlFlow<()>,
    ) -> Result<Vec<f32>> {
        with_progress(options, on_progress, |o| self.sample_raw(n, seed, dims, o))
    }

    fn sample_raw(&self, n: usize, seed: u64, dims: i32, o: *const sys::sogmm_options) -> Result<Vec<f32>> {
        let mut out = vec![0.0f32; len_of(n, dims_ok(dims)?, "samples")?];
        // SAFETY: `out` holds n * dims floats.
        check(unsafe { sys::sogmm_map_sample_f32(self.raw(), n, seed, dims, o, out.as_mut_ptr()) })?;
        Ok(out)
    }

    /// Writes the map as a world-frame .sogmm file with its frame provenance,
    /// atomically (write keys of `options` apply). Flush pending points first.
    pub fn save(&self, path: impl AsRef<Path>, options: Option<&Options>) -> Result<()> {
        let p = c_path(path.as_ref())?;
        // SAFETY: NUL-terminated path; const use of the map.
        check(unsafe { sys::sogmm_map_save(self.raw(), p.as_ptr(), opt_ptr(options)) })
    }
}

impl Drop for Map {
    fn drop(&mut self) {
        // SAFETY: we own the handle; nothing else uses it once dropped.
        unsafe { sys::sogmm_map_free(self.ptr.as_ptr()) }
    }
}

impl std::fmt::Debug for Map {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = self.stats().unwrap_or_default();
        f.debug_struct("Map")
            .field("n_frames", &s.n_frames)
            .field("n_components", &s.n_components)
            .field("n_pending", &s.n_pending)
            .finish_non_exhaustive()
    }
}
