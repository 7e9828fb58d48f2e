"""Bad input becomes a SogmmError subclass carrying the C library's message."""

from __future__ import annotations

import numpy as np
import pytest

import sogmm
from sogmm import _ffi

from conftest import blobs, synthetic_rgbd


def test_error_classes():
    assert issubclass(sogmm.InvalidArgumentError, ValueError)
    assert issubclass(sogmm.SogmmIOError, OSError)
    assert issubclass(sogmm.NotFittedError, AttributeError)
    for cls in (sogmm.InvalidArgumentError, sogmm.InvalidDataError, sogmm.NumericError, sogmm.SogmmIOError,
                sogmm.FormatError, sogmm.LimitError, sogmm.NotFoundError, sogmm.InternalError):
        assert issubclass(cls, sogmm.SogmmError)


@pytest.mark.parametrize("bad", [np.zeros((10, 5), np.float32), np.zeros(40, np.float32), np.zeros((2, 3, 4)),
                                 np.array([["a", "b", "c", "d"]]), np.zeros((10, 4), np.complex64)])
def test_wrong_shape_or_dtype(bad):
    with pytest.raises(sogmm.InvalidArgumentError):
        sogmm.SOGMM().fit(bad)


def test_nan_points_message_from_c():
    x = blobs(n_per=20)
    x[5, 2] = np.nan
    with pytest.raises(sogmm.InvalidDataError) as e:
        sogmm.SOGMM().fit(x)
    assert e.value.status == -3
    assert e.value.message and str(e.value) == e.value.message
    assert "nan" in e.value.message.lower() or "finite" in e.value.message.lower()


def test_empty_points():
    with pytest.raises(sogmm.InvalidDataError):
        sogmm.SOGMM().fit(np.zeros((0, 4), np.float32))


@pytest.mark.parametrize("params, needle", [
    (dict(bandwidth=-0.1), "bandwidth"),
    (dict(bandwidth=0.0), "bandwidth"),
    (dict(bandwidth=float("nan")), "bandwidth"),
    (dict(bandwidth=4e-314), "bandwidth"),  # 1 / (2 bw^2) overflows
    (dict(bandwidth=1e154), "bandwidth"),  # 2 bw^2 overflows
    (dict(reg_covar=1e39), "reg"),  # not finite in float32
    (dict(tol=-1e-9), "tol"),
    (dict(reg_covar=-1.0), "reg"),
    (dict(max_iter=0), "iter"),
    (dict(n_threads=-1), "thread"),
])
def test_bad_parameters_are_rejected_by_c(params, needle):
    with pytest.raises(sogmm.InvalidArgumentError) as e:
        sogmm.SOGMM(**params).fit(blobs(n_per=20))
    assert e.value.status == -2
    assert needle in e.value.message.lower()


def test_bad_parameters_checked_in_python():
    for params in (dict(n_components=0), dict(n_components=2.5), dict(seed="x"), dict(mode_counter="nope")):
        with pytest.raises(sogmm.InvalidArgumentError):
            sogmm.SOGMM(**params).fit(blobs(n_per=20))
    with pytest.raises(sogmm.InvalidArgumentError):
        sogmm.SOGMM().set_params(nonsense=1)


def test_k_larger_than_n():
    with pytest.raises(sogmm.InvalidArgumentError) as e:
        sogmm.SOGMM(n_components=31).fit(blobs(n_per=30, centers=[[0, 0, 1, 0.5]]))
    assert "31" in e.value.message


def test_inference_errors(fitted):
    with pytest.raises(sogmm.InvalidArgumentError):
        fitted.score_samples(np.zeros((3, 2), np.float32))
    bad = np.zeros((3, 4), np.float32)
    bad[1, 0] = np.inf
    with pytest.raises(sogmm.InvalidDataError):
        fitted.score_samples(bad)
    with pytest.raises(sogmm.InvalidDataError):
        fitted.regress_gray(np.full((2, 3), np.nan))
    with pytest.raises(sogmm.InvalidArgumentError):
        fitted.regress_gray(np.zeros((2, 4)))
    with pytest.raises(sogmm.InvalidArgumentError):
        fitted.sample(-1)
    with pytest.raises(sogmm.InvalidArgumentError):
        fitted.sample(10, truncation=0.0)
    with pytest.raises(sogmm.InvalidArgumentError):
        fitted.transform(np.diag([1.0, 1.0, -1.0, 1.0]))  # a reflection


def test_from_arrays_errors():
    cov = np.eye(4, dtype=np.float32)[None] * 0.01
    with pytest.raises(sogmm.InvalidDataError):
        sogmm.GMM.from_arrays([1.1], [[0, 0, 0, 0]], cov)
    with pytest.raises(sogmm.InvalidDataError):
        sogmm.GMM.from_arrays([1.0], [[0, 0, np.nan, 0]], cov)
    asym = cov.copy()
    asym[0, 0, 1] = 0.005
    with pytest.raises(sogmm.InvalidDataError):
        sogmm.GMM.from_arrays([1.0], [[0, 0, 0, 0]], asym)
    not_pd = -cov
    with pytest.raises(sogmm.NumericError):
        sogmm.GMM.from_arrays([1.0], [[0, 0, 0, 0]], not_pd)
    with pytest.raises(sogmm.InvalidArgumentError):
        sogmm.GMM.from_arrays([0.5, 0.5], [[0, 0, 0, 0]], cov)
    with pytest.raises(sogmm.InvalidDataError):
        sogmm.GMM.from_arrays(np.zeros(0), np.zeros((0, 4)), np.zeros((0, 4, 4)))


