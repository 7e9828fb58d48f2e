"""The map-building reduce of :mod:`sogmm.distributed`: one ``sogmm.Map`` per tile.

An incremental map (issue 18; novelty test, batched fits, optional fusion) is
sequential by nature: whether a point of frame t is new depends on the map
after frames < t. So the map cannot be split below the unit it is built over;
here that unit is the spatial tile of the merge tree (camera positions in a
cube of ``tile_size`` metres, :func:`sogmm.distributed.runner.tile_of`). The
order is defined, not scheduled:

- inside a tile, frames are inserted in frame-id order into one ``sogmm.Map``
  (one Ray task per tile, so the map is built exactly as ``sogmm map`` builds
  it over those frames), flushed at the end;
- tiles are independent maps: novelty and fusion act inside a tile, and the
  tiles' maps are combined by the plain world-frame union of the tree
  (:func:`sogmm.distributed.partial.reduce_partials`), whose canonical
  finalize orders them by their first frame id.

The result is a pure function of (frames, settings, tile_size): independent of
worker count, fan-in and completion order, and bitwise equal to
:func:`sogmm.distributed.sequential_build` with the same ``tile_size``; with
``tile_size = 0`` (one tile) it is the ``sogmm map`` of the whole sequence.
Only the public ``sogmm.Map`` API is used.
"""

from __future__ import annotations

import dataclasses
import os
import tempfile
import time

import numpy as np

from ..camera import Camera
from ..errors import SogmmError
from ..map import Map
from ..model import GMM
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

    novelty: bool = True
    novelty_threshold: float = 3.0
    batch_size: int = 12288
    fusion: str = "off"
    fusion_threshold: float = 0.3
    novelty_bandwidth_scale: float = 0.7
    revisit_refit_ratio: float = 1.25

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


def map_tile(frames: list[Frame], settings: FitSettings, map_settings: MapSettings,
             camera: dict) -> tuple[list[dict], dict | None]:
    """(per-frame infos, partial map of the tile or None) of one tile: its
    frames inserted in id order into one map. A bad frame (unreadable, or the
    map refuses it, e.g. no valid depth) gets an info with ``error`` and is
    left out, as the map leaves itself unchanged on a failed insert."""
    infos, inserted = [], []
    cam = Camera(**camera)
    with map_settings.new_map(settings) as m:
        for f in sorted(frames, key=lambda f: f.index):
            test_hold(f.index)
            start = time.perf_counter()
            info = {"frame": f.index, "pid": os.getpid(), "error": None, "bytes": 0}
            try:
                depth, color = read_images(f)
                m.insert_rgbd(depth, color, cam, np.asarray(f.pose).reshape(4, 4))
                inserted.append(f.index)
            except (SogmmError, OSError, ValueError) as e:
                info["error"] = f"{type(e).__name__}: {e}"
            info["seconds"] = time.perf_counter() - start
            infos.append(info)
        if not inserted:
            return infos, None
        start = time.perf_counter()
        m.flush()
        # The library writes the provenance (map_frames, map_options, fit
        # record, camera) only into a file: save it and read it back.
        with tempfile.TemporaryDirectory(prefix="sogmm_tile_") as d:
            path = os.path.join(d, "tile.sogmm")
            m.save(path, compress=False)
            part = _map_partial(GMM.load(path), inserted)
        infos[-1]["seconds"] += time.perf_counter() - start
    infos[-1]["bytes"] = size_bytes(part)
    return infos, part
