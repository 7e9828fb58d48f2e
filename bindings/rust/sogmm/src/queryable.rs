//! `Queryable`: the read-only queries a `Model` (in its own frame) and a
//! `Map` (in the world frame, without exporting it) share, written once over
//! the C calls of each handle kind (sogmm_model_* and sogmm_map_*). A map's
//! answer is bitwise the answer of the model `Map::export` gives.
//!
//! Each query takes `Option<&Options>` (None = defaults); the options'
//! progress closure (`OptionsBuilder::on_progress`) gets the query's reports
//! and may cancel it.
use sogmm_sys as sys;

use crate::error::{check, Error, Result, Status};
use crate::map::Pose;
use crate::model::{dims_ok, invalid, len_of, rows};
use crate::options::Options;
use crate::progress::with_progress;
use crate::render::{Camera, RenderFn, Rendered};

type Opt = *const sys::sogmm_options;

/// The C queries over a handle of type `H` (sogmm_model or sogmm_map).
pub(crate) type ScoreFn<H> = unsafe extern "C" fn(*const H, *const f32, usize, i32, Opt, *mut f64) -> sys::sogmm_status;
pub(crate) type RegressFn<H> =
    unsafe extern "C" fn(*const H, *const f32, usize, Opt, *mut f32, *mut f32) -> sys::sogmm_status;
pub(crate) type SampleFn<H> = unsafe extern "C" fn(*const H, usize, u64, i32, Opt, *mut f32) -> sys::sogmm_status;
pub(crate) type DistanceFn<H> =
    unsafe extern "C" fn(*const H, *const f32, usize, Opt, *mut f64, *mut f64) -> sys::sogmm_status;
pub(crate) type CollisionFn<H> =
    unsafe extern "C" fn(*const H, *const f64, *const f64, usize, Opt, *mut f64) -> sys::sogmm_status;

pub(crate) mod sealed {
    use super::{CollisionFn, DistanceFn, RegressFn, SampleFn, ScoreFn};
    use crate::render::RenderFn;

    /// The C handle of a queryable type and the C queries of its kind.
    pub trait Handle {
        type Raw;
        fn raw_handle(&self) -> *const Self::Raw;
        const SCORE: ScoreFn<Self::Raw>;
        const REGRESS: RegressFn<Self::Raw>;
        const SAMPLE: SampleFn<Self::Raw>;
        const RENDER: RenderFn<Self::Raw>;
        const DISTANCE: DistanceFn<Self::Raw>;
        const COLLISION: CollisionFn<Self::Raw>;
    }
}

/// Queries of a `Model` or a `Map` (`use sogmm::Queryable` to call them).
/// All take `&self`: they may run on many threads at once.
pub trait Queryable: sealed::Handle {
    /// Log-density of rows of `dims` floats (4: joint; 3: marginal over gray)
    /// with the threads and culling (`query_truncation_nats`: each culled
    /// score is at most ln(1 + M e^-nats) below the exact one) of `options`.
    /// Progress: `Stage::Scoring`. An empty map: `Status::InvalidData`.
    fn score_samples(&self, points: &[f32], dims: i32, options: Option<&Options>) -> Result<Vec<f64>> {
        let n = rows(points, dims_ok(dims)?, "points")?;
        let mut out = vec![0.0f64; n];
        with_progress(options, |o| {
            // SAFETY: n rows of `dims` floats in, n doubles of room; `o` valid or NULL.
            check(unsafe { Self::SCORE(self.raw_handle(), points.as_ptr(), n, dims, o, out.as_mut_ptr()) })
        })?;
        Ok(out)
    }

    /// Expected gray and its conditional variance at points (`xyz`: rows of
    /// 3); options as `score_samples`. Progress: `Stage::Regression`.
    fn regress_gray(&self, xyz: &[f32], options: Option<&Options>) -> Result<(Vec<f32>, Vec<f32>)> {
        let n = rows(xyz, 3, "xyz")?;
        let (mut mean, mut var) = (vec![0.0f32; n], vec![0.0f32; n]);
        with_progress(options, |o| {
            // SAFETY: n rows of 3 floats in, n floats of room in each output.
            check(unsafe {
                Self::REGRESS(
                    self.raw_handle(),
                    xyz.as_ptr(),
                    n,
                    o,
                    mean.as_mut_ptr(),
                    var.as_mut_ptr(),
                )
            })
        })?;
        Ok((mean, var))
    }

    /// Draws n points (rows of `dims` floats: 4 = x, y, z, gray; 3 = x, y,
    /// z), grouped by component; `options` gives SOGMM_OPT_SAMPLE_TRUNCATION.
    /// Same seed, same samples. Progress: `Stage::Sampling`.
    fn sample(&self, n: usize, seed: u64, dims: i32, options: Option<&Options>) -> Result<Vec<f32>> {
        let mut out = vec![0.0f32; len_of(n, dims_ok(dims)?, "samples")?];
        with_progress(options, |o| {
            // SAFETY: `out` holds n * dims floats.
            check(unsafe { Self::SAMPLE(self.raw_handle(), n, seed, dims, o, out.as_mut_ptr()) })
        })?;
        Ok(out)
    }

