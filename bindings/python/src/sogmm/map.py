"""Map: an incremental world map over libsogmm's ``sogmm_map_*`` (issue 18).

Frames go in with their camera-to-world pose; only points the map does not
yet explain (3-D log-likelihood under the local submap below
``novelty_threshold``) are kept, batched and fitted, and the new components
are merged in the world frame (optionally fused into close ones). The
algorithm is documented in core/include/sogmm/map.hpp.
"""

from __future__ import annotations

import ctypes
import os
import threading
import weakref
from contextlib import contextmanager
from ctypes import byref, c_double, c_int64, c_size_t, c_uint64, c_void_p

import numpy as np

from . import _ffi
from ._ffi import check, lib
from .camera import Camera, prepare_frame
from .errors import InvalidArgumentError, MapBusyError
from ._arrays import _pose, _real_array, _rows
from .model import GMM, SOGMM, _read_options, _write_options
from .progress import ProgressArg, call_with_progress
from .queryable import Queryable
from .registration import RegistrationInfo, info_dict

# The library's option defaults (sogmm_option_get_info): keyword defaults read, never copied.
_D = _ffi.DEFAULTS

__all__ = ["Map"]

_FUSION = {None: None, "off": None, "hellinger": _ffi.FUSION_HELLINGER, "kl": _ffi.FUSION_KL}


# The keys behind stats() and frame_stats(): name -> key.
_MAP_KEYS = {
    "n_components": _ffi.MAP_N_COMPONENTS,
    "n_pending": _ffi.MAP_N_PENDING,
    "n_frames": _ffi.MAP_N_FRAMES,
    "n_flushes": _ffi.MAP_N_FLUSHES,
    "n_fused": _ffi.MAP_N_FUSED,
    "n_refits": _ffi.MAP_N_REFITS,
}
_FRAME_I64_KEYS = {
    "n_points": _ffi.MAP_FRAME_N_POINTS,
    "n_novel": _ffi.MAP_FRAME_N_NOVEL,
    "n_components": _ffi.MAP_FRAME_N_COMPONENTS,
    "flushed": _ffi.MAP_FRAME_FLUSHED,
    "n_replaced": _ffi.MAP_FRAME_N_REPLACED,
}
_FRAME_F64_KEYS = {
    "ms_novelty": _ffi.MAP_FRAME_MS_NOVELTY,
    "ms_fit": _ffi.MAP_FRAME_MS_FIT,
    "ms_merge": _ffi.MAP_FRAME_MS_MERGE,
}


class _UseGuard:
    """The Python side of the map's use guard (sogmm.h, "Use guard"): a call
    that changes the map (insert, flush, close) needs it alone, calls that read
    it share it, and a call that finds it otherwise taken raises MapBusyError
    at once. The C library checks the same, but only inside its calls: this
    also covers what Python does around them (the handle that close() frees,
    the progress callback an insert installs and removes), so two threads,
    or a callback calling back into its map, get the error and never free or
    change the map under a running call."""

    def __init__(self):
        self._lock = threading.Lock()
        self._users = 0  # > 0: reading calls; -1: the one changing call

    def _busy(self, what: str, conflict: str) -> MapBusyError:
        return MapBusyError(f"map busy: Map.{what} cannot run while {conflict} (on another thread, or the call "
                            f"whose progress callback is running); a map is changed by one call at a time", -13)

    @contextmanager
    def changing(self, what: str):
        with self._lock:
            if self._users != 0:
                raise self._busy(what, "another call is using the map")
            self._users = -1
        try:
            yield
        finally:
            with self._lock:
                self._users = 0

    @contextmanager
    def reading(self, what: str):
        with self._lock:
            if self._users < 0:
                raise self._busy(what, "a call changing the map runs")
            self._users += 1
        try:
            yield
        finally:
            with self._lock:
                self._users -= 1


