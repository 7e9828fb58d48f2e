//! Tests of the safe API against hand-computed values and invariants.
use sogmm::{Color, Frame, Model, Options, Queryable, Status};

/// One 4-D Gaussian: mean (0, 0, 0, 0.5); covariance diag(1, 1, 1, 0.5) with
/// cov(x, gray) = 0.2.
fn one_gaussian() -> Model {
    let mut cov = [0.0f32; 16];
    for i in 0..3 {
        cov[i * 5] = 1.0;
    }
    cov[15] = 0.5;
    cov[3] = 0.2; // (x, gray)
    cov[12] = 0.2; // (gray, x)
    Model::from_arrays(&[1.0], &[0.0, 0.0, 0.0, 0.5], &cov, 10).unwrap()
}

/// Deterministic points: two blobs (around x = -1 and x = +1, gray 0.2 and
/// 0.8) from a fixed linear congruential generator.
fn two_blobs(n: usize) -> Vec<f32> {
    let mut s: u64 = 12345;
    let mut next = || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((s >> 40) as f32 / (1u64 << 24) as f32) - 0.5 // [-0.5, 0.5)
    };
    let mut pts = Vec::with_capacity(n * 4);
    for i in 0..n {
        let (cx, g) = if i % 2 == 0 { (-1.0, 0.2) } else { (1.0, 0.8) };
        pts.extend_from_slice(&[cx + 0.1 * next(), 0.1 * next(), 2.0 + 0.1 * next(), g + 0.01 * next()]);
    }
    pts
}

#[test]
fn arrays_round_trip_bitwise() {
    let m = one_gaussian();
    assert_eq!(m.n_components(), 1);
    assert_eq!(m.weights().unwrap(), vec![1.0]);
    assert_eq!(m.means().unwrap(), vec![0.0, 0.0, 0.0, 0.5]);
    assert_eq!(m.covariances().unwrap()[3], 0.2);
    assert_eq!(m.info_i64(sogmm::sys::SOGMM_INFO_SUPPORT_SIZE).unwrap(), Some(10));
    // A model built from arrays has no fit report: None, not an error.
    assert_eq!(m.info_i64(sogmm::sys::SOGMM_INFO_FIT_ITERATIONS).unwrap(), None);
}

#[test]
fn regression_matches_closed_form() {
    // Gaussian conditioning: mean = 0.5 + 0.2 * x, variance = 0.5 - 0.2^2.
    // Both points are within 2.3 sigma: far out (beyond ~6.5 sigma) the answer
    // blends towards the prior on purpose (sogmm.h, sogmm_model_regress_gray).
    let (mean, var) = one_gaussian()
        .regress_gray(&[1.0, 0.0, 0.0, -2.0, 0.5, 1.0], None)
        .unwrap();
    assert!((mean[0] - 0.7).abs() < 1e-6 && (mean[1] - 0.1).abs() < 1e-6, "{mean:?}");
    assert!(var.iter().all(|v| (v - 0.46).abs() < 1e-6), "{var:?}");
}

#[test]
fn score_matches_closed_form() {
    // log N(mu; mu, S) = -0.5 (4 ln 2 pi + ln det S), det S = 0.5 - 0.04.
    let got = one_gaussian().score_samples(&[0.0, 0.0, 0.0, 0.5], 4, None).unwrap();
    let want = -0.5 * (4.0 * (2.0 * std::f64::consts::PI).ln() + 0.46f64.ln());
    assert!((got[0] - want).abs() < 1e-5, "{got:?} vs {want}");
    // Marginal over gray: a 3-D standard normal at its mean.
    let got3 = one_gaussian().score_samples(&[0.0, 0.0, 0.0], 3, None).unwrap();
    assert!((got3[0] + 1.5 * (2.0 * std::f64::consts::PI).ln()).abs() < 1e-5);
}

