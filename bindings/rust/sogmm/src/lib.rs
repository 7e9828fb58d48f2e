//! Safe Rust API of libsogmm, the C library fitting Self-Organizing Gaussian
//! Mixture Models to RGB-D frames (4-D: x, y, z, gray).
//!
//! ```no_run
//! let points: Vec<f32> = vec![/* n rows of x, y, z, gray */];
//! let opts = sogmm::Options::builder().bandwidth(0.05).seed(1).build()?;
//! let model = sogmm::Model::fit(&points, Some(&opts))?;
//! use sogmm::Queryable; // score, regress, sample, render: models and maps
//! let samples = model.sample(1000, 42, 4, None)?;
//! model.save("frame.sogmm", None)?;
//! # Ok::<(), sogmm::Error>(())
//! ```
//!
//! Linking: the `sogmm-sys` crate links libsogmm dynamically, or statically
//! with the `static` feature, which a program needs to run without finding
//! libsogmm.so at load time (see its build.rs and bindings/rust/README.md).
//! The first handle created checks that the library's ABI version is the one
//! these bindings were written for.
//!
//! Threads: `Model`, `Map` and `Options` are `Send + Sync`. The C API lets any
//! number of threads call functions taking a `const` handle at once; those
//! are the `&self` methods here. Mutations (`set_pose`, `set_value`, ...)
//! take `&mut self`, so the borrow checker gives them the exclusive use the C
//! API requires. The thread-local error message is read on the calling
//! thread right after each call.
#[macro_use]
mod handle;

pub mod error;
pub mod frames;
pub mod map;
pub mod metrics;
pub mod model;
pub mod options;
pub mod progress;
pub mod queryable;
pub mod registration;
pub mod render;
pub mod surface;

use std::ffi::CStr;
use std::sync::OnceLock;

pub use error::{Error, Result, Status};
pub use frames::{ColorPixels, ImageFrame, Trajectory};
pub use map::{Map, MapFrameStats, MapMergeStats, MapStats, Pose};
pub use metrics::{psnr_images, Psnr};
pub use model::{Color, Frame, Model};
pub use options::{
    option_info, option_keys, FusionMethod, ModeCounter, OptionInfo, OptionValues, Options, OptionsBuilder,
};
pub use progress::{Progress, Stage};
pub use queryable::Queryable;
pub use registration::{Registration, RegistrationStatus};
pub use render::{Camera, Rendered};
pub use sogmm_sys as sys;
pub use surface::{OCCUPANCY_FREE, OCCUPANCY_OCCUPIED, OCCUPANCY_UNKNOWN};

/// "MAJOR.MINOR.PATCH" of the loaded library.
pub fn version() -> &'static str {
    // SAFETY: static, never-NULL, ASCII.
    unsafe { CStr::from_ptr(sys::sogmm_version_string()) }
        .to_str()
        .unwrap_or("?")
}

/// Checks once per process that the loaded libsogmm has the ABI version of
/// sogmm-sys (git2-rs's `init()` idea); every constructor calls it.
pub(crate) fn ensure_abi() -> Result<()> {
    static ABI: OnceLock<u32> = OnceLock::new();
    // SAFETY: never fails, no arguments.
    let loaded = *ABI.get_or_init(|| unsafe { sys::sogmm_abi_version() });
    if loaded == sys::SOGMM_ABI_VERSION {
        Ok(())
    } else {
        Err(Error::new(
            Status::Internal,
            format!(
                "libsogmm has ABI version {loaded}, these bindings need {}",
                sys::SOGMM_ABI_VERSION
            ),
        ))
    }
}
