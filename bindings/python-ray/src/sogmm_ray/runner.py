"""The Ray job: fit tasks, a spatially tiled merge tree, progress and failure policy."""

from __future__ import annotations

import dataclasses
import math
import time
from collections import defaultdict

from sogmm import GMM, InvalidArgumentError, SogmmError

from .frame_fit import FitSettings, camera_dict, fit_chunk
from .map_tile import MapSettings, map_tile
from .partial import finalize, reduce_partials, sequential_partial, size_bytes
from .sequence import Frame


class FrameError(SogmmError):
    """A frame could not be fitted and the failure policy is "fail"."""

    def __init__(self, frame: int, message: str):
        super().__init__(f"frame {frame}: {message}")
        self.frame = frame


@dataclasses.dataclass
class MapResult:
    """The canonical map and what it took to build it."""

    model: GMM
    skipped: list  # (frame id, message) of bad frames skipped
    n_frames: int  # frames fitted into the map
    seconds_wall: float
    seconds_fit: float  # sum over fit tasks (inside the task)
    seconds_merge: float  # sum over merge tasks (inside the task)
    bytes_moved: int  # bytes of every partial map put into the object store
    merges: int  # merge tasks
    tasks: int  # fit (or tile map) tasks


def tile_of(frame: Frame, size: float) -> tuple:
    """Tile of the camera position (pose translation), size metres on a side (0: one tile)."""
    p = frame.pose
    return tuple(math.floor(p[i] / size) for i in (3, 7, 11)) if size > 0 else ()


def tiles_of(frames: list[Frame], tile_size: float) -> list[list[Frame]]:
    """The frames grouped by tile, tiles in coordinate order, frames in id order."""
    tiles = defaultdict(list)
    for f in sorted(frames, key=lambda f: f.index):
        tiles[tile_of(f, tile_size)].append(f)
    return [tiles[k] for k in sorted(tiles)]


