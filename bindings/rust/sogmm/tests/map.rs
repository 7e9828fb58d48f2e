//! The safe `Map`: inserts, statistics, export, files, world-frame queries
//! (bitwise the exported model's), progress and cancel; the warm start.
use std::ops::ControlFlow;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicU64, AtomicU8, Ordering};
use std::sync::{Arc, Mutex};

use sogmm::{Color, Frame, Map, Model, Options, Pose, Queryable, Stage, Status};

const IDENTITY: Pose = [1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1.];

fn shifted(tx: f64) -> Pose {
    let mut p = IDENTITY;
    p[3] = tx;
    p
}

/// Deterministic cloud: three tight blobs (x, y, z, gray) from a fixed LCG.
fn blobs(n: usize, seed: u64) -> Vec<f32> {
    let centres = [[0.0, 0.0, 1.0, 0.2], [0.5, 0.0, 1.5, 0.5], [0.0, 0.5, 2.0, 0.8]];
    let mut s = seed;
    let mut next = || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((s >> 40) as f32 / (1u64 << 24) as f32) - 0.5
    };
    (0..n).flat_map(|i| centres[i % 3].map(|c| c + 0.05 * next())).collect()
}

fn map_builder(novelty: bool) -> sogmm::OptionsBuilder {
    Options::builder()
        .map_novelty(novelty)
        .map_batch_size(100_000)
        .threads(2)
}

fn map_options(novelty: bool) -> Options {
    map_builder(novelty).build().unwrap()
}

/// What `steered` does at each report: go on, stop, or panic.
const GO_ON: u8 = 0;
const STOP: u8 = 1;
const PANIC: u8 = 2;

/// A progress closure doing what `mode` says, recording the stages it sees.
fn steered(
    mode: &Arc<AtomicU8>,
    stages: &Arc<Mutex<Vec<Stage>>>,
) -> impl FnMut(sogmm::Progress) -> ControlFlow<()> + Send + 'static {
    let (mode, stages) = (Arc::clone(mode), Arc::clone(stages));
    move |p| {
        stages.lock().unwrap_or_else(|e| e.into_inner()).push(p.stage);
        match mode.load(Ordering::SeqCst) {
            GO_ON => ControlFlow::Continue(()),
            STOP => ControlFlow::Break(()),
            _ => panic!("stop"),
        }
    }
}

/// Two posed copies of the blobs, flushed.
fn two_frame_map() -> Map {
    let pts = blobs(3000, 7);
    let mut map = Map::new(Some(&map_options(true))).unwrap();
    map.insert_points(&pts, &IDENTITY).unwrap();
    map.insert_points(&pts, &shifted(2.0)).unwrap();
    map.flush().unwrap();
    map
}

