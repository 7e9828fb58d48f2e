//! `Model::render` and `Map::render`: the closed-form depth, gray and
//! variance of one component on the optical axis; the same images when model
//! and pose move together; a map renders as its export; progress, cancel and
//! bad input.
use std::ops::ControlFlow;

use sogmm::{Camera, Map, Model, Options, Pose, Queryable, Stage, Status};

const IDENTITY: Pose = [1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1.];
const CAM: Camera = Camera {
    width: 9,
    height: 7,
    fx: 10.0,
    fy: 12.0,
    cx: 4.0,
    cy: 3.0,
};
const CENTRE: usize = 3 * 9 + 4;

/// One component at (0, 0, 1.5), gray 0.4, gray correlated with x (cov 0.002):
/// along the central ray its density peaks at t = 1.5, where gray = 0.4 and
/// Var = 0.01 - 0.002^2 / 0.05^2.
fn on_axis() -> Model {
    let cov = [
        0.0025, 0., 0., 0.002, 0., 0.0016, 0., 0., 0., 0., 0.0001, 0., 0.002, 0., 0., 0.01,
    ];
    Model::from_arrays(&[1.0], &[0.0, 0.0, 1.5, 0.4], &cov, 100).unwrap()
}

#[test]
fn single_component_closed_form() {
    let r = on_axis().render(&CAM, None, None).unwrap();
    assert_eq!((r.width, r.height, r.depth.len()), (9, 7, 63));
    assert!((r.depth[CENTRE] - 1.5).abs() < 1e-5);
    assert!((r.gray[CENTRE] - 0.4).abs() < 1e-5);
    assert!((r.variance[CENTRE] as f64 - (0.01 - 0.002f64.powi(2) / 0.0025)).abs() < 1e-6);
    assert!(r.depth[0].is_nan() && r.gray[0].is_nan() && r.variance[0].is_nan());
    let near = Options::builder().depth_max(1.4).build().unwrap();
    assert!(on_axis().render(&CAM, None, Some(&near)).unwrap().depth[CENTRE].is_nan());
}

/// Two components (weights 0.5): A at (0.025, 0, 1), isotropic sigma 0.01,
/// gray 0.2; B a flat patch at (0, 0, 2) (sigma 0.1, 0.1, 0.01), gray 0.8.
/// The optical axis passes A at 2.5 sigma: at z = 1 the evidence
/// sum_k exp(-D_k^2 / 2) is exp(-3.125) = 0.044 (B is 100 sigma away), at
/// z = 2 it is 1. Surface sigma 0 shows A at 1 m (gray 0.2); s = 2 needs
/// exp(-2) = 0.135 there, so the ray passes on to B at 2 m (gray 0.8); s = 3
/// needs exp(-4.5) = 0.011 and shows A again.
#[test]
fn render_surface_sigma_passes_a_graze_on_to_the_surface_behind() {
    let cov = [
        1e-4, 0., 0., 0., 0., 1e-4, 0., 0., 0., 0., 1e-4, 0., 0., 0., 0., 0.01, //
        0.01, 0., 0., 0., 0., 0.01, 0., 0., 0., 0., 1e-4, 0., 0., 0., 0., 0.01,
    ];
    let m = Model::from_arrays(&[0.5, 0.5], &[0.025, 0., 1., 0.2, 0., 0., 2., 0.8], &cov, 100).unwrap();
    let axis = Camera {
        width: 1,
        height: 1,
        fx: 100.0,
        fy: 100.0,
        cx: 0.0,
        cy: 0.0,
    };
    for (s, depth, gray) in [(0.0, 1.0, 0.2), (2.0, 2.0, 0.8), (3.0, 1.0, 0.2)] {
        let o = Options::builder().render_surface_sigma(s).build().unwrap();
        let r = m.render(&axis, None, Some(&o)).unwrap();
        assert!(
            (r.depth[0] - depth).abs() < 1e-5 && (r.gray[0] - gray).abs() < 1e-5,
            "s {s}: {:?}",
            r
        );
    }
    let bad = Options::builder().render_surface_sigma(-1.0).build();
    assert_eq!(bad.unwrap_err().status(), Status::InvalidArg);
}

