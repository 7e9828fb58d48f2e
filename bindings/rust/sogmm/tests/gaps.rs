//! PSNR, set_info and culled queries of the safe API, against hand-computed
//! values, round trips and the documented bound.
use std::ops::ControlFlow;

use sogmm::sys;
use sogmm::{psnr_images, Map, Model, Options, Progress, Queryable, Status};

// ---- psnr_images --------------------------------------------------------

/// Pixels and the error e = 1/8 are exact in f32: constant error e gives
/// 10 log10(R^2 / e^2); the pixel at -1 is empty.
const TRUTH: [f32; 4] = [0.25, 0.5, -1.0, 0.75];
const ESTIMATE: [f32; 4] = [0.375, 0.625, -1.0, 0.875];
const E: f64 = 0.125;

#[test]
fn psnr_of_a_constant_error_is_the_closed_form() {
    let r = psnr_images(&TRUTH, &ESTIMATE, 1.0).unwrap();
    assert!((r.psnr - 10.0 * (1.0 / (E * E)).log10()).abs() < 1e-12, "{r:?}");
    // Paper figure: range 2, all 4 pixels counted, the empty one as perfect.
    let paper = 10.0 * (4.0 / (3.0 * E * E / 4.0)).log10();
    assert!((r.psnr_paper - paper).abs() < 1e-12, "{r:?}");
    // Range 2 adds exactly 20 log10 2; the paper figure ignores the range.
    let two = psnr_images(&TRUTH, &ESTIMATE, 2.0).unwrap();
    assert!((two.psnr - r.psnr - 20.0 * 2f64.log10()).abs() < 1e-12);
    assert_eq!(two.psnr_paper, r.psnr_paper);
    // Range 0: the valid truth's range, 0.75 - 0.25.
    let auto = psnr_images(&TRUTH, &ESTIMATE, 0.0).unwrap();
    assert!((auto.psnr - 10.0 * (0.25 / (E * E)).log10()).abs() < 1e-12);
    let same = psnr_images(&TRUTH, &TRUTH, 1.0).unwrap();
    assert!(same.psnr == f64::INFINITY && same.psnr_paper == f64::INFINITY);
}

#[test]
fn psnr_refuses_bad_input_with_a_message() {
    let e = psnr_images(&TRUTH, &ESTIMATE[..3], 1.0).unwrap_err();
    assert_eq!(e.status(), Status::InvalidArg);
    assert!(e.message().contains("same size"), "{e}");
    for bad in [-1.0, f64::NAN, f64::INFINITY] {
        let e = psnr_images(&TRUTH, &ESTIMATE, bad).unwrap_err();
        assert_eq!(e.status(), Status::InvalidArg, "{bad}");
        assert!(e.message().contains("data range"), "{e}");
    }
    let empty = psnr_images(&[-1.0; 4], &[0.0; 4], 1.0).unwrap_err();
    assert_eq!(empty.status(), Status::InvalidData);
    let nan = psnr_images(&TRUTH, &[f32::NAN, 0.0, 0.0, 0.0], 1.0).unwrap_err();
    assert_eq!(nan.status(), Status::InvalidData);
}

// ---- set_info -------------------------------------------------------------

fn two_components() -> Model {
    let mut cov = [0.0f32; 32];
    for k in 0..2 {
        for i in 0..4 {
            cov[16 * k + 5 * i] = 0.01 * (i + 1) as f32;
        }
    }
    let means: Vec<f32> = (0..8).map(|v| v as f32).collect();
    Model::from_arrays(&[0.25, 0.75], &means, &cov, 40).unwrap()
}

#[test]
fn set_info_round_trips_through_a_file() {
    let mut m = two_components();
    assert_eq!(m.info_i64(sys::SOGMM_INFO_FIT_ITERATIONS).unwrap(), None);
    m.set_info_i64(sys::SOGMM_INFO_FIT_ITERATIONS, 40).unwrap();
    m.set_info_i64(sys::SOGMM_INFO_FIT_CONVERGED, 1).unwrap();
    m.set_info_f64(sys::SOGMM_INFO_FIT_BANDWIDTH, 0.02).unwrap();
    m.set_info_f64(sys::SOGMM_INFO_FIT_LOG_LIKELIHOOD, -3.25).unwrap();
    m.set_info_i64(sys::SOGMM_INFO_FIT_SEED, u64::MAX as i64).unwrap(); // the u64's bits
    m.set_info_i64(sys::SOGMM_INFO_CAMERA_DECIMATION, 5).unwrap();
    m.set_info_f64(sys::SOGMM_INFO_CAMERA_FX, 525.5).unwrap();
    let path = std::env::temp_dir().join(format!("sogmm-rust-set-info-{}.sogmm", std::process::id()));
    m.save(&path, None).unwrap();
    let back = Model::load(&path, None).unwrap();
    std::fs::remove_file(&path).unwrap();
    for model in [&m, &back] {
        assert_eq!(model.info_i64(sys::SOGMM_INFO_FIT_ITERATIONS).unwrap(), Some(40));
        assert_eq!(model.info_i64(sys::SOGMM_INFO_FIT_CONVERGED).unwrap(), Some(1));
        assert_eq!(model.info_f64(sys::SOGMM_INFO_FIT_BANDWIDTH).unwrap(), Some(0.02));
        assert_eq!(model.info_f64(sys::SOGMM_INFO_FIT_LOG_LIKELIHOOD).unwrap(), Some(-3.25));
        assert_eq!(model.info_i64(sys::SOGMM_INFO_FIT_SEED).unwrap(), Some(-1));
        assert_eq!(model.info_i64(sys::SOGMM_INFO_CAMERA_DECIMATION).unwrap(), Some(5));
        assert_eq!(model.info_f64(sys::SOGMM_INFO_CAMERA_FX).unwrap(), Some(525.5));
    }
    assert_eq!(back.to_bytes(None).unwrap().len(), m.to_bytes(None).unwrap().len());
}

