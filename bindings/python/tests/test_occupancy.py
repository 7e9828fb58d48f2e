"""Map.occupancy and GMM/Map.surface_distance (issue 31) against a hand-made
scene: a plane at z = 2 m seen by a camera at the origin, so z = 1 is free,
z = 2 occupied, z = 3 (hidden) and points outside the frustum unknown; the
distance to the plane is |z - 2| and its gradient the plane's normal; a
single disc's distance in closed form; collision probability of a sphere
above the plane; bad input raises."""

from __future__ import annotations

import numpy as np
import pytest

import sogmm
from sogmm.progress import STAGE_SCORING

CAM = sogmm.Camera(64, 48, 50.0, 50.0, 31.5, 23.5)


@pytest.fixture(scope="module")
def plane_map():
    m = sogmm.Map(novelty=False, seed=0)
    m.insert_rgbd(np.full((48, 64), 2000, np.uint16), np.full((48, 64, 3), 128, np.uint8), CAM, np.eye(4))
    m.flush()
    yield m
    m.close()


def test_plane_is_free_occupied_and_unknown(plane_map):
    pts = np.array([[0, 0, 1], [0, 0, 2], [0, 0, 3], [5, 0, 2], [0, 0, -1]], np.float32)
    p, s = plane_map.occupancy(pts, return_state=True)
    assert s.dtype == np.uint8 and p.dtype == np.float64 and p.shape == (5,)
    assert list(s) == [sogmm.OCCUPANCY_FREE, sogmm.OCCUPANCY_OCCUPIED, sogmm.OCCUPANCY_UNKNOWN,
                       sogmm.OCCUPANCY_UNKNOWN, sogmm.OCCUPANCY_UNKNOWN]
    assert p[0] < 1e-6 and p[1] > 0.9
    assert p[2] == 0.5 and p[3] == 0.5 and p[4] == 0.5
    assert np.array_equal(plane_map.occupancy(pts), p)


def test_occupancy_options_reach_the_model(plane_map):
    # 3 cm in front of the surface: free with a 2 cm shell, occupied with a 5 cm one.
    pts = np.array([[0, 0, 1.97]], np.float32)
    assert plane_map.occupancy(pts, thickness=0.02)[0] < 0.5 < plane_map.occupancy(pts, thickness=0.05)[0]
    with pytest.raises(sogmm.InvalidArgumentError, match="surface_sigma"):
        plane_map.occupancy(pts, surface_sigma=0.0)


def test_map_without_camera_is_unknown():
    m = sogmm.Map(novelty=False, seed=0)
    rng = np.random.default_rng(0)
    pts = np.column_stack([rng.uniform(-1, 1, (500, 2)), np.full(500, 2.0), np.full(500, 0.5)]).astype(np.float32)
    m.insert_points(pts, np.eye(4))
    m.flush()
    p, s = m.occupancy(np.array([[0, 0, 1], [0, 0, 2]], np.float32), return_state=True)
    assert list(p) == [0.5, 0.5] and list(s) == [sogmm.OCCUPANCY_UNKNOWN] * 2


def test_plane_distance_and_gradient(plane_map):
    dz = np.array([-0.3, -0.05, -0.02, 0.02, 0.05, 0.3])
    pts = np.column_stack([np.full(6, 0.2), np.full(6, -0.1), 2.0 + dz]).astype(np.float32)
    d, g = plane_map.surface_distance(pts, gradient=True)
    np.testing.assert_allclose(d, np.abs(dz), atol=0.005)
    assert np.all(np.sign(dz) * g[:, 2] > np.cos(np.radians(10)))
    exported = plane_map.export()
    assert np.array_equal(exported.surface_distance(pts), d)
    seen = []
    d2 = exported.surface_distance(pts, progress=lambda stage, *_: seen.append(stage) and False)
    assert np.array_equal(d2, d) and STAGE_SCORING in seen


def test_disc_closed_form():
    # One flat component, standard deviations 0.1, 0.05, 0.001 m: the disc at
    # 2 sigma has semi-axes 0.2 and 0.1 in the plane z = 0.
    cov = np.zeros((1, 4, 4))
    cov[0] = np.diag([0.1 ** 2, 0.05 ** 2, 0.001 ** 2, 0.01])
    g = sogmm.GMM.from_arrays(np.ones(1), np.zeros((1, 4)), cov)
    pts = np.array([[0.02, 0.01, 0.3], [0.5, 0.0, 0.1]], np.float32)
    d, grad = g.surface_distance(pts, gradient=True)
    np.testing.assert_allclose(d, [0.3, np.hypot(0.3, 0.1)], atol=1e-6)
    np.testing.assert_allclose(grad[1], [0.3 / np.hypot(0.3, 0.1), 0, 0.1 / np.hypot(0.3, 0.1)], atol=1e-6)
    assert g.surface_distance(pts, disc_sigmas=1.0)[1] == pytest.approx(np.hypot(0.4, 0.1), abs=1e-6)


def test_bad_input_raises(plane_map):
    with pytest.raises(sogmm.InvalidDataError, match="index 3 is nan"):
        plane_map.occupancy(np.array([[0, 0, 1], [np.nan, 0, 1]], np.float32))
    with pytest.raises(sogmm.InvalidDataError, match="index 0 is inf"):
        plane_map.surface_distance(np.array([[np.inf, 0, 1]], np.float32))
    with pytest.raises(sogmm.InvalidArgumentError):
        plane_map.surface_distance(np.zeros((2, 4), np.float32))
    with pytest.raises(sogmm.InvalidDataError):
        sogmm.Map().surface_distance(np.zeros((1, 3), np.float32))
    assert plane_map.occupancy(np.zeros((0, 3), np.float32)).shape == (0,)


def test_collision_probability(plane_map):
    # Spheres of radius 0.1 m centred on the plane, then 2, 4, ... 20 cm in front of it.
    z = 2.0 - 0.02 * np.arange(11)
    centers = np.column_stack([np.full(11, 0.1), np.full(11, 0.05), z])
    shapes = np.broadcast_to(np.eye(3) * 0.01, (11, 3, 3))
    p = plane_map.collision_probability(centers, shapes)
    assert p[0] >= 0.99 and p[-1] <= 0.01
    assert np.all(np.diff(p) <= 1e-12)
    assert np.array_equal(plane_map.export().collision_probability(centers, shapes), p)
    with pytest.raises(sogmm.InvalidArgumentError, match="robot 1"):
        plane_map.collision_probability(centers[:2], np.stack([np.eye(3), -np.eye(3)]))
    with pytest.raises(sogmm.InvalidArgumentError):
        plane_map.collision_probability(centers, shapes[:3])
