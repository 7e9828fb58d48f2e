//! Progress reports and cancellation through the closure API.
use std::ops::ControlFlow;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::{Arc, Mutex};

use sogmm::{Model, Options, Progress, Queryable, Stage, Status};

/// Deterministic cloud: n points uniform in a unit cube (fixed LCG), so EM
/// with several components runs many iterations.
fn cube(n: usize) -> Vec<f32> {
    let mut s: u64 = 99;
    (0..4 * n)
        .map(|_| {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 40) as f32 / (1u64 << 24) as f32
        })
        .collect()
}

fn builder() -> sogmm::OptionsBuilder {
    Options::builder()
        .n_components(8)
        .tol(1e-12)
        .max_iter(25)
        .seed(5)
        .threads(2)
}

fn opts() -> Options {
    builder().build().unwrap()
}

/// `opts()` with `f` as the progress closure.
fn reporting(f: impl FnMut(Progress) -> ControlFlow<()> + Send + 'static) -> Options {
    builder().on_progress(f).build().unwrap()
}

/// A progress closure that records every report, and the record.
fn recorder() -> (
    impl FnMut(Progress) -> ControlFlow<()> + Send + 'static,
    Arc<Mutex<Vec<Progress>>>,
) {
    let seen = Arc::new(Mutex::new(Vec::new()));
    let sink = Arc::clone(&seen);
    (
        move |p| {
            sink.lock().unwrap().push(p);
            ControlFlow::Continue(())
        },
        seen,
    )
}

#[test]
fn reports_em_iterations_in_order_and_change_nothing() {
    let pts = cube(3000);
    let (f, seen) = recorder();
    let m = Model::fit(&pts, Some(&reporting(f))).unwrap();
    let seen = seen.lock().unwrap().clone();
    let plain = Model::fit(&pts, Some(&opts())).unwrap();
    assert_eq!(m.means().unwrap(), plain.means().unwrap(), "progress changed the model");
    assert_eq!(m.covariances().unwrap(), plain.covariances().unwrap());
    let iterations = m.info_i64(sogmm::sys::SOGMM_INFO_FIT_ITERATIONS).unwrap().unwrap() as u64;
    // Stages in order: seeding then EM (fixed K: no mode count).
    assert_eq!(seen.first().unwrap().stage, Stage::Seeding);
    assert_eq!(seen.last().unwrap().stage, Stage::Em);
    let em: Vec<&Progress> = seen.iter().filter(|p| p.stage == Stage::Em).collect();
    assert!(
        em.windows(2).all(|w| w[0].step <= w[1].step),
        "EM steps decrease: {em:?}"
    );
    assert!(em.iter().all(|p| p.total == 25));
    let mut steps: Vec<u64> = em.iter().map(|p| p.step).collect();
    steps.dedup();
    assert_eq!(
        steps,
        (0..=iterations).collect::<Vec<_>>(),
        "every iteration reported once"
    );
    let last = em.last().unwrap().log_likelihood;
    assert_eq!(
        last,
        m.info_f64(sogmm::sys::SOGMM_INFO_FIT_LOG_LIKELIHOOD).unwrap().unwrap()
    );
}

#[test]
fn break_cancels_with_no_model() {
    let pts = cube(3000);
    let calls = Arc::new(Mutex::new(0));
    let counter = Arc::clone(&calls);
    let r = Model::fit(
        &pts,
        Some(&reporting(move |p| {
            *counter.lock().unwrap() += 1;
            if p.stage == Stage::Em && p.step == 2 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })),
    );
    let e = r.unwrap_err();
    assert_eq!(e.status(), Status::Cancelled);
    assert_eq!(e.code(), sogmm::sys::SOGMM_E_CANCELLED);
    assert!(e.message().contains("EM iteration 2"), "{}", e.message());
    let after = *calls.lock().unwrap();
    assert!(after >= 3);
    // Other options are untouched: a later fit with them has no callback.
    assert!(Model::fit(&pts, Some(&opts())).is_ok());
}

#[test]
fn a_panic_cancels_then_resumes_here() {
    let pts = cube(3000);
    let after_panic = Arc::new(Mutex::new(0));
    let counter = Arc::clone(&after_panic);
    let o = reporting(move |p| {
        if p.stage == Stage::Em && p.step >= 1 {
            *counter.lock().unwrap_or_else(|e| e.into_inner()) += 1;
            panic!("boom");
        }
        ControlFlow::Continue(())
    });
    let r = catch_unwind(AssertUnwindSafe(|| Model::fit(&pts, Some(&o))));
    let payload = r.unwrap_err();
    assert_eq!(payload.downcast_ref::<&str>(), Some(&"boom"));
    assert_eq!(
        *after_panic.lock().unwrap_or_else(|e| e.into_inner()),
        1,
        "the closure is not called again after a panic"
    );
}

#[test]
fn scoring_and_regression_report_points_and_change_nothing() {
    let pts = cube(3000);
    let m = Model::fit(&pts, Some(&opts())).unwrap();
    let q: Vec<f32> = cube(10_000).chunks(4).flat_map(|r| [r[0], r[1], r[2]]).collect();
    let (f, seen) = recorder();
    let o = Options::builder().on_progress(f).build().unwrap();
    let last = || seen.lock().unwrap().last().map(|p| (p.stage, p.step));
    let got = m.score_samples(&q, 3, Some(&o)).unwrap();
    assert_eq!(got, m.score_samples(&q, 3, None).unwrap());
    assert_eq!(last(), Some((Stage::Scoring, 10_000)));
    let got = m.regress_gray(&q, Some(&o));
    assert_eq!(got.unwrap(), m.regress_gray(&q, None).unwrap());
    assert_eq!(last(), Some((Stage::Regression, 10_000)));
    let stop = Options::builder()
        .on_progress(|_| ControlFlow::Break(()))
        .build()
        .unwrap();
    let e = m.score_samples(&q, 3, Some(&stop)).unwrap_err();
    assert_eq!(e.status(), Status::Cancelled);
}