#[test]
fn set_info_refuses_what_files_cannot_hold_and_changes_nothing() {
    let mut m = two_components();
    m.set_info_i64(sys::SOGMM_INFO_FIT_ITERATIONS, 7).unwrap();
    let refused = [
        m.set_info_i64(sys::SOGMM_INFO_SUPPORT_SIZE, 3),  // not a stored info key
        m.set_info_i64(sys::SOGMM_INFO_FIT_CONVERGED, 2), // 0 or 1
        m.set_info_i64(sys::SOGMM_INFO_FIT_ITERATIONS, 1 << 31), // an int32 field
        m.set_info_i64(sys::SOGMM_INFO_CAMERA_DECIMATION, 0), // >= 1
        m.set_info_f64(sys::SOGMM_INFO_FIT_BANDWIDTH, f64::NAN),
    ];
    for (i, r) in refused.into_iter().enumerate() {
        let e = r.expect_err(&format!("refused value {i}"));
        assert_eq!(e.status(), Status::InvalidArg, "{e}");
        assert!(!e.message().is_empty());
    }
    assert_eq!(m.info_i64(sys::SOGMM_INFO_FIT_ITERATIONS).unwrap(), Some(7));
    assert_eq!(m.info_i64(sys::SOGMM_INFO_SUPPORT_SIZE).unwrap(), Some(40));
    assert_eq!(m.info_i64(sys::SOGMM_INFO_CAMERA_DECIMATION).unwrap(), None);
}

// ---- culled queries (query_truncation_nats) and query threads -------------

/// Component 0 at the origin (gray 0.25) and 9 components 4 sigma away along
/// x (gray 0.75): at the query points those 9 terms are 8+ nats below the
/// first, more than a probe keeps (8), so culling at 2 or 6 nats skips some.
fn far_cluster() -> Model {
    const M: usize = 10;
    let mut cov = vec![0.0f32; 16 * M];
    for k in 0..M {
        for i in 0..4 {
            cov[16 * k + 5 * i] = 1.0;
        }
    }
    let mut means = vec![0.0, 0.0, 0.0, 0.25];
    for k in 1..M {
        means.extend_from_slice(&[4.0, 0.25 * (k - 1) as f32, 0.0, 0.75]);
    }
    // A known support size: loaded as a map, an unknown one (0) is refused.
    Model::from_arrays(&[0.1; M], &means, &cov, 1000).unwrap()
}

const QUERY: [f32; 12] = [0.0, 0.0, 0.0, 0.25, 0.0, 0.5, 0.0, 0.5, -1.0, 0.0, 0.0, 0.25];
const QUERY_XYZ: [f32; 9] = [0.0, 0.0, 0.0, 0.0, 0.5, 0.0, -1.0, 0.0, 0.0];

fn culled(nats: f64, threads: i64) -> Options {
    Options::builder()
        .query_truncation_nats(nats)
        .threads(threads)
        .build()
        .unwrap()
}