    /// What shows from `camera` at the camera-to-world `pose` (None =
    /// identity): per pixel the first surface along its ray, its depth, the
    /// gray regressed there and its variance. `options` gives depth_min /
    /// depth_max (the depths that count as surfaces), render_surface_sigma
    /// (the evidence a mode needs to be a surface) and threads (the same
    /// bits for any count). Progress: `Stage::Rendering` (rows done).
    fn render(&self, camera: &Camera, pose: Option<&Pose>, options: Option<&Options>) -> Result<Rendered> {
        // The pixel limit first, so that no huge buffer is allocated for a call that must fail.
        let pixels = (camera.width as usize)
            .checked_mul(camera.height as usize)
            .filter(|&n| n <= sys::SOGMM_MAX_RENDER_PIXELS)
            .ok_or_else(|| {
                Error::new(
                    Status::Limit,
                    format!(
                        "render: {} x {} pixels exceed {}",
                        camera.width,
                        camera.height,
                        sys::SOGMM_MAX_RENDER_PIXELS
                    ),
                )
            })?;
        let (mut depth, mut gray, mut variance) = (vec![0.0f32; pixels], vec![0.0f32; pixels], vec![0.0f32; pixels]);
        let p = pose.map_or(std::ptr::null(), |p| p.as_ptr());
        let c = camera;
        with_progress(options, |o| {
            // SAFETY: width * height floats of room in each image; `p` is 16 doubles or NULL.
            check(unsafe {
                Self::RENDER(
                    self.raw_handle(),
                    c.width,
                    c.height,
                    c.fx,
                    c.fy,
                    c.cx,
                    c.cy,
                    p,
                    o,
                    depth.as_mut_ptr(),
                    gray.as_mut_ptr(),
                    variance.as_mut_ptr(),
                )
            })
        })?;
        Ok(Rendered {
            width: camera.width,
            height: camera.height,
            depth,
            gray,
            variance,
        })
    }

    /// Unsigned distance (metres) of points (`xyz`: rows of 3) to the surface
    /// and its gradient (rows of 3: unit vectors away from the nearest
    /// surface point); `options`: SOGMM_OPT_SURFACE_DISC_SIGMAS, threads.
    fn surface_distance(&self, xyz: &[f32], options: Option<&Options>) -> Result<(Vec<f64>, Vec<f64>)> {
        let n = rows(xyz, 3, "xyz")?;
        let (mut d, mut g) = (vec![0.0f64; n], vec![0.0f64; len_of(n, 3, "gradient")?]);
        with_progress(options, |o| {
            // SAFETY: n rows of 3 floats in, room for n and 3 n doubles.
            check(unsafe { Self::DISTANCE(self.raw_handle(), xyz.as_ptr(), n, o, d.as_mut_ptr(), g.as_mut_ptr()) })
        })?;
        Ok((d, g))
    }

    /// Probability that each ellipsoidal robot touches the surface: `centers`
    /// rows of 3, `shapes` a row-major symmetric positive definite 3 x 3 S per
    /// robot ({x : (x - c)^T S^-1 (x - c) <= 1}; a sphere of radius r is
    /// r^2 I); options as `surface_distance`.
    fn collision_probability(&self, centers: &[f64], shapes: &[f64], options: Option<&Options>) -> Result<Vec<f64>> {
        if centers.len() % 3 != 0 || shapes.len() != 3 * centers.len() {
            return Err(invalid(format!(
                "centers must hold rows of 3 and shapes 9 values per centre (got {} and {})",
                centers.len(),
                shapes.len()
            )));
        }
        let n = centers.len() / 3;
        let mut out = vec![0.0f64; n];
        with_progress(options, |o| {
            // SAFETY: n centres and n shapes checked above, n doubles of room.
            check(unsafe {
                Self::COLLISION(
                    self.raw_handle(),
                    centers.as_ptr(),
                    shapes.as_ptr(),
                    n,
                    o,
                    out.as_mut_ptr(),
                )
            })
        })?;
        Ok(out)
    }
}

impl sealed::Handle for crate::Model {
    type Raw = sys::sogmm_model;
    fn raw_handle(&self) -> *const sys::sogmm_model {
        self.raw()
    }
    const SCORE: ScoreFn<Self::Raw> = sys::sogmm_model_score_samples_f32;
    const REGRESS: RegressFn<Self::Raw> = sys::sogmm_model_regress_gray_f32;
    const SAMPLE: SampleFn<Self::Raw> = sys::sogmm_model_sample_f32;
    const RENDER: RenderFn<Self::Raw> = sys::sogmm_model_render_f32;
    const DISTANCE: DistanceFn<Self::Raw> = sys::sogmm_model_surface_distance_f32;
    const COLLISION: CollisionFn<Self::Raw> = sys::sogmm_model_collision_probability;
}

impl sealed::Handle for crate::Map {
    type Raw = sys::sogmm_map;
    fn raw_handle(&self) -> *const sys::sogmm_map {
        self.raw()
    }
    const SCORE: ScoreFn<Self::Raw> = sys::sogmm_map_score_samples_f32;
    const REGRESS: RegressFn<Self::Raw> = sys::sogmm_map_regress_gray_f32;
    const SAMPLE: SampleFn<Self::Raw> = sys::sogmm_map_sample_f32;
    const RENDER: RenderFn<Self::Raw> = sys::sogmm_map_render_f32;
    const DISTANCE: DistanceFn<Self::Raw> = sys::sogmm_map_surface_distance_f32;
    const COLLISION: CollisionFn<Self::Raw> = sys::sogmm_map_collision_probability;
}

impl Queryable for crate::Model {}
impl Queryable for crate::Map {}
