"""Files, bytes, pickling and PLY output."""

from __future__ import annotations

import copy
import os
import pickle

import numpy as np
import pytest

import sogmm

from conftest import mean_moves_in_sigmas, synthetic_rgbd


def _assert_bit_exact(a, b):
    for name in ("weights_", "means_", "covariances_"):
        x, y = getattr(a, name), getattr(b, name)
        assert x.dtype == y.dtype and x.shape == y.shape
        assert x.tobytes() == y.tobytes(), name


@pytest.fixture(scope="module")
def rgbd_model():
    depth, color, cam = synthetic_rgbd()
    m = sogmm.SOGMM(bandwidth=0.05, seed=9).fit_rgbd(depth, color, cam, decimate=2)
    m.pose = np.array([[0, -1, 0, 1.0], [1, 0, 0, 2.0], [0, 0, 1, 3.0], [0, 0, 0, 1]], float)
    m.set_metadata("sequence", "synthetic")
    return m


def test_save_load_roundtrip(rgbd_model, tmp_path):
    p = tmp_path / "m.sogmm"
    rgbd_model.save(p)
    g = sogmm.load(p)
    assert isinstance(g, sogmm.GMM)
    _assert_bit_exact(g, rgbd_model)
    assert g.n_iter_ == rgbd_model.n_iter_ and g.lower_bound_ == rgbd_model.lower_bound_
    assert g.converged_ == rgbd_model.converged_ and g.support_size_ == rgbd_model.support_size_
    assert g.camera_ == rgbd_model.camera_
    np.testing.assert_array_equal(g.pose, rgbd_model.pose)
    # the fit records its regulariser (spec/format.md 2.4)
    assert g.metadata == {"reg_covar_gray": "1e-06", "reg_covar_source": "auto", "sequence": "synthetic"}
    assert "fit_seconds_total" not in g.info()  # timings are not stored
    # str paths and float64 / uncompressed storage work too.
    rgbd_model.save(str(tmp_path / "m64.sogmm"), float64=True, compress=False)
    _assert_bit_exact(sogmm.GMM.load(str(tmp_path / "m64.sogmm")), rgbd_model)
    assert not [f for f in os.listdir(tmp_path) if f not in ("m.sogmm", "m64.sogmm")]  # no temporary files left


def test_bytes_roundtrip(rgbd_model):
    b = rgbd_model.to_bytes()
    assert isinstance(b, bytes) and len(b) > 100
    for data in (b, bytearray(b), memoryview(b)):
        _assert_bit_exact(sogmm.from_bytes(data), rgbd_model)
    assert sogmm.from_bytes(b).to_bytes()[:4] == b[:4]


def test_pickle_roundtrip(rgbd_model, fitted):
    for m in (rgbd_model, fitted, sogmm.GMM.from_arrays([1.0], [[0, 0, 1, 0.5]], [np.eye(4) * 0.01])):
        for proto in (2, pickle.HIGHEST_PROTOCOL):
            r = pickle.loads(pickle.dumps(m, protocol=proto))
            assert type(r) is type(m)
            _assert_bit_exact(r, m)
    r = pickle.loads(pickle.dumps(rgbd_model))
    assert r.get_params() == rgbd_model.get_params()
    assert r.camera_ == rgbd_model.camera_
    np.testing.assert_array_equal(r.score_samples(rgbd_model.means_), rgbd_model.score_samples(rgbd_model.means_))
    unfitted = pickle.loads(pickle.dumps(sogmm.SOGMM(bandwidth=0.07, n_components=3)))
    assert unfitted.bandwidth == 0.07 and unfitted.n_components == 3 and not hasattr(unfitted, "means_")


def test_copies_are_independent(rgbd_model):
    c = copy.deepcopy(rgbd_model)
    _assert_bit_exact(c, rgbd_model)
    c.set_metadata("sequence", "changed")
    assert rgbd_model.metadata["sequence"] == "synthetic"
    assert copy.copy(rgbd_model)._ptr != rgbd_model._ptr