#[test]
fn inserts_stats_export_and_files() {
    let pts = blobs(3000, 7);
    let mut map = Map::new(Some(&map_options(true))).unwrap();
    assert_eq!(map.export().unwrap_err().status(), Status::InvalidData);
    map.insert_points(&pts, &IDENTITY).unwrap();
    let s = map.stats().unwrap();
    assert_eq!((s.n_frames, s.n_pending, s.n_components), (1, 3000, 0));
    map.flush().unwrap();
    // The same points again are (almost) all explained; 2 m away, all novel.
    map.insert_points(&pts, &IDENTITY).unwrap();
    assert!(map.frame_stats(1).unwrap().n_novel < 150);
    map.insert_points(&pts, &shifted(2.0)).unwrap();
    let f = map.frame_stats(2).unwrap();
    assert_eq!((f.n_points, f.n_novel, f.pose[3]), (3000, 3000, 2.0));
    assert_eq!(map.frame_stats(3).unwrap_err().status(), Status::InvalidArg);
    let path = std::env::temp_dir().join(format!("sogmm-rust-map-{}.sogmm", std::process::id()));
    assert_eq!(map.save(&path, None).unwrap_err().status(), Status::InvalidArg); // pending
    map.flush().unwrap();
    let all = map.export().unwrap();
    assert_eq!(all.n_components() as u64, map.stats().unwrap().n_components);
    assert_eq!(all.value("coordinate_frame").unwrap().as_deref(), Some("world"));
    let part = map.export_box(&[-0.3, -0.3, 0.7, 0.3, 0.3, 1.3]).unwrap();
    assert!(part.n_components() >= 1 && part.n_components() < all.n_components());
    map.save(&path, None).unwrap();
    let loaded = Map::load(&path, Some(&map_options(true))).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert_eq!(loaded.stats().unwrap().n_frames, 3);
    assert_eq!(loaded.frame_stats(2).unwrap().pose[3], 2.0);
    assert_eq!(loaded.export().unwrap().means().unwrap(), all.means().unwrap());
    // Bad input: ragged rows, an empty frame, a pose that is not rigid.
    assert_eq!(
        map.insert_points(&pts[..7], &IDENTITY).unwrap_err().status(),
        Status::InvalidArg
    );
    assert_eq!(
        map.insert_points(&[], &IDENTITY).unwrap_err().status(),
        Status::InvalidData
    );
    let mut scaled = IDENTITY;
    scaled[0] = 2.0;
    let e = map.insert_points(&pts, &scaled).unwrap_err();
    assert_eq!(e.status(), Status::InvalidArg);
    assert!(e.message().contains("pose"), "{e}");
}

#[test]
fn queries_equal_the_exported_model_bitwise() {
    let map = two_frame_map();
    let model = map.export().unwrap();
    // The blobs, every fifth point moved 3.5 m off (far regime).
    let q4: Vec<f32> = blobs(5000, 11)
        .chunks(4)
        .enumerate()
        .flat_map(|(i, r)| [r[0] + if i % 5 == 0 { 3.5 } else { 0.0 }, r[1], r[2], r[3]])
        .collect();
    let q3: Vec<f32> = q4.chunks(4).flat_map(|r| [r[0], r[1], r[2]]).collect();
    for (q, dims) in [(&q3, 3), (&q4, 4)] {
        let want = model.score_samples(q, dims, None).unwrap();
        assert_eq!(map.score_samples(q, dims, None).unwrap(), want);
        let last = Arc::new(AtomicU64::new(0));
        let sink = Arc::clone(&last);
        let o = Options::builder()
            .on_progress(move |p| {
                assert_eq!(p.stage, Stage::Scoring);
                sink.store(p.step, Ordering::SeqCst);
                ControlFlow::Continue(())
            })
            .build()
            .unwrap();
        let got = map.score_samples(q, dims, Some(&o)).unwrap();
        assert_eq!(got, want);
        assert_eq!(last.load(Ordering::SeqCst), 5000);
    }
    assert_eq!(
        map.regress_gray(&q3, None).unwrap(),
        model.regress_gray(&q3, None).unwrap()
    );
    let go_on = Options::builder()
        .on_progress(|_| ControlFlow::Continue(()))
        .build()
        .unwrap();
    assert_eq!(
        map.regress_gray(&q3, Some(&go_on)).unwrap(),
        model.regress_gray(&q3, None).unwrap()
    );
    assert_eq!(
        map.sample(4000, 3, 4, None).unwrap(),
        model.sample(4000, 3, 4, None).unwrap()
    );
    let trunc = Options::builder().sample_truncation(1.0).build().unwrap();
    assert_eq!(
        map.sample(4000, 3, 3, Some(&trunc)).unwrap(),
        model.sample(4000, 3, 3, Some(&trunc)).unwrap()
    );
    // Cancel and bad input.
    let stop = Options::builder()
        .on_progress(|_| ControlFlow::Break(()))
        .build()
        .unwrap();
    let e = map.regress_gray(&q3, Some(&stop)).unwrap_err();
    assert_eq!(e.status(), Status::Cancelled);
    assert_eq!(
        map.score_samples(&q3, 5, None).unwrap_err().status(),
        Status::InvalidArg
    );
    assert_eq!(
        map.score_samples(&q3[..4], 3, None).unwrap_err().status(),
        Status::InvalidArg
    );
    let mut nan = q3.clone();
    nan[4] = f32::NAN;
    assert_eq!(
        map.score_samples(&nan, 3, None).unwrap_err().status(),
        Status::InvalidData
    );
    let empty = Map::new(None).unwrap();
    assert_eq!(empty.sample(10, 1, 4, None).unwrap_err().status(), Status::InvalidData);
    // Shared across threads: the same answers.
    std::thread::scope(|s| {
        let handles: Vec<_> = (0..2)
            .map(|_| s.spawn(|| map.score_samples(&q4, 4, None).unwrap()))
            .collect();
        for h in handles {
            assert_eq!(h.join().unwrap(), model.score_samples(&q4, 4, None).unwrap());
        }
    });
}

