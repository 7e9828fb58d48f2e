"""The Ray job: fit tasks, a spatially tiled merge tree, progress and failure policy."""

from __future__ import annotations

import dataclasses
import math
import time
from collections import defaultdict

from ..errors import InvalidArgumentError, SogmmError
from ..model import GMM
from .frame_fit import FitSettings, camera_dict, fit_frame
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
    merges: int


def _tile(frame: Frame, size: float) -> tuple:
    """Tile of the camera position (pose translation), size metres on a side."""
    p = frame.pose
    return tuple(math.floor(p[i] / size) for i in (3, 7, 11)) if size > 0 else ()


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
    return tqdm(total=total, unit="frame", desc="sogmm.distributed", smoothing=0.1)


def build_map(frames: list[Frame], settings: FitSettings, camera, *, workers: int | None = None,
              address: str | None = None, fan_in: int = 8, tile_size: float = 2.0, on_error: str = "skip",
              max_retries: int = 3, progress: bool = True, metadata: dict | None = None,
              reduce=reduce_partials) -> MapResult:
    """Fits ``frames`` as Ray tasks and merges them into one canonical world-frame map.

    Uses the running Ray if ``ray.init`` was called, else connects to ``address``
    (an existing cluster), else starts a local Ray with ``workers`` CPUs (and
    shuts it down at the end). Merges form a tree of fan-in ``fan_in`` inside
    each tile of ``tile_size`` metres (by camera position), then across tiles.
    ``on_error``: "skip" (a bad frame is left out and listed in ``skipped``) or
    "fail" (FrameError naming the frame). A worker that dies is retried by Ray
    up to ``max_retries`` times. The model does not depend on any of these
    choices (see sogmm.distributed.partial). ``reduce`` is the tree's one reduce
    function (list of partial maps -> partial map; a module-level function, so
    workers import it): the plain merge today, a map with fusion later."""
    import ray

    if on_error not in ("skip", "fail"):
        raise InvalidArgumentError(f"on_error must be 'skip' or 'fail', got {on_error!r}")
    if isinstance(fan_in, bool) or not isinstance(fan_in, int) or fan_in < 2:
        raise InvalidArgumentError(f"fan_in must be an int >= 2, got {fan_in!r}")
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
        return _run(ray, frames, settings, camera_dict(camera), fan_in, tile_size, on_error, max_retries, progress,
                    metadata, reduce)
    finally:
        if started_here:
            ray.shutdown()


def _run(ray, frames, settings, camera, fan_in, tile_size, on_error, max_retries, progress, metadata,
         reduce_fn) -> MapResult:
    start = time.perf_counter()
    fit = ray.remote(fit_frame).options(num_returns=2, num_cpus=1, max_retries=max_retries, retry_exceptions=False)
    merge = ray.remote(_merge_task).options(num_returns=2, num_cpus=1, max_retries=max_retries,
                                            retry_exceptions=False)
    settings_ref = ray.put(settings)
    camera_ref = ray.put(camera)
    tiles = defaultdict(list)
    pending = []  # the fit tasks' small info objects, watched for progress and failures
    for f in sorted(frames, key=lambda f: f.index):
        info, part = fit.remote(f, settings_ref, camera_ref)
        pending.append(info)
        tiles[_tile(f, tile_size)].append(part)
    merge_infos = []

    def reduce(*parts):
        info, out = merge.remote(reduce_fn, *parts)
        merge_infos.append(info)
        return out

    root = merge_tree([merge_tree(tiles[k], fan_in, reduce) for k in sorted(tiles)], fan_in, reduce)

    bar = _progress(len(frames), progress)
    skipped, seconds_fit, bytes_moved = [], 0.0, 0
    try:
        while pending:
            done, pending = ray.wait(pending, num_returns=min(len(pending), 16), timeout=1.0)
            for info in ray.get(done):
                seconds_fit += info["seconds"]
                bytes_moved += info["bytes"]
                if info["error"] is not None:
                    if on_error == "fail":
                        raise FrameError(info["frame"], info["error"])
                    skipped.append((info["frame"], info["error"]))
                    bar.set_postfix_str(f"skipped frame {info['frame']}")
                bar.update(1)
    except BaseException:
        for ref in pending:
            ray.cancel(ref, force=False)
        raise
    finally:
        bar.close()
    root_part = ray.get(root)
    merged = ray.get(merge_infos)
    model = finalize(root_part, metadata)
    return MapResult(model=model, skipped=sorted(skipped), n_frames=len(frames) - len(skipped),
                     seconds_wall=time.perf_counter() - start, seconds_fit=seconds_fit,
                     seconds_merge=sum(m["seconds"] for m in merged),
                     bytes_moved=bytes_moved + sum(m["bytes"] for m in merged), merges=len(merged))


def sequential_build(frames: list[Frame], settings: FitSettings, camera, *, on_error: str = "skip",
                     metadata: dict | None = None) -> MapResult:
    """The same map without Ray: frames fitted in this process in id order and
    folded one by one (the reference that build_map must equal bitwise)."""
    start = time.perf_counter()
    leaves, skipped, seconds_fit = [], [], 0.0
    cam = camera_dict(camera)
    for f in sorted(frames, key=lambda f: f.index):
        info, part = fit_frame(f, settings, cam)
        seconds_fit += info["seconds"]
        if info["error"] is not None:
            if on_error == "fail":
                raise FrameError(info["frame"], info["error"])
            skipped.append((info["frame"], info["error"]))
        else:
            leaves.append(part)
    t_merge = time.perf_counter()
    root = sequential_partial(leaves)
    seconds_merge = time.perf_counter() - t_merge
    model = finalize(root, metadata)
    return MapResult(model=model, skipped=skipped, n_frames=len(leaves), seconds_wall=time.perf_counter() - start,
                     seconds_fit=seconds_fit, seconds_merge=seconds_merge, bytes_moved=0,
                     merges=max(len(leaves) - 1, 0))