def test_file_errors(rgbd_model, tmp_path):
    missing = tmp_path / "does-not-exist.sogmm"
    with pytest.raises(sogmm.SogmmIOError) as e:
        sogmm.load(missing)
    assert isinstance(e.value, OSError) and e.value.status == -5 and e.value.message
    with pytest.raises(sogmm.SogmmIOError):
        rgbd_model.save(tmp_path / "no-such-folder" / "m.sogmm")
    text = tmp_path / "text.sogmm"
    text.write_text("hello, this is not a model\n" * 10)
    with pytest.raises(sogmm.FormatError):
        sogmm.load(text)
    good = rgbd_model.to_bytes()
    half = tmp_path / "half.sogmm"
    half.write_bytes(good[: len(good) // 2])
    with pytest.raises(sogmm.FormatError):
        sogmm.load(half)
    with pytest.raises(sogmm.FormatError):
        sogmm.from_bytes(b"")
    with pytest.raises(sogmm.LimitError):
        sogmm.from_bytes(good, max_decoded_bytes=16)
    with pytest.raises(sogmm.InvalidArgumentError):
        sogmm.from_bytes("a string")
    with pytest.raises(sogmm.InvalidArgumentError):
        rgbd_model.save(tmp_path / "x.sogmm", zstd_level=99)


def test_write_ply(fitted, tmp_path):
    pts = fitted.sample(1000, seed=1)
    pts[0, 3] = 1.7  # out-of-range gray is clipped in the colour only
    p = tmp_path / "s.ply"
    sogmm.write_ply(p, pts)
    raw = p.read_bytes()
    assert raw.startswith(b"ply\nformat binary_little_endian 1.0\n")
    header_end = raw.index(b"end_header\n") + len(b"end_header\n")
    for line in (b"element vertex 1000", b"property float x", b"property float intensity", b"property uchar red"):
        assert line in raw[:header_end]
    assert len(raw) - header_end == 1000 * (4 * 4 + 3)
    back = sogmm.read_ply(p)
    np.testing.assert_array_equal(back, pts)
    rec = np.frombuffer(raw, offset=header_end, dtype=[("f", "<f4", 4), ("c", "u1", 3)])
    expected = np.rint(np.clip(pts[:, 3], 0, 1) * 255).astype(np.uint8)
    np.testing.assert_array_equal(rec["c"][:, 0], expected)
    np.testing.assert_array_equal(rec["c"][:, 2], expected)
    # Atomic: an overwrite replaces the file, and no temporary is left behind.
    sogmm.write_ply(p, pts[:10])
    assert sogmm.read_ply(p).shape == (10, 4)
    assert os.listdir(tmp_path) == ["s.ply"]
    with pytest.raises(OSError):
        sogmm.write_ply(tmp_path / "missing-dir" / "s.ply", pts)
    with pytest.raises(sogmm.InvalidArgumentError):
        sogmm.write_ply(p, pts[:, :3])
    assert sogmm.read_ply(p).shape == (10, 4)  # a failed write leaves the old file


def test_component_precision_codes_each_mean_within_its_bound(rgbd_model, tmp_path):
    """SOGMM_OPT_ARRAY_PRECISION (``component_precision``; spec/api.md): at
    precision P a saved component's mean moves by at most P of its own
    standard deviations, |L^-1 (mu' - mu)| <= P with S = L L^T the saved
    covariance. The encoder checks that bound on the decoded float32 values
    before writing; numpy recomputes it in binary64 (its rounding, ~1e-15
    relative, is inside the 1e-9 allowed). Mutation tried: the keyword passed
    as the map's MAP_COMPONENT_PRECISION (630) leaves the file uncoded, and
    the size and "some mean moved" checks fail."""
    exact, coded = tmp_path / "exact.sogmm", tmp_path / "coded.sogmm"
    rgbd_model.save(exact, component_precision=0)
    rgbd_model.save(coded, component_precision=0.5)
    assert coded.stat().st_size < exact.stat().st_size
    assert rgbd_model.to_bytes(component_precision=0.5) == coded.read_bytes()
    _assert_bit_exact(sogmm.load(exact), rgbd_model)  # 0: float arrays, bit-exact

    sigmas = mean_moves_in_sigmas(rgbd_model, sogmm.load(coded))
    assert sigmas.max() <= 0.5 * (1 + 1e-9), sigmas.max()
    assert sigmas.max() > 0, "the means were stored as codes, not bit for bit"

    # Out of range: InvalidArgumentError naming the keyword, nothing written.
    before = coded.read_bytes()
    for bad in (0.7, -1.0, float("nan")):
        with pytest.raises(sogmm.InvalidArgumentError, match="component_precision"):
            rgbd_model.save(coded, component_precision=bad)
        assert coded.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["coded.sogmm", "exact.sogmm"]  # no temporary file left
