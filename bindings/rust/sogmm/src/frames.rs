//! Frames and trajectories read by libsogmm itself: the depth PNG and the
//! colour PNG/JPEG are decoded by the C library (libpng, libjpeg-turbo with
//! fixed settings), so Rust gets the pixels C, Python and Go get from the
//! same files, and the same model from them. Trajectories are the library's
//! Redwood `.log` reader and writer.
use std::path::Path;
use std::ptr;

use sogmm_sys as sys;

use crate::error::{check, Result};
use crate::map::Pose;
use crate::model::{c_path, Color, Frame};

/// Colour pixels of an [`ImageFrame`], row-major.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ColorPixels {
    /// width * height bytes, gray 0..255.
    Gray8(Vec<u8>),
    /// width * height * 3 bytes, interleaved R, G, B.
    Rgb8(Vec<u8>),
}

/// An RGB-D frame decoded from image files by the library.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ImageFrame {
    pub width: u32,
    pub height: u32,
    /// width * height raw depth values, row-major.
    pub depth: Vec<u16>,
    /// The colour image; a frame read without one holds gray 0 (what
    /// `sogmm_fit_frame` fits then).
    pub color: ColorPixels,
}

/// Frees the C frame on every way out.
pub(crate) struct Handle(pub(crate) *mut sys::sogmm_frame);
impl Drop for Handle {
    fn drop(&mut self) {
        // SAFETY: created by sogmm_frame_read/decode/from_arrays (or NULL), freed once.
        unsafe { sys::sogmm_frame_free(self.0) }
    }
}

impl ImageFrame {
    /// Reads a depth PNG (one channel, 16-bit; 8-bit widened) and a colour
    /// PNG or JPEG (None = no colour image). Errors (status and message
    /// naming the file): Io (cannot read), Format (corrupt, truncated),
    /// InvalidData (channels, bit depth, sizes differ), Limit (> 2^26 pixels).
    pub fn read(depth_path: impl AsRef<Path>, color_path: Option<&Path>) -> Result<ImageFrame> {
        crate::ensure_abi()?;
        let depth = c_path(depth_path.as_ref())?;
        let color = color_path.map(c_path).transpose()?;
        let mut out = ptr::null_mut();
        // SAFETY: NUL-terminated paths, valid for the call; `out` receives a handle.
        check(unsafe {
            sys::sogmm_frame_read(
                &mut out,
                depth.as_ptr(),
                color.as_ref().map_or(ptr::null(), |c| c.as_ptr()),
            )
        })?;
        Ok(Self::copy(&Handle(out)))
    }

    /// As [`ImageFrame::read`] from the files' bytes.
    pub fn decode(depth: &[u8], color: Option<&[u8]>) -> Result<ImageFrame> {
        crate::ensure_abi()?;
        let mut out = ptr::null_mut();
        let (c, n) = color.map_or((ptr::null(), 0), |c| (c.as_ptr().cast(), c.len()));
        // SAFETY: the slices are valid for the call and only read.
        check(unsafe { sys::sogmm_frame_decode(&mut out, depth.as_ptr().cast(), depth.len(), c, n) })?;
        Ok(Self::copy(&Handle(out)))
    }

    fn copy(h: &Handle) -> ImageFrame {
        // SAFETY: a valid frame; the pixel pointers hold width * height
        // (* 3 for RGB) values owned by the frame, copied before it is freed.
        unsafe {
            let (width, height) = (sys::sogmm_frame_width(h.0), sys::sogmm_frame_height(h.0));
            let n = width as usize * height as usize;
            let depth = std::slice::from_raw_parts(sys::sogmm_frame_depth(h.0), n).to_vec();
            let color = match sys::sogmm_frame_color_format(h.0) {
                sys::SOGMM_COLOR_RGB8 => {
                    ColorPixels::Rgb8(std::slice::from_raw_parts(sys::sogmm_frame_color(h.0), 3 * n).to_vec())
                }
                sys::SOGMM_COLOR_GRAY8 => {
                    ColorPixels::Gray8(std::slice::from_raw_parts(sys::sogmm_frame_color(h.0), n).to_vec())
                }
                _ => ColorPixels::Gray8(vec![0; n]),
            };
            ImageFrame {
                width,
                height,
                depth,
                color,
            }
        }
    }

    /// The frame with full-size pinhole intrinsics, for `Model::fit_rgbd`
    /// and `Map::insert_rgbd`.
    pub fn frame(&self, fx: f64, fy: f64, cx: f64, cy: f64) -> Frame<'_> {
        let color = match &self.color {
            ColorPixels::Gray8(c) => Color::Gray8(c),
            ColorPixels::Rgb8(c) => Color::Rgb8(c),
        };
        Frame {
            depth: &self.depth,
            color,
            width: self.width,
            height: self.height,
            fx,
            fy,
            cx,
            cy,
        }
    }
}

/// A Redwood `.log` trajectory read by the library.
#[derive(Clone, Debug, PartialEq)]
pub struct Trajectory {
    /// ids[k]: the first number of block k's header, the frame of poses[k].
    pub ids: Vec<i64>,
    /// Camera-to-world rigid transforms, row-major, in file order.
    pub poses: Vec<Pose>,
}

impl Trajectory {
    /// Reads a `.log` file. Errors: Io (cannot read, not a regular file),
    /// InvalidData naming the file and line (malformed, a pose not rigid).
    pub fn read(path: impl AsRef<Path>) -> Result<Trajectory> {
        crate::ensure_abi()?;
        let p = c_path(path.as_ref())?;
        let mut out = ptr::null_mut();
        // SAFETY: NUL-terminated path; `out` receives a handle.
        check(unsafe { sys::sogmm_trajectory_read(&mut out, p.as_ptr()) })?;
        // SAFETY: a valid trajectory of n blocks: n ids and 16 n poses,
        // copied before it is freed.
        unsafe {
            let n = sys::sogmm_trajectory_size(out);
            let ids = std::slice::from_raw_parts(sys::sogmm_trajectory_ids(out), n).to_vec();
            let flat = std::slice::from_raw_parts(sys::sogmm_trajectory_poses(out), 16 * n);
            let poses = flat
                .chunks_exact(16)
                .map(|c| c.try_into().expect("16 values"))
                .collect();
            sys::sogmm_trajectory_free(out);
            Ok(Trajectory { ids, poses })
        }
    }

    /// Writes `poses` as a `.log` file (block k with the header "k k+1 n"),
    /// atomically; read back bitwise. Errors: InvalidArgument (no pose, a
    /// pose not rigid), Io.
    pub fn write(path: impl AsRef<Path>, poses: &[Pose]) -> Result<()> {
        crate::ensure_abi()?;
        let p = c_path(path.as_ref())?;
        // SAFETY: `poses` holds 16 * len contiguous doubles, only read.
        check(unsafe { sys::sogmm_trajectory_write(p.as_ptr(), poses.as_ptr().cast(), poses.len()) })
    }
}