#[test]
fn a_cancelled_insert_or_flush_leaves_the_map_as_it_was() {
    let pts = blobs(3000, 5);
    let (mode, stages) = (Arc::new(AtomicU8::new(GO_ON)), Arc::new(Mutex::new(Vec::new())));
    let steered_options = map_builder(false).on_progress(steered(&mode, &stages)).build().unwrap();
    let mut map = Map::new(Some(&steered_options)).unwrap();
    map.insert_points(&pts, &IDENTITY).unwrap();
    assert_eq!(stages.lock().unwrap().last(), Some(&Stage::Em));
    let before = (map.stats().unwrap(), map.export().unwrap().means().unwrap());
    mode.store(STOP, Ordering::SeqCst);
    let e = map.insert_points(&pts, &shifted(3.0)).unwrap_err();
    assert_eq!(e.status(), Status::Cancelled);
    assert_eq!((map.stats().unwrap(), map.export().unwrap().means().unwrap()), before);
    // A panic cancels too, resumes here, and leaves the map as it was.
    mode.store(PANIC, Ordering::SeqCst);
    let r = catch_unwind(AssertUnwindSafe(|| {
        let _ = map.insert_points(&pts, &shifted(3.0));
    }));
    assert!(r.is_err());
    assert_eq!(map.stats().unwrap(), before.0);
    // The closure still works after a panic: the next insert goes through.
    mode.store(GO_ON, Ordering::SeqCst);
    map.insert_points(&pts, &shifted(3.0)).unwrap();
    assert_eq!(map.stats().unwrap().n_frames, 2);

    let steered_pending = map_builder(true).on_progress(steered(&mode, &stages)).build().unwrap();
    let mut pending = Map::new(Some(&steered_pending)).unwrap();
    pending.insert_points(&pts, &IDENTITY).unwrap();
    mode.store(STOP, Ordering::SeqCst);
    let e = pending.flush().unwrap_err();
    assert_eq!(e.status(), Status::Cancelled);
    assert_eq!(pending.stats().unwrap().n_pending, 3000);
    mode.store(GO_ON, Ordering::SeqCst);
    pending.flush().unwrap();
    assert_eq!(pending.stats().unwrap().n_pending, 0);
}

// The warm pass cap (SOGMM_OPT_WARM_MAX_ITER) reaches the core through the
// options: with tol 0 EM runs its whole limit, which the fit record keeps.
#[test]
fn warm_pass_cap_is_an_option() {
    let pts = blobs(3000, 9);
    let cold = Model::fit(&pts, Some(&Options::builder().n_components(3).seed(2).build().unwrap())).unwrap();
    let capped = Options::builder()
        .n_components(3)
        .seed(2)
        .f64(sogmm::sys::SOGMM_OPT_TOL, 0.0)
        .i64(sogmm::sys::SOGMM_OPT_WARM_MAX_ITER, 3)
        .build()
        .unwrap();
    let warm = Model::fit_warm(&pts, &cold, Some(&capped)).unwrap();
    assert_eq!(warm.info_i64(sogmm::sys::SOGMM_INFO_FIT_ITERATIONS).unwrap(), Some(3));
    assert_eq!(warm.info_i64(sogmm::sys::SOGMM_INFO_FIT_MAX_ITER).unwrap(), Some(3));
}