#[test]
fn culled_scores_and_regression_are_within_the_bound() {
    let m = far_cluster();
    let big_m = m.n_components() as f64;
    let exact = m.score_samples(&QUERY, 4, None).unwrap();
    let (mean, var) = m.regress_gray(&QUERY_XYZ, None).unwrap();
    for nats in [2.0, 6.0] {
        let c = m.score_samples(&QUERY, 4, Some(&culled(nats, 1))).unwrap();
        assert_eq!(c, m.score_samples(&QUERY, 4, Some(&culled(nats, 2))).unwrap());
        let bound = (big_m * (-nats).exp()).ln_1p();
        for (e, c) in exact.iter().zip(&c) {
            assert!(
                *c <= *e && e - c <= bound,
                "nats {nats}: exact {e}, culled {c}, bound {bound}"
            );
        }
        assert!(
            exact.iter().zip(&c).any(|(e, c)| e != c),
            "nothing was culled at {nats} nats"
        );
        // Dropped components hold a share <= (M - 1) e^-nats at a point, and
        // every conditional gray is in [0.25, 0.75]: the mean moves by at
        // most 0.5 times that share.
        let (cm, cv) = m.regress_gray(&QUERY_XYZ, Some(&culled(nats, 2))).unwrap();
        let shift = 0.5 * (big_m - 1.0) * (-nats).exp();
        for i in 0..3 {
            assert!(((cm[i] - mean[i]) as f64).abs() <= shift, "{cm:?} vs {mean:?}");
            assert!(cv[i].is_finite() && cv[i] > 0.0);
        }
        assert_ne!(cm, mean);
    }
    // Far above every gap: nothing is culled, the exact bits.
    assert_eq!(m.score_samples(&QUERY, 4, Some(&culled(40.0, 2))).unwrap(), exact);
    let (cm, cv) = m.regress_gray(&QUERY_XYZ, Some(&culled(40.0, 1))).unwrap();
    assert_eq!((cm, cv), (mean, var));
    assert_eq!(m.score_samples(&QUERY, 4, None).unwrap(), exact);
}

#[test]
fn map_queries_take_the_same_options() {
    // The far cluster as a world-frame map file, loaded as a map.
    let mut m = far_cluster();
    m.set_value("coordinate_frame", "world").unwrap();
    let path = std::env::temp_dir().join(format!("sogmm-rust-cull-map-{}.sogmm", std::process::id()));
    m.save(&path, None).unwrap();
    let map = Map::load(&path, None).unwrap();
    std::fs::remove_file(&path).unwrap();
    let o = culled(2.0, 2);
    let c = map.score_samples(&QUERY, 4, Some(&o)).unwrap();
    assert_eq!(c, m.score_samples(&QUERY, 4, Some(&o)).unwrap());
    assert_ne!(c, map.score_samples(&QUERY, 4, None).unwrap());
    let r = map.regress_gray(&QUERY_XYZ, Some(&o)).unwrap();
    assert_eq!(r, m.regress_gray(&QUERY_XYZ, Some(&o)).unwrap());
    assert_ne!(r, map.regress_gray(&QUERY_XYZ, None).unwrap());
    // A progress closure on the same options reports every point and changes no bit.
    let last = std::sync::Arc::new(std::sync::atomic::AtomicU64::new(0));
    let sink = std::sync::Arc::clone(&last);
    let mut reporting = o.clone();
    reporting.set_progress(move |p: Progress| {
        sink.store(p.step, std::sync::atomic::Ordering::SeqCst);
        ControlFlow::Continue(())
    });
    assert_eq!(map.score_samples(&QUERY, 4, Some(&reporting)).unwrap(), c);
    assert_eq!(m.score_samples(&QUERY, 4, Some(&reporting)).unwrap(), c);
    assert_eq!(last.load(std::sync::atomic::Ordering::SeqCst), 3);
    assert_eq!(map.regress_gray(&QUERY_XYZ, Some(&reporting)).unwrap(), r);
    assert_eq!(m.regress_gray(&QUERY_XYZ, Some(&reporting)).unwrap(), r);
}

#[test]
fn invalid_culling_or_threads_are_refused() {
    for nats in [-1.0, f64::NAN, f64::INFINITY] {
        let e = Options::builder().query_truncation_nats(nats).build().unwrap_err();
        assert_eq!(e.status(), Status::InvalidArg, "{nats}");
        assert!(
            e.message().contains("501") || e.message().to_lowercase().contains("truncation"),
            "{e}"
        );
    }
    let e = Options::builder().threads(-1).build().unwrap_err();
    assert_eq!(e.status(), Status::InvalidArg);
}

// ---- the writer keeps to the reader's decoded-size cap --------------------

#[test]
fn save_above_the_decoded_size_cap_is_refused() {
    let m = two_components(); // 2 x 15 f32 values: 120 decoded bytes
    let cap = |c| Options::builder().max_decoded_bytes(c).build().unwrap();
    let e = m.to_bytes(Some(&cap(119))).unwrap_err();
    assert_eq!(e.status(), Status::Limit);
    assert!(e.message().contains("over the cap of 119 bytes"), "{e}");
    assert!(e.message().contains("SOGMM_OPT_MAX_DECODED_BYTES"), "{e}");
    let bytes = m.to_bytes(Some(&cap(120))).unwrap();
    assert_eq!(
        Model::from_bytes(&bytes, Some(&cap(120))).unwrap().means().unwrap(),
        m.means().unwrap()
    );
}