def test_rgbd_errors():
    depth, color, cam = synthetic_rgbd()
    est = sogmm.SOGMM()
    with pytest.raises(sogmm.InvalidArgumentError, match="dtype"):
        est.fit_rgbd(depth.astype(np.float32), color, cam)
    with pytest.raises(sogmm.InvalidArgumentError, match="shape"):
        est.fit_rgbd(depth[:, :-1], color, cam)
    with pytest.raises(sogmm.InvalidArgumentError):
        est.fit_rgbd(depth, color[:, :, :2], cam)
    with pytest.raises(sogmm.InvalidArgumentError):
        est.fit_rgbd(depth, color.astype(np.float32), cam)  # float RGB
    with pytest.raises(sogmm.InvalidArgumentError):
        est.fit_rgbd(depth, color, "camera")
    # The ranges and the rules between the values are the library's registry's
    # (the binding checks only that decimate is an integer).
    with pytest.raises(sogmm.InvalidArgumentError, match="DEPTH_MIN = 2 must be < SOGMM_OPT_DEPTH_MAX = 1"):
        est.fit_rgbd(depth, color, cam, depth_min=2.0, depth_trunc=1.0)
    with pytest.raises(sogmm.InvalidArgumentError, match=r"decimate = 0 is invalid.*\[1, 1024\]"):
        est.fit_rgbd(depth, color, cam, decimate=0)
    with pytest.raises(sogmm.InvalidArgumentError, match="leaves no pixel"):
        est.fit_rgbd(depth, color, cam, decimate=cam.height + 1)
    for bad in (1.5, True, "2"):
        with pytest.raises(sogmm.InvalidArgumentError, match="must be an integer"):
            sogmm.rgbd_to_points(depth, color, cam, decimate=bad)
    with pytest.raises(sogmm.InvalidArgumentError, match="leaves no pixel"):
        sogmm.rgbd_to_points(depth, color, cam, decimate=cam.width + 1)
    with pytest.raises(sogmm.InvalidDataError) as e:
        est.fit_rgbd(np.zeros_like(depth), color, cam)  # no valid pixel: found by C
    assert e.value.status == -3 and "pixel" in e.value.message
    with pytest.raises(sogmm.InvalidArgumentError):
        sogmm.rgbd_to_points(depth, color, cam, depth_scale=0.0)
    # Integer depth of another dtype is accepted when it fits uint16.
    assert sogmm.rgbd_to_points(depth.astype(np.int32), color, cam).shape[0] > 0
    with pytest.raises(sogmm.InvalidArgumentError):
        sogmm.rgbd_to_points(depth.astype(np.int32) - 70000, color, cam)


def test_option_errors_carry_c_messages():
    with pytest.raises(sogmm.InvalidArgumentError) as e:
        _ffi.Options(i64={99999: 1})
    assert e.value.message  # the C library names the key
    with pytest.raises(sogmm.InvalidArgumentError):
        _ffi.Options(f64={_ffi.OPT_MAX_ITER: 1.0})  # i64 key through the f64 setter


def test_info_keys_are_not_option_keys():
    # Info keys (10000 and up) never alias an option: the C library names the key.
    for key in (_ffi.INFO_FIT_ITERATIONS, _ffi.INFO_SUPPORT_SIZE, _ffi.INFO_CAMERA_FX):
        assert key >= 10000
        with pytest.raises(sogmm.InvalidArgumentError) as e:
            _ffi.Options(f64={key: 0.5})
        assert "SOGMM_INFO_" in e.value.message and "info key" in e.value.message
    assert all(k < 10000 for k in _ffi.OPTION_NAMES)



@pytest.mark.parametrize("reg", [-1.0, -1, -1e-9, float("-inf"), float("inf"), float("nan"), "automatic", None])
def test_reg_covar_must_be_auto_or_a_finite_value_at_least_zero(reg):
    # -1 is the C API's SOGMM_REG_COVAR_AUTO: Python refuses it as a value.
    with pytest.raises(sogmm.InvalidArgumentError, match="reg_covar"):
        sogmm.SOGMM(reg_covar=reg).fit(blobs(n_per=20))


def test_reg_covar_auto_and_values_are_recorded():
    pts = blobs(n_per=20)
    auto = sogmm.SOGMM(n_components=2, seed=1).fit(pts)
    assert auto.reg_covar == "auto" and auto.metadata["reg_covar_source"] == "auto"
    user = sogmm.SOGMM(n_components=2, seed=1, reg_covar=2e-4).fit(pts)
    assert user.metadata == {"reg_covar_gray": "0.0002", "reg_covar_source": "user"}
    assert user.info()["fit_reg_covar"] == 2e-4
