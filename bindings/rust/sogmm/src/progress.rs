//! Progress reports and cancellation of long calls (sogmm_progress_fn).
//!
//! The closure is called only on the thread that made the call, during the
//! call (the C API's guarantee), so it needs neither `Send` nor `'static`.
//! `ControlFlow::Break(())` cancels; a panic cancels too and is resumed on the
//! caller's side once the library has returned (a panic must never unwind
//! through C++ frames).
use std::any::Any;
use std::ffi::c_void;
use std::ops::ControlFlow;
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::ptr;

use sogmm_sys as sys;

use crate::error::{check, Result};
use crate::options::{opt_ptr, Options};

/// What a long call is doing (SOGMM_STAGE_*). New stages may be added by the
/// library; they arrive as `Unknown`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Stage {
    /// Mean shift; step/total: seeds (flat) or iterations (blurring).
    ModeCount,
    /// k-means++; step/total: components seeded / K.
    Seeding,
    /// EM; step: iterations done (0 at the start), total: max_iter.
    Em,
    /// With n_init > 1: run `step` (from 1) of `total` starts.
    Run,
    /// Sampling; step/total: points drawn / requested.
    Sampling,
    /// Scoring points on a map; step/total: points scored / requested.
    Scoring,
    /// Gray regression on a map; step/total: points done / requested.
    Regression,
    /// Rendering an image; step/total: rows done / height.
    Rendering,
    /// Registration; step/total: iterations done / levels x max_iter.
    Registration,
    Unknown(i32),
}

impl Stage {
    pub fn from_code(code: i32) -> Stage {
        match code {
            sys::SOGMM_STAGE_MODE_COUNT => Stage::ModeCount,
            sys::SOGMM_STAGE_SEEDING => Stage::Seeding,
            sys::SOGMM_STAGE_EM => Stage::Em,
            sys::SOGMM_STAGE_RUN => Stage::Run,
            sys::SOGMM_STAGE_SAMPLING => Stage::Sampling,
            sys::SOGMM_STAGE_SCORING => Stage::Scoring,
            sys::SOGMM_STAGE_REGRESSION => Stage::Regression,
            sys::SOGMM_STAGE_RENDERING => Stage::Rendering,
            sys::SOGMM_STAGE_REGISTRATION => Stage::Registration,
            other => Stage::Unknown(other),
        }
    }
}

/// One report: `total` is 0 when unknown; `log_likelihood` is the mean per
/// point of the last EM iteration (Em) or the best run so far (Run), else 0.
/// Reports come at each stage start, after each EM iteration and about every
/// 20 ms during long loops; steps never decrease within a stage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Progress {
    pub stage: Stage,
    pub step: u64,
    pub total: u64,
    pub log_likelihood: f64,
}

struct Ctx<'a> {
    f: &'a mut dyn FnMut(Progress) -> ControlFlow<()>,
    panic: Option<Box<dyn Any + Send>>,
}

unsafe extern "C" fn trampoline(stage: i32, step: u64, total: u64, log_likelihood: f64, user_data: *mut c_void) -> i32 {
    // SAFETY: user_data is the &mut Ctx that with_progress passed for this
    // call; the library calls back only on this thread, one call at a time.
    let cx = unsafe { &mut *(user_data as *mut Ctx<'_>) };
    if cx.panic.is_some() {
        return 1; // stop after a panic (git2-rs)
    }
    let report = Progress {
        stage: Stage::from_code(stage),
        step,
        total,
        log_likelihood,
    };
    match catch_unwind(AssertUnwindSafe(|| (cx.f)(report))) {
        Ok(ControlFlow::Continue(())) => 0,
        Ok(ControlFlow::Break(())) => 1,
        Err(payload) => {
            cx.panic = Some(payload);
            1
        }
    }
}

/// Runs `call` with a private clone of `options` (or of the defaults) that
/// carries the trampoline for `f`; resumes a panic of `f` afterwards.
pub(crate) fn with_progress<T>(
    options: Option<&Options>,
    mut f: impl FnMut(Progress) -> ControlFlow<()>,
    call: impl FnOnce(*const sys::sogmm_options) -> Result<T>,
) -> Result<T> {
    let mut raw = ptr::null_mut();
    // SAFETY: valid out-pointer; opt_ptr is a valid handle or NULL.
    check(unsafe {
        if options.is_some() {
            sys::sogmm_options_clone(&mut raw, opt_ptr(options))
        } else {
            sys::sogmm_options_create(&mut raw)
        }
    })?;
    let private = OwnedRaw(raw);
    let mut cx = Ctx { f: &mut f, panic: None };
    // SAFETY: `private` is ours; `cx` outlives the call below, the only one
    // that uses these options.
    check(unsafe {
        sys::sogmm_options_set_progress(private.0, Some(trampoline), &mut cx as *mut Ctx<'_> as *mut c_void)
    })?;
    let result = call(private.0);
    drop(private);
    if let Some(payload) = cx.panic.take() {
        resume_unwind(payload);
    }
    result
}

/// Runs `call` with the trampoline for `f` installed on `map`
/// (sogmm_map_set_progress, for its inserts and flushes) and removed again
/// on every path; resumes a panic of `f` afterwards. The caller holds the map
/// exclusively (`&mut`), so no other call sees the callback.
pub(crate) fn with_map_progress<T>(
    map: *mut sys::sogmm_map,
    mut f: impl FnMut(Progress) -> ControlFlow<()>,
    call: impl FnOnce() -> Result<T>,
) -> Result<T> {
    let mut cx = Ctx { f: &mut f, panic: None };
    // SAFETY: `map` is a valid handle used only by this thread for the call;
    // `cx` outlives it, and the callback is removed before `cx` goes away.
    check(unsafe { sys::sogmm_map_set_progress(map, Some(trampoline), &mut cx as *mut Ctx<'_> as *mut c_void) })?;
    let result = call();
    // SAFETY: as above; removing a callback cannot fail for a valid handle.
    let removed = check(unsafe { sys::sogmm_map_set_progress(map, None, ptr::null_mut()) });
    if let Some(payload) = cx.panic.take() {
        resume_unwind(payload);
    }
    removed?;
    result
}

/// Frees the private options on every path.
struct OwnedRaw(*mut sys::sogmm_options);
impl Drop for OwnedRaw {
    fn drop(&mut self) {
        // SAFETY: created above, freed once.
        unsafe { sys::sogmm_options_free(self.0) }
    }
}
