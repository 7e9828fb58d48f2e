"""The map-building reduce of :mod:`sogmm_ray`: one ``sogmm.Map`` per tile.

An incremental map (issue 18; novelty test, batched fits, optional fusion) is
sequential by nature: whether a point of frame t is new depends on the map
after frames < t. So the map cannot be split below the unit it is built over;
here that unit is the spatial tile of the merge tree (camera positions in a
cube of ``tile_size`` metres, :func:`sogmm_ray.runner.tile_of`). The
order is defined, not scheduled:

- inside a tile, frames are inserted in frame-id order into one ``sogmm.Map``
  (one Ray task per tile, so the map is built exactly as ``sogmm map`` builds
  it over those frames), flushed at the end;
- tiles are independent maps: novelty and fusion act inside a tile, and the
  tiles' maps are combined by the plain world-frame union of the tree
  (:func:`sogmm_ray.partial.reduce_partials`), whose canonical
  finalize orders them by their first frame id.

The result is a pure function of (frames, settings, tile_size): independent of
worker count, fan-in and completion order, and bitwise equal to
:func:`sogmm_ray.sequential_build` with the same ``tile_size``; with
``tile_size = 0`` (one tile) it is the ``sogmm map`` of the whole sequence.
Only the public ``sogmm.Map`` API is used.
"""

from __future__ import annotations

import dataclasses
import os
import tempfile
import time

import numpy as np

from sogmm import DEFAULTS, GMM, Camera, Map, SogmmError

from .frame_fit import FitSettings, read_images, test_hold
from .partial import TABLE, size_bytes
from .sequence import Frame


@dataclasses.dataclass(frozen=True)
class MapSettings:
    """The map flags of `sogmm map` (same meanings and defaults): ``novelty``
    False is --no-novelty, ``novelty_threshold`` --threshold, ``batch_size``
    --batch, ``fusion`` --fusion ("off", "hellinger", "kl"),
    ``fusion_threshold`` --fusion-threshold, ``novelty_bandwidth_scale``
    --novelty-bandwidth-scale, ``revisit_refit_ratio`` --revisit-refit-ratio."""

    novelty: bool = bool(DEFAULTS.map_novelty)
    novelty_threshold: float = DEFAULTS.map_novelty_threshold
    batch_size: int = DEFAULTS.map_batch_size
    fusion: str = "off"
    fusion_threshold: float = DEFAULTS.map_fusion_threshold
    novelty_bandwidth_scale: float = DEFAULTS.map_novelty_bandwidth_scale
    revisit_refit_ratio: float = DEFAULTS.map_revisit_refit_ratio

    def new_map(self, fit: FitSettings) -> Map:
        """An empty ``sogmm.Map`` with these map options and the fit and depth settings."""
        return Map(novelty=self.novelty, novelty_threshold=self.novelty_threshold, batch_size=self.batch_size,
                   fusion=self.fusion, fusion_threshold=self.fusion_threshold,
                   novelty_bandwidth_scale=self.novelty_bandwidth_scale,
                   revisit_refit_ratio=self.revisit_refit_ratio, depth_scale=fit.depth_scale,
                   depth_min=fit.depth_min, depth_trunc=fit.depth_max, decimate=fit.decimate,
                   bandwidth=fit.bandwidth, n_components=fit.n_components, seed=fit.seed, n_init=fit.n_init,
                   n_threads=fit.threads, tol=fit.tol, max_iter=fit.max_iter, reg_covar=fit.reg_covar,
                   truncation_nats=fit.truncate, dequantise_depth=fit.dequantise_depth)


def _map_partial(saved: GMM, frames: list[int]) -> dict:
    """The partial map (one row) of a tile's saved map file."""
    meta = saved.metadata
    fits = int(meta.get("merged_fits", "1"))
    row = np.array([(frames[0], saved.support_size_, saved.n_components_, saved.lower_bound_ or 0.0,
                     saved.n_iter_ or 0, int(bool(saved.converged_)), fits)], dtype=TABLE)
    return {"model": saved.to_bytes(compress=False), "table": row.tobytes(),
            "weights": saved.weights_.astype("<f4").tobytes(), "frames": [frames],
            "map_frames": [meta["map_frames"]], "map_options": meta["map_options"]}