#[test]
fn warm_start_from_a_fit_of_the_same_points() {
    let pts = blobs(3000, 9);
    let fixed = Options::builder().n_components(3).seed(2).threads(2).build().unwrap();
    let cold = Model::fit(&pts, Some(&fixed)).unwrap();
    // EM from a converged model of the same points: at least as likely (EM
    // never lowers the likelihood) and the same size.
    let reports = Arc::new(AtomicU64::new(0));
    let sink = Arc::clone(&reports);
    let counted = Options::builder()
        .n_components(3)
        .seed(2)
        .threads(2)
        .on_progress(move |_| {
            sink.fetch_add(1, Ordering::SeqCst);
            ControlFlow::Continue(())
        })
        .build()
        .unwrap();
    let warm = Model::fit_warm(&pts, &cold, Some(&counted)).unwrap();
    assert!(reports.load(Ordering::SeqCst) > 0);
    assert_eq!(warm.n_components(), 3);
    let ll = |m: &Model| m.score_samples(&pts, 4, None).unwrap().iter().sum::<f64>() / 3000.0;
    assert!(ll(&warm) >= ll(&cold) - 1e-6, "{} < {}", ll(&warm), ll(&cold));
    assert_eq!(
        Model::fit_warm(&pts, &cold, Some(&fixed)).unwrap().means().unwrap(),
        warm.means().unwrap()
    );
    // K must be the initial model's size; a warm start is one run.
    let k4 = Options::builder().n_components(4).build().unwrap();
    assert_eq!(
        Model::fit_warm(&pts, &cold, Some(&k4)).unwrap_err().status(),
        Status::InvalidArg
    );
    let two_runs = Options::builder().n_init(2).build().unwrap();
    assert_eq!(
        Model::fit_warm(&pts, &cold, Some(&two_runs)).unwrap_err().status(),
        Status::InvalidArg
    );
    let stop = Options::builder()
        .on_progress(|_| ControlFlow::Break(()))
        .build()
        .unwrap();
    let e = Model::fit_warm(&pts, &cold, Some(&stop)).unwrap_err();
    assert_eq!(e.status(), Status::Cancelled);
}

#[test]
fn novelty_bandwidth_scale_is_checked_and_reaches_the_map() {
    for bad in [0.0, 1.5, f64::NAN] {
        let e = Options::builder().map_novelty_bandwidth_scale(bad).build().unwrap_err();
        assert_eq!(e.status(), Status::InvalidArg, "{bad}: {e}");
    }
    // Two frames of the same size, 3 m apart, as one batch (h = 1/2 of its
    // point pairs from one frame, so the batch bandwidth is 0.05 x
    // (s + (1 - s) / 4)): a finer scale gives strictly more components. (One
    // frame alone is fitted at the bandwidth itself, whatever the scale.)
    let second: Vec<f32> = blobs(3000, 8)
        .chunks(4)
        .flat_map(|p| [p[0] + 3.0, p[1], p[2], p[3]])
        .collect();
    let count = |scale: f64| {
        let o = Options::builder()
            .map_batch_size(100_000)
            .map_novelty_bandwidth_scale(scale)
            .bandwidth(0.05)
            .threads(2)
            .build()
            .unwrap();
        let mut map = Map::new(Some(&o)).unwrap();
        map.insert_points(&blobs(3000, 7), &IDENTITY).unwrap();
        map.insert_points(&second, &IDENTITY).unwrap();
        map.flush().unwrap();
        map.stats().unwrap().n_components
    };
    let (fine, coarse) = (count(0.1), count(1.0));
    assert!(fine > coarse, "scale 0.1: {fine} components, scale 1: {coarse}");
}

