//! Progress reports and cancellation of long calls (sogmm_progress_fn).
//!
//! The closure rides on the options of a call (`OptionsBuilder::on_progress`,
//! `Options::set_progress`; a map keeps the one of the options it was created
//! with for its inserts and flushes), as git2-rs's callbacks ride on its
//! `FetchOptions`. It is called only on the thread that made the call, during
//! the call (the C API's guarantee); it is `Send + 'static` because options
//! are shared between threads (state it fills goes behind an `Arc`).
//! `ControlFlow::Break(())` cancels: the call returns `Err` with
//! `Status::Cancelled`. A panic cancels too and is resumed on the caller's
//! side once the library has returned (a panic must never unwind through C++
//! frames). Progress never changes a result.
use std::any::Any;
use std::ffi::c_void;
use std::ops::ControlFlow;
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::ptr;
use std::sync::{Arc, Mutex, PoisonError};

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

/// The progress closure of an `Options` value, shared by its clones and by
/// maps created with it. Calls on several threads with the same options take
/// turns per report.
#[derive(Clone)]
pub(crate) struct ProgressHook(Arc<Mutex<ProgressFn>>);

type ProgressFn = Box<dyn FnMut(Progress) -> ControlFlow<()> + Send>;

impl ProgressHook {
    pub(crate) fn new(f: impl FnMut(Progress) -> ControlFlow<()> + Send + 'static) -> ProgressHook {
        ProgressHook(Arc::new(Mutex::new(Box::new(f))))
    }
}

impl std::fmt::Debug for ProgressHook {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ProgressHook(..)")
    }
}

struct Ctx<'a> {
    hook: &'a ProgressHook,
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
    // A panic of an earlier report (resumed then) leaves the lock poisoned;
    // the closure itself is still whole.
    let mut f = cx.hook.0.lock().unwrap_or_else(PoisonError::into_inner);
    match catch_unwind(AssertUnwindSafe(|| (*f)(report))) {
        Ok(ControlFlow::Continue(())) => 0,
        Ok(ControlFlow::Break(())) => 1,
        Err(payload) => {
            cx.panic = Some(payload);
            1
        }
    }
}

/// Runs `call` with the C pointer of `options` or, when they carry a progress
/// closure, of a private clone that reports to it; resumes a panic of the
/// closure afterwards.
pub(crate) fn with_progress<T>(
    options: Option<&Options>,
    call: impl FnOnce(*const sys::sogmm_options) -> Result<T>,
) -> Result<T> {
    let Some((options, hook)) = options.and_then(|o| o.progress().map(|h| (o, h))) else {
        return call(opt_ptr(options));
    };
    let mut raw = ptr::null_mut();
    // SAFETY: valid out-pointer and handle.
    check(unsafe { sys::sogmm_options_clone(&mut raw, options.as_ptr()) })?;
    let private = OwnedRaw(raw);
    let mut cx = Ctx { hook, panic: None };
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

/// Runs `call` with the trampoline for `hook` (if any) installed on `map`
/// (sogmm_map_set_progress, for its inserts and flushes) and removed again
/// on every path; resumes a panic of the closure afterwards. The caller holds
/// the map exclusively (`&mut`), so no other call sees the callback.
pub(crate) fn with_map_progress<T>(
    map: *mut sys::sogmm_map,
    hook: Option<&ProgressHook>,
    call: impl FnOnce() -> Result<T>,
) -> Result<T> {
    let Some(hook) = hook else {
        return call();
    };
    let mut cx = Ctx { hook, panic: None };
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
