"""sogmm.Map world-frame queries (sogmm_map_score_samples_f32, _regress_gray_f32,
_sample_f32): bitwise the exported GMM's answers, with and without progress;
cancel and bad input raise; progress and cancel of inserts and flushes leave a
cancelled map as it was."""

from __future__ import annotations

import numpy as np
import pytest

import sogmm
from sogmm.progress import STAGE_EM, STAGE_REGRESSION, STAGE_SAMPLING, STAGE_SCORING

from conftest import blobs

FIT = dict(bandwidth=0.08, seed=3, n_threads=2)


def shifted(tx: float) -> np.ndarray:
    p = np.eye(4)
    p[0, 3] = tx
    return p


@pytest.fixture(scope="module")
def two_frames():
    pts = blobs(n_per=300, seed=0)
    m = sogmm.Map(batch_size=100000, **FIT)
    m.insert_points(pts, shifted(0.0))
    m.insert_points(pts, shifted(2.0))
    m.flush()
    yield m
    m.close()


def queries(dims: int) -> np.ndarray:
    q = blobs(n_per=2500, seed=9)[:, :dims].copy()  # 10,000 points: three progress chunks
    q[::5, 0] += 3.5  # every fifth point far off
    return q


@pytest.mark.parametrize("dims", [3, 4])
def test_score_equals_the_exported_model_bitwise(two_frames, dims):
    q = queries(dims)
    want = two_frames.export().score_samples(q)
    np.testing.assert_array_equal(two_frames.score_samples(q), want)
    seen = []
    got = two_frames.score_samples(q, progress=lambda *r: seen.append(r))
    np.testing.assert_array_equal(got, want)
    assert seen[0][0] == STAGE_SCORING and seen[-1][1:3] == (len(q), len(q))


def test_regress_and_sample_equal_the_exported_model_bitwise(two_frames):
    g = two_frames.export()
    q = queries(3)
    for got, want in zip(two_frames.regress_gray(q), g.regress_gray(q)):
        np.testing.assert_array_equal(got, want)
    stages = set()
    mean, _ = two_frames.regress_gray(q, progress=lambda s, *_: stages.add(s))
    np.testing.assert_array_equal(mean, g.regress_gray(q)[0])
    np.testing.assert_array_equal(two_frames.sample(3000, seed=4), g.sample(3000, seed=4))
    np.testing.assert_array_equal(two_frames.sample(3000, seed=4, truncation=1.0, spatial_only=True,
                                                    progress=lambda s, *_: stages.add(s)),
                                  g.sample(3000, seed=4, truncation=1.0, spatial_only=True))
    assert stages == {STAGE_REGRESSION, STAGE_SAMPLING}


def test_cancel_and_bad_input_raise(two_frames):
    with pytest.raises(sogmm.CancelledError):
        two_frames.score_samples(queries(4), progress=lambda *_: True)

    class Stop(Exception):
        pass

    def boom(*_):
        raise Stop

    with pytest.raises(Stop):
        two_frames.regress_gray(queries(3), progress=boom)
    with pytest.raises(sogmm.InvalidDataError, match="non-finite|not finite"):
        two_frames.score_samples(np.full((4, 3), np.nan, dtype=np.float32))
    with pytest.raises(sogmm.InvalidArgumentError):
        two_frames.score_samples(np.zeros((4, 5), dtype=np.float32))
    with sogmm.Map(**FIT) as empty, pytest.raises(sogmm.InvalidDataError, match="no component"):
        empty.sample(10, seed=1)


def test_a_cancelled_insert_or_flush_leaves_the_map_as_it_was():
    pts = blobs(n_per=300, seed=0)
    with sogmm.Map(novelty=False, **FIT) as m:
        stages = []
        m.insert_points(pts, shifted(0.0), progress=lambda s, *_: stages.append(s))
        assert stages[-1] == STAGE_EM
        before, means = m.stats(), m.export().means_
        with pytest.raises(sogmm.CancelledError):
            m.insert_points(pts, shifted(3.0), progress=lambda *_: True)
        assert m.stats() == before
        np.testing.assert_array_equal(m.export().means_, means)
        m.insert_points(pts, shifted(3.0))  # the callback is gone; the frame goes in
        assert len(m) == 2
    with sogmm.Map(batch_size=100000, **FIT) as m:
        m.insert_points(pts, shifted(0.0))
        with pytest.raises(sogmm.CancelledError):
            m.flush(progress=lambda *_: True)
        assert m.n_pending_ == len(pts) and m.n_components_ == 0
        assert m.flush(progress=lambda *_: None) > 0


def test_gmm_queries_take_progress(two_frames):
    g = two_frames.export()
    q = queries(3)
    seen = []
    np.testing.assert_array_equal(g.score_samples(q, progress=lambda *r: seen.append(r)), g.score_samples(q))
    assert seen[0][0] == STAGE_SCORING and seen[-1][1] == len(q)
    seen.clear()
    np.testing.assert_array_equal(g.regress_gray(q, progress=lambda *r: seen.append(r))[1], g.regress_gray(q)[1])
    assert seen[-1][0] == STAGE_REGRESSION
    with pytest.raises(sogmm.CancelledError):
        g.regress_gray(q, progress=lambda *_: True)


def test_gmm_and_map_share_one_query_implementation(two_frames):
    # One mixin, one method object per query: the map runs the same code on its handle kind.
    from sogmm.queryable import Queryable

    for name in ("score_samples", "score", "regress_gray", "sample", "render", "surface_distance",
                 "collision_probability"):
        assert getattr(sogmm.GMM, name) is getattr(Queryable, name) is getattr(sogmm.Map, name), name
    # The model's sample now reports too (stage STAGE_SAMPLING, of 3000 points; at least the
    # stage start), with the same draws, and a truthy return cancels it.
    g = two_frames.export()
    seen = []
    np.testing.assert_array_equal(g.sample(3000, seed=4, progress=lambda *r: seen.append(r)),
                                  g.sample(3000, seed=4))
    assert seen and all(r[0] == STAGE_SAMPLING and r[2] == 3000 for r in seen), seen
    with pytest.raises(sogmm.CancelledError):
        g.sample(3000, seed=4, progress=lambda *_: True)