#[test]
fn moving_model_and_pose_together_renders_the_same() {
    // A rotation of 0.7 rad about (1, 1, 0) / sqrt 2 (Rodrigues) and a shift.
    let (c, s, r) = (0.7f64.cos(), 0.7f64.sin(), std::f64::consts::FRAC_1_SQRT_2);
    let t: Pose = [
        c + r * r * (1. - c),
        r * r * (1. - c),
        r * s,
        1.0,
        r * r * (1. - c),
        c + r * r * (1. - c),
        -r * s,
        -2.0,
        -r * s,
        r * s,
        c,
        0.5,
        0.,
        0.,
        0.,
        1.,
    ];
    let m = on_axis();
    let a = m.render(&CAM, None, None).unwrap();
    let b = m.transform(&t).unwrap().render(&CAM, Some(&t), None).unwrap();
    let mut shown = 0;
    for i in 0..a.depth.len() {
        assert_eq!(a.depth[i].is_nan(), b.depth[i].is_nan(), "pixel {i}");
        if a.depth[i].is_nan() {
            continue;
        }
        shown += 1;
        assert!(
            (a.depth[i] - b.depth[i]).abs() < 1e-5 && (a.gray[i] - b.gray[i]).abs() < 1e-5,
            "pixel {i}"
        );
    }
    assert!(shown > 0);
}

#[test]
fn map_renders_as_its_export_with_progress_and_cancel() {
    let cam = Camera {
        width: 40,
        height: 30,
        fx: 30.0,
        fy: 30.0,
        cx: 19.5,
        cy: 14.5,
    };
    let opts = Options::builder().map_batch_size(100_000).threads(2).build().unwrap();
    let mut map = Map::new(Some(&opts)).unwrap();
    assert_eq!(map.render(&cam, None, None).unwrap_err().status(), Status::InvalidData);
    // Points drawn from a model stand for a frame.
    let pts = on_axis().sample(3000, 7, 4, None).unwrap();
    map.insert_points(&pts, &IDENTITY).unwrap();
    map.flush().unwrap();
    let a = map.render(&cam, Some(&IDENTITY), Some(&opts)).unwrap();
    let last = std::sync::Arc::new(std::sync::Mutex::new(None));
    let sink = std::sync::Arc::clone(&last);
    let reporting = Options::builder()
        .on_progress(move |p| {
            *sink.lock().unwrap() = Some((p.stage, p.step));
            ControlFlow::Continue(())
        })
        .build()
        .unwrap();
    let b = map.export().unwrap().render(&cam, None, Some(&reporting)).unwrap();
    let bits = |v: &Vec<f32>| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&a.depth), bits(&b.depth));
    assert_eq!(bits(&a.gray), bits(&b.gray));
    assert!(a.depth.iter().any(|d| !d.is_nan()));
    assert_eq!(*last.lock().unwrap(), Some((Stage::Rendering, 30)));
    let stop = Options::builder()
        .on_progress(|_| ControlFlow::Break(()))
        .build()
        .unwrap();
    let cancelled = map.render(&cam, None, Some(&stop));
    assert_eq!(cancelled.unwrap_err().status(), Status::Cancelled);
}

#[test]
fn bad_input_is_an_error() {
    let m = on_axis();
    let mut scaled = IDENTITY;
    scaled[0] = 2.0;
    assert_eq!(
        m.render(&CAM, Some(&scaled), None).unwrap_err().status(),
        Status::InvalidArg
    );
    let zero = Camera { width: 0, ..CAM };
    assert_eq!(m.render(&zero, None, None).unwrap_err().status(), Status::InvalidArg);
    let flat = Camera { fx: 0.0, ..CAM };
    assert_eq!(m.render(&flat, None, None).unwrap_err().status(), Status::InvalidArg);
    let huge = Camera {
        width: 20000,
        height: 20000,
        ..CAM
    };
    assert_eq!(m.render(&huge, None, None).unwrap_err().status(), Status::Limit);
    let reversed = Options::builder().depth_min(2.0).depth_max(1.0).build().unwrap();
    assert_eq!(
        m.render(&CAM, None, Some(&reversed)).unwrap_err().status(),
        Status::InvalidArg
    );
}
