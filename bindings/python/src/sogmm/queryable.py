"""The read-only queries a model and a map share, written once.

:class:`Queryable` is the mixin of :class:`sogmm.GMM` (in the model's frame)
and :class:`sogmm.Map` (in the world frame, without exporting it): score,
regress, sample, render, surface distance and collision probability. Each
call builds one options handle from its keywords and runs the C function of
the handle's kind, ``<prefix>_<operation>`` (sogmm_model_* or sogmm_map_*),
so both classes give bitwise what the C API gives. ``progress`` is the
:data:`sogmm.progress.ProgressArg` of :meth:`sogmm.SOGMM.fit`.
"""

from __future__ import annotations

import contextlib

import numpy as np

from . import _ffi
from ._arrays import _pose, _rows, _sample_args
from ._ffi import lib
from .camera import Camera
from .errors import InvalidArgumentError, LimitError
from .progress import ProgressArg, call_with_progress

_D = _ffi.DEFAULTS

#: SOGMM_MAX_RENDER_PIXELS of sogmm.h: the largest width * height a render takes.
MAX_RENDER_PIXELS = 1 << 26


class Queryable:
    """Queries over a C handle. A subclass sets ``_C_PREFIX`` ("sogmm_model"
    or "sogmm_map"), gives ``_h()`` (the live handle, or raises) and may wrap
    each call in ``_reading(what)`` (Map: its use guard)."""

    _C_PREFIX = ""

    def _h(self):  # pragma: no cover - every subclass defines it
        raise NotImplementedError

    def _reading(self, what: str):
        return contextlib.nullcontext()

    def _query(self, what: str, operation: str, options: _ffi.Options, progress: ProgressArg, make_args) -> None:
        """Runs C ``<prefix>_<operation>(handle, *make_args(options_ptr))`` under the read guard."""
        fn = getattr(lib, f"{self._C_PREFIX}_{operation}")
        with options as o, self._reading(what):
            h = self._h()
            call_with_progress(o, progress, lambda: fn(h, *make_args(o.ptr)))

    def score_samples(self, X, progress: ProgressArg = None, *, truncation_nats: float = _D.query_truncation_nats,
                      n_threads: int = _D.threads) -> np.ndarray:
        """Log-density of each row: (n, 4) rows (x, y, z, gray) -> joint density,
        (n, 3) rows (x, y, z) -> spatial marginal. Returns float64 (n,).

        ``truncation_nats`` > 0 culls: a component is skipped at a point only
        when its term is provably more than that many nats below the point's
        largest, so each score is at most log(1 + M exp(-truncation_nats))
        below the exact one (0, the default, is exact). ``n_threads``: 0 = all
        cores; the answers are the same for any count. ``progress``: stage
        STAGE_SCORING, points done. A map without components: InvalidDataError."""
        x = _rows(X, (3, 4), "X")
        out = np.empty(x.shape[0], dtype=np.float64)
        self._query("score_samples", "score_samples_f32", _query_options(truncation_nats, n_threads), progress,
                   lambda o: (x, x.shape[0], x.shape[1], o, out))
        return out

    def score(self, X) -> float:
        """Mean log-density of the rows of X (see score_samples)."""
        return float(np.mean(self.score_samples(X)))

    def regress_gray(self, xyz, progress: ProgressArg = None, *, truncation_nats: float = _D.query_truncation_nats,
                     n_threads: int = _D.threads) -> tuple[np.ndarray, np.ndarray]:
        """Expected gray and its conditional variance at (n, 3) points: two float32
        (n,) arrays. ``truncation_nats`` and ``n_threads`` as for score_samples;
        ``progress``: stage STAGE_REGRESSION, points done."""
        x = _rows(xyz, (3,), "xyz")
        mean = np.empty(x.shape[0], dtype=np.float32)
        var = np.empty(x.shape[0], dtype=np.float32)
        self._query("regress_gray", "regress_gray_f32", _query_options(truncation_nats, n_threads), progress,
                   lambda o: (x, x.shape[0], o, mean, var))
        return mean, var

    def sample(self, n_samples: int = 1, seed: int | None = None, *, truncation: float = _D.sample_truncation,
               spatial_only: bool = False, progress: ProgressArg = None) -> np.ndarray:
        """Draws n_samples points, (n, 4) float32 rows (x, y, z, gray), grouped by
        component (or (n, 3) with spatial_only). The same seed gives the same
        samples; seed=None draws a fresh one. ``truncation`` (in standard
        deviations, may be inf) bounds each draw; ``progress``: stage
        STAGE_SAMPLING, points drawn."""
        n, seed, dims, out = _sample_args(n_samples, seed, spatial_only)
        self._query("sample", "sample_f32", _ffi.Options(f64={_ffi.OPT_SAMPLE_TRUNCATION: truncation}), progress,
                   lambda o: (n, seed, dims, o, out))
        return out

    def render(self, camera: Camera, pose=None, *, depth_min: float = _D.depth_min, depth_trunc: float = _D.depth_max,
               surface_sigma: float = _D.render_surface_sigma, n_threads: int = _D.threads,
               progress: ProgressArg = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """What the model or map shows from ``camera`` placed at ``pose`` (4 x 4
        camera-to-world rigid transform; None = identity): per pixel the first
        surface along its ray (the nearest mode of the density along the ray at
        depth in (depth_min, depth_trunc]), the gray regressed there and its
        variance. ``surface_sigma`` 0 counts every mode as a surface; s > 0
        only modes with the evidence of one component at s sigma, so a ray
        grazing a nearer object's components shows the surface behind.
        Returns three float32 (height, width) arrays: depth (camera z,
        metres), gray, variance; NaN where nothing shows. Bitwise the same for
        any ``n_threads``; ``progress``: stage STAGE_RENDERING, rows done. Bad
        camera or pose: InvalidArgumentError."""
        if not isinstance(camera, Camera):
            raise InvalidArgumentError(f"camera must be a sogmm.Camera, got {type(camera).__name__}")
        p = np.eye(4) if pose is None else _pose(pose)
        if camera.width * camera.height > MAX_RENDER_PIXELS:  # before allocating the images
            raise LimitError(f"render: {camera.width} x {camera.height} pixels exceed {MAX_RENDER_PIXELS}")
        depth, gray, var = (np.empty((camera.height, camera.width), dtype=np.float32) for _ in range(3))
        options = _ffi.Options(f64={_ffi.OPT_DEPTH_MIN: depth_min, _ffi.OPT_DEPTH_MAX: depth_trunc,
                                    _ffi.OPT_RENDER_SURFACE_SIGMA: surface_sigma},
                               i64={_ffi.OPT_THREADS: n_threads})
        self._query("render", "render_f32", options, progress,
                   lambda o: (camera.width, camera.height, camera.fx, camera.fy, camera.cx, camera.cy, p, o,
                              depth, gray, var))
        return depth, gray, var

    def surface_distance(self, points, gradient: bool = False, *, disc_sigmas: float = _D.surface_disc_sigmas,
                         n_threads: int = _D.threads, progress: ProgressArg = None):
        """Unsigned distance (metres) of (n, 3) points to the surface: an (n,)
        float64 array, and with ``gradient`` also the (n, 3) gradient (unit
        vectors pointing away from the nearest surface point). The surface is
        the union of the components' discs (their two largest principal axes
        out to ``disc_sigmas`` standard deviations); the search is exact."""
        x = _rows(points, (3,), "points")
        dist = np.empty(x.shape[0], dtype=np.float64)
        grad = np.empty((x.shape[0], 3), dtype=np.float64) if gradient else None
        grad_ptr = grad.ctypes.data if grad is not None and grad.size else None
        self._query("surface_distance", "surface_distance_f32", _surface_options(disc_sigmas, n_threads), progress,
                   lambda o: (x, x.shape[0], o, dist, grad_ptr))
        return (dist, grad) if gradient else dist

    def collision_probability(self, centers, shapes, *, disc_sigmas: float = _D.surface_disc_sigmas,
                              n_threads: int = _D.threads, progress: ProgressArg = None) -> np.ndarray:
        """Probability that each ellipsoidal robot touches the surface: ``centers``
        (n, 3), ``shapes`` (n, 3, 3) symmetric positive definite S (the robot is
        {x : (x - c)^T S^-1 (x - c) <= 1}; a sphere of radius r is r^2 I).
        The largest over the components' discs of Phi(-clearance / sigma_k),
        sigma_k the patch's noise along its normal: 1/2 at contact."""
        c = np.ascontiguousarray(centers, dtype=np.float64)
        s = np.ascontiguousarray(shapes, dtype=np.float64)
        if c.ndim != 2 or c.shape[1] != 3 or s.shape != (c.shape[0], 3, 3):
            raise InvalidArgumentError(f"centers must be (n, 3) and shapes (n, 3, 3), got {c.shape} and {s.shape}")
        out = np.empty(c.shape[0], dtype=np.float64)
        self._query("collision_probability", "collision_probability", _surface_options(disc_sigmas, n_threads),
                   progress, lambda o: (c, s, c.shape[0], o, out))
        return out


def _query_options(truncation_nats: float, n_threads: int) -> _ffi.Options:
    return _ffi.Options(f64={_ffi.OPT_QUERY_TRUNCATION_NATS: truncation_nats}, i64={_ffi.OPT_THREADS: n_threads})


def _surface_options(disc_sigmas: float, n_threads: int) -> _ffi.Options:
    return _ffi.Options(f64={_ffi.OPT_SURFACE_DISC_SIGMAS: disc_sigmas}, i64={_ffi.OPT_THREADS: n_threads})


__all__ = ["Queryable", "MAX_RENDER_PIXELS"]