#[test]
fn fixed_k_fit_finds_both_blobs() {
    let opts = Options::builder().seed(7).threads(1).n_components(2).build().unwrap();
    let m = Model::fit(&two_blobs(400), Some(&opts)).unwrap();
    let mut xs: Vec<(f32, f32)> = m.means().unwrap().chunks(4).map(|r| (r[0], r[3])).collect();
    xs.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert!((xs[0].0 + 1.0).abs() < 0.05 && (xs[0].1 - 0.2).abs() < 0.01, "{xs:?}");
    assert!((xs[1].0 - 1.0).abs() < 0.05 && (xs[1].1 - 0.8).abs() < 0.01, "{xs:?}");
    let w = m.weights().unwrap();
    assert!((w[0] - 0.5).abs() < 1e-3 && (w[1] - 0.5).abs() < 1e-3, "{w:?}");
    assert_eq!(m.info_i64(sogmm::sys::SOGMM_INFO_FIT_N_POINTS).unwrap(), Some(400));
    assert_eq!(m.info_i64(sogmm::sys::SOGMM_INFO_FIT_SEED).unwrap(), Some(7));
}

#[test]
fn self_organizing_fit_and_seeds() {
    let opts = Options::builder().bandwidth(0.5).seed(3).threads(1).build().unwrap();
    let a = Model::fit(&two_blobs(200), Some(&opts)).unwrap();
    let b = Model::fit(&two_blobs(200), Some(&opts)).unwrap();
    assert_eq!(a.means().unwrap(), b.means().unwrap(), "same seed, same fit");
    assert_eq!(a.sample(100, 9, 4, None).unwrap(), b.sample(100, 9, 4, None).unwrap());
    assert_ne!(a.sample(100, 9, 4, None).unwrap(), a.sample(100, 10, 4, None).unwrap());
    assert_eq!(a.sample(50, 1, 3, None).unwrap().len(), 150);
}

#[test]
fn errors_carry_status_and_message() {
    let e = Model::fit(&[f32::NAN, 0.0, 0.0, 0.0], None).unwrap_err();
    assert_eq!(e.status(), Status::InvalidData);
    assert_eq!(e.code(), -3);
    assert!(!e.message().is_empty());
    assert!(e.to_string().starts_with("invalid"), "{e}");

    let e = Options::builder().bandwidth(-1.0).build().unwrap_err();
    assert_eq!(e.status(), Status::InvalidArg);
    assert!(e.message().to_lowercase().contains("bandwidth"), "{}", e.message());

    let e = Model::fit(&[0.0; 5], None).unwrap_err();
    assert_eq!(e.status(), Status::InvalidArg); // ragged rows, refused before C

    let e = Model::from_bytes(b"not a model", None).unwrap_err();
    assert_eq!(e.status(), Status::Format);

    let e = Model::load("/nonexistent/dir/x.sogmm", None).unwrap_err();
    assert_eq!(e.status(), Status::Io);

    let e = one_gaussian().sample(1, 0, 5, None).unwrap_err();
    assert_eq!(e.status(), Status::InvalidArg);
    let e = one_gaussian().sample(usize::MAX / 2, 0, 4, None).unwrap_err();
    assert_eq!(e.status(), Status::Limit); // n * dims overflows: refused before allocating
}

#[test]
fn options_get_set_clone() {
    let mut o = Options::builder().seed(u64::MAX).zstd_level(3).build().unwrap();
    assert_eq!(o.get_i64(sogmm::sys::SOGMM_OPT_SEED).unwrap(), -1); // the u64's bits
    let c = o.clone();
    o.set_i64(sogmm::sys::SOGMM_OPT_ZSTD_LEVEL, 5).unwrap();
    assert_eq!(c.get_i64(sogmm::sys::SOGMM_OPT_ZSTD_LEVEL).unwrap(), 3, "clone is deep");
    assert_eq!(o.get_f64(sogmm::sys::SOGMM_OPT_BANDWIDTH).unwrap(), 0.02, "default");
    assert_eq!(
        o.get_f64(sogmm::sys::SOGMM_OPT_SEED).unwrap_err().status(),
        Status::InvalidArg
    );
}

#[test]
fn bytes_and_files_round_trip() {
    let mut m = one_gaussian();
    m.set_value("origin", "rust test").unwrap();
    let pose = [
        1.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 2.0, 0.0, 0.0, 1.0, 3.0, 0.0, 0.0, 0.0, 1.0,
    ];
    m.set_pose(&pose).unwrap();
    let opts = Options::builder().zstd_level(1).build().unwrap();
    let back = Model::from_bytes(&m.to_bytes(Some(&opts)).unwrap(), None).unwrap();
    assert_eq!(back.covariances().unwrap(), m.covariances().unwrap());
    assert_eq!(back.value("origin").unwrap().as_deref(), Some("rust test"));
    assert_eq!(back.value("absent").unwrap(), None);
    assert_eq!(back.pose().unwrap(), Some(pose));

    let path = std::env::temp_dir().join(format!("sogmm-rust-{}.sogmm", std::process::id()));
    m.save(&path, None).unwrap();
    let loaded = Model::load(&path, None).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert_eq!(
        loaded.values().unwrap(),
        vec![("origin".to_string(), "rust test".to_string())]
    );
}

