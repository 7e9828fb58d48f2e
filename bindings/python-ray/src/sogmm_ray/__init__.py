"""Fit and merge thousands of RGB-D frames on a Ray cluster (``pip install sogmm[ray]``).

Fits run as Ray tasks (a few consecutive frames per task, ``frames_per_task``)
in worker processes that open libsogmm once; models move between tasks as
``.sogmm`` bytes. Merges form a tree of configurable fan-in, first inside
spatial tiles (by camera position), then across them. Two reduces: the plain
world-frame merge of every frame's fit, or (``map=MapSettings(...)``) one
incremental ``sogmm.Map`` per tile (novelty, optional fusion; see
:mod:`sogmm_ray.map_tile`) united across tiles. The final model is
canonical (components in (first frame, component) order, weights rounded
once), so it is bitwise equal to the sequential build whatever the completion
order, worker count, fan-in or chunking; see :mod:`sogmm_ray.partial`.

    from sogmm_ray import FitSettings, build_map, load_frames
    frames = load_frames("seq", "seq/trajectory.log")
    result = build_map(frames, FitSettings(decimate=5), sogmm.Camera.from_json("seq/intrinsics.json"), workers=8)
    result.model.save("map.sogmm")

Command line: ``python -m sogmm_ray --help``.
"""

from .frame_fit import FitSettings, fit_chunk, fit_frame
from .map_tile import MapSettings, map_tile
from .partial import finalize, reduce_partials, sequential_partial
from .runner import FrameError, MapResult, auto_frames_per_task, build_map, merge_tree, sequential_build, tiles_of
from .sequence import Frame, load_frames

__all__ = ["FitSettings", "Frame", "FrameError", "MapResult", "MapSettings", "auto_frames_per_task", "build_map",
           "finalize", "fit_chunk", "fit_frame", "load_frames", "map_tile", "merge_tree", "reduce_partials",
           "sequential_build", "sequential_partial", "tiles_of"]
