"""Models: GMM (any 4-D mixture held by libsogmm) and SOGMM (the estimator).

Arrays go in as C-contiguous float32 (converted with np.ascontiguousarray, no
copy when the layout already fits) and come out in arrays allocated here and
filled by C. Each model owns one ``sogmm_model`` handle, released by
weakref.finalize (or early by ``close()`` / a ``with`` block).
"""

from __future__ import annotations

import os
import weakref
from ctypes import byref, c_char_p, c_double, c_int64, c_size_t, c_void_p

import numpy as np

from . import _ffi
from ._ffi import check, lib
from .camera import Camera, prepare_frame
from ._arrays import _count, _pose, _real_array, _rows
from .errors import InvalidArgumentError, NotFittedError, NotFoundError
from .progress import ProgressArg, call_with_progress
from .queryable import Queryable

# The library's option defaults (sogmm_option_get_info): keyword defaults read, never copied.
_D = _ffi.DEFAULTS

__all__ = ["GMM", "SOGMM", "load", "from_bytes"]


def _write_options(float64: bool, compress: bool, zstd_level: int, max_decoded_bytes: int = _D.max_decoded_bytes,
                   component_precision: float = _D.array_precision) -> _ffi.Options:
    return _ffi.Options(
        f64={_ffi.OPT_ARRAY_PRECISION: component_precision},
        i64={_ffi.OPT_FLOAT64: int(bool(float64)), _ffi.OPT_COMPRESS: int(bool(compress)), _ffi.OPT_ZSTD_LEVEL: zstd_level,
             _ffi.OPT_MAX_DECODED_BYTES: max_decoded_bytes}
    )


def _read_options(verify_checksums: bool, max_decoded_bytes: int) -> _ffi.Options:
    return _ffi.Options(
        i64={_ffi.OPT_VERIFY_CHECKSUMS: int(bool(verify_checksums)), _ffi.OPT_MAX_DECODED_BYTES: max_decoded_bytes}
    )


