//! What a planner asks a map (issue 31; sogmm.h, `sogmm_map_occupancy_f32`,
//! `sogmm_*_surface_distance_f32`, `sogmm_*_collision_probability`): the
//! occupancy of world points from the map's own frames, the distance to the
//! surface with its gradient, and the collision probability of ellipsoidal
//! robots. Options (None = defaults): `SOGMM_OPT_OCCUPANCY_*`,
//! `SOGMM_OPT_SURFACE_DISC_SIGMAS`, `SOGMM_OPT_THREADS`.
use sogmm_sys as sys;

use crate::error::{check, Result};
use crate::model::{invalid, rows};
use crate::options::opt_ptr;
use crate::{Map, Model, Options};

/// The state of a point (`Map::occupancy`).
pub const OCCUPANCY_FREE: u8 = sys::SOGMM_OCCUPANCY_FREE;
pub const OCCUPANCY_OCCUPIED: u8 = sys::SOGMM_OCCUPANCY_OCCUPIED;
pub const OCCUPANCY_UNKNOWN: u8 = sys::SOGMM_OCCUPANCY_UNKNOWN;

/// Distances and gradients (rows of 3) of n points: `call(n, distance, gradient)`.
fn distance_with(xyz: &[f32], call: impl FnOnce(usize, *mut f64, *mut f64) -> i32) -> Result<(Vec<f64>, Vec<f64>)> {
    let n = rows(xyz, 3, "xyz")?;
    let (mut d, mut g) = (vec![0.0f64; n], vec![0.0f64; 3 * n]);
    check(call(n, d.as_mut_ptr(), g.as_mut_ptr()))?;
    Ok((d, g))
}

/// Collision probabilities of n robots: `call(n, out)` after the shape checks.
fn collision_with(centers: &[f64], shapes: &[f64], call: impl FnOnce(usize, *mut f64) -> i32) -> Result<Vec<f64>> {
    if centers.len() % 3 != 0 || shapes.len() != 3 * centers.len() {
        return Err(invalid(format!(
            "centers must hold rows of 3 and shapes 9 values per centre (got {} and {})",
            centers.len(),
            shapes.len()
        )));
    }
    let n = centers.len() / 3;
    let mut out = vec![0.0f64; n];
    check(call(n, out.as_mut_ptr()))?;
    Ok(out)
}

impl Map {
    /// P(occupied) in [0, 1] of world points (`xyz`: rows of 3) and their
    /// states (`OCCUPANCY_*`) from what the map's own frames see; 0.5 where
    /// no frame observed a point.
    pub fn occupancy(&self, xyz: &[f32], options: Option<&Options>) -> Result<(Vec<f64>, Vec<u8>)> {
        let n = rows(xyz, 3, "xyz")?;
        let (mut p, mut s) = (vec![0.0f64; n], vec![0u8; n]);
        // SAFETY: n rows of 3 floats in, n doubles and n bytes of room; options valid or NULL.
        check(unsafe {
            sys::sogmm_map_occupancy_f32(
                self.raw(),
                xyz.as_ptr(),
                n,
                opt_ptr(options),
                p.as_mut_ptr(),
                s.as_mut_ptr(),
            )
        })?;
        Ok((p, s))
    }

    /// Distance (metres) of world points to the map's surface and its
    /// gradient (rows of 3: unit vectors away from the nearest surface point).
    pub fn surface_distance(&self, xyz: &[f32], options: Option<&Options>) -> Result<(Vec<f64>, Vec<f64>)> {
        // SAFETY: distance_with passes n rows and room for n and 3 n doubles.
        distance_with(xyz, |n, d, g| unsafe {
            sys::sogmm_map_surface_distance_f32(self.raw(), xyz.as_ptr(), n, opt_ptr(options), d, g)
        })
    }

    /// Probability that each ellipsoidal robot touches the map's surface:
    /// `centers` rows of 3, `shapes` a row-major symmetric positive definite
    /// 3 x 3 S per robot ({x : (x - c)^T S^-1 (x - c) <= 1}).
    pub fn collision_probability(
        &self,
        centers: &[f64],
        shapes: &[f64],
        options: Option<&Options>,
    ) -> Result<Vec<f64>> {
        // SAFETY: collision_with checked n centres and n shapes and gives n doubles of room.
        collision_with(centers, shapes, |n, out| unsafe {
            sys::sogmm_map_collision_probability(
                self.raw(),
                centers.as_ptr(),
                shapes.as_ptr(),
                n,
                opt_ptr(options),
                out,
            )
        })
    }
}

impl Model {
    /// `Map::surface_distance` for a model (its frame).
    pub fn surface_distance(&self, xyz: &[f32], options: Option<&Options>) -> Result<(Vec<f64>, Vec<f64>)> {
        // SAFETY: as Map::surface_distance.
        distance_with(xyz, |n, d, g| unsafe {
            sys::sogmm_model_surface_distance_f32(self.raw(), xyz.as_ptr(), n, opt_ptr(options), d, g)
        })
    }

    /// `Map::collision_probability` for a model (its frame).
    pub fn collision_probability(
        &self,
        centers: &[f64],
        shapes: &[f64],
        options: Option<&Options>,
    ) -> Result<Vec<f64>> {
        // SAFETY: as Map::collision_probability.
        collision_with(centers, shapes, |n, out| unsafe {
            sys::sogmm_model_collision_probability(
                self.raw(),
                centers.as_ptr(),
                shapes.as_ptr(),
                n,
                opt_ptr(options),
                out,
            )
        })
    }
}
