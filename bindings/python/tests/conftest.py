"""Shared fixtures of the sogmm Python tests.

The package under test is the importable `sogmm` (an installed wheel, or
PYTHONPATH=bindings/python/src as ctest sets it); when none is importable the
checkout's src/ folder is used. Real frames come from ../shared/data beside
the project root (or SOGMM_DATA_DIR); tests that need them skip, saying why,
when the folder is absent.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest

TESTS_DIR = Path(__file__).resolve().parent
REPO_ROOT = TESTS_DIR.parents[2]  # <repo>/bindings/python/tests

try:
    import sogmm  # noqa: F401
except ImportError:
    src = TESTS_DIR.parent / "src"
    if (src / "sogmm" / "__init__.py").is_file():
        sys.path.insert(0, str(src))
    import sogmm  # noqa: F401,E402


def pytest_report_header(config):
    return [f"sogmm package: {Path(sogmm.__file__).parent}", f"libsogmm: {sogmm.library_path()} ({sogmm.library_version()})",
            f"data: {data_dir()} ({'present' if data_dir().is_dir() else 'absent'})"]


def data_dir() -> Path:
    env = os.environ.get("SOGMM_DATA_DIR")
    if env:
        return Path(env)
    return REPO_ROOT.parent / "shared" / "data"


def header_path() -> Path:
    return REPO_ROOT / "capi" / "include" / "sogmm" / "sogmm.h"


def blobs(n_per=400, seed=0, centers=None, scale=0.03) -> np.ndarray:
    """Deterministic (n, 4) float32 points around a few (x, y, z, gray) centres."""
    rng = np.random.default_rng(seed)
    if centers is None:
        centers = [[0.0, 0.0, 1.0, 0.2], [0.4, 0.1, 1.4, 0.8], [-0.3, 0.3, 1.2, 0.5], [0.1, -0.3, 0.9, 0.4]]
    parts = [rng.normal(c, scale, size=(n_per, 4)) for c in centers]
    return np.concatenate(parts).astype(np.float32)


@pytest.fixture(scope="session")
def points() -> np.ndarray:
    return blobs()


@pytest.fixture(scope="session")
def fitted(points):
    return sogmm.SOGMM(bandwidth=0.08, seed=3).fit(points)


def synthetic_rgbd(width=101, height=77, seed=0):
    """A small tilted-plane frame with holes and out-of-range depth; odd sizes
    exercise the nearest-neighbour decimation."""
    rng = np.random.default_rng(seed)
    cam = sogmm.Camera(width, height, 0.9 * width, 0.85 * width, width / 2 - 0.3, height / 2 + 0.2)
    v, u = np.mgrid[0:height, 0:width]
    z_m = 1.0 + 0.01 * u + 0.005 * v + rng.normal(0, 0.003, (height, width))
    depth = np.round(z_m * 1000).astype(np.uint16)
    depth[rng.random((height, width)) < 0.1] = 0  # holes
    depth[:3, :] = 3500  # beyond depth_trunc
    color = rng.integers(0, 256, size=(height, width, 3), dtype=np.uint8)
    return depth, color, cam


@pytest.fixture(scope="session")
def livingroom():
    """(depth uint16, color RGB uint8, Camera) of livingroom frame 00000."""
    folder = data_dir() / "rgbd" / "livingroom"
    if not (folder / "depth" / "00000.png").is_file():
        pytest.skip(f"real RGB-D frames not found at {folder} (../shared/data is absent); synthetic tests still run")
    try:
        from PIL import Image
    except ImportError:
        pytest.skip("Pillow is not installed: cannot read the PNG/JPEG frames (pip install pillow)")
    depth = np.asarray(Image.open(folder / "depth" / "00000.png"))
    color = np.asarray(Image.open(folder / "color" / "00000.jpg").convert("RGB"))
    cam = sogmm.Camera.from_json(folder / "intrinsics.json")
    return depth, color, cam, folder


def mean_moves_in_sigmas(saved, back) -> np.ndarray:
    """Per component, how far a re-read mean moved in its own standard
    deviations, |L^-1 (mu' - mu)| with S = L L^T the saved covariance, in
    binary64 (the bound of SOGMM_OPT_ARRAY_PRECISION; numpy's rounding, ~1e-15
    relative, is far inside the 1e-9 the tests allow)."""
    d = back.means_.astype(np.float64) - saved.means_.astype(np.float64)
    lower = np.linalg.cholesky(saved.covariances_.astype(np.float64))
    return np.linalg.norm(np.linalg.solve(lower, d[:, :, None])[:, :, 0], axis=1)