#[test]
fn clone_is_deep_and_merge_transform_work() {
    let a = one_gaussian();
    let mut b = a.clone();
    b.set_value("k", "v").unwrap();
    assert_eq!(a.value("k").unwrap(), None);
    let ab = a.merge(&b).unwrap();
    assert_eq!(ab.n_components(), 2);
    assert_eq!(ab.weights().unwrap(), vec![0.5, 0.5]);
    let moved = a
        .transform(&[
            1.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
        ])
        .unwrap();
    assert_eq!(moved.means().unwrap(), vec![1.0, 0.0, 0.0, 0.5]);
}

/// A frame of 8-bit gray, `width` x `height`, focal length `f` on both axes
/// and principal point (cx, cy).
fn gray_frame<'a>(
    depth: &'a [u16],
    gray: &'a [u8],
    (width, height): (u32, u32),
    f: f64,
    (cx, cy): (f64, f64),
) -> Frame<'a> {
    Frame {
        depth,
        color: Color::Gray8(gray),
        width,
        height,
        fx: f,
        fy: f,
        cx,
        cy,
    }
}

#[test]
fn rgbd_fit_checks_slice_lengths() {
    let (w, h) = (32u32, 24u32);
    let depth: Vec<u16> = (0..w * h).map(|i| 1000 + (i % w) as u16 * 10).collect();
    let gray: Vec<u8> = (0..w * h).map(|i| if i % w < w / 2 { 40 } else { 200 }).collect();
    let frame = gray_frame(&depth, &gray, (w, h), 30.0, (15.5, 11.5));
    let opts = Options::builder().bandwidth(0.1).threads(1).build().unwrap();
    let m = Model::fit_rgbd(&frame, Some(&opts)).unwrap();
    assert_eq!(m.info_i64(sogmm::sys::SOGMM_INFO_CAMERA_WIDTH).unwrap(), Some(32));
    assert_eq!(
        m.info_i64(sogmm::sys::SOGMM_INFO_SUPPORT_SIZE).unwrap(),
        Some((w * h) as i64)
    );
    let short = Frame {
        depth: &depth[1..],
        ..frame
    };
    assert_eq!(Model::fit_rgbd(&short, None).unwrap_err().status(), Status::InvalidArg);
    let rgb_too_short = Frame {
        color: Color::Rgb8(&gray),
        ..frame
    };
    assert_eq!(
        Model::fit_rgbd(&rgb_too_short, None).unwrap_err().status(),
        Status::InvalidArg
    );
}

