//! Rendering a model or map from a pinhole camera (`Model::render`,
//! `Map::render`; sogmm_model_render_f32, sogmm_map_render_f32).
use sogmm_sys as sys;

use crate::error::{check, Error, Result, Status};
use crate::map::Pose;

/// Pinhole intrinsics of the rendered image: pixel (u, v) looks along
/// ((u - cx) / fx, (v - cy) / fy, 1) in the camera's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub width: u32,
    pub height: u32,
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
}

/// Rendered images, row-major `width` x `height`: the first surface's depth
/// (camera z, metres), the gray regressed there and its variance; NaN where
/// the model shows nothing.
#[derive(Clone, Debug, PartialEq)]
pub struct Rendered {
    pub width: u32,
    pub height: u32,
    pub depth: Vec<f32>,
    pub gray: Vec<f32>,
    pub variance: Vec<f32>,
}

/// sogmm_model_render_f32 or sogmm_map_render_f32, over the handle type `H`.
pub(crate) type RenderFn<H> = unsafe extern "C" fn(
    *const H,
    u32,
    u32,
    f64,
    f64,
    f64,
    f64,
    *const f64,
    *const sys::sogmm_options,
    *mut f32,
    *mut f32,
    *mut f32,
) -> sys::sogmm_status;

/// Allocates the three images (after the pixel limit, so that no huge
/// buffer is allocated for a call that must fail) and renders `handle` with
/// `render` into them. `handle` must be a valid handle of its type and `o`
/// valid options or NULL.
pub(crate) fn render_into<H>(
    render: RenderFn<H>,
    handle: *const H,
    camera: &Camera,
    pose: Option<&Pose>,
    o: *const sys::sogmm_options,
) -> Result<Rendered> {
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
    let mut depth = vec![0.0f32; pixels];
    let mut gray = vec![0.0f32; pixels];
    let mut variance = vec![0.0f32; pixels];
    let p = pose.map_or(std::ptr::null(), |p| p.as_ptr());
    let c = camera;
    // SAFETY: width * height floats of room in each image; `p` is 16 doubles
    // or NULL; `handle` and `o` as the caller promises.
    check(unsafe {
        render(
            handle,
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
    })?;
    Ok(Rendered {
        width: camera.width,
        height: camera.height,
        depth,
        gray,
        variance,
    })
}
