//! `Map`: an owned sogmm_map handle, the incremental world map of posed
//! frames (core/include/sogmm/map.hpp): only the points the map does not yet
//! explain are fitted and merged in the world frame.
use std::path::Path;
use std::ptr::{self, NonNull};

use sogmm_sys as sys;

use crate::error::{check, Result};
use crate::model::{c_path, rows, Frame, Model};
use crate::options::{opt_ptr, Options};
use crate::progress::{with_map_progress, ProgressHook};
use crate::registration::{self, Registration};

/// A row-major 4 x 4 rigid camera-to-world transform [R t; 0 0 0 1].
pub type Pose = [f64; 16];

/// What `Map::merge_map` did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MapMergeStats {
    /// This map's components kept.
    pub n_kept: u64,
    /// This map's components the other map holds more sharply (removed).
    pub n_removed: u64,
    /// The other map's components added.
    pub n_added: u64,
    /// The other map's components this map already holds as sharply (left out).
    pub n_skipped: u64,
    /// Frame provenance lines added (the other map's frames).
    pub n_frames: u64,
}

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
/// (`stats`, `export`, `save`, `occupancy` and those of `Queryable`) take
/// `&self` and may run on many threads at once.
///
/// The C library refuses a call on a map that another call is using
/// (SOGMM_E_BUSY, "map busy"); here the borrow rules already forbid it, so
/// `Status::Busy` never comes from safe code. A progress closure is
/// `'static`, so it cannot reach the map whose insert runs it:
///
/// ```compile_fail
/// let map = sogmm::Map::new(None).unwrap();
/// let opts = sogmm::Options::builder()
///     .on_progress(|_| {
///         let _ = map.stats(); // error[E0373]: closure may outlive `map`
///         std::ops::ControlFlow::Continue(())
///     })
///     .build()
///     .unwrap();
/// ```
///
/// and dropping it from another thread while an insert runs needs the map
/// by value, which the insert's `&mut` borrow prevents.
pub struct Map {
    ptr: NonNull<sys::sogmm_map>,
    /// The progress closure of the options the map was created with.
    progress: Option<ProgressHook>,
}

// SAFETY: sogmm.h: functions taking a const map may run concurrently on one
// handle (the `&self` methods); inserts, flushes and sogmm_map_set_progress
// need exclusive use, which `&mut self` and `Drop` give. The map has no
// thread affinity, so moving it between threads is fine.
unsafe impl Send for Map {}
unsafe impl Sync for Map {}

impl Map {
    fn make(options: Option<&Options>, f: impl FnOnce(*mut *mut sys::sogmm_map) -> i32) -> Result<Map> {
        crate::ensure_abi()?;
        let mut out = ptr::null_mut();
        check(f(&mut out))?;
        Ok(Map {
            ptr: NonNull::new(out).expect("libsogmm returned OK and a NULL map"),
            progress: options.and_then(Options::progress).cloned(),
        })
    }

    pub(crate) fn raw(&self) -> *const sys::sogmm_map {
        self.ptr.as_ptr()
    }

    /// An empty map with the map, fit and RGB-D keys of `options` (None =
    /// defaults: novelty 3.0 nats, batches of 12,288 points, no fusion). Its
    /// inserts and flushes report to the options' progress closure
    /// (`OptionsBuilder::on_progress`), which may cancel them: `Err` with
    /// `Status::Cancelled` (a panic cancels too, then resumes) and the map as
    /// before the call.
    pub fn new(options: Option<&Options>) -> Result<Map> {
        // SAFETY: valid out-pointer; options a valid handle or NULL.
        Map::make(options, |out| unsafe { sys::sogmm_map_create(out, opt_ptr(options)) })
    }

    /// Reads a map file written by `save` (or any world-frame model, without
    /// frame provenance); the keys of `options` and their progress closure
    /// govern later inserts.
    pub fn load(path: impl AsRef<Path>, options: Option<&Options>) -> Result<Map> {
        let p = c_path(path.as_ref())?;
        // SAFETY: NUL-terminated path.
        Map::make(options, |out| unsafe {
            sys::sogmm_map_load(out, p.as_ptr(), opt_ptr(options))
        })
    }

    /// Inserts n points (rows of x, y, z, gray) in the camera frame with the
    /// frame's camera-to-world pose. A failed insert leaves the map as it was.
    pub fn insert_points(&mut self, points: &[f32], pose: &Pose) -> Result<()> {
        let n = rows(points, 4, "points")?;
        let map = self.ptr.as_ptr();
        // SAFETY: exclusive through &mut self; n * 4 floats and 16 doubles.
        with_map_progress(map, self.progress.as_ref(), || {
            check(unsafe { sys::sogmm_map_insert_points_f32(map, points.as_ptr(), n, pose.as_ptr()) })
        })
    }

    /// Inserts an RGB-D frame (decimation and depth range from the map's
    /// options) with its camera-to-world pose. The first frame fixes the camera.
    pub fn insert_frame(&mut self, frame: &Frame<'_>, pose: &Pose) -> Result<()> {
        let h = frame.handle()?;
        let map = self.ptr.as_ptr();
        // SAFETY: exclusive through &mut self; a valid frame and 16 doubles.
        with_map_progress(map, self.progress.as_ref(), || {
            check(unsafe { sys::sogmm_map_insert_frame(map, h.0, pose.as_ptr()) })
        })
    }