#[test]
fn shared_model_across_threads_matches_serial() {
    fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<Model>();
    assert_send_sync::<Options>();
    let m = one_gaussian();
    let serial: Vec<Vec<f32>> = (0..4).map(|s| m.sample(500, s, 4, None).unwrap()).collect();
    let parallel: Vec<Vec<f32>> = std::thread::scope(|sc| {
        let hs: Vec<_> = (0..4)
            .map(|s| {
                let m = &m;
                sc.spawn(move || m.sample(500, s, 4, None).unwrap())
            })
            .collect();
        hs.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert_eq!(serial, parallel);
    // The error message is per thread: a failure elsewhere does not leak here.
    std::thread::scope(|sc| {
        sc.spawn(|| assert!(Model::fit(&[f32::NAN; 4], None).is_err()));
    });
    assert!(m.sample(1, 0, 4, None).is_ok());
}

#[test]
fn version_is_the_header_version() {
    assert_eq!(sogmm::version(), sogmm::sys::SOGMM_VERSION_STRING);
}

#[test]
fn frame_to_points_by_hand() {
    // 2 x 2 frame, fx = fy = 2, cx = cy = 0.5: x = (u - 0.5) z / 2, y = (v - 0.5) z / 2.
    let depth = [1000u16, 2000, 0, 1000]; // 1 m, 2 m, no reading, 1 m
    let gray = [0u8, 255, 7, 51];
    let frame = gray_frame(&depth, &gray, (2, 2), 2.0, (0.5, 0.5));
    let pts = frame.to_points(None).unwrap();
    let want = [-0.25, -0.25, 1.0, 0.0, 0.5, -0.5, 2.0, 1.0, 0.25, 0.25, 1.0, 0.2];
    assert_eq!(pts.len(), want.len(), "{pts:?}");
    for (g, w) in pts.iter().zip(want) {
        assert!((g - w).abs() < 1e-6, "{pts:?}");
    }
    let none = Frame {
        depth: &[0, 0, 0, 0],
        ..frame
    };
    assert!(none.to_points(None).unwrap().is_empty());
}

/// The library's default (SOGMM_DEQUANTISE_AUTO) floors an RGB-D frame: the
/// same model as `dequantise_depth(true)`, not that of `dequantise_depth(false)`.
/// The frame is 8 fronto-parallel steps 10 cm apart (exact depth levels).
#[test]
fn the_depth_floor_is_the_default_for_frames() {
    let (w, h) = (96u32, 72u32);
    let depth: Vec<u16> = (0..w * h).map(|i| 1000 + 100 * ((i % w) / 12) as u16).collect();
    let gray: Vec<u8> = (0..w * h).map(|i| (60 + 2 * (i % w) + i / w) as u8).collect();
    let frame = gray_frame(
        &depth,
        &gray,
        (w, h),
        77.0,
        ((w as f64 - 1.0) / 2.0, (h as f64 - 1.0) / 2.0),
    );
    let covariances = |floor: Option<bool>| {
        let mut b = Options::builder().bandwidth(0.05).seed(3).threads(1).decimation(2);
        if let Some(on) = floor {
            b = b.dequantise_depth(on);
        }
        let m = Model::fit_rgbd(&frame, Some(&b.build().unwrap())).unwrap();
        m.covariances().unwrap()
    };
    let defaults = Options::new().unwrap();
    assert_eq!(
        defaults.get_i64(sogmm::sys::SOGMM_OPT_DEQUANTISE_DEPTH).unwrap(),
        sogmm::sys::SOGMM_DEQUANTISE_AUTO
    );
    let (default, on, off) = (covariances(None), covariances(Some(true)), covariances(Some(false)));
    assert_eq!(default, on);
    assert_ne!(default, off, "the floor changed nothing: the test would be vacuous");
}

/// The registry's defaults are what a fresh Options holds, for every key.
#[test]
fn option_info_reports_every_default_a_fresh_handle_holds() {
    let o = sogmm::Options::new().unwrap();
    let keys = sogmm::option_keys().unwrap();
    assert!(keys.len() >= 31);
    assert!(keys.windows(2).all(|w| w[0] < w[1]));
    for key in keys {
        let info = sogmm::option_info(key).unwrap();
        assert!(info.name.starts_with("SOGMM_OPT_"), "{}", info.name);
        assert!(!info.range.is_empty() && !info.doc.is_empty());
        match info.values {
            sogmm::OptionValues::F64 { default, lower, upper } => {
                assert_eq!(o.get_f64(key).unwrap(), default, "{}", info.name);
                assert!(lower <= default && default <= upper, "{}", info.name);
            }
            sogmm::OptionValues::I64 { default, lower, upper } => {
                assert_eq!(o.get_i64(key).unwrap(), default, "{}", info.name);
                assert!(lower <= default && default <= upper, "{}", info.name);
            }
        }
    }
    let tol = sogmm::option_info(sogmm::sys::SOGMM_OPT_TOL).unwrap();
    assert_eq!(tol.name, "SOGMM_OPT_TOL");
    assert_eq!(sogmm::option_info(99).unwrap_err().status(), sogmm::Status::InvalidArg);
}

/// 3000 points of three overlapping clusters along x (a fixed linear
/// congruential generator), where plain EM creeps to its fixed point.
fn three_overlapping_clusters() -> Vec<f32> {
    let mut s: u64 = 35;
    let mut next = || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((s >> 40) as f32 / (1u64 << 24) as f32) - 0.5 // [-0.5, 0.5)
    };
    let mut pts = Vec::new();
    for i in 0..3000 {
        let k = (i % 3) as f32;
        pts.extend_from_slice(&[
            0.8 * k + 1.5 * next(),
            0.5 * next(),
            1.0 + 0.3 * next(),
            0.3 + 0.3 * next(),
        ]);
    }
    pts
}

/// SQUAREM (`squarem(true)`, SOGMM_OPT_EM_ACCELERATION) reaches plain EM's
/// fixed point on three overlapping clusters in fewer passes, no lower; a
/// value outside 0..=1 is refused.
#[test]
fn squarem_reaches_the_fixed_point_in_fewer_passes() {
    let pts = three_overlapping_clusters();
    let fit = |squarem: bool| {
        let o = Options::builder()
            .n_components(3)
            .seed(1)
            .threads(1)
            .tol(1e-7)
            .max_iter(3000)
            .squarem(squarem);
        let m = Model::fit(&pts, Some(&o.build().unwrap())).unwrap();
        let it = m.info_i64(sogmm::sys::SOGMM_INFO_FIT_ITERATIONS).unwrap().unwrap();
        let ll = m.info_f64(sogmm::sys::SOGMM_INFO_FIT_LOG_LIKELIHOOD).unwrap().unwrap();
        (it, ll)
    };
    let (plain, fast) = (fit(false), fit(true));
    assert!(fast.0 < plain.0, "{fast:?} vs {plain:?}");
    assert!(fast.1 >= plain.1 - 1e-5, "{fast:?} vs {plain:?}");
    let mut o = Options::new().unwrap();
    assert_eq!(o.get_i64(sogmm::sys::SOGMM_OPT_EM_ACCELERATION).unwrap(), 0);
    assert!(o.set_i64(sogmm::sys::SOGMM_OPT_EM_ACCELERATION, 2).is_err());
}

/// `tol_standard_errors(c)` (SOGMM_OPT_TOL_STANDARD_ERRORS) reaches the fit:
/// on three_overlapping_clusters() plain EM creeps for hundreds of passes at tol 1e-7,
/// far below one standard error of the mean log-likelihood, so c = 1 stops
/// it sooner; c = 0 is the default and the fit itself; a negative c is
/// refused. Mutation tried: the setter writing SOGMM_OPT_TOL instead (c = 0
/// then sets tol 0: the "same as default" check fails).
#[test]
fn tol_standard_errors_stops_the_creep() {
    let pts = three_overlapping_clusters();
    let fit = |c: Option<f64>| {
        let mut o = Options::builder()
            .n_components(3)
            .seed(1)
            .threads(1)
            .tol(1e-7)
            .max_iter(3000);
        if let Some(c) = c {
            o = o.tol_standard_errors(c);
        }
        let m = Model::fit(&pts, Some(&o.build().unwrap())).unwrap();
        m.info_i64(sogmm::sys::SOGMM_INFO_FIT_ITERATIONS).unwrap().unwrap()
    };
    let (plain, zero, noise) = (fit(None), fit(Some(0.0)), fit(Some(1.0)));
    assert_eq!(zero, plain);
    assert!(noise < plain, "{noise} vs {plain}");
    assert!(Options::builder().tol_standard_errors(-0.5).build().is_err());
}

/// `m` components like a map's: means spread over a metre, covariances
/// A A^T / 100 + I / 1000 from a fixed linear congruential generator (all
/// positive definite, conditions up to ~10^3), weights over a decade.
fn varied_components(m: usize) -> Model {
    let mut s: u64 = 2024;
    let mut next = || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((s >> 40) as f64 / (1u64 << 24) as f64) - 0.5 // [-0.5, 0.5)
    };
    let (mut w, mut mu, mut cov) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..m {
        w.push((1.5 + next()) as f32);
        mu.extend([next(), next(), 2.0 + next(), 0.5 + 0.5 * next()].map(|v| v as f32));
        let a: Vec<f64> = (0..16).map(|_| next()).collect();
        for i in 0..4 {
            for j in 0..4 {
                let aat: f64 = (0..4).map(|k| a[4 * i + k] * a[4 * j + k]).sum();
                cov.push((aat / 100.0 + if i == j { 1e-3 } else { 0.0 }) as f32);
            }
        }
    }
    let total: f32 = w.iter().sum();
    let w: Vec<f32> = w.iter().map(|v| v / total).collect();
    Model::from_arrays(&w, &mu, &cov, 1000).unwrap()
}