class Map(Queryable):
    """An incremental world map of posed frames.

    Args:
        novelty: False fits every inserted frame whole (append everything).
        novelty_threshold: nats; points whose 3-D log-likelihood under the
            local map is below it are new (default 3.0, the authors').
        batch_size: new points that trigger a fit (default 12288: one frame
            decimated by 5).
        novelty_bandwidth_scale: s in (0, 1] (default 0.7): with novelty on, a
            batch of new points is fitted with the bandwidth times
            s + (1 - s) h^2, h the share of its point pairs from one frame (1
            for a batch of one frame, ~0.1 for the slivers of many), since a map
            component serves closer views than the one it was fitted from and
            a batch pools the slivers of many frames; core/include/sogmm/map.hpp.
        revisit_refit_ratio: 0 (off) or >= 1 (default 1.25): an RGB-D frame
            whose points the map explains, with at least this many times as
            many modes as the map has components on its surfaces, replaces
            those components by a fit of its points plus samples of their mass
            it does not see (the map keeps the finest view of each surface, not
            the first; not with a fixed ``n_components`` or ``warm_start``;
            details in core/include/sogmm/map.hpp).
        free_space_carve: in [0, 0.5] (default 0.002, one of the 256
            samples; 0: off): with novelty on,
            a map component with at least this share of its samples where an
            RGB-D frame sees past them (free space) is reshaped to the moments
            of its other samples (weight kept), so that its tail past an
            outline no longer stops that view's rays; new components are
            carved by every RGB-D frame inserted since the map was created or
            loaded (core/include/sogmm/map.hpp).
        component_precision: in [0, 0.5] standard deviations (default 0: off,
            full float32): each fitted component is rounded before the map
            stores it, its mean by at most this many of its standard
            deviations and its covariance's eigenvalues by at most this
            fraction, so that the low mantissa bits are zeros that deltas and
            map files compress away (bounds: MapOptions::component_precision,
            core/include/sogmm/map.hpp).
        fusion: None/"off", "hellinger" or "kl": fuse new components into
            close existing ones (distance below ``fusion_threshold``).
        fusion_threshold: Hellinger distance in [0, 1] or symmetric KL in nats.
        warm_start: True starts each batch's fit from the previous batch's
            model moved into its camera (as ``SOGMM.fit(init=...)``); meant for
            ``novelty=False``, needs ``n_init=1``.
        depth_scale, depth_min, depth_trunc, decimate: back-projection of
            :meth:`insert_rgbd` frames (as :func:`sogmm.rgbd_to_points`).
        registration_use_gray: :meth:`track_rgbd` registers with gray too (the
            4-D density, as :func:`sogmm.register`'s ``use_gray``; the
            default), which holds the pose where geometry alone lets a frame
            slide (a wall, a floor); False: the geometry alone, no odometry.
        tracking_odometry: with ``registration_use_gray``, a frame the map
            does not accept is registered to the last frame :meth:`track_rgbd`
            inserted too, and inserted when the two poses agree (within
            ``tracking_max_disagreement`` metres, RMS over the frame's points)
            or the map has too few inliers to judge (rule and why:
            core/include/sogmm/map_tracking.hpp).
        delta_history: how many of its latest revisions the map keeps the
            changes of for :meth:`export_delta` (0, the default: all of them;
            an older start then raises InvalidArgumentError naming the oldest
            kept). Bounds what a long run keeps.
        **fit_params: parameters of each batch's fit, as :class:`sogmm.SOGMM`
            (bandwidth, seed, n_threads, ...).

    Errors raise the :class:`sogmm.SogmmError` subclasses: a pose that is not
    a finite rigid transform -> InvalidArgumentError, an empty frame ->
    InvalidDataError, a frame of another size than the first RGB-D frame ->
    InvalidArgumentError. A failed insert leaves the map unchanged.

    Threads and callbacks: one call changes a map at a time. An insert, flush
    or close() while another call on the map runs (on another thread, or from
    the progress callback of that call) raises :class:`sogmm.MapBusyError`
    ("map busy: ...") and changes nothing; so does a query or statistics call
    while an insert or flush runs. Queries and statistics may run on several
    threads at once.
    """

    def __init__(self, *, novelty: bool = bool(_D.map_novelty),
                 novelty_threshold: float = _D.map_novelty_threshold, batch_size: int = _D.map_batch_size,
                 fusion: str | None = None, fusion_threshold: float = _D.map_fusion_threshold,
                 warm_start: bool = bool(_D.map_warm_start),
                 novelty_bandwidth_scale: float = _D.map_novelty_bandwidth_scale,
                 revisit_refit_ratio: float = _D.map_revisit_refit_ratio,
                 free_space_carve: float = _D.map_free_space_carve,
                 component_precision: float = _D.map_component_precision,
                 depth_scale: float = _D.depth_scale, depth_min: float = _D.depth_min,
                 depth_trunc: float = _D.depth_max, decimate: int = _D.decimation,
                 registration_use_gray: bool = bool(_D.registration_use_gray),
                 tracking_odometry: bool = bool(_D.tracking_odometry),
                 tracking_max_disagreement: float = _D.tracking_max_disagreement,
                 delta_history: int = _D.map_delta_history,
                 **fit_params):
        self._ptr = None
        self._finalizer = None
        self._guard = _UseGuard()
        self._depth = (depth_scale, depth_min, depth_trunc, decimate)
        self._carve = free_space_carve
        self._precision = component_precision
        with self._options(novelty, novelty_threshold, batch_size, fusion, fusion_threshold, warm_start,
                           fit_params, novelty_bandwidth_scale, revisit_refit_ratio, registration_use_gray,
                           tracking_odometry, tracking_max_disagreement, delta_history) as o:
            out = c_void_p()
            if self._load_from is None:
                check(lib.sogmm_map_create(byref(out), o.ptr))
            else:
                self._load(o, out)
        self._attach(out)

    def _options(self, novelty, novelty_threshold, batch_size, fusion, fusion_threshold, warm_start,
                 fit_params, novelty_bandwidth_scale, revisit_refit_ratio, registration_use_gray,
                 tracking_odometry, tracking_max_disagreement, delta_history) -> _ffi.Options:
        if fusion not in _FUSION:
            raise InvalidArgumentError(f"fusion must be None, 'off', 'hellinger' or 'kl', got {fusion!r}")
        for name, v in (("batch_size", batch_size), ("delta_history", delta_history)):
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
                raise InvalidArgumentError(f"{name} must be an int, got {v!r}")
        for k in fit_params:
            if k not in SOGMM._PARAMS:
                raise InvalidArgumentError(f"unknown parameter {k!r} for Map")
        depth_scale, depth_min, depth_trunc, decimate = self._depth
        if isinstance(decimate, bool) or int(decimate) != decimate or int(decimate) < 1:
            raise InvalidArgumentError(f"decimate = {decimate!r} must be an integer >= 1")
        f64 = {_ffi.OPT_MAP_NOVELTY_THRESHOLD: novelty_threshold, _ffi.OPT_MAP_FUSION_THRESHOLD: fusion_threshold,
               _ffi.OPT_MAP_NOVELTY_BANDWIDTH_SCALE: novelty_bandwidth_scale,
               _ffi.OPT_MAP_REVISIT_REFIT_RATIO: revisit_refit_ratio,
               _ffi.OPT_MAP_FREE_SPACE_CARVE: self._carve,
               _ffi.OPT_MAP_COMPONENT_PRECISION: self._precision,
               _ffi.OPT_TRACKING_MAX_DISAGREEMENT: tracking_max_disagreement,
               _ffi.OPT_DEPTH_SCALE: depth_scale, _ffi.OPT_DEPTH_MIN: depth_min, _ffi.OPT_DEPTH_MAX: depth_trunc}
        i64 = {_ffi.OPT_MAP_NOVELTY: int(bool(novelty)), _ffi.OPT_MAP_BATCH_SIZE: int(batch_size),
               _ffi.OPT_MAP_FUSION: int(_FUSION[fusion] is not None), _ffi.OPT_DECIMATION: int(decimate),
               _ffi.OPT_MAP_WARM_START: int(bool(warm_start)),
               _ffi.OPT_REGISTRATION_USE_GRAY: int(bool(registration_use_gray)),
               _ffi.OPT_TRACKING_ODOMETRY: int(bool(tracking_odometry)),
               _ffi.OPT_MAP_DELTA_HISTORY: int(delta_history)}
        if _FUSION[fusion] is not None:
            i64[_ffi.OPT_MAP_FUSION_METHOD] = _FUSION[fusion]
        # The fit keys exactly as SOGMM sets them (same checks and messages).
        return SOGMM(**fit_params)._fit_options(f64, i64)

    # ---- handle management ----------------------------------------------
    def _attach(self, ptr: c_void_p) -> None:
        self._ptr = int(ptr.value)
        self._finalizer = weakref.finalize(self, lib.sogmm_map_free, c_void_p(self._ptr))

    def _h(self) -> c_void_p:
        if self._ptr is None:
            raise InvalidArgumentError("this Map is closed")
        return c_void_p(self._ptr)

    def close(self) -> None:
        """Releases the C map now (otherwise done when the object is
        collected). MapBusyError while another call uses the map (from another
        thread, or from that call's progress callback): close it after."""
        with self._guard.changing("close"):
            if self._finalizer is not None:
                self._finalizer()
            self._finalizer = None
            self._ptr = None

    def __enter__(self) -> "Map":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # ---- inserting ---------------------------------------------------------
    def _call(self, what: str, progress: ProgressArg, c_call) -> None:
        """One mutating C call on the map, with ``progress`` (as in SOGMM.fit)
        reporting the fit it may run (sogmm_map_set_progress). A cancelled
        call leaves the map as it was. ``c_call(h)`` gets the handle; the
        call holds the map alone (MapBusyError otherwise)."""
        with self._guard.changing(what):
            h = self._h()
            if progress is None:
                check(c_call(h))
                return
            call_with_progress(None, progress, lambda: c_call(h),
                               install=lambda cb: lib.sogmm_map_set_progress(h, cb, None))

    def insert_points(self, points, pose, progress: ProgressArg = None) -> dict:
        """Inserts (n, 4) points (x, y, z, gray) in the camera frame with the
        4 x 4 camera-to-world ``pose``; returns that frame's statistics
        (see :meth:`frame_stats`)."""
        x = _rows(points, (4,), "points")
        p = _pose(pose)
        self._call("insert_points", progress, lambda h: lib.sogmm_map_insert_points_f32(h, x, x.shape[0], p))
        return self.frame_stats(-1)

    def insert_rgbd(self, depth, color, camera: Camera, pose, progress: ProgressArg = None) -> dict:
        """Inserts an RGB-D frame (depth and color as :meth:`sogmm.SOGMM.fit_rgbd`;
        back-projection options from the constructor) with its 4 x 4
        camera-to-world ``pose``; returns that frame's statistics."""
        f = prepare_frame(depth, color, camera, *self._depth)
        p = _pose(pose)
        with f.handle() as frame:
            self._call("insert_rgbd", progress, lambda h: lib.sogmm_map_insert_frame(h, frame, p))
        return self.frame_stats(-1)

    def track_rgbd(self, depth, color, camera: Camera, guess=None,
                   progress: ProgressArg = None) -> tuple[np.ndarray, dict]:
        """Inserts an RGB-D frame at the camera-to-world pose that registration
        to the map finds (``sogmm_map_track_frame``): from ``guess`` (4 x 4),
        or with None the constant-velocity prediction from the map's last two
        frames. The map's first frame is inserted at the guess (None: the
        identity). The frame is inserted only when the registration converged
        or, with ``registration_use_gray`` and ``tracking_odometry``, when its
        registration to the last tracked frame vouches for it (see the
        constructor); ``info`` is the map registration's either way.

        Returns ``(pose, info)``: the pose used (or the registration's last
        iterate when not inserted) and :func:`sogmm.register`'s figures plus
        ``inserted`` (bool) and ``registered`` (False for the first frame).
        Bad input raises as :meth:`insert_rgbd` and :func:`sogmm.register`.
        """
        f = prepare_frame(depth, color, camera, *self._depth)
        start = None if guess is None else np.ascontiguousarray(_pose(guess))
        pose = np.empty(16, dtype=np.float64)
        inserted = ctypes.c_int32(0)
        info = RegistrationInfo(struct_size=ctypes.sizeof(RegistrationInfo))
        with f.handle() as frame:
            self._call("track_rgbd", progress, lambda h: lib.sogmm_map_track_frame(
                h, frame, None if start is None else start.ctypes.data, pose, byref(inserted), byref(info)))
        out = info_dict(info)
        out["inserted"] = bool(inserted.value)
        out["registered"] = out["iterations"] > 0
        return pose.reshape(4, 4), out

    def flush(self, progress: ProgressArg = None) -> int:
        """Fits the pending points now; returns the number of components added."""
        before = self.n_components_
        self._call("flush", progress, lambda h: lib.sogmm_map_flush(h))
        return self.n_components_ - before

    def discard_pending(self) -> int:
        """Drops the points pending for a fit (they never become components);
        returns how many there were. The frames stay recorded. The way out
        when a flush keeps failing and the map cannot be saved."""
        dropped = c_uint64()
        with self._guard.changing("discard_pending"):
            check(lib.sogmm_map_discard_pending(self._h(), byref(dropped)))
        return int(dropped.value)

    @property
    def origin(self) -> np.ndarray:
        """The map's origin (anchor; 3 world coordinates, metres): the map holds
        its components relative to it, so that far from the world origin
        (geo-referenced poses) they keep room-scale resolution. By default the
        first frame's translation rounded to 1 km per axis (0 near the world
        origin); a loaded map's comes from its file (sogmm_map_get_origin)."""
        out = np.empty(3, dtype=np.float64)
        with self._guard.reading("origin"):
            check(lib.sogmm_map_get_origin(self._h(), out))
        return out

    def set_origin(self, origin) -> None:
        """Declares the origin (3 world coordinates, metres, finite within
        float32 range) instead of the first frame's; only before the first
        insert, else InvalidArgumentError (sogmm_map_set_origin)."""
        o = _real_array(origin, np.float64, "origin")
        if o.shape != (3,):
            raise InvalidArgumentError(f"origin must hold 3 values, got shape {o.shape}")
        with self._guard.changing("set_origin"):
            check(lib.sogmm_map_set_origin(self._h(), o))

    # ---- statistics ----------------------------------------------------------
    def stats(self) -> dict:
        """n_components, n_pending, n_frames, n_flushes, n_fused, n_refits
        (revisit refits, also counted in n_flushes)."""
        out = {}
        v = c_int64()
        with self._guard.reading("stats"):
            for name, key in _MAP_KEYS.items():
                check(lib.sogmm_map_get_i64(self._h(), key, byref(v)))
                out[name] = int(v.value)
        return out

    @property
    def n_components_(self) -> int:
        return self.stats()["n_components"]

    @property
    def n_pending_(self) -> int:
        """Novel points waiting for a fit."""
        return self.stats()["n_pending"]

    def __len__(self) -> int:
        return self.stats()["n_frames"]

    def frame_stats(self, frame: int) -> dict:
        """What the insert of ``frame`` (insertion order; negative counts from
        the end) did: n_points, n_novel, n_components (after it), flushed,
        ms_novelty, ms_fit, ms_merge, n_replaced (components its revisit refit
        replaced, 0 when none ran) and its pose (4 x 4)."""
        n = len(self)
        if isinstance(frame, bool) or not isinstance(frame, (int, np.integer)) or not -n <= frame < n:
            raise InvalidArgumentError(f"frame {frame!r} does not exist ({n} frames)")
        i = int(frame) % n
        out: dict = {}
        iv, fv = c_int64(), c_double()
        pose = np.empty(16, dtype=np.float64)
        with self._guard.reading("frame_stats"):
            for name, key in _FRAME_I64_KEYS.items():
                check(lib.sogmm_map_frame_get_i64(self._h(), i, key, byref(iv)))
                out[name] = bool(iv.value) if name == "flushed" else int(iv.value)
            for name, key in _FRAME_F64_KEYS.items():
                check(lib.sogmm_map_frame_get_f64(self._h(), i, key, byref(fv)))
                out[name] = float(fv.value)
            check(lib.sogmm_map_frame_get_pose(self._h(), i, pose))
        out["pose"] = pose.reshape(4, 4)
        return out

    def frames(self) -> list[dict]:
        """frame_stats of every frame, in insertion order."""
        return [self.frame_stats(i) for i in range(len(self))]

    # ---- the map as a model ----------------------------------------------------
    def export(self, box=None) -> GMM:
        """The map (or the components whose 3-sigma box meets ``box`` =
        (x_min, y_min, z_min, x_max, y_max, z_max)) as a world-frame
        :class:`sogmm.GMM`; score, sample and regress with it."""
        out = c_void_p()
        b = None
        if box is not None:
            b = np.ascontiguousarray(np.asarray(box, dtype=np.float32))
            if b.shape != (6,):
                raise InvalidArgumentError(f"box must hold 6 numbers (min xyz, max xyz), got shape {b.shape}")
        with self._guard.reading("export"):
            check(lib.sogmm_map_export(byref(out), self._h(), None if b is None else b.ctypes.data_as(c_void_p)))
        return GMM._wrap(out)

    # The world-frame queries on the map itself (no export, no copy) come from
    # Queryable: each answer is bitwise what the same GMM method gives on
    # export(); a map without components (nothing flushed yet) raises
    # InvalidDataError. Each holds the map's use guard for reading.
    _C_PREFIX = "sogmm_map"

    def _reading(self, what: str):
        return self._guard.reading(what)

    def occupancy(self, points, return_state: bool = False, *, surface_sigma: float = _D.occupancy_sigma,
                  thickness: float = _D.occupancy_thickness, n_threads: int = _D.threads,
                  progress: ProgressArg = None):
        """P(occupied) of (n, 3) world points from what the map's own frames see:
        an (n,) float64 array in [0, 1], 0.5 where no frame observed the point;
        with ``return_state`` also an (n,) uint8 array (OCCUPANCY_FREE 0,
        OCCUPANCY_OCCUPIED 1, OCCUPANCY_UNKNOWN 2). A point in front of the
        first surface a frame renders along its ray is free, one within
        ``thickness`` metres of it occupied, one behind it unknown; the surface
        is uncertain by ``surface_sigma`` metres (spec/api.md, "Occupancy"). A
        map without frames, camera record or components: unknown everywhere."""
        x = _rows(points, (3,), "points")
        prob = np.empty(x.shape[0], dtype=np.float64)
        state = np.empty(x.shape[0], dtype=np.uint8)
        state_ptr = state.ctypes.data if state.size else None
        f64 = {_ffi.OPT_OCCUPANCY_SIGMA: surface_sigma, _ffi.OPT_OCCUPANCY_THICKNESS: thickness}
        self._query("occupancy", "occupancy_f32", _ffi.Options(f64=f64, i64={_ffi.OPT_THREADS: n_threads}), progress,
                    lambda o: (x, x.shape[0], o, prob, state_ptr))
        return (prob, state) if return_state else prob

    # ---- deltas (spec/format.md section 2.5) ---------------------------------------
    @property
    def revision(self) -> int:
        """The map's revision: 0 when created, +1 for every insert, fitting
        flush or applied delta that changed it."""
        v = c_int64()
        with self._guard.reading("revision"):
            check(lib.sogmm_map_get_i64(self._h(), _ffi.MAP_REVISION, byref(v)))
        return int(v.value)

    def export_delta(self, since_revision: int) -> bytes:
        """The delta file (bytes) from ``since_revision`` to the current
        revision; a receiver at that revision applies it with apply_delta."""
        size = c_size_t()
        with self._guard.reading("export_delta"):
            check(lib.sogmm_map_export_delta(self._h(), since_revision, None, None, 0, byref(size)))
            buf = ctypes.create_string_buffer(size.value)
            check(lib.sogmm_map_export_delta(self._h(), since_revision, None, buf, size.value, byref(size)))
        return buf.raw[: size.value]

    def apply_delta(self, delta: bytes) -> None:
        """Applies a delta of the sender's map; afterwards this map is bitwise
        the sender's. A gap, a duplicate, another map's or a damaged delta
        raises (InvalidArgumentError / FormatError) and changes nothing."""
        data = bytes(delta)
        with self._guard.changing("apply_delta"):
            check(lib.sogmm_map_apply_delta(self._h(), data, len(data), None))

    def merge_map(self, other: "Map", pose=None) -> dict:
        """Merges the map ``other`` into this one (two robots, one map), the
        4 x 4 rigid ``pose`` (None = identity) moving the other map's world
        frame into this map's. Where both hold a surface the sharper view
        wins instead of both being stacked; the other's frame provenance is
        appended; one revision, carried by deltas (sogmm_map_merge_map).
        Returns the counts n_kept, n_removed (this map's components),
        n_added, n_skipped (the other's) and n_frames (frame lines added).
        Errors (this map unchanged): ``other`` not a Map or this map, points
        pending in either, a pose not finite or not rigid ->
        InvalidArgumentError; ``other`` without components ->
        InvalidDataError; either map in use -> MapBusyError."""
        if not isinstance(other, Map):
            raise InvalidArgumentError(f"merge_map needs a Map, got {type(other).__name__}")
        if other is self:
            raise InvalidArgumentError("a map cannot be merged into itself (merge a copy)")
        p = _pose(np.eye(4) if pose is None else pose)
        out = (c_uint64 * 5)()
        with self._guard.changing("merge_map"), other._guard.reading("merge_map"):
            check(lib.sogmm_map_merge_map(self._h(), other._h(), p, out))
        return dict(zip(("n_kept", "n_removed", "n_added", "n_skipped", "n_frames"), (int(v) for v in out)))

    # ---- files -------------------------------------------------------------------
    def save(self, path: str | os.PathLike, *, float64: bool = bool(_D.float64), compress: bool = bool(_D.compress),
             zstd_level: int = _D.zstd_level, component_precision: float = _D.array_precision) -> None:
        """Writes the map as a world-frame .sogmm file with its frame provenance
        (atomically). Pending points must be flushed first (InvalidArgumentError).

        ``component_precision`` as in :meth:`GMM.save` (SOGMM_OPT_ARRAY_PRECISION):
        > 0 stores each component as integer codes that move its mean by at
        most that many of its standard deviations, 0 float arrays. It codes
        the file only; the constructor's keyword of the same name
        (SOGMM_OPT_MAP_COMPONENT_PRECISION) rounds the map's own components.
        Out of range: InvalidArgumentError, nothing written."""
        with _write_options(float64, compress, zstd_level, component_precision=component_precision) as o, \
                self._guard.reading("save"):
            check(lib.sogmm_map_save(self._h(), os.fsencode(path), o.ptr))

    # Set by load() for the constructor's run: (path, verify_checksums, max_decoded_bytes).
    _load_from = None

    @classmethod
    def load(cls, path: str | os.PathLike, *, verify_checksums: bool = bool(_D.verify_checksums),
             max_decoded_bytes: int = _D.max_decoded_bytes,
             **options) -> "Map":
        """Reads a map file (or any world-frame model). ``options`` (the
        constructor's keywords, with its defaults) govern later inserts."""
        obj = cls.__new__(cls)
        obj._load_from = (path, verify_checksums, max_decoded_bytes)
        obj.__init__(**options)
        del obj._load_from
        return obj

    def _load(self, o: _ffi.Options, out: c_void_p) -> None:
        path, verify_checksums, max_decoded_bytes = self._load_from
        with _read_options(verify_checksums, max_decoded_bytes) as r:
            # One options handle carries both: copy the read keys over.
            for key in (_ffi.OPT_VERIFY_CHECKSUMS, _ffi.OPT_MAX_DECODED_BYTES):
                v = c_int64()
                check(lib.sogmm_options_get_i64(r.ptr, key, byref(v)))
                check(lib.sogmm_options_set_i64(o.ptr, key, v.value))
            check(lib.sogmm_map_load(byref(out), os.fsencode(path), o.ptr))

    def __repr__(self) -> str:
        if self._ptr is None:
            return "Map(closed)"
        s = self.stats()
        return f"Map(frames={s['n_frames']}, components={s['n_components']}, pending={s['n_pending']})"