#[test]
fn free_space_carve_and_component_precision_are_checked_and_reach_the_map() {
    for bad in [-0.1, 0.6, f64::NAN] {
        let e = Options::builder().map_free_space_carve(bad).build().unwrap_err();
        assert_eq!(e.status(), Status::InvalidArg, "carve {bad}: {e}");
        let e = Options::builder().map_component_precision(bad).build().unwrap_err();
        assert_eq!(e.status(), Status::InvalidArg, "precision {bad}: {e}");
    }
    // One frame fitted with and without rounding (novelty off: the same fit,
    // rounded after it): the rounded means differ from the plain fit's, and
    // each moves by at most 0.25 of its component's standard deviations in
    // the component's own metric, so along each axis by at most 0.25 sqrt(S_ii)
    // (the rounding happens after the fit, so this holds on every kernel).
    let build = |precision: f64| {
        let o = map_builder(false)
            .bandwidth(0.05)
            .map_component_precision(precision)
            .build()
            .unwrap();
        let mut map = Map::new(Some(&o)).unwrap();
        map.insert_points(&blobs(3000, 7), &IDENTITY).unwrap();
        map.flush().unwrap();
        map.export().unwrap()
    };
    let (plain, rounded) = (build(0.0), build(0.25));
    assert_eq!(plain.n_components(), rounded.n_components());
    let (mp, mr, cp) = (
        plain.means().unwrap(),
        rounded.means().unwrap(),
        plain.covariances().unwrap(),
    );
    assert_ne!(mp, mr, "precision 0.25 changed no mean");
    for k in 0..plain.n_components() {
        for d in 0..4 {
            let sigma = (cp[16 * k + 5 * d] as f64).sqrt();
            let moved = (mp[4 * k + d] as f64 - mr[4 * k + d] as f64).abs();
            assert!(
                moved <= 0.25 * sigma * (1.0 + 1e-6),
                "component {k} axis {d} moved {moved} > 0.25 x {sigma}"
            );
        }
    }
}

#[test]
fn revisit_refit_ratio_is_checked_and_reaches_the_map() {
    for bad in [0.5, -1.0, f64::NAN, f64::INFINITY] {
        let e = Options::builder().map_revisit_refit_ratio(bad).build().unwrap_err();
        assert_eq!(e.status(), Status::InvalidArg, "{bad}: {e}");
    }
    // A wall seen in one gray (one batch), then again in 8 gray stripes: many
    // more modes than the map has components there, so a second fit replaces
    // them at the default ratio and not at ratio 0.
    let (w, h) = (64u32, 48u32);
    let depth = vec![1500u16; (w * h) as usize];
    let plain = vec![128u8; (w * h) as usize];
    let striped: Vec<u8> = (0..w * h).map(|i| (32 * (((i % w) / 4) % 8)) as u8).collect();
    let fits = |ratio: Option<f64>| {
        let mut b = Options::builder().map_batch_size(i64::from(w * h));
        if let Some(r) = ratio {
            b = b.map_revisit_refit_ratio(r);
        }
        let o = b.build().unwrap();
        let mut map = Map::new(Some(&o)).unwrap();
        for gray in [&plain, &striped] {
            let frame = Frame {
                depth: &depth,
                color: Color::Gray8(gray),
                width: w,
                height: h,
                fx: 60.0,
                fy: 60.0,
                cx: 32.0,
                cy: 24.0,
            };
            map.insert_frame(&frame, &IDENTITY).unwrap();
        }
        let st = map.stats().unwrap();
        assert_eq!(st.n_pending, 0);
        assert_eq!(st.n_refits, st.n_flushes - 1); // the refit is the second fit
        assert_eq!(map.frame_stats(0).unwrap().n_replaced, 0);
        let refit = map.frame_stats(1).unwrap();
        assert_eq!(refit.n_replaced > 0, st.n_flushes == 2, "{refit:?}");
        assert_eq!(refit.flushed, st.n_flushes == 2);
        st.n_flushes
    };
    assert_eq!(fits(None), 2);
    assert_eq!(fits(Some(0.0)), 1);
}

