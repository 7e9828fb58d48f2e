"""Fitting, attributes and inference, checked against independent NumPy formulas."""

from __future__ import annotations

import gc

import numpy as np
import pytest

import sogmm

from conftest import blobs


def _logpdf(x, mu, cov):
    """Gaussian log-density of rows x (float64, NumPy only)."""
    d = x.shape[1]
    L = np.linalg.cholesky(cov)
    z = np.linalg.solve(L, (x - mu).T)
    return -0.5 * np.sum(z * z, axis=0) - np.log(np.diag(L)).sum() - 0.5 * d * np.log(2 * np.pi)


def _mixture_logpdf(x, w, mu, cov):
    comps = np.stack([np.log(w[k]) + _logpdf(x, mu[k], cov[k]) for k in range(len(w))])
    m = comps.max(axis=0)
    return m + np.log(np.exp(comps - m).sum(axis=0))


def test_fit_attributes(fitted, points):
    m = fitted
    M = m.n_components_
    assert M >= 2
    assert m.weights_.shape == (M,) and m.weights_.dtype == np.float32
    assert m.means_.shape == (M, 4) and m.means_.dtype == np.float32
    assert m.covariances_.shape == (M, 4, 4) and m.covariances_.dtype == np.float32
    assert abs(float(m.weights_.sum()) - 1.0) < 1e-4
    assert np.allclose(m.covariances_, np.transpose(m.covariances_, (0, 2, 1)))
    assert isinstance(m.converged_, bool) and isinstance(m.n_iter_, int) and m.n_iter_ >= 1
    assert np.isfinite(m.lower_bound_)
    assert m.support_size_ == points.shape[0]
    assert not m.weights_.flags.writeable  # read-only views of the model
    info = m.info()
    assert info["fit_n_points"] == points.shape[0]
    assert info["fit_bandwidth"] == pytest.approx(0.08)
    assert info["fit_seed"] == 3
    assert m.camera_ is None


