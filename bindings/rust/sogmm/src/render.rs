//! The camera and images of a render (`Queryable::render`;
//! sogmm_model_render_f32, sogmm_map_render_f32).
use sogmm_sys as sys;

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
