//! Rigid registration of a point cloud or of a model to a model (issue 32;
//! sogmm.h, `sogmm_register_points_f32`, `sogmm_register_model`). Options (None = defaults):
//! `SOGMM_OPT_REGISTRATION_*`, `SOGMM_OPT_THREADS`; progress
//! `Stage::Registration`.
use sogmm_sys as sys;

use crate::error::{check, Result};
use crate::map::Pose;
use crate::model::rows;
use crate::progress::with_progress;
use crate::{Model, Options};

/// How a registration ended (`SOGMM_REGISTRATION_*`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RegistrationStatus {
    /// The pose is an estimate.
    Converged,
    /// The iterations ran out or no point came near the target.
    NotConverged,
    /// Converged, but too few points are explained by the target.
    LowFitness,
    /// Converged, but some directions are unobservable (`unobservable`).
    Degenerate,
}

/// The figures of one registration (sogmm_registration_info).
#[derive(Debug, Clone)]
pub struct Registration {
    /// Row-major 4 x 4 pose taking source points into the target frame.
    pub pose: Pose,
    pub status: RegistrationStatus,
    pub iterations: i32,
    /// Mean log-likelihood per source point at the pose.
    pub log_likelihood: f64,
    /// Fraction of points the mixture explains better than the outlier term.
    pub inlier_ratio: f64,
    /// Mahalanobis RMS of the inliers per dimension (about 1 when they fit).
    pub rmse: f64,
    /// Row-major 6 x 6 observed information over (rotation, translation).
    pub information: [f64; 36],
    /// Number of unobservable directions.
    pub unobservable: i32,
    /// Smallest / largest eigenvalue of the scaled information.
    pub eigen_ratio: f64,
}

impl Model {
    /// The rigid pose that best explains `points` (rows of x, y, z, gray in
    /// their own frame) under this model, from `init` (None = identity).
    /// Check `status`: the pose is an estimate only when `Converged`. The
    /// options' progress closure gets `Stage::Registration` reports.
    pub fn register_points(
        &self,
        points: &[f32],
        init: Option<&Pose>,
        options: Option<&Options>,
    ) -> Result<Registration> {
        let n = rows(points, 4, "points")?;
        let mut pose: Pose = [0.0; 16];
        let mut info = empty_info();
        let init_ptr = init.map_or(std::ptr::null(), |p| p.as_ptr());
        with_progress(options, |o| {
            // SAFETY: n rows of 4 floats, init 16 doubles or NULL, room for 16 doubles and the sized struct.
            check(unsafe {
                sys::sogmm_register_points_f32(
                    self.raw(),
                    points.as_ptr(),
                    n,
                    init_ptr,
                    o,
                    pose.as_mut_ptr(),
                    &mut info,
                )
            })
        })?;
        Ok(registration_of(pose, &info))
    }

    /// The rigid pose that best explains the model `source` (e.g. a frame's
    /// own fit, in its own frame) under this model: distribution to
    /// distribution (D2D), each source component scored by the closed-form
    /// overlap of its Gaussian with this model's and counted as the points
    /// it stands for; figures per point stood for. Otherwise as
    /// `register_points`. Errors: a source standing for fewer than
    /// `SOGMM_OPT_REGISTRATION_MIN_POINTS` points is `InvalidData`.
    pub fn register_model(
        &self,
        source: &Model,
        init: Option<&Pose>,
        options: Option<&Options>,
    ) -> Result<Registration> {
        let mut pose: Pose = [0.0; 16];
        let mut info = empty_info();
        let init_ptr = init.map_or(std::ptr::null(), |p| p.as_ptr());
        with_progress(options, |o| {
            // SAFETY: two live model handles, init 16 doubles or NULL, room for 16 doubles and the sized struct.
            check(unsafe {
                sys::sogmm_register_model(self.raw(), source.raw(), init_ptr, o, pose.as_mut_ptr(), &mut info)
            })
        })?;
        Ok(registration_of(pose, &info))
    }
}

/// A `sogmm_registration_info` sized for this binding, to be filled by a call.
pub(crate) fn empty_info() -> sys::sogmm_registration_info {
    sys::sogmm_registration_info {
        struct_size: std::mem::size_of::<sys::sogmm_registration_info>(),
        status: 0,
        iterations: 0,
        log_likelihood: 0.0,
        inlier_ratio: 0.0,
        rmse: 0.0,
        information: [0.0; 36],
        unobservable: 0,
        eigen_ratio: 0.0,
    }
}

/// The figures a call wrote into `info`, with its pose.
pub(crate) fn registration_of(pose: Pose, info: &sys::sogmm_registration_info) -> Registration {
    let status = match info.status {
        sys::SOGMM_REGISTRATION_CONVERGED => RegistrationStatus::Converged,
        sys::SOGMM_REGISTRATION_LOW_FITNESS => RegistrationStatus::LowFitness,
        sys::SOGMM_REGISTRATION_DEGENERATE => RegistrationStatus::Degenerate,
        _ => RegistrationStatus::NotConverged,
    };
    Registration {
        pose,
        status,
        iterations: info.iterations,
        log_likelihood: info.log_likelihood,
        inlier_ratio: info.inlier_ratio,
        rmse: info.rmse,
        information: info.information,
        unobservable: info.unobservable,
        eigen_ratio: info.eigen_ratio,
    }
}
