"""sogmm.Map (the C API's sogmm_map_*): append-everything equals per-frame fits
merged by hand, revisits add nothing, bad input raises, files round-trip."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

import sogmm

from conftest import blobs, mean_moves_in_sigmas, synthetic_rgbd


def rigid(yaw_deg: float, t) -> np.ndarray:
    a = math.radians(yaw_deg)
    p = np.eye(4)
    p[:3, :3] = [[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]]
    p[:3, 3] = t
    return p


FIT = dict(bandwidth=0.08, seed=3, n_threads=1)
POSES = [rigid(0, [0, 0, 0]), rigid(20, [0.3, -0.1, 0.2])]


def frames():
    return [blobs(n_per=300, seed=0), blobs(n_per=300, seed=1)]


def test_append_everything_is_the_merge_of_each_frames_fit():
    # Independent truth: fit each frame alone, move it by its pose, merge (GMM API).
    expected = None
    for pts, pose in zip(frames(), POSES):
        g = sogmm.SOGMM(**FIT).fit(pts).transform(pose)
        expected = g if expected is None else expected.merge(g)
    with sogmm.Map(novelty=False, **FIT) as m:
        for pts, pose in zip(frames(), POSES):
            st = m.insert_points(pts, pose)
            assert st["n_points"] == len(pts) and st["n_novel"] == len(pts) and st["flushed"]
            np.testing.assert_array_equal(st["pose"], pose)
        assert m.n_pending_ == 0 and len(m) == 2
        got = m.export()
    assert got.n_components_ == expected.n_components_
    np.testing.assert_array_equal(got.weights_, expected.weights_)
    np.testing.assert_array_equal(got.means_, expected.means_)
    np.testing.assert_array_equal(got.covariances_, expected.covariances_)
    assert got.support_size_ == sum(len(p) for p in frames())
    assert got.metadata.get("coordinate_frame") == "world"


def test_a_revisited_frame_is_not_novel():
    # Four blobs of sigma 3 cm, far apart: a point's score renormalises over
    # its own blob's component, so at the centre log p(x) = -1.5 log(2 pi)
    # - 3 log 0.03 = 7.76 nats and a point is novel (< 3 nats) when its
    # squared Mahalanobis distance exceeds 9.52: P(chi2_3 > 9.52) = 2.3%.
    pts = blobs(n_per=300, seed=0)
    with sogmm.Map(batch_size=len(pts), **FIT) as m:
        first = m.insert_points(pts, POSES[1])
        assert first["n_novel"] == len(pts) and first["flushed"]
        k = m.n_components_
        again = m.insert_points(blobs(n_per=300, seed=5), POSES[1])  # same scene, new noise
        assert 0.01 * len(pts) < again["n_novel"] < 0.06 * len(pts), again
        # Only the novel tail points are fitted and appended.
        assert m.flush() > 0 and m.n_components_ > k
        assert m.export().support_size_ == len(pts) + again["n_novel"]
        # Points 1 m away from everything are novel.
        far = pts.copy()
        far[:, 0] += 3.0
        assert m.insert_points(far, POSES[1])["n_novel"] == len(pts)


def test_novel_points_wait_for_a_full_batch():
    pts = blobs(n_per=100, seed=0)
    with sogmm.Map(batch_size=1000, **FIT) as m:
        st = m.insert_points(pts, POSES[0])
        assert not st["flushed"] and m.n_pending_ == len(pts) and m.n_components_ == 0
        with pytest.raises(sogmm.SogmmError):
            m.export()  # nothing fitted yet
        assert m.flush() > 0 and m.n_pending_ == 0


@pytest.mark.parametrize(
    "pose, why",
    [(np.diag([2.0, 1, 1, 1]), "scaled"), (np.full((4, 4), np.nan), "nan"),
     (np.array([[1, 0, 0, np.inf], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]), "inf")],
)
def test_a_bad_pose_raises_and_changes_nothing(pose, why):
    with sogmm.Map(**FIT) as m:
        with pytest.raises(sogmm.InvalidArgumentError):
            m.insert_points(blobs(n_per=50), pose)
        assert len(m) == 0 and m.n_pending_ == 0


def test_bad_frames_raise():
    with sogmm.Map(decimate=2, **FIT) as m:
        with pytest.raises(sogmm.InvalidDataError):
            m.insert_points(np.zeros((0, 4), np.float32), np.eye(4))
        with pytest.raises(sogmm.InvalidArgumentError):
            m.insert_points(np.zeros((5, 3), np.float32), np.eye(4))  # 3 columns
        depth, color, cam = synthetic_rgbd()
        m.insert_rgbd(depth, color, cam, np.eye(4))
        depth2, color2, cam2 = synthetic_rgbd(width=90, height=77)
        with pytest.raises(sogmm.InvalidArgumentError):
            m.insert_rgbd(depth2, color2, cam2, np.eye(4))  # another frame size
        with pytest.raises(sogmm.InvalidDataError):
            m.insert_rgbd(np.zeros_like(depth), color, cam, np.eye(4))  # no valid pixel
        assert len(m) == 1
    with pytest.raises(sogmm.InvalidArgumentError):
        sogmm.Map(fusion="average")
    with pytest.raises(sogmm.InvalidArgumentError):
        sogmm.Map(batch_size=0)


def test_save_load_and_box(tmp_path):
    path = tmp_path / "map.sogmm"
    with sogmm.Map(novelty=False, **FIT) as m:
        for pts, pose in zip(frames(), POSES):
            m.insert_points(pts, pose)
        m.save(path)
        whole = m.export()
        # The box around the first blob of frame 0 keeps fewer components, renormalised.
        part = m.export([-0.1, -0.1, 0.9, 0.1, 0.1, 1.1])
        assert 0 < part.n_components_ < whole.n_components_
        assert abs(float(part.weights_.sum()) - 1.0) < 1e-4
        with pytest.raises(sogmm.InvalidArgumentError):
            m.export([1, 1, 1, 0, 0, 0])  # min > max
    with sogmm.Map.load(path) as back:
        assert len(back) == 2
        np.testing.assert_array_equal(back.frame_stats(1)["pose"], POSES[1])
        got = back.export()
        np.testing.assert_array_equal(got.weights_, whole.weights_)
        np.testing.assert_array_equal(got.means_, whole.means_)
        # World-frame queries are those of the exported model.
        x = whole.means_[:5, :3]
        np.testing.assert_allclose(back.score_samples(x), whole.score_samples(x))
    pending = sogmm.Map(batch_size=10_000, **FIT)
    pending.insert_points(blobs(n_per=50), np.eye(4))
    with pytest.raises(sogmm.SogmmError):
        pending.save(tmp_path / "pending.sogmm")  # flush first
    assert not (tmp_path / "pending.sogmm").exists()


def test_a_loaded_map_takes_the_registry_depth_defaults(tmp_path):
    # Map.load runs the constructor's keywords: the depth settings of later
    # RGB-D inserts are the library's (sogmm_option_get_info), or the caller's.
    path = tmp_path / "map.sogmm"
    with sogmm.Map(novelty=False, **FIT) as m:
        m.insert_points(frames()[0], POSES[0])
        m.save(path)
    keys = (sogmm._ffi.OPT_DEPTH_SCALE, sogmm._ffi.OPT_DEPTH_MIN, sogmm._ffi.OPT_DEPTH_MAX, sogmm._ffi.OPT_DECIMATION)
    with sogmm.Map.load(path) as back:
        assert back._depth == tuple(sogmm._ffi.option_default(k) for k in keys)
    with sogmm.Map.load(path, depth_scale=5000.0, decimate=4) as tum:
        assert tum._depth[0] == 5000.0 and tum._depth[3] == 4
    with pytest.raises(sogmm.InvalidArgumentError):
        sogmm.Map.load(path, decimate=0)


def test_warm_start_fits_each_frame_from_the_previous_fit():
    # Independent truth: fit frame 0 cold, frame 1 warm from frame 0's fit moved
    # into frame 1's camera (SOGMM.fit(init=)), each moved to the world, appended.
    def inverse(p):  # (R^T, -R^T t), summed in the same order as the library
        q = np.eye(4)
        q[:3, :3] = p[:3, :3].T
        for r in range(3):
            q[r, 3] = -(p[0, r] * p[0, 3] + p[1, r] * p[1, 3] + p[2, r] * p[2, 3])
        return q

    # Frame 1 sees frame 0's blobs from its own pose (new noise), so frame 0's
    # fit moved into frame 1's camera explains it: a warm start that keeps
    # components, not the cold fallback of a start that explains nothing.
    f0, f1 = frames()
    to_cam1 = inverse(POSES[1]) @ POSES[0]
    f1 = f1.copy()
    f1[:, :3] = (f1[:, :3].astype(np.float64) @ to_cam1[:3, :3].T + to_cam1[:3, 3]).astype(np.float32)
    g0 = sogmm.SOGMM(**FIT).fit(f0)
    g1 = sogmm.SOGMM(**FIT).fit(f1, init=g0.transform(POSES[0]).transform(inverse(POSES[1])))
    cold1 = sogmm.SOGMM(**FIT).fit(f1)
    with sogmm.Map(novelty=False, warm_start=True, **FIT) as m:
        m.insert_points(f0, POSES[0])
        m.insert_points(f1, POSES[1])
        got = m.export()
    expected = np.vstack([g0.transform(POSES[0]).means_, g1.transform(POSES[1]).means_])
    np.testing.assert_array_equal(got.means_, expected)
    assert got.n_components_ != g0.n_components_ + cold1.n_components_ or not np.array_equal(
        got.means_[g0.n_components_:], cold1.transform(POSES[1]).means_)  # the warm start did something
    with pytest.raises(sogmm.InvalidArgumentError):
        sogmm.Map(novelty=False, warm_start=True, n_init=2, **FIT)


@pytest.mark.parametrize("scale", [1.0, 0.5])
def test_novel_points_are_fitted_with_the_scaled_bandwidth(scale):
    # Two frames in one batch, identity poses: the batch is the frames' points
    # one after the other, fitted at bandwidth x (s + (1 - s) h^2), with s the
    # novelty_bandwidth_scale and h = 1/2 the share of its point pairs from
    # one frame (two frames of the same size).
    a, b = blobs(n_per=300, seed=0), blobs(n_per=300, seed=1) + np.float32([3, 0, 0, 0])
    assert len(a) == len(b)
    with sogmm.Map(novelty_bandwidth_scale=scale, batch_size=100000, **FIT) as m:
        m.insert_points(a, np.eye(4))
        m.insert_points(b, np.eye(4))
        m.flush()
        got = m.export()
    fit = dict(FIT, bandwidth=FIT["bandwidth"] * (scale + (1 - scale) * 0.25))
    want = sogmm.SOGMM(**fit).fit(np.concatenate([a, b]))
    assert got.n_components_ == want.n_components_
    assert got.means_.tobytes() == want.means_.tobytes()


def test_novelty_bandwidth_scale_out_of_range_raises():
    for bad in (0.0, 1.5, float("nan")):
        with pytest.raises(sogmm.InvalidArgumentError, match="NOVELTY_BANDWIDTH_SCALE|novelty_bandwidth_scale"):
            sogmm.Map(novelty_bandwidth_scale=bad)


def _wall(striped: bool):
    """A 64 x 48 view of a wall at 1.5 m, in one gray or in 8 gray stripes."""
    cam = sogmm.Camera(64, 48, 60.0, 60.0, 32.0, 24.0)
    depth = np.full((48, 64), 1500, np.uint16)
    u = np.broadcast_to(np.arange(64), (48, 64))
    gray = (32 * ((u // 4) % 8)).astype(np.uint8) if striped else np.full((48, 64), 128, np.uint8)
    return depth, np.repeat(gray[:, :, None], 3, axis=2), cam


@pytest.mark.parametrize("ratio, fits", [(1.5, 2), (0.0, 1)])
def test_a_revisit_with_many_more_modes_refits_what_it_sees(ratio, fits):
    # The first (plain) frame is one batch; the striped revisit has many more
    # modes than the map has components on the wall: a second fit replaces
    # them, unless the refit is off.
    with sogmm.Map(batch_size=64 * 48, revisit_refit_ratio=ratio) as m:
        m.insert_rgbd(*_wall(False), np.eye(4))
        plain = m.export()
        m.insert_rgbd(*_wall(True), np.eye(4))
        st = m.stats()
        assert st["n_flushes"] == fits and st["n_pending"] == 0
        assert st["n_refits"] == fits - 1  # the refit is the second fit
        assert m.frame_stats(0)["n_replaced"] == 0
        assert (m.frame_stats(1)["n_replaced"] > 0) == (fits == 2)
        assert m.frame_stats(1)["flushed"] == (fits == 2)
        after = m.export()
    if fits == 2:
        assert after.n_components_ > plain.n_components_
    else:
        assert after.means_.tobytes() == plain.means_.tobytes()


def test_revisit_refit_ratio_out_of_range_raises():
    for bad in (0.5, -1.0, float("nan"), float("inf")):
        with pytest.raises(sogmm.InvalidArgumentError, match="REVISIT_REFIT_RATIO|revisit_refit_ratio"):
            sogmm.Map(revisit_refit_ratio=bad)


def test_discard_pending_unlocks_a_map_that_cannot_be_saved(tmp_path):
    pts = blobs(n_per=50)
    with sogmm.Map(batch_size=10_000, **FIT) as m:
        m.insert_points(pts, np.eye(4))
        with pytest.raises(sogmm.InvalidArgumentError):
            m.save(tmp_path / "pending.sogmm")  # pending points: flush first
        assert m.discard_pending() == len(pts)
        assert m.n_pending_ == 0 and len(m) == 1 and m.n_components_ == 0
        assert m.discard_pending() == 0
        # The dropped points' voxels are forgotten: the same frame is new again.
        assert m.insert_points(pts, np.eye(4))["n_novel"] == len(pts)
        m.flush()
        m.save(tmp_path / "map.sogmm")
    assert (tmp_path / "map.sogmm").exists()


def test_a_frame_far_from_the_pending_ones_fails_at_its_insert():
    # Issue 36: on 9ad39ee the far frame went pending and every flush failed.
    pts = blobs(n_per=50)
    far = np.eye(4)
    far[0, 3] = 1e10
    with sogmm.Map(batch_size=10_000, **FIT) as m:
        m.insert_points(pts, np.eye(4))
        with pytest.raises(sogmm.SogmmError, match="flush"):
            m.insert_points(pts, far)
        assert len(m) == 1 and m.n_pending_ == len(pts)
        m.flush()
        assert m.n_components_ > 0


def test_deltas_in_order_rebuild_the_map_bitwise_and_a_gap_is_refused():
    with sogmm.Map(novelty=False, **FIT) as sender, sogmm.Map() as receiver:
        deltas = []
        for pts, pose in zip(frames(), POSES):
            since = sender.revision
            sender.insert_points(pts, pose)
            deltas.append(sender.export_delta(since))
        assert sender.revision == 2
        with pytest.raises(sogmm.InvalidArgumentError, match="revision"):
            receiver.apply_delta(deltas[1])  # a gap
        assert receiver.revision == 0
        with pytest.raises(sogmm.FormatError):
            receiver.apply_delta(deltas[0][:-3])  # truncated
        for d in deltas:
            receiver.apply_delta(d)
        assert receiver.revision == sender.revision
        a, b = sender.export(), receiver.export()
        for x, y in ((a.weights_, b.weights_), (a.means_, b.means_), (a.covariances_, b.covariances_)):
            assert x.tobytes() == y.tobytes()
        with pytest.raises(sogmm.InvalidArgumentError, match="already applied"):
            receiver.apply_delta(deltas[1])  # a duplicate


def test_a_bounded_delta_history_refuses_older_revisions():
    with sogmm.Map(novelty=False, delta_history=1, **FIT) as m:
        for pts, pose in zip(frames(), POSES):
            m.insert_points(pts, pose)
        assert m.revision == 2
        assert len(m.export_delta(1)) > 0
        with pytest.raises(sogmm.InvalidArgumentError, match="changes from revision 1"):
            m.export_delta(0)
    with pytest.raises(sogmm.InvalidArgumentError, match="delta_history"):
        sogmm.Map(delta_history=1.5)


def test_a_far_map_keeps_its_origin(tmp_path):
    # Issue 36: a map 1000 km out holds its components relative to its origin
    # (the first frame's translation rounded to 1 km) and finds in a mapped
    # frame the novel points it finds at the world origin.
    pts = blobs(n_per=50)
    novel = []
    for km in (0.0, 1000.0):
        pose = rigid(20.0, (1000.0 * km + 3.37, -1000.0 * km, 1.0))
        with sogmm.Map(batch_size=10_000, **FIT) as m:
            m.insert_points(pts, pose)
            m.flush()
            assert list(m.origin) == [1000.0 * km, -1000.0 * km, 0.0]
            novel.append(m.insert_points(pts, pose)["n_novel"])
            m.discard_pending()
            m.save(tmp_path / "far.sogmm")
    assert novel[1] == novel[0]
    with sogmm.Map.load(tmp_path / "far.sogmm") as loaded:
        assert list(loaded.origin) == [1.0e6, -1.0e6, 0.0]
        with pytest.raises(sogmm.InvalidArgumentError, match="before the first insert"):
            loaded.set_origin([0.0, 0.0, 0.0])
    with sogmm.Map(**FIT) as m:
        with pytest.raises(sogmm.InvalidArgumentError, match="origin"):
            m.set_origin([0.0, math.nan, 0.0])
        with pytest.raises(sogmm.InvalidArgumentError, match="3 values"):
            m.set_origin([1.0, 2.0])
        m.set_origin([5.0e5, 0.5, 0.0])
        assert list(m.origin) == [5.0e5, 0.5, 0.0]


def _map_of_one_frame(precision: float):
    with sogmm.Map(novelty=False, component_precision=precision, **FIT) as m:
        m.insert_points(frames()[0], POSES[1])
        return m.export()


def test_component_precision_rounds_each_mean_within_its_own_bound():
    # Independent truth (component_precision.hpp): with novelty off the one
    # fit is the same at both precisions (the rounding is applied after it),
    # so each rounded mean is the full one moved by at most `precision`
    # standard deviations in the component's own metric, and lies on a power
    # of two grid q = 2^floor(log2(p / sqrt(trace(S^-1)))); q / 2 is checked so
    # that a last-bit difference in numpy's trace cannot flip the grid. Both
    # maps come from the same kernel's fit, so the bound holds on every kernel
    # (SOGMM_ISA=sse2, avx2, default). Mutation tried: the option not passed
    # to the C options (precision ignored) fails the "differs" assert.
    p = 0.25
    full, rounded = _map_of_one_frame(0.0), _map_of_one_frame(p)
    assert rounded.n_components_ == full.n_components_ > 0
    assert rounded.means_.tobytes() != full.means_.tobytes()
    for k in range(full.n_components_):
        s = full.covariances_[k].astype(np.float64)
        t = np.trace(np.linalg.inv(s))
        q = 2.0 ** math.floor(math.log2(p / math.sqrt(t)))
        m = rounded.means_[k].astype(np.float64)
        np.testing.assert_array_equal(np.round(m / (q / 2)), m / (q / 2))
        d = m - full.means_[k].astype(np.float64)
        assert float(d @ np.linalg.solve(s, d)) <= p * p * (1 + 1e-9)
        # The covariance moves by at most the fraction p of its eigenvalues.
        lam = np.linalg.eigvalsh(np.linalg.solve(np.linalg.cholesky(s), np.linalg.solve(
            np.linalg.cholesky(s), rounded.covariances_[k].astype(np.float64)).T))
        assert np.all(np.abs(lam - 1) <= p + 1e-6)


def test_component_precision_out_of_range_raises():
    for bad in (-0.1, 0.6, float("nan"), float("inf")):
        with pytest.raises(sogmm.InvalidArgumentError, match="component_precision"):
            sogmm.Map(component_precision=bad)


def test_save_codes_components_at_the_files_precision_within_the_bound(tmp_path):
    """``Map.save(component_precision=)`` (SOGMM_OPT_ARRAY_PRECISION, as
    GMM.save): at precision P each saved mean moves by at most P of its
    component's own standard deviations, |L^-1 (mu' - mu)| <= P with
    S = L L^T (the encoder checks it on the decoded float32 values;
    conftest.mean_moves_in_sigmas recomputes it in binary64, on every kernel:
    both files hold the one fit). The default stores float
    arrays, bit-exact. Mutation tried: the keyword not passed to the write
    options leaves the file uncoded (size and "some mean moved" fail)."""
    with sogmm.Map(novelty=False, **FIT) as m:
        m.insert_points(frames()[0], POSES[1])
        exact, coded = tmp_path / "exact.sogmm", tmp_path / "coded.sogmm"
        m.save(exact)
        m.save(coded, component_precision=0.5)
        full = m.export()
        before = coded.read_bytes()
        for bad in (0.7, -1.0, float("nan")):
            with pytest.raises(sogmm.InvalidArgumentError, match="component_precision"):
                m.save(coded, component_precision=bad)
            assert coded.read_bytes() == before
    assert coded.stat().st_size < exact.stat().st_size
    with sogmm.Map.load(exact) as e:
        assert e.export().means_.tobytes() == full.means_.tobytes()
    with sogmm.Map.load(coded) as c:
        back = c.export()
        assert c.stats()["n_frames"] == 1  # the provenance came along
    sigmas = mean_moves_in_sigmas(full, back)
    assert sigmas.max() <= 0.5 * (1 + 1e-9), sigmas.max()
    assert sigmas.max() > 0, "the means were stored as codes, not bit for bit"
    assert sorted(os.listdir(tmp_path)) == ["coded.sogmm", "exact.sogmm"]  # no temporary file left