    /// Tracking (`sogmm_map_track_frame`): inserts `frame` at the
    /// camera-to-world pose that registration to the map finds, from `guess`
    /// or (None) the constant-velocity prediction from the map's last two
    /// frames; the map's first frame goes in at the guess (None: identity).
    /// Registration options are the map's creation options
    /// (`SOGMM_OPT_REGISTRATION_*`, `SOGMM_OPT_TRACKING_*`). Returns the map
    /// registration (its pose is the one used, or its last iterate) and
    /// whether the frame was inserted: when the status is `Converged` or, with
    /// gray and `SOGMM_OPT_TRACKING_ODOMETRY`, when the registration to the
    /// last tracked frame vouches for it (sogmm.h states the rule). The first
    /// frame reports `Converged` with 0 iterations.
    pub fn track_frame(&mut self, frame: &Frame<'_>, guess: Option<&Pose>) -> Result<(Registration, bool)> {
        let h = frame.handle()?;
        let map = self.ptr.as_ptr();
        let mut pose: Pose = [0.0; 16];
        let mut inserted = 0i32;
        let mut info = registration::empty_info();
        let guess_ptr = guess.map_or(ptr::null(), |p| p.as_ptr());
        // SAFETY: exclusive through &mut self; a valid frame, 16 doubles or NULL, and room for every output.
        with_map_progress(map, self.progress.as_ref(), || {
            check(unsafe {
                sys::sogmm_map_track_frame(map, h.0, guess_ptr, pose.as_mut_ptr(), &mut inserted, &mut info)
            })
        })?;
        Ok((registration::registration_of(pose, &info), inserted != 0))
    }

    /// Fits the pending points now (nothing when none are pending); a
    /// cancelled flush keeps them.
    pub fn flush(&mut self) -> Result<()> {
        let map = self.ptr.as_ptr();
        // SAFETY: exclusive through &mut self.
        with_map_progress(map, self.progress.as_ref(), || {
            check(unsafe { sys::sogmm_map_flush(map) })
        })
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

    /// The map's revision: 0 when created, +1 for every insert, fitting flush
    /// or applied delta that changed it.
    pub fn revision(&self) -> Result<u64> {
        let mut v = 0i64;
        // SAFETY: valid handle and out-pointer.
        check(unsafe { sys::sogmm_map_get_i64(self.raw(), sys::SOGMM_MAP_REVISION, &mut v) })?;
        Ok(v as u64)
    }

    /// The delta file (spec/format.md section 2.5) from revision `since` to
    /// the current one; a receiver at `since` applies it with `apply_delta`.
    pub fn export_delta(&self, since: u64) -> Result<Vec<u8>> {
        let mut size = 0usize;
        // SAFETY: a size query (out NULL, capacity 0).
        check(unsafe {
            sys::sogmm_map_export_delta(self.raw(), since, std::ptr::null(), std::ptr::null_mut(), 0, &mut size)
        })?;
        let mut out = vec![0u8; size];
        // SAFETY: `out` has room for `size` bytes.
        check(unsafe {
            sys::sogmm_map_export_delta(
                self.raw(),
                since,
                std::ptr::null(),
                out.as_mut_ptr().cast(),
                out.len(),
                &mut size,
            )
        })?;
        out.truncate(size);
        Ok(out)
    }

    /// Applies a delta of the sender's map; afterwards this map is bitwise
    /// the sender's. A gap, a duplicate, another map's or a damaged delta is
    /// an error (InvalidArg / Format) and the map is unchanged.
    pub fn apply_delta(&mut self, delta: &[u8]) -> Result<()> {
        // SAFETY: exclusive use of the map; `delta` is read during the call.
        check(unsafe {
            sys::sogmm_map_apply_delta(self.ptr.as_ptr(), delta.as_ptr().cast(), delta.len(), std::ptr::null())
        })
    }

    /// Merges the map `other` into this one (two robots, one map),
    /// `other_to_this` moving the other map's world frame into this map's:
    /// where both hold a surface the sharper view wins instead of both being
    /// stacked; the other's frame provenance is appended; one revision,
    /// carried by deltas (sogmm_map_merge_map). Errors (this map unchanged):
    /// points pending in either map or a pose not finite or not rigid ->
    /// InvalidArg; `other` without components -> InvalidData.
    pub fn merge_map(&mut self, other: &Map, other_to_this: &Pose) -> Result<MapMergeStats> {
        let mut out = [0u64; 5];
        // SAFETY: exclusive use of this map, shared use of `other` (the
        // borrows rule out the same map); 16 pose doubles and 5 outputs.
        check(unsafe {
            sys::sogmm_map_merge_map(self.ptr.as_ptr(), other.raw(), other_to_this.as_ptr(), out.as_mut_ptr())
        })?;
        Ok(MapMergeStats {
            n_kept: out[0],
            n_removed: out[1],
            n_added: out[2],
            n_skipped: out[3],
            n_frames: out[4],
        })
    }

    /// Writes the map as a world-frame .sogmm file with its frame provenance,
    /// atomically (write keys of `options` apply). Flush pending points first.
    pub fn save(&self, path: impl AsRef<Path>, options: Option<&Options>) -> Result<()> {
        let p = c_path(path.as_ref())?;
        // SAFETY: NUL-terminated path; const use of the map.
        check(unsafe { sys::sogmm_map_save(self.raw(), p.as_ptr(), opt_ptr(options)) })
    }
}

owned_handle!(Map, sys::sogmm_map_free);

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
