//! `Model::register_points` and `Model::register_model` (issue 32): points
//! sampled from a corner of three planes, and the corner model itself, moved
//! by -t register back to the translation t; a NaN initial pose is an
//! invalid argument, a source model standing for too few points invalid data;
//! the depth-noise option reaches the core.
use sogmm::{Model, Options, Pose, Queryable, RegistrationStatus, Status};

/// Flat components tiling the unit squares of the planes x = 0, y = 0, z = 0.
fn corner(support_size: u64) -> Model {
    let (mut w, mut mu, mut cov) = (Vec::new(), Vec::new(), Vec::new());
    for axis in 0..3 {
        for a in 0..5 {
            for b in 0..5 {
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                let mut m = [0.0f32; 4];
                m[u] = 0.1 + 0.2 * a as f32;
                m[v] = 0.1 + 0.2 * b as f32;
                m[3] = 0.5;
                let mut c = [0.0f32; 16];
                c[5 * u] = 0.08 * 0.08;
                c[5 * v] = 0.08 * 0.08;
                c[5 * axis] = 0.003 * 0.003;
                c[15] = 0.01;
                w.push(1.0 / 75.0);
                mu.extend_from_slice(&m);
                cov.extend_from_slice(&c);
            }
        }
    }
    Model::from_arrays(&w, &mu, &cov, support_size).unwrap()
}

#[test]
fn recovers_a_translation() {
    let model = corner(1);
    let t = [0.02f32, -0.01, 0.03];
    let mut pts = model.sample(3000, 1, 4, None).unwrap();
    for row in pts.chunks_mut(4) {
        for k in 0..3 {
            row[k] -= t[k];
        }
    }
    let r = model.register_points(&pts, None, None).unwrap();
    assert_eq!(r.status, RegistrationStatus::Converged);
    // Noise: 3 mm / sqrt(1000) per plane normal, far below 1 mm.
    for k in 0..3 {
        assert!((r.pose[4 * k + 3] - t[k] as f64).abs() < 1e-3, "{:?}", r.pose);
        assert!((r.pose[5 * k] - 1.0).abs() < 1e-4);
    }
    assert!(r.inlier_ratio > 0.95 && r.unobservable == 0);

    let mut nan: Pose = [1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1.];
    nan[3] = f64::NAN;
    let e = model.register_points(&pts, Some(&nan), None).unwrap_err();
    assert_eq!(e.status(), Status::InvalidArg);
}

#[test]
fn model_to_model_recovers_a_translation() {
    let model = corner(30000);
    let t = [0.02f64, -0.01, 0.03];
    let back: Pose = [1., 0., 0., -t[0], 0., 1., 0., -t[1], 0., 0., 1., -t[2], 0., 0., 0., 1.];
    let moved = model.transform(&back).unwrap();
    let r = model.register_model(&moved, None, None).unwrap();
    assert_eq!(r.status, RegistrationStatus::Converged);
    // The optimum of a model against its own moved copy: t up to the copy's
    // float rounding (< 1 um in the core's test).
    for k in 0..3 {
        assert!((r.pose[4 * k + 3] - t[k]).abs() < 1e-4, "{:?}", r.pose);
        assert!((r.pose[5 * k] - 1.0).abs() < 1e-6);
    }
    assert!(r.inlier_ratio > 0.95 && r.unobservable == 0);
    let e = model.register_model(&corner(1), None, None).unwrap_err();
    assert_eq!(e.status(), Status::InvalidData);
    assert!(e.message().contains("min_points"), "{}", e.message());
}

// SOGMM_OPT_REGISTRATION_DEPTH_NOISE reaches the core through the options.
// The points are seen by a sensor 2 m before the corner (source frame =
// sensor frame, so rays cross the planes at an angle): drawn from the model
// itself, they score lower once each point's covariance is widened along its
// ray (the model they were drawn from maximises their expected
// log-likelihood), the pose still comes back, and a value above 1 per metre
// is an invalid argument.
#[test]
fn depth_noise_is_an_option() {
    let model = corner(1);
    let c = [0.5f32, 0.5, 2.0];
    let mut pts = model.sample(3000, 1, 4, None).unwrap();
    for row in pts.chunks_mut(4) {
        for k in 0..3 {
            row[k] += c[k];
        }
    }
    let mut init: Pose = [1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1.];
    for k in 0..3 {
        init[4 * k + 3] = -c[k] as f64;
    }
    let plain = model.register_points(&pts, Some(&init), None).unwrap();
    let noisy_options = Options::builder()
        .f64(sogmm::sys::SOGMM_OPT_REGISTRATION_DEPTH_NOISE, 0.002)
        .build()
        .unwrap();
    let noisy = model.register_points(&pts, Some(&init), Some(&noisy_options)).unwrap();
    assert_eq!(noisy.status, RegistrationStatus::Converged);
    assert!(
        noisy.log_likelihood < plain.log_likelihood,
        "{} against {}",
        noisy.log_likelihood,
        plain.log_likelihood
    );
    // Rays 8 mm wide at 2 m and the corner 2 m off the sensor, where a turn
    // of 1e-3 rad moves it by 2 mm: within 3 mm and 1e-3 of the truth.
    for k in 0..3 {
        assert!((noisy.pose[4 * k + 3] + c[k] as f64).abs() < 3e-3, "{:?}", noisy.pose);
        assert!((noisy.pose[5 * k] - 1.0).abs() < 1e-3, "{:?}", noisy.pose);
    }
    let e = Options::builder()
        .f64(sogmm::sys::SOGMM_OPT_REGISTRATION_DEPTH_NOISE, 2.0)
        .build()
        .unwrap_err();
    assert_eq!(e.status(), Status::InvalidArg);
}