class GMM(Queryable):
    """A 4-D Gaussian mixture over (x, y, z, gray) held by libsogmm.

    Create one with :meth:`from_arrays`, :func:`sogmm.load`,
    :func:`sogmm.from_bytes`, or by fitting a :class:`SOGMM`. Attributes
    follow scikit-learn's GaussianMixture: ``weights_`` (M,), ``means_``
    (M, 4), ``covariances_`` (M, 4, 4), all float32 and read-only.
    """

    _ptr: int | None = None
    _finalizer = None
    _C_PREFIX = "sogmm_model"  # the queries of Queryable

    # ---- handle management ----------------------------------------------
    @classmethod
    def _wrap(cls, ptr: c_void_p) -> "GMM":
        obj = cls.__new__(cls)
        obj._attach(ptr)
        return obj

    def _attach(self, ptr: c_void_p) -> None:
        self._release()
        self._ptr = int(ptr.value)
        self._cache = {}
        self._finalizer = weakref.finalize(self, lib.sogmm_model_free, c_void_p(self._ptr))

    def _release(self) -> None:
        if self._finalizer is not None:
            self._finalizer()  # frees the handle exactly once
        self._finalizer = None
        self._ptr = None
        self._cache = {}

    def _h(self) -> c_void_p:
        if self._ptr is None:
            raise NotFittedError(
                f"this {type(self).__name__} holds no model (not fitted yet, or closed): call fit() first"
            )
        return c_void_p(self._ptr)

    def close(self) -> None:
        """Releases the C model now (otherwise done when the object is collected)."""
        self._release()

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # ---- construction ----------------------------------------------------
    @classmethod
    def from_arrays(cls, weights, means, covariances, support_size: int = 0) -> "GMM":
        """A model from M weights, M x 4 means and M x 4 x 4 covariances (copied).

        ``support_size`` is the number of points the model stands for (used to
        weight merges; 0 = unknown). Weights must sum to 1 within 1e-4 and
        covariances be symmetric positive definite (InvalidDataError /
        NumericError otherwise)."""
        w = _real_array(weights, np.float32, "weights")
        mu = _real_array(means, np.float32, "means")
        cov = _real_array(covariances, np.float32, "covariances")
        if w.ndim != 1:
            raise InvalidArgumentError(f"weights must be 1-D (M,), got shape {w.shape}")
        m = w.shape[0]
        if mu.shape != (m, 4):
            raise InvalidArgumentError(f"means must have shape ({m}, 4), got {mu.shape}")
        if cov.shape != (m, 4, 4):
            raise InvalidArgumentError(f"covariances must have shape ({m}, 4, 4), got {cov.shape}")
        support_size = _count(support_size, "support_size")
        out = c_void_p()
        check(lib.sogmm_model_from_arrays_f32(byref(out), m, w, mu, cov, support_size))
        return GMM._wrap(out)

    def copy(self) -> "GMM":
        """Deep copy of the model and its metadata (a GMM)."""
        out = c_void_p()
        check(lib.sogmm_model_clone(byref(out), self._h()))
        return GMM._wrap(out)

    # ---- arrays and report -------------------------------------------------
    @property
    def n_components_(self) -> int:
        n = c_size_t()
        check(lib.sogmm_model_n_components(self._h(), byref(n)))
        return int(n.value)

    def _array(self, name: str, getter, shape_tail: tuple[int, ...]) -> np.ndarray:
        h = self._h()
        cached = self._cache.get(name)
        if cached is not None:
            return cached
        m = self.n_components_
        out = np.empty((m,) + shape_tail, dtype=np.float32)
        check(getter(h, out, out.size))
        out.flags.writeable = False
        self._cache[name] = out
        return out

    @property
    def weights_(self) -> np.ndarray:
        return self._array("weights", lib.sogmm_model_get_weights_f32, ())

    @property
    def means_(self) -> np.ndarray:
        return self._array("means", lib.sogmm_model_get_means_f32, (4,))

    @property
    def covariances_(self) -> np.ndarray:
        return self._array("covariances", lib.sogmm_model_get_covariances_f32, (4, 4))

    def _info(self, key: int, get, ctype):
        """The value of info key ``key`` read by ``get`` into a ``ctype``; None when the model has none."""
        v = ctype()
        try:
            check(get(self._h(), key, byref(v)))
        except NotFoundError:
            return None
        return v.value

    def _info_i64(self, key: int) -> int | None:
        return self._info(key, lib.sogmm_model_get_info_i64, c_int64)

    def _info_f64(self, key: int) -> float | None:
        return self._info(key, lib.sogmm_model_get_info_f64, c_double)

    @property
    def support_size_(self) -> int:
        """Number of points the model stands for (0 = unknown; merges refuse an unknown size against a known one)."""
        return self._info_i64(_ffi.INFO_SUPPORT_SIZE) % (1 << 64)  # the C API returns the uint64's bits

    @property
    def converged_(self) -> bool | None:
        """True if EM stopped on the tolerance (None: no fit record)."""
        v = self._info_i64(_ffi.INFO_FIT_CONVERGED)
        return None if v is None else bool(v)

    @property
    def n_iter_(self) -> int | None:
        """EM iterations run (None: no fit record)."""
        return self._info_i64(_ffi.INFO_FIT_ITERATIONS)

    @property
    def lower_bound_(self) -> float | None:
        """Final mean log-likelihood per point of the fit (None: no fit record)."""
        return self._info_f64(_ffi.INFO_FIT_LOG_LIKELIHOOD)

    @property
    def camera_(self) -> Camera | None:
        """The camera of an RGB-D fit (full-size intrinsics), else None."""
        w = self._info_i64(_ffi.INFO_CAMERA_WIDTH)
        if w is None:
            return None
        return Camera(
            w,
            self._info_i64(_ffi.INFO_CAMERA_HEIGHT),
            self._info_f64(_ffi.INFO_CAMERA_FX),
            self._info_f64(_ffi.INFO_CAMERA_FY),
            self._info_f64(_ffi.INFO_CAMERA_CX),
            self._info_f64(_ffi.INFO_CAMERA_CY),
        )

    _INFO_KEYS = {
        "support_size": (_ffi.INFO_SUPPORT_SIZE, "i"),
        "created_unix_ms": (_ffi.INFO_CREATED_UNIX_MS, "i"),
        "fit_iterations": (_ffi.INFO_FIT_ITERATIONS, "i"),
        "fit_converged": (_ffi.INFO_FIT_CONVERGED, "i"),
        "fit_log_likelihood": (_ffi.INFO_FIT_LOG_LIKELIHOOD, "f"),
        "fit_bandwidth": (_ffi.INFO_FIT_BANDWIDTH, "f"),
        "fit_n_components_requested": (_ffi.INFO_FIT_N_COMPONENTS_REQUESTED, "i"),
        "fit_tol": (_ffi.INFO_FIT_TOL, "f"),
        "fit_reg_covar": (_ffi.INFO_FIT_REG_COVAR, "f"),
        "fit_max_iter": (_ffi.INFO_FIT_MAX_ITER, "i"),
        "fit_seed": (_ffi.INFO_FIT_SEED, "i"),
        "fit_n_points": (_ffi.INFO_FIT_N_POINTS, "i"),
        "fit_seconds_mode_count": (_ffi.INFO_FIT_SECONDS_MODE_COUNT, "f"),
        "fit_seconds_seeding": (_ffi.INFO_FIT_SECONDS_SEEDING, "f"),
        "fit_seconds_em": (_ffi.INFO_FIT_SECONDS_EM, "f"),
        "fit_seconds_total": (_ffi.INFO_FIT_SECONDS_TOTAL, "f"),
        "fit_n_init": (_ffi.INFO_FIT_N_INIT, "i"),
        "fit_run": (_ffi.INFO_FIT_RUN, "i"),
        "camera_width": (_ffi.INFO_CAMERA_WIDTH, "i"),
        "camera_height": (_ffi.INFO_CAMERA_HEIGHT, "i"),
        "camera_fx": (_ffi.INFO_CAMERA_FX, "f"),
        "camera_fy": (_ffi.INFO_CAMERA_FY, "f"),
        "camera_cx": (_ffi.INFO_CAMERA_CX, "f"),
        "camera_cy": (_ffi.INFO_CAMERA_CY, "f"),
        "camera_decimation": (_ffi.INFO_CAMERA_DECIMATION, "i"),
        "camera_depth_scale": (_ffi.INFO_CAMERA_DEPTH_SCALE, "f"),
        "camera_depth_min": (_ffi.INFO_CAMERA_DEPTH_MIN, "f"),
        "camera_depth_max": (_ffi.INFO_CAMERA_DEPTH_MAX, "f"),
    }

    def info(self) -> dict:
        """Every fit-report, camera and timing value the model has (absent ones left out)."""
        out = {}
        for name, (key, kind) in self._INFO_KEYS.items():
            v = self._info_i64(key) if kind == "i" else self._info_f64(key)
            if v is not None:
                out[name] = v
        return out

    def set_info(self, **values) -> None:
        """Sets fit-record and camera values by their :meth:`info` names (e.g.
        ``fit_bandwidth=0.02, fit_iterations=40, camera_decimation=5``), the
        ones .sogmm files store; a model without that record gets one with the
        format's defaults first. Other names, or values the format cannot hold,
        raise InvalidArgumentError (earlier values of the call stay set)."""
        for name, value in values.items():
            if name not in self._INFO_KEYS:
                raise InvalidArgumentError(f"unknown info name {name!r}")
            key, kind = self._INFO_KEYS[name]
            if kind == "i":
                if isinstance(value, (bool, np.bool_)):
                    value = int(value)
                if not isinstance(value, (int, np.integer)):
                    raise InvalidArgumentError(f"{name} must be an int, got {value!r}")
                v = int(value)
                if name == "fit_seed" and (1 << 63) <= v < (1 << 64):
                    v -= 1 << 64  # the uint64's bits, as the getter returns them
                if not -(1 << 63) <= v < (1 << 63):
                    raise InvalidArgumentError(f"{name} = {value} does not fit in 64 bits")
                check(lib.sogmm_model_set_info_i64(self._h(), key, v))
            else:
                check(lib.sogmm_model_set_info_f64(self._h(), key, float(value)))

    # ---- pose and key/values -----------------------------------------------
    @property
    def pose(self) -> np.ndarray | None:
        """4 x 4 rigid transform of the model's frame to the world (None if unset).

        Assigning validates it (InvalidArgumentError unless rigid); None clears it."""
        out = np.empty((4, 4), dtype=np.float64)
        try:
            check(lib.sogmm_model_get_pose(self._h(), out))
        except NotFoundError:
            return None
        return out

    @pose.setter
    def pose(self, value) -> None:
        if value is None:
            check(lib.sogmm_model_clear_pose(self._h()))
        else:
            check(lib.sogmm_model_set_pose(self._h(), _pose(value)))

    @property
    def metadata(self) -> dict[str, str]:
        """Copy of the free-form key/value strings (stored in .sogmm files).

        A file may repeat a key; like the C API's lookup, the first pair with
        that key gives its value. Strings are valid UTF-8 without NUL: the
        library's reader rejects files whose strings are not."""
        h = self._h()
        n = c_size_t()
        check(lib.sogmm_model_value_count(h, byref(n)))
        out = {}
        for i in range(n.value):
            k, v = c_char_p(), c_char_p()
            check(lib.sogmm_model_value_at(h, i, byref(k), byref(v)))
            out.setdefault(k.value.decode("utf-8"), v.value.decode("utf-8"))
        return out

    def set_metadata(self, key: str, value: str) -> None:
        """Adds one key/value string, or replaces the value of the first pair with that key."""
        if not isinstance(key, str) or not isinstance(value, str):
            raise InvalidArgumentError("metadata keys and values must be str")
        if "\0" in key or "\0" in value:
            raise InvalidArgumentError("metadata keys and values must not contain NUL characters")
        try:
            k, v = key.encode("utf-8"), value.encode("utf-8")
        except UnicodeEncodeError as e:  # a lone surrogate has no UTF-8 form
            raise InvalidArgumentError(f"metadata keys and values must be valid Unicode text: {e}") from None
        check(lib.sogmm_model_set_value(self._h(), k, v))

    def merge(self, other: "GMM") -> "GMM":
        """A new model with the components of both, weighted by support size.

        A support size of 0 means unknown: two unknowns count equally, and an
        unknown against a known size raises InvalidArgumentError (any share
        would be a guess; build the model with its ``support_size``). Sizes
        whose sum exceeds 2**64 - 1 raise LimitError."""
        if not isinstance(other, GMM):
            raise InvalidArgumentError(f"merge needs a GMM, got {type(other).__name__}")
        out = c_void_p()
        check(lib.sogmm_model_merge(byref(out), self._h(), other._h()))
        return GMM._wrap(out)

    def transform(self, pose) -> "GMM":
        """A new model moved by the 4 x 4 rigid transform ``pose``: means -> R mu + t.

        InvalidArgumentError when a moved mean or covariance would not be
        finite in float32 (e.g. a translation of 1e39)."""
        p = _pose(pose)
        out = c_void_p()
        check(lib.sogmm_model_transform(byref(out), self._h(), p))
        return GMM._wrap(out)

    # ---- files and bytes ---------------------------------------------------
    def save(self, path: str | os.PathLike, *, float64: bool = bool(_D.float64), compress: bool = bool(_D.compress),
             zstd_level: int = _D.zstd_level, max_decoded_bytes: int = _D.max_decoded_bytes,
             component_precision: float = _D.array_precision) -> None:
        """Writes a .sogmm file atomically (temporary file + rename).

        Arrays decoding to more than ``max_decoded_bytes`` (0 = the 1 GiB that
        :func:`sogmm.load` accepts by default) raise LimitError, nothing
        written: raise it here and in ``load`` together.
        ``component_precision`` > 0 (at most 0.5; SOGMM_OPT_ARRAY_PRECISION)
        stores each component as integer codes that move its mean by at most
        that many of its standard deviations (spec/api.md has the bounds); 0
        stores float arrays, bit-exact. Out of range: InvalidArgumentError,
        nothing written."""
        h = self._h()
        p = os.fsencode(os.fspath(path))
        with _write_options(float64, compress, zstd_level, max_decoded_bytes, component_precision) as o:
            check(lib.sogmm_model_save(h, p, o.ptr))

    def to_bytes(self, *, float64: bool = bool(_D.float64), compress: bool = bool(_D.compress), zstd_level: int = _D.zstd_level,
                 max_decoded_bytes: int = _D.max_decoded_bytes, component_precision: float = _D.array_precision) -> bytes:
        """The bytes of a .sogmm file (``max_decoded_bytes`` and ``component_precision`` as in :meth:`save`)."""
        h = self._h()
        buf = c_void_p()
        with _write_options(float64, compress, zstd_level, max_decoded_bytes, component_precision) as o:
            check(lib.sogmm_model_save_to_memory(byref(buf), h, o.ptr))
        try:
            return _ffi.buffer_to_bytes(buf)
        finally:
            lib.sogmm_buffer_free(buf)

    @classmethod
    def load(cls, path: str | os.PathLike, *, verify_checksums: bool = bool(_D.verify_checksums),
             max_decoded_bytes: int = _D.max_decoded_bytes) -> "GMM":
        """Reads a .sogmm file (SogmmIOError if it cannot be read, FormatError if invalid)."""
        p = os.fsencode(os.fspath(path))
        out = c_void_p()
        with _read_options(verify_checksums, max_decoded_bytes) as o:
            check(lib.sogmm_model_load(byref(out), p, o.ptr))
        return GMM._wrap(out)

    @classmethod
    def from_bytes(cls, data, *, verify_checksums: bool = bool(_D.verify_checksums),
             max_decoded_bytes: int = _D.max_decoded_bytes) -> "GMM":
        """Reads a model from the bytes of a .sogmm file (bytes, bytearray, memoryview)."""
        if isinstance(data, str):
            raise InvalidArgumentError("from_bytes needs a bytes-like object, got str")
        try:
            buf = np.frombuffer(data, dtype=np.uint8)  # no copy for bytes, bytearray, memoryview
        except (TypeError, ValueError, BufferError):
            try:
                buf = np.frombuffer(memoryview(data).tobytes(), dtype=np.uint8)
            except TypeError:
                raise InvalidArgumentError(
                    f"from_bytes needs a bytes-like object, got {type(data).__name__}") from None
        out = c_void_p()
        with _read_options(verify_checksums, max_decoded_bytes) as o:
            check(lib.sogmm_model_load_from_memory(byref(out), buf.ctypes.data, buf.size, o.ptr))
        return GMM._wrap(out)

    # ---- pickling and copies -------------------------------------------------
    def __getstate__(self):
        state = {k: v for k, v in self.__dict__.items() if k not in ("_ptr", "_finalizer", "_cache")}
        state["_sogmm_bytes"] = self.to_bytes(compress=True) if self._ptr is not None else None
        return state

    def __setstate__(self, state):
        state = dict(state)
        data = state.pop("_sogmm_bytes", None)
        self.__dict__.update(state)
        self._ptr = None
        self._finalizer = None
        self._cache = {}
        if data is not None:
            self._attach(GMM.from_bytes(data)._detach())

    def _detach(self) -> c_void_p:
        """Hands the handle over to the caller (this object then holds none)."""
        ptr = self._h()
        if self._finalizer is not None:
            self._finalizer.detach()
        self._finalizer = None
        self._ptr = None
        self._cache = {}
        return ptr

    def __copy__(self):
        import copy as _copy

        return _copy.deepcopy(self)

    def __deepcopy__(self, memo):
        obj = type(self).__new__(type(self))
        obj.__dict__.update({k: v for k, v in self.__dict__.items() if k not in ("_ptr", "_finalizer", "_cache")})
        obj._ptr = None
        obj._finalizer = None
        obj._cache = {}
        if self._ptr is not None:
            obj._attach(self.copy()._detach())
        return obj

    def __repr__(self) -> str:
        if self._ptr is None:
            return f"<{type(self).__name__} (no model)>"
        return f"<GMM n_components={self.n_components_} support_size={self.support_size_}>"