/// |L^-1 d| for S = L L^T (4 x 4, row-major): the distance d in standard
/// deviations of the Gaussian with covariance S.
fn sigmas(s: &[f32], d: &[f64]) -> f64 {
    let mut l = [0.0f64; 16];
    for j in 0..4 {
        let diag = s[5 * j] as f64 - (0..j).map(|k| l[4 * j + k] * l[4 * j + k]).sum::<f64>();
        l[5 * j] = diag.sqrt();
        for i in j + 1..4 {
            let v = s[4 * i + j] as f64 - (0..j).map(|k| l[4 * i + k] * l[4 * j + k]).sum::<f64>();
            l[4 * i + j] = v / l[5 * j];
        }
    }
    let mut x = [0.0f64; 4];
    for i in 0..4 {
        x[i] = (d[i] - (0..i).map(|k| l[4 * i + k] * x[k]).sum::<f64>()) / l[5 * i];
    }
    x.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// SOGMM_OPT_ARRAY_PRECISION (sogmm.h, spec/api.md): at precision P a saved
/// component's mean moves by at most P of its own standard deviations,
/// |L^-1 (mu' - mu)| <= P with S = L L^T the saved covariance. The encoder
/// checks that bound on the decoded float32 values before writing; this test
/// recomputes it in binary64 (its own rounding, ~1e-15 relative, is inside
/// the 1e-9 allowed). Mutation tried: the setter's f64 key swapped for the
/// map's MAP_COMPONENT_PRECISION (630) leaves the file uncoded: the size and
/// "some mean moved" checks fail.
#[test]
fn array_precision_codes_means_within_their_bound_and_refuses_out_of_range() {
    let m = varied_components(40);
    let dir = std::env::temp_dir();
    let id = std::process::id();
    let exact_path = dir.join(format!("sogmm-rust-exact-{id}.sogmm"));
    let coded_path = dir.join(format!("sogmm-rust-coded-{id}.sogmm"));
    let exact = Options::builder().array_precision(0.0).build().unwrap();
    let coded = Options::builder().array_precision(0.5).build().unwrap();
    m.save(&exact_path, Some(&exact)).unwrap();
    m.save(&coded_path, Some(&coded)).unwrap();
    let (exact_bytes, coded_bytes) = (std::fs::read(&exact_path).unwrap(), std::fs::read(&coded_path).unwrap());
    assert!(
        coded_bytes.len() < exact_bytes.len(),
        "{} >= {}",
        coded_bytes.len(),
        exact_bytes.len()
    );

    let back = Model::load(&coded_path, None).unwrap();
    assert_eq!(back.n_components(), m.n_components());
    let (mu0, s0, mu1) = (m.means().unwrap(), m.covariances().unwrap(), back.means().unwrap());
    let mut moved = 0;
    for k in 0..m.n_components() {
        let d: Vec<f64> = (0..4).map(|i| mu1[4 * k + i] as f64 - mu0[4 * k + i] as f64).collect();
        let e = sigmas(&s0[16 * k..16 * k + 16], &d);
        assert!(e <= 0.5 * (1.0 + 1e-9), "component {k}: {e} sigmas");
        moved += usize::from(e > 0.0);
    }
    assert!(moved > 0, "the means were stored as codes, not bit for bit");
    let exact_back = Model::load(&exact_path, None).unwrap();
    assert_eq!(exact_back.means().unwrap(), mu0, "precision 0: float arrays, bit-exact");

    // Out of range: the binding's InvalidArg, the options keep their value
    // (a save with them writes the same bytes again) and the file is untouched.
    let mut o = coded.clone();
    for bad in [0.7, -1.0, f64::NAN] {
        let e = Options::builder().array_precision(bad).build().unwrap_err();
        assert_eq!(e.status(), Status::InvalidArg, "{bad}");
        let e = o.set_f64(sogmm::sys::SOGMM_OPT_ARRAY_PRECISION, bad).unwrap_err();
        assert_eq!(e.status(), Status::InvalidArg, "{bad}");
        assert_eq!(o.get_f64(sogmm::sys::SOGMM_OPT_ARRAY_PRECISION).unwrap(), 0.5, "{bad}");
        assert_eq!(std::fs::read(&coded_path).unwrap(), coded_bytes, "{bad}");
    }
    m.save(&exact_path, Some(&o)).unwrap();
    assert_eq!(std::fs::read(&exact_path).unwrap(), coded_bytes);
    std::fs::remove_file(&exact_path).unwrap();
    std::fs::remove_file(&coded_path).unwrap();
}
