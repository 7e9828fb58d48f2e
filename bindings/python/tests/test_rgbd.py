"""RGB-D frames: Camera, rgbd_to_points against the C library's own
back-projection (through sogmm_fit_rgbd), and the C++ CLI as a reference."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import sogmm

from conftest import REPO_ROOT, synthetic_rgbd


def _same_model(a, b):
    for name in ("weights_", "means_", "covariances_"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.lower_bound_ == b.lower_bound_ and a.n_iter_ == b.n_iter_


# ---- Camera ---------------------------------------------------------------
def test_camera_json_roundtrip(tmp_path):
    cam = sogmm.Camera(640, 480, 525.0, 526.0, 319.5, 239.5)
    p = tmp_path / "intr.json"
    p.write_text(cam.to_json())
    assert sogmm.Camera.from_json(p) == cam
    assert sogmm.Camera.from_json(str(p)) == cam
    np.testing.assert_array_equal(cam.intrinsic_matrix, [[525, 0, 319.5], [0, 526, 239.5], [0, 0, 1]])


def test_camera_json_errors(tmp_path):
    with pytest.raises(FileNotFoundError):
        sogmm.Camera.from_json(tmp_path / "missing.json")
    bad = tmp_path / "bad.json"
    for text, needle in [("{", "not valid JSON"), ('{"width": 640, "height": 480}', "intrinsic_matrix"),
                         ('{"width": 640, "height": 480, "intrinsic_matrix": [1, 2]}', "9 numbers"),
                         ('{"width": 0, "height": 480, "intrinsic_matrix": [1,0,0,0,1,0,0,0,1]}', "width"),
                         ('{"width": 64, "height": 48, "intrinsic_matrix": [-1,0,0,0,1,0,0,0,1]}', "fx")]:
        bad.write_text(text)
        with pytest.raises(sogmm.FormatError, match=needle):
            sogmm.Camera.from_json(bad)


def test_camera_json_refuses_a_fifo_at_once(tmp_path):
    # Opening a FIFO for reading waits for a writer: a child process with a
    # time limit turns a hang into a failure instead of blocking the suite.
    fifo = tmp_path / "intr.fifo"
    os.mkfifo(fifo)
    code = (f"import sogmm\ntry:\n    sogmm.Camera.from_json({str(fifo)!r})\n"
            "except sogmm.SogmmIOError as e:\n    print(e)\n")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert p.returncode == 0 and "it is a FIFO, not a regular file" in p.stdout, p.stdout + p.stderr


def test_camera_validation():
    with pytest.raises(sogmm.InvalidArgumentError):
        sogmm.Camera(640, 480, 0.0, 525.0, 319.5, 239.5)
    with pytest.raises(sogmm.InvalidArgumentError):
        sogmm.Camera(640, 480, 525.0, 525.0, float("nan"), 239.5)
    with pytest.raises(sogmm.InvalidArgumentError):
        sogmm.Camera(640.5, 480, 525.0, 525.0, 319.5, 239.5)


# ---- back-projection -------------------------------------------------------
def test_rgbd_to_points_formula():
    depth = np.zeros((4, 6), np.uint16)
    depth[1, 2] = 1500
    depth[3, 5] = 4000  # beyond depth_trunc
    depth[0, 0] = 50  # below depth_min
    color = np.full((4, 6), 51, np.uint8)
    cam = sogmm.Camera(6, 4, 2.0, 4.0, 1.0, 2.0)
    p = sogmm.rgbd_to_points(depth, color, cam)
    assert p.shape == (1, 4) and p.dtype == np.float32
    np.testing.assert_allclose(p[0], [(2 - 1.0) * 1.5 / 2.0, (1 - 2.0) * 1.5 / 4.0, 1.5, 0.2], rtol=1e-6)
    rgb = np.zeros((4, 6, 3), np.uint8)
    rgb[1, 2] = [255, 0, 0]
    assert sogmm.rgbd_to_points(depth, rgb, cam)[0, 3] == pytest.approx(0.299, abs=1e-6)
    gray_f = np.full((4, 6), 0.75, np.float64)
    assert sogmm.rgbd_to_points(depth, gray_f, cam)[0, 3] == pytest.approx(0.75)
    assert sogmm.rgbd_to_points(depth, color, cam, depth_trunc=5.0).shape == (2, 4)


@pytest.mark.parametrize("decimate", [1, 2, 3, 7])
def test_rgbd_to_points_is_what_the_c_library_fits(decimate):
    """Fitting rgbd_to_points' output (sogmm_rgbd_to_points_f32) gives bit
    for bit the model that sogmm_fit_rgbd fits."""
    depth, color, cam = synthetic_rgbd()
    kw = dict(depth_scale=1000.0, depth_min=0.1, depth_trunc=3.0, decimate=decimate)
    pts = sogmm.rgbd_to_points(depth, color, cam, **kw)
    assert pts.shape[0] > 20
    n = min(8, pts.shape[0])
    a = sogmm.SOGMM(n_components=n, seed=4).fit_rgbd(depth, color, cam, **kw)
    b = sogmm.SOGMM(n_components=n, seed=4).fit(pts)
    assert a.support_size_ == pts.shape[0] == a.info()["fit_n_points"]
    _same_model(a, b)
    gray = color[:, :, 0]
    c = sogmm.SOGMM(n_components=n, seed=4).fit_rgbd(depth, gray, cam, **kw)
    d = sogmm.SOGMM(n_components=n, seed=4).fit(sogmm.rgbd_to_points(depth, gray, cam, **kw))
    _same_model(c, d)


def test_fit_rgbd_records_the_camera():
    depth, color, cam = synthetic_rgbd()
    m = sogmm.SOGMM(bandwidth=0.05).fit_rgbd(depth, color, cam, depth_scale=1000.0, depth_trunc=2.5, decimate=2)
    assert m.camera_ == cam
    info = m.info()
    assert info["camera_decimation"] == 2 and info["camera_depth_max"] == 2.5
    # Float gray (e.g. a normalised thermal image) goes to the C library too and
    # records the camera; gray8 / 255 in float32 is the same model as gray8.
    gray8 = np.ascontiguousarray(color[:, :, 1])
    g = sogmm.SOGMM(bandwidth=0.05, seed=2).fit_rgbd(depth, gray8.astype(np.float32) / np.float32(255), cam, decimate=2)
    assert g.camera_ == cam and g.support_size_ > 0
    _same_model(g, sogmm.SOGMM(bandwidth=0.05, seed=2).fit_rgbd(depth, gray8, cam, decimate=2))
    bad = gray8.astype(np.float32) / 255
    bad[3, 4] = np.nan
    with pytest.raises(sogmm.InvalidDataError, match="not finite"):
        sogmm.SOGMM().fit_rgbd(depth, bad, cam)
    with pytest.raises(sogmm.InvalidDataError, match="not finite"):
        sogmm.rgbd_to_points(depth, bad, cam)


# ---- real frames -------------------------------------------------------------
def test_livingroom_fit(livingroom):
    depth, color, cam, _ = livingroom
    assert depth.dtype == np.uint16 and color.shape == (480, 640, 3)
    m = sogmm.SOGMM(bandwidth=0.02, seed=0).fit_rgbd(depth, color, cam, decimate=5)
    pts = sogmm.rgbd_to_points(depth, color, cam, decimate=5)
    assert m.support_size_ == pts.shape[0] > 5000
    assert 50 < m.n_components_ < 5000
    assert m.converged_
    assert m.score(pts) == pytest.approx(m.lower_bound_, abs=0.05)
    # The same points fitted through sogmm_fit_points_f32 with the depth floor
    # that fit_rgbd applies by default: the same model.
    _same_model(m, sogmm.SOGMM(bandwidth=0.02, seed=0, dequantise_depth=True).fit(pts))
    # Gray regression reproduces the image's gray reasonably.
    mean, _ = m.regress_gray(pts[:, :3])
    assert np.abs(mean - pts[:, 3]).mean() < 0.08


def _cli() -> Path | None:
    found = [p for p in REPO_ROOT.glob("build*/tools/sogmm/sogmm") if p.is_file() and "asan" not in str(p)]
    found.sort(key=lambda p: p.stat().st_mtime, reverse=True)
    if found:
        return found[0]
    which = shutil.which("sogmm")
    return Path(which) if which else None


def test_livingroom_agrees_with_the_cpp_cli(livingroom):
    depth, color, cam, folder = livingroom
    cli = _cli()
    if cli is None:
        pytest.skip("the C++ CLI (build*/tools/sogmm/sogmm) is not built: no C++ reference to compare with")
    r = subprocess.run([str(cli), "eval", "--depth", str(folder / "depth" / "00000.png"),
                        "--color", str(folder / "color" / "00000.jpg"), "--intrinsics", str(folder / "intrinsics.json"),
                        "--decimate", "5", "--bandwidth", "0.02", "--seed", "0", "--json"],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    ref = json.loads(r.stdout.strip().splitlines()[-1])
    m = sogmm.SOGMM(bandwidth=0.02, seed=0).fit_rgbd(depth, color, cam, decimate=5)
    assert m.support_size_ == ref["n_points"]
    # Pillow and OpenCV decode the JPEG to the same pixels on this machine; if
    # a decoder ever differs, the gray values (not the depth) change a little.
    assert m.n_components_ == pytest.approx(ref["n_components"], rel=0.02)
    assert m.lower_bound_ == pytest.approx(ref["log_likelihood"], abs=0.02)
    assert m.converged_ == ref["converged"]


def test_frame_over_the_point_limit_is_refused_from_its_size():
    # 8200 x 8200 > 2^26 pixels: refused before the frame is read (np.zeros
    # pages stay untouched), with the size in the message.
    depth = np.zeros((8200, 8200), np.uint16)
    color = np.zeros((8200, 8200), np.uint8)
    cam = sogmm.Camera(8200, 8200, 7000.0, 7000.0, 4100.0, 4100.0)
    with pytest.raises(sogmm.LimitError, match="67240000"):
        sogmm.SOGMM().fit_rgbd(depth, color, cam)
    with pytest.raises(sogmm.LimitError, match="67240000"):
        sogmm.rgbd_to_points(depth, color, cam)


def test_intrinsics_that_back_project_to_infinity_are_refused():
    depth = np.full((4, 4), 1000, np.uint16)
    color = np.full((4, 4), 128, np.uint8)
    with pytest.raises(sogmm.InvalidArgumentError, match="fx"):
        sogmm.rgbd_to_points(depth, color, sogmm.Camera(4, 4, 1e-300, 3.0, 2.0, 2.0))
