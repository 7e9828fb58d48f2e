"""Independent check against scikit-learn's GaussianMixture (full covariances).

The C API has no way to pass initial means, so the comparison starts
scikit-learn from our converged fixed-K model: its densities must equal ours
and one more EM step of scikit-learn must barely move it."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import sogmm

sk_mixture = pytest.importorskip("sklearn.mixture", reason="scikit-learn is not installed")


def _sklearn_from(model) -> "sk_mixture.GaussianMixture":
    w, mu, cov = (np.asarray(a, np.float64) for a in (model.weights_, model.means_, model.covariances_))
    gm = sk_mixture.GaussianMixture(n_components=len(w), covariance_type="full")
    gm.weights_, gm.means_, gm.covariances_ = w, mu, cov
    chol = np.linalg.cholesky(cov)
    gm.precisions_cholesky_ = np.stack([np.linalg.inv(c).T for c in chol])
    gm.precisions_ = np.stack([p @ p.T for p in gm.precisions_cholesky_])
    return gm


def test_densities_equal_sklearn(fitted, points):
    gm = _sklearn_from(fitted)
    np.testing.assert_allclose(fitted.score_samples(points), gm.score_samples(points.astype(np.float64)),
                               rtol=1e-4, atol=1e-4)
    assert fitted.score(points) == pytest.approx(gm.score(points.astype(np.float64)), abs=1e-4)


def test_one_sklearn_em_step_from_our_converged_model_barely_moves_it(points):
    tol = 1e-4
    ours = sogmm.SOGMM(n_components=6, seed=2, tol=tol, max_iter=1000, reg_covar=1e-6).fit(points)
    assert ours.converged_
    w, mu, cov = (np.asarray(a, np.float64) for a in (ours.weights_, ours.means_, ours.covariances_))
    gm = sk_mixture.GaussianMixture(n_components=6, covariance_type="full", reg_covar=1e-6, max_iter=1, tol=0.0,
                                    weights_init=w / w.sum(), means_init=mu, precisions_init=np.linalg.inv(cov))
    x = points.astype(np.float64)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # ConvergenceWarning after one iteration is expected
        gm.fit(x)
    # scikit-learn's lower bound is evaluated at the initial (= our) parameters.
    assert gm.lower_bound_ == pytest.approx(ours.lower_bound_, abs=10 * tol)
    # After the step: the likelihood changed by less than the tolerance, and the parameters barely moved.
    assert abs(gm.score(x) - ours.score(points)) < tol * 10
    np.testing.assert_allclose(gm.weights_, w, atol=1e-3)
    np.testing.assert_allclose(gm.means_, mu, atol=1e-3)
    np.testing.assert_allclose(gm.covariances_, cov, atol=1e-4)


def test_sklearn_fit_from_our_init_reaches_our_likelihood(points):
    ours = sogmm.SOGMM(n_components=4, seed=0, tol=1e-5, max_iter=1000).fit(points)
    w, mu, cov = (np.asarray(a, np.float64) for a in (ours.weights_, ours.means_, ours.covariances_))
    gm = sk_mixture.GaussianMixture(n_components=4, covariance_type="full", reg_covar=1e-6, tol=1e-6, max_iter=500,
                                    weights_init=w / w.sum(), means_init=mu, precisions_init=np.linalg.inv(cov))
    gm.fit(points.astype(np.float64))
    assert gm.score(points.astype(np.float64)) == pytest.approx(ours.score(points), abs=1e-3)
