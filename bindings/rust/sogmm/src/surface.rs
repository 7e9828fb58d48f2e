//! What a planner asks a map (issue 31; sogmm.h, `sogmm_map_occupancy_f32`):
//! the occupancy of world points from the map's own frames, its only query
//! that a model lacks. The distance to the surface and the collision
//! probability of ellipsoidal robots are `Queryable` (models and maps).
//! Options (None = defaults): `SOGMM_OPT_OCCUPANCY_*`,
//! `SOGMM_OPT_SURFACE_DISC_SIGMAS`, `SOGMM_OPT_THREADS`.
use sogmm_sys as sys;

use crate::error::{check, Result};
use crate::model::rows;
use crate::progress::with_progress;
use crate::{Map, Options};

/// The state of a point (`Map::occupancy`).
pub const OCCUPANCY_FREE: u8 = sys::SOGMM_OCCUPANCY_FREE;
pub const OCCUPANCY_OCCUPIED: u8 = sys::SOGMM_OCCUPANCY_OCCUPIED;
pub const OCCUPANCY_UNKNOWN: u8 = sys::SOGMM_OCCUPANCY_UNKNOWN;

impl Map {
    /// P(occupied) in [0, 1] of world points (`xyz`: rows of 3) and their
    /// states (`OCCUPANCY_*`) from what the map's own frames see; 0.5 where
    /// no frame observed a point.
    pub fn occupancy(&self, xyz: &[f32], options: Option<&Options>) -> Result<(Vec<f64>, Vec<u8>)> {
        let n = rows(xyz, 3, "xyz")?;
        let (mut p, mut s) = (vec![0.0f64; n], vec![0u8; n]);
        with_progress(options, |o| {
            // SAFETY: n rows of 3 floats in, n doubles and n bytes of room; `o` valid or NULL.
            check(unsafe {
                sys::sogmm_map_occupancy_f32(self.raw(), xyz.as_ptr(), n, o, p.as_mut_ptr(), s.as_mut_ptr())
            })
        })?;
        Ok((p, s))
    }
}