def auto_frames_per_task(n_frames: int, cpus: int) -> int:
    """Frames per fit task when not given: as many as keep at least 4 tasks per
    CPU (so the last tasks still balance), at most 8 (beyond that Ray's
    per-task cost, about 5 ms, is already below 2% of a 35 ms fit)."""
    return max(1, min(8, n_frames // (4 * max(cpus, 1))))


def merge_tree(items: list, fan_in: int, reduce) -> object:
    """Reduces a list with `reduce(*chunk)` in a balanced tree of the given fan-in."""
    while len(items) > 1:
        items = [reduce(*items[i:i + fan_in]) if len(items[i:i + fan_in]) > 1 else items[i]
                 for i in range(0, len(items), fan_in)]
    return items[0]


def _merge_task(reduce, *parts):
    start = time.perf_counter()
    out = reduce(list(parts))
    return {"seconds": time.perf_counter() - start, "bytes": size_bytes(out)}, out


def _progress(total: int, enabled: bool):
    try:
        from tqdm import tqdm
    except ImportError:  # progress is optional; the `ray` extra installs tqdm
        enabled = False
        tqdm = None
    if not enabled:
        class _Quiet:
            def update(self, n=1): pass
            def set_postfix_str(self, s): pass
            def close(self): pass
        return _Quiet()
    return tqdm(total=total, unit="frame", desc="sogmm_ray", smoothing=0.1)


def build_map(frames: list[Frame], settings: FitSettings, camera, *, workers: int | None = None,
              address: str | None = None, fan_in: int = 8, tile_size: float = 2.0, on_error: str = "skip",
              max_retries: int = 3, progress: bool = True, metadata: dict | None = None,
              map: MapSettings | None = None, frames_per_task: int | None = None) -> MapResult:
    """Fits ``frames`` as Ray tasks and merges them into one canonical world-frame map.

    Uses the running Ray if ``ray.init`` was called, else connects to ``address``
    (an existing cluster), else starts a local Ray with ``workers`` CPUs (and
    shuts it down at the end). Merges form a tree of fan-in ``fan_in`` inside
    each tile of ``tile_size`` metres (by camera position), then across tiles.

    The reduce: ``map`` None fits every frame alone and the tree is the plain
    world-frame merge (a task fits ``frames_per_task`` consecutive frames of a
    tile; None = :func:`auto_frames_per_task`); a :class:`MapSettings` builds
    one ``sogmm.Map`` per tile (novelty, optional fusion; one task per tile,
    see :mod:`sogmm_ray.map_tile`) and the tree unites the tiles' maps.

    ``on_error``: "skip" (a bad frame is left out and listed in ``skipped``) or
    "fail" (FrameError naming the frame). A worker that dies is retried by Ray
    up to ``max_retries`` times. The model does not depend on worker count,
    fan-in, chunking or completion order, and with ``map`` None not on the
    tiling either (see sogmm_ray.partial)."""
    import ray

    if on_error not in ("skip", "fail"):
        raise InvalidArgumentError(f"on_error must be 'skip' or 'fail', got {on_error!r}")
    if isinstance(fan_in, bool) or not isinstance(fan_in, int) or fan_in < 2:
        raise InvalidArgumentError(f"fan_in must be an int >= 2, got {fan_in!r}")
    if frames_per_task is not None and (isinstance(frames_per_task, bool) or not isinstance(frames_per_task, int)
                                        or frames_per_task < 1):
        raise InvalidArgumentError(f"frames_per_task must be an int >= 1 or None (auto), got {frames_per_task!r}")
    if not frames:
        raise InvalidArgumentError("no frame to fit")
    if len({f.index for f in frames}) != len(frames):
        raise InvalidArgumentError("a frame id is given twice")
    started_here = not ray.is_initialized()
    if started_here:
        if address:
            ray.init(address=address, log_to_driver=False)
        else:
            ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False)
    try:
        if frames_per_task is None:
            frames_per_task = auto_frames_per_task(len(frames), int(ray.cluster_resources().get("CPU", 1)))
        return _run(ray, frames, settings, camera_dict(camera), fan_in, tile_size, on_error, max_retries, progress,
                    metadata, map, frames_per_task)
    finally:
        if started_here:
            ray.shutdown()


def _chunks(tile: list[Frame], map_settings, frames_per_task: int) -> list[list[Frame]]:
    """The tasks of a tile: the whole tile for a map, else runs of consecutive frames."""
    if map_settings is not None:
        return [tile]
    return [tile[i:i + frames_per_task] for i in range(0, len(tile), frames_per_task)]


def _account(infos: list, on_error: str, skipped: list) -> tuple[float, float, int]:
    """(fit seconds, in-task merge seconds, bytes) of one task's infos; applies the failure policy."""
    fit = merge = 0.0
    moved = 0
    for info in infos:
        fit += info["seconds"]
        merge += info.get("merge_seconds", 0.0)
        moved += info["bytes"]
        if info["error"] is not None:
            if on_error == "fail":
                raise FrameError(info["frame"], info["error"])
            skipped.append((info["frame"], info["error"]))
    return fit, merge, moved


def _run(ray, frames, settings, camera, fan_in, tile_size, on_error, max_retries, progress, metadata, map_settings,
         frames_per_task) -> MapResult:
    start = time.perf_counter()
    opts = dict(num_returns=2, num_cpus=1, max_retries=max_retries, retry_exceptions=False)
    if map_settings is None:
        leaf_task = ray.remote(fit_chunk).options(**opts)
        extra = ()
    else:
        leaf_task = ray.remote(map_tile).options(**opts)
        extra = (ray.put(map_settings),)
    merge = ray.remote(_merge_task).options(**opts)
    settings_ref = ray.put(settings)
    camera_ref = ray.put(camera)
    tile_roots = []
    pending = {}  # the tasks' small info objects (watched for progress and failures) -> frames in the task
    merge_infos = []

    def reduce(*parts):
        info, out = merge.remote(reduce_partials, *parts)
        merge_infos.append(info)
        return out

    for tile in tiles_of(frames, tile_size):
        parts = []
        for chunk in _chunks(tile, map_settings, frames_per_task):
            info, part = leaf_task.remote(chunk, settings_ref, *extra, camera_ref)
            pending[info] = len(chunk)
            parts.append(part)
        tile_roots.append(merge_tree(parts, fan_in, reduce))
    root = merge_tree(tile_roots, fan_in, reduce)

    bar = _progress(len(frames), progress)
    skipped, seconds_fit, seconds_merge, bytes_moved = [], 0.0, 0.0, 0
    waiting = list(pending)
    try:
        while waiting:
            done, waiting = ray.wait(waiting, num_returns=min(len(waiting), 16), timeout=1.0)
            for ref, infos in zip(done, ray.get(done)):
                before = len(skipped)
                fit, merged, moved = _account(infos, on_error, skipped)
                seconds_fit += fit
                seconds_merge += merged
                bytes_moved += moved
                if len(skipped) > before:
                    bar.set_postfix_str(f"skipped frame {skipped[-1][0]}")
                bar.update(pending[ref])
    except BaseException:
        for ref in waiting:
            ray.cancel(ref, force=False)
        raise
    finally:
        bar.close()
    root_part = ray.get(root)
    merged = ray.get(merge_infos)
    model = finalize(root_part, metadata)
    return MapResult(model=model, skipped=sorted(skipped), n_frames=len(frames) - len(skipped),
                     seconds_wall=time.perf_counter() - start, seconds_fit=seconds_fit,
                     seconds_merge=seconds_merge + sum(m["seconds"] for m in merged),
                     bytes_moved=bytes_moved + sum(m["bytes"] for m in merged), merges=len(merged),
                     tasks=len(pending))


def sequential_build(frames: list[Frame], settings: FitSettings, camera, *, on_error: str = "skip",
                     metadata: dict | None = None, map: MapSettings | None = None,
                     tile_size: float = 2.0) -> MapResult:
    """The same map without Ray, in this process (the reference that build_map
    must equal bitwise): ``map`` None: frames fitted in id order and folded one
    by one (``tile_size`` does not matter); a MapSettings: one map per tile,
    tiles in coordinate order, folded one by one."""
    start = time.perf_counter()
    cam = camera_dict(camera)
    units = ([[f] for f in sorted(frames, key=lambda f: f.index)] if map is None else tiles_of(frames, tile_size))
    leaves, skipped, seconds_fit, seconds_merge = [], [], 0.0, 0.0
    for unit in units:
        infos, part = fit_chunk(unit, settings, cam) if map is None else map_tile(unit, settings, map, cam)
        fit, merged, _ = _account(infos, on_error, skipped)
        seconds_fit += fit
        seconds_merge += merged
        if part is not None:
            leaves.append(part)
    t_merge = time.perf_counter()
    root = sequential_partial(leaves)
    seconds_merge += time.perf_counter() - t_merge
    model = finalize(root, metadata)
    return MapResult(model=model, skipped=sorted(skipped), n_frames=len(frames) - len(skipped),
                     seconds_wall=time.perf_counter() - start, seconds_fit=seconds_fit, seconds_merge=seconds_merge,
                     bytes_moved=0, merges=max(len(leaves) - 1, 0), tasks=0)
