"""Rigid registration of a point cloud (``sogmm_register_points_f32``) or of a model
(``sogmm_register_model``, distribution to distribution) to a model."""
from __future__ import annotations

import ctypes
import warnings

import numpy as np

from . import _ffi
from ._ffi import DEFAULTS as _D
from .model import GMM, _pose, _rows
from .progress import ProgressArg, call_with_progress


class RegistrationInfo(ctypes.Structure):
    """sogmm_registration_info."""

    _fields_ = [
        ("struct_size", ctypes.c_size_t),
        ("status", ctypes.c_int32),
        ("iterations", ctypes.c_int32),
        ("log_likelihood", ctypes.c_double),
        ("inlier_ratio", ctypes.c_double),
        ("rmse", ctypes.c_double),
        ("information", ctypes.c_double * 36),
        ("unobservable", ctypes.c_int32),
        ("eigen_ratio", ctypes.c_double),
    ]


def register(source=None, target_model: GMM = None, init=None, *, source_points=None, progress: ProgressArg = None,
             max_iter: int = _D.registration_max_iter, tol: float = _D.registration_tol,
             outlier_ratio: float = _D.registration_outlier_ratio, use_gray: bool = bool(_D.registration_use_gray),
             levels: int = _D.registration_levels, coarse_sigma: float = _D.registration_coarse_sigma,
             min_inlier_ratio: float = _D.registration_min_inlier_ratio,
             degeneracy_ratio: float = _D.registration_degeneracy_ratio,
             min_points: int = _D.registration_min_points, depth_noise: float = _D.registration_depth_noise,
             n_threads: int = _D.threads) -> tuple[np.ndarray, dict]:
    """The rigid pose that best explains ``source`` under ``target_model``.

    Args:
        source: (N, 4) rows of x, y, z, gray in the source's own frame, or a
            fitted GMM (e.g. a frame's own fit, in its own frame): then each
            of its components is scored by the closed-form overlap of its
            Gaussian with the target's (distribution to distribution, D2D),
            counted as many times as the points it stands for, and the
            figures are per point stood for.
        target_model: a fitted GMM (or a Map's exported model).
        init: 4 x 4 rigid initial guess, source to target frame (None = identity).
        source_points: the keyword this argument had before it also took a
            model; deprecated (a DeprecationWarning), use ``source``.
        depth_noise: k of the source points' depth noise sigma_z = k z^2
            (1/m; points in the sensor's frame, z their depth), added along
            each point's ray to the components' covariances; 0 off; point
            sources only (SOGMM_OPT_REGISTRATION_DEPTH_NOISE). The other
            keywords are the SOGMM_OPT_REGISTRATION_* options.

    Returns ``(pose, info)``: ``pose`` a 4 x 4 float64 array mapping source
    points into the target frame; ``info`` a dict with ``status``
    ("converged", "not_converged", "low_fitness", "degenerate"),
    ``converged`` (status == "converged"), ``iterations``,
    ``log_likelihood``, ``inlier_ratio``, ``rmse``, ``information`` (6 x 6
    observed information over (rotation, translation) about the target
    origin), ``unobservable`` and ``eigen_ratio``. The pose is an estimate
    only when converged: check ``info["status"]``. Bad input raises
    (InvalidArgumentError, InvalidDataError) as the C call does.
    """
    if source_points is not None:
        if source is not None:
            raise TypeError("register() got both source and source_points: pass source only")
        warnings.warn("register(source_points=...) is deprecated: pass source=", DeprecationWarning, stacklevel=2)
        source = source_points
    if source is None or target_model is None:
        raise TypeError("register() needs a source (points or a GMM) and a target_model")
    x = None if isinstance(source, GMM) else _rows(source, (4,), "source")
    start = None if init is None else np.ascontiguousarray(_pose(init))
    pose = np.empty(16, dtype=np.float64)
    info = RegistrationInfo(struct_size=ctypes.sizeof(RegistrationInfo))
    f64 = {_ffi.OPT_REGISTRATION_TOL: tol, _ffi.OPT_REGISTRATION_OUTLIER_RATIO: outlier_ratio,
           _ffi.OPT_REGISTRATION_COARSE_SIGMA: coarse_sigma, _ffi.OPT_REGISTRATION_MIN_INLIER_RATIO: min_inlier_ratio,
           _ffi.OPT_REGISTRATION_DEGENERACY_RATIO: degeneracy_ratio, _ffi.OPT_REGISTRATION_DEPTH_NOISE: depth_noise}
    i64 = {_ffi.OPT_REGISTRATION_MAX_ITER: max_iter, _ffi.OPT_REGISTRATION_USE_GRAY: int(bool(use_gray)),
           _ffi.OPT_REGISTRATION_LEVELS: levels, _ffi.OPT_REGISTRATION_MIN_POINTS: min_points,
           _ffi.OPT_THREADS: n_threads}
    with _ffi.Options(f64=f64, i64=i64) as o:
        init_ptr = None if start is None else start.ctypes.data
        if x is None:
            call_with_progress(o, progress, lambda: _ffi.lib.sogmm_register_model(
                target_model._h(), source._h(), init_ptr, o.ptr, pose, ctypes.byref(info)))
        else:
            call_with_progress(o, progress, lambda: _ffi.lib.sogmm_register_points_f32(
                target_model._h(), x, x.shape[0], init_ptr, o.ptr, pose, ctypes.byref(info)))
    return pose.reshape(4, 4), info_dict(info)


def info_dict(info: RegistrationInfo) -> dict:
    """The figures of a ``sogmm_registration_info`` as ``register`` returns them."""
    status = _ffi.REGISTRATION_STATUS[info.status]
    return {
        "status": status,
        "converged": status == "converged",
        "iterations": int(info.iterations),
        "log_likelihood": float(info.log_likelihood),
        "inlier_ratio": float(info.inlier_ratio),
        "rmse": float(info.rmse),
        "information": np.array(info.information, dtype=np.float64).reshape(6, 6),
        "unobservable": int(info.unobservable),
        "eigen_ratio": float(info.eigen_ratio),
    }