class _TileMap:
    """A tile's ``sogmm.Map`` and the log of what built it, so that a failure
    is charged to the frame that caused it, not to the frame whose insert
    happened to trigger a fit.

    A failed insert undoes itself but leaves the points of earlier frames
    pending, and an insert that fills the batch fits those together with its
    own: its error may belong to an earlier frame. So a frame is refused only
    by an insert or a fit that holds its points alone: on a failed insert
    with other frames pending, those are fitted first (frame by frame if
    together they cannot be, rebuilding the map from the log, as no call
    drops pending points) and the frame is inserted again alone."""

    def __init__(self, settings: FitSettings, map_settings: MapSettings, camera: Camera):
        self._settings, self._map_settings, self._camera = settings, map_settings, camera
        self.map = map_settings.new_map(settings)
        self._log = []  # the frames inserted, or None for an explicit flush, in order
        self._batch = []  # log entries whose points are pending

    @property
    def inserted(self) -> list[int]:
        return [frame.index for frame in self._log if frame is not None]

    def close(self) -> None:
        self.map.close()

    def _insert(self, frame: Frame, images=None) -> None:
        depth, color = images if images is not None else read_images(frame)  # a replay reads them again
        self.map.insert_rgbd(depth, color, self._camera, np.asarray(frame.pose).reshape(4, 4))
        self._log.append(frame)
        self._batch = [] if self.map.n_pending_ == 0 else self._batch + [self._log[-1]]

    def _flush(self) -> None:
        self.map.flush()
        self._log.append(None)
        self._batch = []

    def _rebuild(self, log: list) -> None:
        """Replays ``log`` into a new map (the same calls give the same map)."""
        self.map.close()
        self.map = self._map_settings.new_map(self._settings)
        self._log, self._batch = [], []
        for frame in log:
            if frame is None:
                self._flush()
            else:
                self._insert(frame)

    def settle(self) -> dict:
        """Fits every pending point; returns {frame id: error} of the pending
        frames that cannot be fitted even alone (they are left out)."""
        if not self._batch:
            return {}
        try:
            self._flush()
            return {}
        except SogmmError:
            pass
        batch = self._batch
        errors = {}
        self._rebuild(self._log[:len(self._log) - len(batch)])  # the map before the batch: nothing pending
        for frame in batch:
            before = list(self._log)
            try:
                self._insert(frame)
                self._flush()
            except SogmmError as e:
                errors[frame.index] = _describe(e)
                self._rebuild(before)
        return errors

    def add(self, frame: Frame, images) -> dict:
        """Inserts a frame. Returns {frame id: error} of the frames left out:
        this one when the map refuses it alone (the map is then unchanged),
        and pending ones that could not be fitted even alone."""
        try:
            self._insert(frame, images)
            return {}
        except SogmmError as e:
            if not self._batch:  # nothing else was pending: the error is this frame's
                return {frame.index: _describe(e)}
        errors = self.settle()
        try:
            self._insert(frame, images)
        except SogmmError as e:
            errors[frame.index] = _describe(e)
        return errors


def _describe(e: Exception) -> str:
    return f"{type(e).__name__}: {e}"


def map_tile(frames: list[Frame], settings: FitSettings, map_settings: MapSettings,
             camera: dict) -> tuple[list[dict], dict | None]:
    """(per-frame infos, partial map of the tile or None) of one tile: its
    frames inserted in id order into one map. A bad frame (unreadable, or the
    map refuses it, e.g. no valid depth, or its points cannot be fitted) gets
    an info with ``error`` and is left out; the error is always the frame's
    own (see :class:`_TileMap`), never that of frames still pending."""
    infos = {}
    tile = _TileMap(settings, map_settings, Camera(**camera))
    try:
        for f in sorted(frames, key=lambda f: f.index):
            test_hold(f.index)
            start = time.perf_counter()
            info = infos[f.index] = {"frame": f.index, "pid": os.getpid(), "error": None, "bytes": 0}
            try:
                left_out = tile.add(f, read_images(f))
            except (OSError, ValueError) as e:  # unreadable images
                left_out = {f.index: _describe(e)}
            for frame, error in left_out.items():
                infos[frame]["error"] = error
            info["seconds"] = time.perf_counter() - start
        start = time.perf_counter()
        for frame, error in tile.settle().items():
            infos[frame]["error"] = error
        inserted = tile.inserted
        infos = [infos[k] for k in sorted(infos)]
        if not inserted:
            return infos, None
        # The library writes the provenance (map_frames, map_options, fit
        # record, camera) only into a file: save it and read it back.
        with tempfile.TemporaryDirectory(prefix="sogmm_tile_") as d:
            path = os.path.join(d, "tile.sogmm")
            tile.map.save(path, compress=False)
            saved = GMM.load(path)
            if saved.pose is not None:
                # A tile far from the world origin holds its components
                # relative to its origin, the file's pose (spec/format.md
                # 2.3.1); the merge tree's rows are world-frame.
                saved = saved.transform(saved.pose)
                saved.pose = None
            part = _map_partial(saved, inserted)
    finally:
        tile.close()
    infos[-1]["seconds"] += time.perf_counter() - start
    infos[-1]["bytes"] = size_bytes(part)
    return infos, part
