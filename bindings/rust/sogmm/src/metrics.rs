//! Image metrics: the PSNR of a gray image against the frame's
//! (sogmm_psnr_images_f32).
use sogmm_sys as sys;

use crate::error::{check, Result};
use crate::model::invalid;

/// Both figures of `psnr_images`, in dB (+inf for identical images).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Psnr {
    /// 10 log10(data_range^2 / MSE) over the pixels valid in the truth (>= 0).
    pub psnr: f64,
    /// The authors' evaluation: range 2, every pixel counted (empty ones as perfect).
    pub psnr_paper: f64,
}

/// PSNR of the gray image `estimate` against `truth` (the same number of
/// pixels, -1 marking an empty one, as `sogmm eval` draws a rendering of the
/// model against the frame's gray). `data_range` is the peak: 1 for gray in
/// [0, 1], any other peak for other data, or 0 for the actual range of the
/// valid truth pixels (max - min).
///
/// Errors: lengths that differ -> `Status::InvalidArg`; `data_range`
/// negative or not finite -> `Status::InvalidArg` (from the library, naming
/// it); NaN/Inf pixels, no valid truth pixel, or range 0 on a constant truth
/// not matched exactly -> `Status::InvalidData`.
pub fn psnr_images(truth: &[f32], estimate: &[f32], data_range: f64) -> Result<Psnr> {
    crate::ensure_abi()?;
    if truth.len() != estimate.len() {
        return Err(invalid(format!(
            "truth has {} pixels and estimate {}: they must be the same size",
            truth.len(),
            estimate.len()
        )));
    }
    let mut r = Psnr {
        psnr: 0.0,
        psnr_paper: 0.0,
    };
    // SAFETY: both slices hold truth.len() floats (checked above); the two
    // outputs are valid f64 places. C keeps nothing after the call.
    check(unsafe {
        sys::sogmm_psnr_images_f32(
            truth.as_ptr(),
            estimate.as_ptr(),
            truth.len(),
            data_range,
            &mut r.psnr,
            &mut r.psnr_paper,
        )
    })?;
    Ok(r)
}
