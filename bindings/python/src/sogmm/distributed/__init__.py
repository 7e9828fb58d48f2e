"""Fit and merge thousands of RGB-D frames on a Ray cluster (``pip install sogmm[ray]``).

Each frame is a Ray task that opens libsogmm itself; models move between tasks
as ``.sogmm`` bytes. Merges form a tree of configurable fan-in, first inside
spatial tiles (by camera position), then across them. The final model is
canonical (components in (frame, component) order, weights rounded once), so it
is bitwise equal to the sequential build whatever the completion order, worker
count, fan-in or tiling; see :mod:`sogmm.distributed.partial`.

    from sogmm.distributed import FitSettings, build_map, load_frames
    frames = load_frames("seq", "seq/trajectory.log")
    result = build_map(frames, FitSettings(decimate=5), sogmm.Camera.from_json("seq/intrinsics.json"), workers=8)
    result.model.save("map.sogmm")

Command line: ``python -m sogmm.distributed --help``.
"""

from .frame_fit import FitSettings, fit_frame
from .partial import finalize, reduce_partials, sequential_partial
from .runner import FrameError, MapResult, build_map, merge_tree, sequential_build
from .sequence import Frame, load_frames

__all__ = ["FitSettings", "Frame", "FrameError", "MapResult", "build_map", "finalize", "fit_frame", "load_frames",
           "merge_tree", "reduce_partials", "sequential_build", "sequential_partial"]