def test_same_seed_same_model_and_params_reach_c(points):
    a = sogmm.SOGMM(bandwidth=0.08, seed=11, n_threads=1).fit(points)
    b = sogmm.SOGMM(bandwidth=0.08, seed=11, n_threads=2).fit(points)
    for name in ("weights_", "means_", "covariances_"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert a.lower_bound_ == b.lower_bound_ and a.n_iter_ == b.n_iter_
    c = sogmm.SOGMM(bandwidth=0.08, seed=11, tol=0.5, max_iter=2, reg_covar=1e-4).fit(points)
    info = c.info()
    assert info["fit_tol"] == 0.5 and info["fit_max_iter"] == 2 and info["fit_reg_covar"] == pytest.approx(1e-4)
    assert c.n_iter_ <= 2


def test_bandwidth_controls_the_number_of_components(points):
    small = sogmm.SOGMM(bandwidth=0.03).fit(points).n_components_
    large = sogmm.SOGMM(bandwidth=0.5).fit(points).n_components_
    assert small > large >= 1


def test_fixed_k(points):
    m = sogmm.SOGMM(n_components=4, seed=1, max_iter=200).fit(points)
    assert m.n_components_ == 4
    assert m.info()["fit_n_components_requested"] == 4
    assert m.info()["fit_bandwidth"] == 0.0
    # The four blobs are found: each true centre has a mean within 0.02.
    centres = np.array([[0.0, 0.0, 1.0, 0.2], [0.4, 0.1, 1.4, 0.8], [-0.3, 0.3, 1.2, 0.5], [0.1, -0.3, 0.9, 0.4]])
    d = np.linalg.norm(centres[:, None, :] - m.means_[None, :, :], axis=2).min(axis=1)
    assert d.max() < 0.02
    np.testing.assert_allclose(np.sort(m.weights_), 0.25, atol=0.01)


def test_n_init_keeps_the_best_run(points):
    single = [sogmm.SOGMM(n_components=9, seed=20 + r).fit(points) for r in range(3)]
    best = sogmm.SOGMM(n_components=9, seed=20, n_init=3).fit(points)
    info = best.info()
    assert info["fit_n_init"] == 3
    lls = [m.lower_bound_ for m in single]
    assert info["fit_run"] == int(np.argmax(lls))  # first of equal maxima, as np.argmax
    assert info["fit_seed"] == 20 + info["fit_run"]
    assert best.lower_bound_ == max(lls)
    kept = single[info["fit_run"]]
    for name in ("weights_", "means_", "covariances_"):
        np.testing.assert_array_equal(getattr(best, name), getattr(kept, name))
    for bad in (0, 1001, 2.0, True):
        with pytest.raises(sogmm.InvalidArgumentError):
            sogmm.SOGMM(n_components=3, n_init=bad).fit(points)


def test_not_fitted():
    est = sogmm.SOGMM()
    assert not hasattr(est, "weights_")
    with pytest.raises(sogmm.NotFittedError):
        est.score_samples(np.zeros((1, 4), np.float32))
    assert "SOGMM(bandwidth=0.02" in repr(est)
    assert est.get_params()["bandwidth"] == 0.02
    est.set_params(bandwidth=0.05)
    assert est.bandwidth == 0.05


def test_score_samples_matches_numpy(fitted, points):
    m = fitted
    w, mu, cov = (np.asarray(a, np.float64) for a in (m.weights_, m.means_, m.covariances_))
    x = points[::7].astype(np.float64)
    ours4 = m.score_samples(points[::7])
    assert ours4.dtype == np.float64 and ours4.shape == (x.shape[0],)
    np.testing.assert_allclose(ours4, _mixture_logpdf(x, w, mu, cov), rtol=1e-4, atol=1e-4)
    ours3 = m.score_samples(points[::7, :3])
    np.testing.assert_allclose(ours3, _mixture_logpdf(x[:, :3], w, mu[:, :3], cov[:, :3, :3]), rtol=1e-4, atol=1e-4)
    assert m.score(points) == pytest.approx(np.mean(m.score_samples(points)))
    assert m.score_samples(np.zeros((0, 4), np.float32)).shape == (0,)


def test_regress_gray_matches_numpy(fitted, points):
    m = fitted
    w, mu, cov = (np.asarray(a, np.float64) for a in (m.weights_, m.means_, m.covariances_))
    xyz = points[::11, :3]
    mean, var = m.regress_gray(xyz)
    assert mean.dtype == np.float32 and var.dtype == np.float32
    x = xyz.astype(np.float64)
    logr = np.stack([np.log(w[k]) + _logpdf(x, mu[k, :3], cov[k, :3, :3]) for k in range(len(w))])
    r = np.exp(logr - logr.max(axis=0))
    r /= r.sum(axis=0)
    lam = np.stack([mu[k, 3] + (x - mu[k, :3]) @ np.linalg.solve(cov[k, :3, :3], cov[k, :3, 3]) for k in range(len(w))])
    nu2 = np.array([cov[k, 3, 3] - cov[k, 3, :3] @ np.linalg.solve(cov[k, :3, :3], cov[k, :3, 3]) for k in range(len(w))])
    exp_mean = (r * lam).sum(axis=0)
    exp_var = (r * (nu2[:, None] + lam**2)).sum(axis=0) - exp_mean**2
    np.testing.assert_allclose(mean, exp_mean, atol=1e-4)
    np.testing.assert_allclose(var, exp_var, atol=1e-4)
    # The regression recovers the gray of the training points (blobs are far apart).
    assert np.abs(mean - points[::11, 3]).mean() < 0.05


def test_culled_queries_within_bound_and_thread_independent(fitted, points):
    """truncation_nats culls components provably below each point's best term
    (issue 17): the score never rises and falls by at most log(1 + M e^-nats);
    0 is the exact default, and the thread count changes no bit."""
    m = fitted
    M = m.n_components_
    exact = m.score_samples(points)
    np.testing.assert_array_equal(exact, m.score_samples(points, truncation_nats=0.0, n_threads=1))
    np.testing.assert_array_equal(exact, m.score_samples(points, n_threads=2))
    for nats in (2.0, 20.0):
        culled = m.score_samples(points, truncation_nats=nats)
        np.testing.assert_array_equal(culled, m.score_samples(points, truncation_nats=nats, n_threads=1))
        slack = 1e-12 * (1 + np.abs(exact))
        assert np.all(culled <= exact + slack)
        assert np.all(exact - culled <= np.log1p(M * np.exp(-nats)) + slack)
    mean, var = m.regress_gray(points[:, :3])
    cm, cv = m.regress_gray(points[:, :3], truncation_nats=20.0, n_threads=1)
    np.testing.assert_allclose(cm, mean, atol=1e-5)
    with pytest.raises(sogmm.InvalidArgumentError, match="truncation"):
        m.score_samples(points, truncation_nats=-1.0)
    with pytest.raises(sogmm.InvalidArgumentError, match="truncation"):
        m.regress_gray(points[:, :3], truncation_nats=float("nan"))


def test_sample(fitted):
    m = fitted
    a = m.sample(20000, seed=5)
    assert a.shape == (20000, 4) and a.dtype == np.float32
    np.testing.assert_array_equal(a, m.sample(20000, seed=5))
    assert not np.array_equal(a, m.sample(20000, seed=6))
    assert m.sample(10, spatial_only=True, seed=1).shape == (10, 3)
    assert m.sample(0).shape == (0, 4)
    expected_mean = (m.weights_[:, None] * m.means_).sum(axis=0)
    np.testing.assert_allclose(a.mean(axis=0), expected_mean, atol=0.01)
    # Samples score well under the model.
    assert m.score(a) > m.score(a + np.float32(0.5))
    untruncated = m.sample(1000, seed=5, truncation=float("inf"))
    assert untruncated.shape == (1000, 4)


def test_merge(points):
    a = sogmm.SOGMM(bandwidth=0.08).fit(points[:800])
    b = sogmm.SOGMM(bandwidth=0.08).fit(points[800:1000])
    c = a.merge(b)
    assert isinstance(c, sogmm.GMM)
    assert c.n_components_ == a.n_components_ + b.n_components_
    assert c.support_size_ == 1000
    np.testing.assert_allclose(c.weights_[: a.n_components_], a.weights_ * 0.8, rtol=1e-5)
    np.testing.assert_allclose(c.weights_[a.n_components_:], b.weights_ * 0.2, rtol=1e-5)
    np.testing.assert_array_equal(c.means_, np.concatenate([a.means_, b.means_]))
    # spec/format.md 2.2: the same fit settings, so a fit record with the total iterations
    assert c.n_iter_ == a.n_iter_ + b.n_iter_
    with pytest.raises(sogmm.InvalidArgumentError):
        a.merge("not a model")


def test_merge_support_rules(points):
    a = sogmm.SOGMM(bandwidth=0.08).fit(points[:500])
    unknown = sogmm.GMM.from_arrays(a.weights_, a.means_, a.covariances_)  # support 0 = unknown
    with pytest.raises(sogmm.InvalidArgumentError, match="support size 0"):
        a.merge(unknown)  # a known size against an unknown one would be a guess
    both = unknown.merge(unknown)  # two unknowns count equally
    np.testing.assert_allclose(both.weights_, np.concatenate([a.weights_, a.weights_]) / 2, rtol=1e-6)
    huge = sogmm.GMM.from_arrays(a.weights_, a.means_, a.covariances_, support_size=2**63 + 1)
    assert huge.support_size_ == 2**63 + 1
    with pytest.raises(sogmm.LimitError):
        huge.merge(huge)  # 2^64 + 2 does not fit


def test_transform_beyond_float32_is_an_error(fitted):
    pose = np.eye(4)
    pose[0, 3] = 1e39
    with pytest.raises(sogmm.InvalidArgumentError, match="float32"):
        fitted.transform(pose)


def _rotation(ax, ay, az):
    cx, sx, cy, sy, cz, sz = np.cos(ax), np.sin(ax), np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


def test_transform_and_pose(fitted, points):
    pose = np.eye(4)
    pose[:3, :3] = _rotation(0.3, -0.2, 1.1)
    pose[:3, 3] = [0.5, -1.0, 2.0]
    t = fitted.transform(pose)
    R, tr = pose[:3, :3], pose[:3, 3]
    np.testing.assert_allclose(t.means_[:, :3], fitted.means_[:, :3] @ R.T + tr, atol=1e-5)
    np.testing.assert_allclose(t.means_[:, 3], fitted.means_[:, 3])
    np.testing.assert_allclose(t.covariances_[:, :3, :3], R @ fitted.covariances_[:, :3, :3] @ R.T, atol=1e-6)
    moved = points.copy()
    moved[:, :3] = (points[:, :3].astype(np.float64) @ R.T + tr).astype(np.float32)
    np.testing.assert_allclose(t.score_samples(moved), fitted.score_samples(points), rtol=1e-3, atol=1e-3)

    g = fitted.copy()
    assert g.pose is None
    g.pose = pose
    np.testing.assert_allclose(g.pose, pose)
    with pytest.raises(sogmm.InvalidArgumentError):
        g.pose = np.diag([2.0, 1.0, 1.0, 1.0])
    np.testing.assert_allclose(g.pose, pose)  # a rejected pose leaves the old one
    g.pose = None
    assert g.pose is None
    with pytest.raises(sogmm.InvalidArgumentError):
        fitted.transform(np.eye(3))


def test_metadata(fitted):
    g = fitted.copy()
    fit = {"reg_covar_gray": "1e-06", "reg_covar_source": "auto"}  # what the fit records (spec/format.md 2.4)
    assert g.metadata == fit
    g.set_metadata("sensor", "PrimeSense")
    g.set_metadata("frame", "00000")
    g.set_metadata("sensor", "Kinect")
    assert g.metadata == {**fit, "sensor": "Kinect", "frame": "00000"}
    with pytest.raises(sogmm.InvalidArgumentError):
        g.set_metadata("", "x")


def test_from_arrays(fitted):
    g = sogmm.GMM.from_arrays(fitted.weights_, fitted.means_, fitted.covariances_, support_size=123)
    np.testing.assert_array_equal(g.means_, fitted.means_)
    np.testing.assert_array_equal(g.covariances_, fitted.covariances_)
    assert g.support_size_ == 123
    assert g.n_iter_ is None and g.converged_ is None and g.lower_bound_ is None
    # float64 and list inputs are converted.
    g2 = sogmm.GMM.from_arrays([1.0], [[0, 0, 1, 0.5]], [np.eye(4) * 0.01])
    assert g2.n_components_ == 1 and g2.support_size_ == 0
    x = np.array([[0, 0, 1, 0.5]], np.float32)
    assert g2.score_samples(x)[0] == pytest.approx(-0.5 * 4 * np.log(2 * np.pi * 0.01), rel=1e-5)


def test_handle_lifetime(points):
    m = sogmm.SOGMM(bandwidth=0.1).fit(points[:200])
    fin = m._finalizer
    assert fin.alive
    del m
    gc.collect()
    assert not fin.alive  # the C model was freed

    m = sogmm.SOGMM(bandwidth=0.1).fit(points[:200])
    fin = m._finalizer
    m.fit(points[200:400])  # refitting frees the previous handle
    assert not fin.alive and m._finalizer.alive
    with m:
        assert m.n_components_ >= 1
    with pytest.raises(sogmm.NotFittedError):
        m.weights_  # noqa: B018 - closed


def test_inputs_are_not_copied_when_the_layout_fits():
    from sogmm.model import _rows

    a = blobs(n_per=10)
    assert _rows(a, (4,), "X") is a
    f64 = a.astype(np.float64)
    assert _rows(f64, (4,), "X").dtype == np.float32
    strided = np.asfortranarray(a)
    assert _rows(strided, (4,), "X").flags.c_contiguous


def test_non_contiguous_and_float64_input_give_the_same_fit(points):
    a = sogmm.SOGMM(bandwidth=0.08).fit(points)
    b = sogmm.SOGMM(bandwidth=0.08).fit(np.asfortranarray(points.astype(np.float64)))
    np.testing.assert_array_equal(a.means_, b.means_)


def test_dequantise_depth_reaches_the_fit():
    # Two tilted planes 1.6-1.8 m away whose depth sits on Kinect-style levels
    # 1 / (0.0036 k) (as tests/core/test_depth_quantisation.cpp): the floor
    # along the viewing rays changes the fit only when asked for.
    rng = np.random.default_rng(5)
    u, v = rng.uniform(-0.5, 0.5, 6000), rng.uniform(-0.5, 0.5, 6000)
    plane = np.arange(6000) % 2
    x = np.where(plane, 0.8 * u, 0.9 * u + 0.2)
    y = np.where(plane, 0.6 * v, 0.5 * v)
    z = np.where(plane, 1.8 + 0.5 * u + 0.3 * v, 1.6 - 0.35 * u + 0.1 * v)
    zq = 1.0 / (0.0036 * np.round(1.0 / (0.0036 * z)))
    pts = np.column_stack([x * zq / z, y * zq / z, zq, 0.5 + 0.3 * u]).astype(np.float32)
    params = dict(n_components=60, seed=3, n_threads=1)
    assert sogmm.SOGMM(dequantise_depth=True).get_params()["dequantise_depth"] is True
    plain = sogmm.SOGMM(**params).fit(pts)
    again = sogmm.SOGMM(dequantise_depth=False, **params).fit(pts)
    floored = sogmm.SOGMM(dequantise_depth=True, **params).fit(pts)
    np.testing.assert_array_equal(plain.means_, again.means_)
    assert not np.array_equal(plain.means_, floored.means_)


def _staircase_frame():
    # 8 fronto-parallel steps 10 cm apart: exact depth levels, so the
    # quantisation is detected and the floor changes the fit.
    width, height = 96, 72
    v, u = np.mgrid[0:height, 0:width]
    depth = (1000 + 100 * (u // 12)).astype(np.uint16)
    gray = (60 + 2 * u + v).astype(np.uint8)
    return depth, gray, sogmm.Camera(width, height, 77.0, 77.0, (width - 1) / 2, (height - 1) / 2)


def test_the_depth_floor_is_the_default_for_frames_and_not_for_arrays():
    # The library's default (SOGMM_DEQUANTISE_AUTO): a frame is floored, the
    # same points given as an array are not (issue 29 item 1).
    depth, gray, cam = _staircase_frame()
    params = dict(bandwidth=0.05, seed=3, n_threads=1)
    assert sogmm.SOGMM().get_params()["dequantise_depth"] is None
    default = sogmm.SOGMM(**params).fit_rgbd(depth, gray, cam, decimate=2)
    on = sogmm.SOGMM(dequantise_depth=True, **params).fit_rgbd(depth, gray, cam, decimate=2)
    off = sogmm.SOGMM(dequantise_depth=False, **params).fit_rgbd(depth, gray, cam, decimate=2)
    np.testing.assert_array_equal(default.covariances_, on.covariances_)
    assert not np.array_equal(default.covariances_, off.covariances_)
    pts = sogmm.rgbd_to_points(depth, gray, cam, decimate=2)
    array_default = sogmm.SOGMM(**params).fit(pts)
    np.testing.assert_array_equal(array_default.covariances_, off.covariances_)
    np.testing.assert_array_equal(sogmm.SOGMM(dequantise_depth=True, **params).fit(pts).covariances_,
                                  on.covariances_)


def _creeping_fit():
    """Three overlapping clusters along x and fit parameters (tol 1e-7) under
    which plain EM creeps to its fixed point for hundreds of passes."""
    rng = np.random.default_rng(35)
    k = np.arange(3000) % 3
    pts = np.column_stack([0.8 * k + 0.5 * rng.standard_normal(3000), 0.2 * rng.standard_normal(3000),
                           1.0 + 0.1 * rng.standard_normal(3000), 0.3 + 0.1 * rng.standard_normal(3000)])
    return pts, dict(n_components=3, seed=1, n_threads=1, tol=1e-7, max_iter=3000)


def test_em_acceleration_reaches_the_fit():
    # Three overlapping clusters along x: plain EM creeps to its fixed point
    # (tol 1e-7); SQUAREM gets there in fewer passes, no lower.
    pts, params = _creeping_fit()
    assert sogmm.SOGMM().get_params()["em_acceleration"] == "none"
    plain = sogmm.SOGMM(**params).fit(pts)
    again = sogmm.SOGMM(em_acceleration="none", **params).fit(pts)
    fast = sogmm.SOGMM(em_acceleration="squarem", **params).fit(pts)
    np.testing.assert_array_equal(plain.means_, again.means_)
    assert fast.info()["fit_iterations"] < plain.info()["fit_iterations"]
    assert fast.info()["fit_log_likelihood"] >= plain.info()["fit_log_likelihood"] - 1e-5
    with pytest.raises(sogmm.InvalidArgumentError, match="em_acceleration"):
        sogmm.SOGMM(em_acceleration="fast", **params).fit(pts)


def test_tol_standard_errors_reaches_the_fit():
    # SOGMM_OPT_TOL_STANDARD_ERRORS (c): EM also stops when a pass gains less
    # than c standard errors of the mean log-likelihood. The scene of the test
    # above, where plain EM creeps for many passes at tol 1e-7: at c = 1 the
    # creep (far below one standard error, ~0.02 nats at N = 3000) stops at
    # once, so fewer passes; c = 0 is the library's default and the fit
    # itself, bit for bit (the noise rule is the only change, on any kernel:
    # both fits run on the same one). Mutation tried: the keyword left out of
    # the C options (same passes: the "fewer" assert fails).
    pts, params = _creeping_fit()
    assert sogmm.SOGMM().get_params()["tol_standard_errors"] == 0.0
    plain = sogmm.SOGMM(**params).fit(pts)
    zero = sogmm.SOGMM(tol_standard_errors=0.0, **params).fit(pts)
    noise = sogmm.SOGMM(tol_standard_errors=1.0, **params).fit(pts)
    np.testing.assert_array_equal(plain.means_, zero.means_)
    assert zero.info()["fit_iterations"] == plain.info()["fit_iterations"]
    assert noise.info()["fit_iterations"] < plain.info()["fit_iterations"]
    for bad in (-0.5, float("nan"), float("inf")):
        with pytest.raises(sogmm.InvalidArgumentError, match="tol_standard_errors"):
            sogmm.SOGMM(tol_standard_errors=bad, **params).fit(pts)