#[test]
fn discard_pending_unlocks_a_map_that_cannot_be_saved() {
    let pts = blobs(300, 3);
    let mut map = Map::new(Some(&map_options(true))).unwrap();
    map.insert_points(&pts, &IDENTITY).unwrap();
    let dir = std::env::temp_dir().join(format!("sogmm_rust_discard_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("pending.sogmm");
    // Pending points: no save (flush first).
    assert_eq!(map.save(&path, None).unwrap_err().status(), Status::InvalidArg);
    assert_eq!(map.discard_pending().unwrap(), 300);
    let s = map.stats().unwrap();
    assert_eq!((s.n_frames, s.n_pending, s.n_components), (1, 0, 0));
    assert_eq!(map.discard_pending().unwrap(), 0);
    // The dropped points' voxels are forgotten: the same frame is new again.
    map.insert_points(&pts, &IDENTITY).unwrap();
    assert_eq!(map.frame_stats(1).unwrap().n_novel, 300);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Deltas applied in order rebuild the sender's map bit for bit; a gap is
/// refused and leaves the receiver at its revision.
#[test]
fn deltas_in_order_rebuild_the_map_bitwise_and_a_gap_is_refused() {
    let mut sender = Map::new(Some(&map_options(false))).unwrap();
    let mut receiver = Map::new(None).unwrap();
    let mut deltas = Vec::new();
    for (k, tx) in [0.0, 3.0].into_iter().enumerate() {
        let since = sender.revision().unwrap();
        sender.insert_points(&blobs(1500, 11 + k as u64), &shifted(tx)).unwrap();
        deltas.push(sender.export_delta(since).unwrap());
    }
    assert_eq!(sender.revision().unwrap(), 2);
    assert_eq!(
        receiver.apply_delta(&deltas[1]).unwrap_err().status(),
        Status::InvalidArg
    );
    assert_eq!(receiver.revision().unwrap(), 0);
    for d in &deltas {
        receiver.apply_delta(d).unwrap();
    }
    let (a, b) = (sender.export().unwrap(), receiver.export().unwrap());
    let bits = |v: Vec<f32>| v.into_iter().map(f32::to_bits).collect::<Vec<u32>>();
    assert_eq!(bits(a.weights().unwrap()), bits(b.weights().unwrap()));
    assert_eq!(bits(a.means().unwrap()), bits(b.means().unwrap()));
    assert_eq!(bits(a.covariances().unwrap()), bits(b.covariances().unwrap()));
}

/// A bounded journal (`map_delta_history`): with N = 1 the last revision's
/// changes are exported and older ones are refused, naming the oldest kept.
#[test]
fn a_bounded_delta_history_refuses_older_revisions() {
    let o = Options::builder()
        .threads(1)
        .map_novelty(false)
        .map_delta_history(1)
        .build()
        .unwrap();
    let mut sender = Map::new(Some(&o)).unwrap();
    for (k, tx) in [0.0, 3.0].into_iter().enumerate() {
        sender.insert_points(&blobs(400, 21 + k as u64), &shifted(tx)).unwrap();
    }
    assert_eq!(sender.revision().unwrap(), 2);
    assert!(!sender.export_delta(1).unwrap().is_empty());
    let e = sender.export_delta(0).unwrap_err();
    assert_eq!(e.status(), Status::InvalidArg);
    assert!(e.message().contains("changes from revision 1"), "{}", e.message());
    let bad = Options::builder().map_delta_history(-1).build().unwrap_err();
    assert_eq!(bad.status(), Status::InvalidArg);
}

// Issue 36: a map 1000 km out holds its components relative to its origin
// (the first frame's translation rounded to 1 km), finds in a mapped frame
// the novel points it finds at the world origin, and keeps the origin
// through save and load; it is declared only before the first insert.
#[test]
fn a_far_map_keeps_its_origin() {
    let pts = blobs(300, 3);
    let dir = std::env::temp_dir().join(format!("sogmm_rust_origin_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("far.sogmm");
    let mut novel = Vec::new();
    for km in [0.0, 1000.0] {
        let mut pose = IDENTITY;
        pose[3] = 1000.0 * km + 3.37;
        pose[7] = -1000.0 * km;
        let mut map = Map::new(Some(&map_options(true))).unwrap();
        map.insert_points(&pts, &pose).unwrap();
        map.flush().unwrap();
        assert_eq!(map.origin().unwrap(), [1000.0 * km, -1000.0 * km, 0.0]);
        map.insert_points(&pts, &pose).unwrap();
        novel.push(map.frame_stats(1).unwrap().n_novel);
        map.discard_pending().unwrap();
        map.save(&path, None).unwrap();
    }
    assert_eq!(novel[1], novel[0]);
    let mut loaded = Map::load(&path, Some(&map_options(true))).unwrap();
    assert_eq!(loaded.origin().unwrap(), [1.0e6, -1.0e6, 0.0]);
    assert_eq!(loaded.set_origin([0.0; 3]).unwrap_err().status(), Status::InvalidArg);
    let mut fresh = Map::new(Some(&map_options(true))).unwrap();
    assert_eq!(
        fresh.set_origin([f64::NAN, 0.0, 0.0]).unwrap_err().status(),
        Status::InvalidArg
    );
    fresh.set_origin([5.0e5, 0.5, 0.0]).unwrap();
    assert_eq!(fresh.origin().unwrap(), [5.0e5, 0.5, 0.0]);
    std::fs::remove_dir_all(&dir).unwrap();
}

// sogmm_map_merge_map: into an empty map it gives the other map bitwise, a
// receiver follows it as one delta, bad input changes nothing.
#[test]
fn merge_map_into_an_empty_map_gives_the_other_map() {
    let mut other = Map::new(Some(&map_options(false))).unwrap();
    other.insert_points(&blobs(1500, 11), &IDENTITY).unwrap();
    let n = other.stats().unwrap().n_components;
    let mut map = Map::new(None).unwrap();
    let mut receiver = Map::new(None).unwrap();
    let st = map.merge_map(&other, &IDENTITY).unwrap();
    assert_eq!(
        (st.n_kept, st.n_removed, st.n_added, st.n_skipped, st.n_frames),
        (0, 0, n, 0, 1)
    );
    assert_eq!(map.revision().unwrap(), 1);
    receiver.apply_delta(&map.export_delta(0).unwrap()).unwrap();
    let bits = |v: Vec<f32>| v.into_iter().map(f32::to_bits).collect::<Vec<u32>>();
    for m in [&map, &receiver] {
        let (a, b) = (other.export().unwrap(), m.export().unwrap());
        assert_eq!(bits(a.weights().unwrap()), bits(b.weights().unwrap()));
        assert_eq!(bits(a.means().unwrap()), bits(b.means().unwrap()));
        assert_eq!(bits(a.covariances().unwrap()), bits(b.covariances().unwrap()));
    }
    let mut nan = IDENTITY;
    nan[3] = f64::NAN;
    assert_eq!(map.merge_map(&other, &nan).unwrap_err().status(), Status::InvalidArg);
    let empty = Map::new(None).unwrap();
    assert_eq!(
        map.merge_map(&empty, &IDENTITY).unwrap_err().status(),
        Status::InvalidData
    );
    assert_eq!(map.revision().unwrap(), 1);
}
