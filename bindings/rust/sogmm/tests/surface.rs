//! `Map::occupancy`, `surface_distance` and `collision_probability` (issue
//! 31) on a plane at z = 2 m seen from the origin: z = 1 free, z = 2
//! occupied, z = 3 and outside the frustum unknown (0.5); the distance
//! |z - 2| and the plane's normal; spheres on and clear of the plane; bad input.
use sogmm::{
    Color, Frame, Map, Options, Pose, Queryable, Status, OCCUPANCY_FREE, OCCUPANCY_OCCUPIED, OCCUPANCY_UNKNOWN,
};

const IDENTITY: Pose = [1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1.];

fn plane_map() -> Map {
    let mut o = Options::new().unwrap();
    o.set_i64(sogmm::sys::SOGMM_OPT_MAP_NOVELTY, 0).unwrap();
    let mut m = Map::new(Some(&o)).unwrap();
    let (depth, gray) = (vec![2000u16; 64 * 48], vec![128u8; 64 * 48]);
    let frame = Frame {
        depth: &depth,
        color: Color::Gray8(&gray),
        width: 64,
        height: 48,
        fx: 50.0,
        fy: 50.0,
        cx: 31.5,
        cy: 23.5,
    };
    m.insert_frame(&frame, &IDENTITY).unwrap();
    m.flush().unwrap();
    m
}

#[test]
fn plane_occupancy_distance_and_collision() {
    let m = plane_map();
    let (p, s) = m
        .occupancy(&[0., 0., 1., 0., 0., 2., 0., 0., 3., 5., 0., 2.], None)
        .unwrap();
    assert_eq!(
        s,
        vec![OCCUPANCY_FREE, OCCUPANCY_OCCUPIED, OCCUPANCY_UNKNOWN, OCCUPANCY_UNKNOWN]
    );
    assert!(p[0] < 1e-6 && p[1] > 0.9 && p[2] == 0.5 && p[3] == 0.5, "{p:?}");
    let xyz = [0.2f32, -0.1, 1.7, 0.2, -0.1, 2.05];
    let (d, g) = m.surface_distance(&xyz, None).unwrap();
    assert!((d[0] - 0.3).abs() < 0.005 && (d[1] - 0.05).abs() < 0.005, "{d:?}");
    assert!(g[2] < -0.98 && g[5] > 0.98, "{g:?}");
    let exported = m.export().unwrap();
    assert_eq!(exported.surface_distance(&xyz, None).unwrap().0, d);
    let sphere = [0.01, 0., 0., 0., 0.01, 0., 0., 0., 0.01];
    let shapes: Vec<f64> = sphere.iter().chain(sphere.iter()).copied().collect();
    let c = m
        .collision_probability(&[0.1, 0.05, 2.0, 0.1, 0.05, 1.8], &shapes, None)
        .unwrap();
    assert!(c[0] >= 0.99 && c[1] <= 0.01, "{c:?}");
}

#[test]
fn bad_input_is_refused() {
    let m = plane_map();
    let e = m.occupancy(&[0., f32::NAN, 1.], None).unwrap_err();
    assert_eq!(e.status(), Status::InvalidData);
    let negative = [-0.01, 0., 0., 0., -0.01, 0., 0., 0., -0.01];
    let e = m.collision_probability(&[0., 0., 1.], &negative, None).unwrap_err();
    assert_eq!(e.status(), Status::InvalidArg);
    assert!(m.collision_probability(&[0., 0., 1.], &negative[..8], None).is_err());
    assert!(m.surface_distance(&[0., 0.], None).is_err());
}
