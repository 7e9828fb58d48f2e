"""GMM.render and Map.render (sogmm_model_render_f32, sogmm_map_render_f32):
the closed-form depth, gray and variance of one component on the optical
axis; a fitted plane rendered at the plane; the same images when model and
pose move together; a map renders bitwise as its export; progress, cancel
and bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

import sogmm
from sogmm.progress import STAGE_RENDERING

from conftest import blobs

CAM = sogmm.Camera(width=9, height=7, fx=10.0, fy=12.0, cx=4.0, cy=3.0)


def on_axis() -> sogmm.GMM:
    """One component at (0, 0, 1.5), gray 0.4, gray correlated with x (cov 0.002)."""
    cov = np.diag([0.05**2, 0.04**2, 0.01**2, 0.01]).astype(np.float32)
    cov[0, 3] = cov[3, 0] = 0.002
    return sogmm.GMM.from_arrays([1.0], [[0.0, 0.0, 1.5, 0.4]], [cov], support_size=100)


def rotation(axis, angle) -> np.ndarray:
    a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def test_single_component_closed_form():
    depth, gray, var = on_axis().render(CAM)
    assert depth.shape == gray.shape == var.shape == (7, 9) and depth.dtype == np.float32
    # The central ray (0, 0, 1) passes through the mean: the ray's density peaks at t = 1.5; there
    # x = mu, so gray = 0.4 and Var = 0.01 - 0.002^2 / 0.05^2.
    assert depth[3, 4] == pytest.approx(1.5, abs=1e-5)
    assert gray[3, 4] == pytest.approx(0.4, abs=1e-5)
    assert var[3, 4] == pytest.approx(0.01 - 0.002**2 / 0.05**2, abs=1e-6)
    assert np.isnan(depth[0, 0]) and np.isnan(gray[0, 0]) and np.isnan(var[0, 0])  # far off every component
    near, _, _ = on_axis().render(CAM, depth_trunc=1.4)
    assert np.isnan(near[3, 4])


def test_fitted_plane_is_rendered_at_the_plane():
    # A regular grid on the plane z = 1.5 + 0.2 x, gray a ramp in y (no randomness).
    x, y = np.meshgrid(np.arange(-0.4, 0.401, 0.01), np.arange(-0.3, 0.301, 0.01))
    pts = np.stack([x.ravel(), y.ravel(), 1.5 + 0.2 * x.ravel(), 0.5 + y.ravel()], axis=1).astype(np.float32)
    model = sogmm.SOGMM(bandwidth=0.05, seed=1).fit(pts)
    cam = sogmm.Camera(width=40, height=30, fx=40.0, fy=40.0, cx=19.5, cy=14.5)
    depth, gray, _ = model.render(cam)
    u, v = np.meshgrid(np.arange(40), np.arange(30))
    dx, dy = (u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy
    t = 1.5 / (1 - 0.2 * dx)  # where the pixel's ray meets the plane
    inside = (np.abs(t * dx) < 0.3) & (np.abs(t * dy) < 0.2)
    assert inside.sum() > 100
    assert not np.isnan(depth[inside]).any()
    assert np.abs(depth[inside] - t[inside]).max() < 0.005
    assert np.abs(gray[inside] - (0.5 + t * dy)[inside]).max() < 0.03


def test_moving_model_and_pose_together_renders_the_same():
    T = np.eye(4)
    T[:3, :3] = rotation([1, 1, 0], 0.7)
    T[:3, 3] = [1.0, -2.0, 0.5]
    m = on_axis()
    a = m.render(CAM)
    b = m.transform(T).render(CAM, T)
    assert np.array_equal(np.isnan(a[0]), np.isnan(b[0]))
    shown = ~np.isnan(a[0])
    assert shown.sum() > 0
    for x, y, tol in zip(a, b, (1e-5, 1e-5, 1e-6)):
        assert np.abs(x[shown] - y[shown]).max() <= tol


def test_map_renders_as_its_export_and_reports_progress():
    m = sogmm.Map(batch_size=100000, bandwidth=0.08, seed=3, n_threads=2)
    cam = sogmm.Camera(width=40, height=30, fx=30.0, fy=30.0, cx=19.5, cy=14.5)
    with pytest.raises(sogmm.InvalidDataError):
        m.render(cam)  # nothing flushed yet
    m.insert_points(blobs(n_per=300, seed=0), np.eye(4))
    m.flush()
    seen = []
    d1, g1, v1 = m.render(cam, n_threads=2)
    d2, g2, v2 = m.export().render(cam, n_threads=1, progress=lambda *r: seen.append(r))
    for x, y in ((d1, d2), (g1, g2), (v1, v2)):
        assert x.tobytes() == y.tobytes()  # NaN included: the same bits
    assert (~np.isnan(d1)).sum() > 0
    assert seen and all(s[0] == STAGE_RENDERING and s[2] == 30 for s in seen) and seen[-1][1] == 30
    with pytest.raises(sogmm.CancelledError):
        m.render(cam, progress=lambda *r: True)
    m.close()


# Two components (weights 0.5): A at (0.025, 0, 1), isotropic sigma 0.01, gray 0.2; B a flat patch at
# (0, 0, 2) (sigma 0.1, 0.1, 0.01), gray 0.8. The optical axis passes A at 2.5 sigma: at z = 1 the
# evidence sum_k exp(-D_k^2 / 2) is exp(-3.125) = 0.044 (B is 100 sigma away), at z = 2 it is 1 (A is
# 100 sigma away). surface_sigma 0 shows A's mode at 1 m (gray 0.2); s = 2 needs exp(-2) = 0.135 there,
# so the ray passes on to B at 2 m (gray 0.8); s = 3 needs exp(-4.5) = 0.011 and shows A again.
def test_surface_sigma_passes_a_graze_on_to_the_surface_behind():
    cov_a = np.diag([1e-4, 1e-4, 1e-4, 0.01]).astype(np.float32)
    cov_b = np.diag([0.01, 0.01, 1e-4, 0.01]).astype(np.float32)
    model = sogmm.GMM.from_arrays([0.5, 0.5], [[0.025, 0.0, 1.0, 0.2], [0.0, 0.0, 2.0, 0.8]], [cov_a, cov_b],
                                  support_size=100)
    axis = sogmm.Camera(width=1, height=1, fx=100.0, fy=100.0, cx=0.0, cy=0.0)
    for s, want_depth, want_gray in ((0.0, 1.0, 0.2), (2.0, 2.0, 0.8), (3.0, 1.0, 0.2)):
        depth, gray, _ = model.render(axis, surface_sigma=s)
        assert depth[0, 0] == pytest.approx(want_depth, abs=1e-5), s
        assert gray[0, 0] == pytest.approx(want_gray, abs=1e-5), s
    with pytest.raises(sogmm.InvalidArgumentError, match="surface_sigma"):
        model.render(axis, surface_sigma=-1.0)


def test_bad_input_raises():
    m = on_axis()
    with pytest.raises(sogmm.InvalidArgumentError):
        m.render((9, 7, 10.0, 12.0, 4.0, 3.0))  # not a Camera
    with pytest.raises(sogmm.InvalidArgumentError):
        m.render(CAM, np.diag([2.0, 1.0, 1.0, 1.0]))  # a scale, not a rigid pose
    with pytest.raises(sogmm.InvalidArgumentError):
        m.render(CAM, np.eye(3))
    with pytest.raises(sogmm.InvalidArgumentError):
        m.render(CAM, depth_min=2.0, depth_trunc=1.0)
    with pytest.raises(sogmm.LimitError):
        m.render(sogmm.Camera(width=20000, height=20000, fx=1.0, fy=1.0, cx=0.0, cy=0.0))