_MODE_COUNTERS = {
    "flat_binned": _ffi.MODE_COUNTER_FLAT_BINNED,
    "gaussian_blurring": _ffi.MODE_COUNTER_GAUSSIAN_BLURRING,
}
# SOGMM_OPT_EM_ACCELERATION's values by name; the keyword's default is the library's.
_EM_ACCELERATIONS = {"none": 0, "squarem": 1}
_EM_ACCELERATION_DEFAULT = next(k for k, v in _EM_ACCELERATIONS.items() if v == _D.em_acceleration)


class SOGMM(GMM):
    """Self-organizing Gaussian mixture model of (x, y, z, gray) points.

    Parameters:
        bandwidth: mean-shift bandwidth that decides the number of components
            (ignored when n_components is set).
        seed: random seed (k-means++ seeding).
        tol: EM stops when the mean log-likelihood changes by less than tol.
        tol_standard_errors: c > 0: EM also stops when a pass changes the mean
            log-likelihood by less than c of its standard error (the per-point
            log-likelihoods' spread over sqrt(N), from the same E-step), so it
            stops at the data's own noise level; 0 (the library's default,
            SOGMM_OPT_TOL_STANDARD_ERRORS) = tol alone.
        reg_covar: "auto" (default): one floor added to the x, y, z covariance
            diagonals and one to gray's, derived from the data's scales
            (1e-6 and 1e-6 for a room-sized frame with gray in [0, 1], 1 m^2
            for a kilometre scene; see ``fit_reg_covar`` and the metadata
            keys ``reg_covar_gray`` and ``reg_covar_source`` of the fitted
            model). A number >= 0: added to all four diagonals as given.
        max_iter: EM iterations at most.
        n_components: None = self-organizing; an int K fits exactly K components.
        n_threads: worker threads of the fit (0 = all cores).
        mode_counter: "flat_binned" (default) or "gaussian_blurring".
        truncation_nats: 0 (default) = exact E-step; > 0 = truncated E-step that
            skips components provably more than this many nats below every
            point's best in a block (25 is a good value for full frames).
        dequantise_depth: None (default) = the library's automatic choice: on
            for ``fit_rgbd`` (points back-projected from a depth image), off for
            ``fit`` of an array. True: when the camera-frame depth sits on
            discrete levels, floor each component's variance along its viewing
            ray at the level's bin variance, so components do not collapse onto
            single levels (every seed converges; held-out pixels spread in their
            depth bins score higher;
            lower training likelihood). False: the paper's plain EM.
        n_init: runs of k-means++ + EM, seeded seed, seed + 1, ...; the run with
            the highest final mean log-likelihood is kept (as scikit-learn's
            GaussianMixture(n_init)). 1 (default) = the paper's single run.
        em_acceleration: "none" = plain EM, "squarem" = SQUAREM steps
            (extrapolation along two EM steps, rejected when the likelihood
            would fall; max_iter counts every E+M pass). The default is the
            library's (SOGMM_OPT_EM_ACCELERATION).
        warm_max_iter: EM passes at most of a warm start (``fit(X, init=...)``)
            while ``max_iter`` is left at its default (a ``max_iter`` set to
            anything else wins; never more than ``max_iter``); 0 = ``max_iter``
            alone. The default is the library's (SOGMM_OPT_WARM_MAX_ITER).

    After ``fit`` the estimator is also the fitted model (a :class:`GMM`).
    """

    def __init__(self, bandwidth: float = _D.bandwidth, seed: int = _D.seed, tol: float = _D.tol,
                 reg_covar: float | str = "auto", max_iter: int = _D.max_iter, n_components: int | None = None, n_threads: int = _D.threads,
                 mode_counter: str = "flat_binned", truncation_nats: float = _D.truncation_nats,
                 n_init: int = _D.n_init,
                 dequantise_depth: bool | None = None, em_acceleration: str = _EM_ACCELERATION_DEFAULT,
                 tol_standard_errors: float = _D.tol_standard_errors, warm_max_iter: int = _D.warm_max_iter):
        self.bandwidth = bandwidth
        self.seed = seed
        self.tol = tol
        self.reg_covar = reg_covar
        self.max_iter = max_iter
        self.n_components = n_components
        self.n_threads = n_threads
        self.mode_counter = mode_counter
        self.truncation_nats = truncation_nats
        self.n_init = n_init
        self.dequantise_depth = dequantise_depth
        self.em_acceleration = em_acceleration
        self.tol_standard_errors = tol_standard_errors
        self.warm_max_iter = warm_max_iter
        self._ptr = None
        self._finalizer = None
        self._cache = {}

    _PARAMS = ("bandwidth", "seed", "tol", "reg_covar", "max_iter", "n_components", "n_threads", "mode_counter",
               "truncation_nats", "n_init", "dequantise_depth", "em_acceleration", "tol_standard_errors",
               "warm_max_iter")

    def get_params(self, deep: bool = True) -> dict:
        return {k: getattr(self, k) for k in self._PARAMS}

    def set_params(self, **params) -> "SOGMM":
        for k, v in params.items():
            if k not in self._PARAMS:
                raise InvalidArgumentError(f"unknown parameter {k!r} for SOGMM")
            setattr(self, k, v)
        return self

    def _fit_options(self, extra_f64=None, extra_i64=None) -> _ffi.Options:
        if self.mode_counter not in _MODE_COUNTERS:
            raise InvalidArgumentError(f"mode_counter must be one of {sorted(_MODE_COUNTERS)}, got {self.mode_counter!r}")
        if self.em_acceleration not in _EM_ACCELERATIONS:
            raise InvalidArgumentError(
                f"em_acceleration must be one of {sorted(_EM_ACCELERATIONS)}, got {self.em_acceleration!r}")
        k = self.n_components
        if k is None:
            k = 0
        elif isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
            raise InvalidArgumentError(f"n_components must be None or an int >= 1, got {k!r}")
        for name in ("seed", "max_iter", "n_threads", "n_init", "warm_max_iter"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
                raise InvalidArgumentError(f"{name} must be an int, got {v!r}")
        seed = int(self.seed) & 0xFFFFFFFFFFFFFFFF
        if seed >= 2**63:
            seed -= 2**64  # the uint64 seed's bits as an int64
        f64 = {_ffi.OPT_BANDWIDTH: self.bandwidth, _ffi.OPT_TOL: self.tol, _ffi.OPT_TRUNCATION_NATS: self.truncation_nats,
               _ffi.OPT_TOL_STANDARD_ERRORS: self.tol_standard_errors}
        reg = self.reg_covar
        if isinstance(reg, str):
            if reg != "auto":
                raise InvalidArgumentError(f"reg_covar must be 'auto' or a finite number >= 0, got {reg!r}")
        else:
            # Checked here as well: the C API reads -1 as SOGMM_REG_COVAR_AUTO.
            if isinstance(reg, (int, float, np.integer, np.floating)) and not isinstance(reg, bool) and reg < 0:
                raise InvalidArgumentError(f"reg_covar must be 'auto' or a finite number >= 0, got {reg!r}")
            f64[_ffi.OPT_REG_COVAR] = reg  # NaN, inf and non-numbers are rejected below or by the C API
        i64 = {
            _ffi.OPT_N_COMPONENTS: int(k),
            _ffi.OPT_MAX_ITER: int(self.max_iter),
            _ffi.OPT_SEED: seed,
            _ffi.OPT_THREADS: int(self.n_threads),
            _ffi.OPT_N_INIT: int(self.n_init),
            _ffi.OPT_DEQUANTISE_DEPTH: (_ffi.DEQUANTISE_AUTO if self.dequantise_depth is None
                                        else int(bool(self.dequantise_depth))),
            _ffi.OPT_MODE_COUNTER: _MODE_COUNTERS[self.mode_counter],
            _ffi.OPT_EM_ACCELERATION: _EM_ACCELERATIONS[self.em_acceleration],
            _ffi.OPT_WARM_MAX_ITER: int(self.warm_max_iter),
        }
        f64.update(extra_f64 or {})
        i64.update(extra_i64 or {})
        for key, v in f64.items():
            if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)):
                raise InvalidArgumentError(f"{_ffi.OPTION_NAMES.get(key, f'option {key}')} must be a number, got {v!r}")
        return _ffi.Options(f64=f64, i64=i64)

    def fit(self, X, y=None, progress: ProgressArg = None, init: GMM | None = None) -> "SOGMM":
        """Fits the model to (n, 4) points (x, y, z, gray). Returns self.

        progress: None, True (a tqdm bar per stage) or a callable(stage, step,
        total, log_likelihood) called on this thread about every 20 ms (stages:
        sogmm.progress.STAGE_*); a truthy return cancels the fit with
        CancelledError, an exception it raises cancels and is re-raised. Ctrl-C
        cancels the fit and raises KeyboardInterrupt. A cancelled fit leaves
        the estimator as it was; a fit that had completed when Ctrl-C was seen
        is kept (the estimator is fitted) and KeyboardInterrupt is raised after
        it, with ``sogmm_completed = True`` (sogmm.progress).

        ``init``: warm start from a model of an earlier, overlapping cloud,
        already in these points' frame (e.g. ``prev.transform(relative_pose)``);
        the rule for keeping, removing and adding components is that of
        ``sogmm_fit_points_f32`` with ``initial`` (needs ``n_init == 1``), and
        so is its EM limit: ``warm_max_iter`` passes while ``max_iter`` is
        left at its default, ``max_iter`` otherwise."""
        x = _rows(X, (4,), "X")
        if init is not None and not isinstance(init, GMM):
            raise InvalidArgumentError(f"init must be a fitted GMM or SOGMM, got {type(init).__name__}")
        out = c_void_p()
        initial = None if init is None else init._h()
        with self._fit_options() as o:
            call_with_progress(o, progress,
                               lambda: lib.sogmm_fit_points_f32(byref(out), x, x.shape[0], initial, o.ptr),
                               keep=lambda: self._attach(out))
        return self

    def fit_rgbd(self, depth, color, camera: Camera, depth_scale: float = _D.depth_scale,
                 depth_min: float = _D.depth_min, depth_trunc: float = _D.depth_max, decimate: int = _D.decimation, progress: ProgressArg = None) -> "SOGMM":
        """Fits the model to one RGB-D frame (arguments as :func:`sogmm.rgbd_to_points`).

        The C library back-projects the frame (uint8 gray, uint8 RGB or float
        gray) and records the camera in the model (``camera_``). progress and
        Ctrl-C as :meth:`fit`. Returns self."""
        f = prepare_frame(depth, color, camera, depth_scale, depth_min, depth_trunc, decimate)
        out = c_void_p()
        with self._fit_options(f.f64, f.i64) as o, f.handle() as frame:
            call_with_progress(o, progress, lambda: lib.sogmm_fit_frame(byref(out), frame, o.ptr),
                               keep=lambda: self._attach(out))
        return self

    def __repr__(self) -> str:
        params = ", ".join(f"{k}={getattr(self, k)!r}" for k in self._PARAMS)
        fitted = f" fitted: M={self.n_components_}" if self._ptr is not None else ""
        return f"SOGMM({params}){fitted}"


def load(path: str | os.PathLike, **kwargs) -> GMM:
    """Reads a .sogmm file; see :meth:`GMM.load`."""
    return GMM.load(path, **kwargs)


def from_bytes(data, **kwargs) -> GMM:
    """Reads a model from .sogmm bytes; see :meth:`GMM.from_bytes`."""
    return GMM.from_bytes(data, **kwargs)

