"""Warm start from Python (issue 17): fit(X, init=model)."""

from __future__ import annotations

import numpy as np
import pytest

import sogmm

from conftest import blobs


def test_warm_start_on_moved_cloud_matches_cold_fit():
    centers = [[0.0, 0.0, 1.0, 0.2], [0.4, 0.1, 1.4, 0.8], [-0.3, 0.3, 1.2, 0.5]]
    a = blobs(centers=centers, seed=1)
    prev = sogmm.SOGMM(bandwidth=0.08, seed=3).fit(a)
    # The next "frame": the same scene 5 cm further along x, one cluster gone, one new.
    moved = centers[:2] + [[0.1, -0.3, 0.9, 0.4]]
    b = blobs(centers=moved, seed=2)
    b[:, 0] -= 0.05
    pose = np.eye(4)
    pose[0, 3] = -0.05
    init = prev.transform(pose)
    warm = sogmm.SOGMM(bandwidth=0.08, seed=3).fit(b, init=init)
    cold = sogmm.SOGMM(bandwidth=0.08, seed=3).fit(b)
    assert warm.lower_bound_ >= cold.lower_bound_ - 0.02
    # No component is left where the vanished cluster was.
    gone = np.array(centers[2], dtype=np.float32) - np.array([0.05, 0, 0, 0], dtype=np.float32)
    assert np.min(np.linalg.norm(warm.means_ - gone, axis=1)) > 0.1
    # The initial model is not consumed.
    assert init.n_components_ == prev.n_components_


def test_warm_pass_cap_is_the_library_default_and_a_keyword():
    # With tol 0 EM runs its whole pass limit, so n_iter_ is that limit.
    x = blobs(seed=4)
    prev = sogmm.SOGMM(bandwidth=0.08, seed=3).fit(x)
    assert sogmm.SOGMM().warm_max_iter == sogmm._ffi.option_default(sogmm._ffi.OPT_WARM_MAX_ITER)
    assert sogmm.SOGMM(bandwidth=0.08, tol=0.0).fit(x, init=prev).n_iter_ == sogmm.SOGMM().warm_max_iter
    assert sogmm.SOGMM(bandwidth=0.08, tol=0.0, warm_max_iter=3).fit(x, init=prev).n_iter_ == 3
    assert sogmm.SOGMM(bandwidth=0.08, tol=0.0, warm_max_iter=3, max_iter=5).fit(x, init=prev).n_iter_ == 5
    assert sogmm.SOGMM(bandwidth=0.08, tol=0.0, warm_max_iter=3).fit(x).n_iter_ == sogmm.SOGMM().max_iter
    with pytest.raises(sogmm.InvalidArgumentError, match="WARM_MAX_ITER|warm_max_iter"):
        sogmm.SOGMM(bandwidth=0.08, warm_max_iter=-1).fit(x, init=prev)


def test_warm_start_errors():
    x = blobs()
    prev = sogmm.SOGMM(bandwidth=0.08).fit(x)
    with pytest.raises(sogmm.InvalidArgumentError, match="init"):
        sogmm.SOGMM().fit(x, init="model")
    with pytest.raises(sogmm.InvalidArgumentError, match="n_init"):
        sogmm.SOGMM(bandwidth=0.08, n_init=2).fit(x, init=prev)
    with pytest.raises(sogmm.NotFittedError):
        sogmm.SOGMM().fit(x, init=sogmm.SOGMM())
