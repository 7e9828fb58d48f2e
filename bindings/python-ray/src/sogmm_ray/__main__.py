"""python -m sogmm_ray: `sogmm fit --sequence` or `sogmm map` on a Ray cluster.

    python -m sogmm_ray --sequence DIR --trajectory LOG --workers N -o map.sogmm [--decimate 5 ...]
    python -m sogmm_ray --address HEAD:6379 --sequence DIR --trajectory LOG -o map.sogmm
    python -m sogmm_ray --reduce map --fusion hellinger --sequence DIR --trajectory LOG -o map.sogmm

--reduce merge (default): every frame is fitted whole and the fits are merged in
the world frame (the model of `sogmm fit --sequence`). --reduce map: one
incremental map per tile, with the map flags of `sogmm map` (--threshold,
--batch, --no-novelty, --fusion, --fusion-threshold, --novelty-bandwidth-scale); --tile-size 0 gives the
`sogmm map` of the whole sequence (one task), smaller tiles more parallelism.

Exit status 0 on success, 1 with one line on stderr on bad input or a failed job.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from sogmm import Camera, SogmmError

from .frame_fit import FitSettings
from .map_tile import MapSettings
from .output_check import check_output
from .runner import build_map
from .sequence import load_frames


def _parser() -> argparse.ArgumentParser:
    d = FitSettings()
    ap = argparse.ArgumentParser(prog="python -m sogmm_ray", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sequence", required=True,
                    help="DIR/depth/*.png + DIR/color/*.{jpg,png} (paired with each other and with the poses by "
                         "the frame number of their names, 00012.png: pose 12)")
    ap.add_argument("--pair-by-order", action="store_true",
                    help="pair images and poses by file order, ignoring frame numbers (default: by number, "
                         "mismatches refused)")
    ap.add_argument("--trajectory", required=True, help="Redwood .log camera-to-world poses")
    ap.add_argument("--frames", default=":", help="I, A:B (B excluded) or A:B:STEP; default all")
    ap.add_argument("-o", "--output", required=True, help="output map (.sogmm, world frame)")
    ap.add_argument("--intrinsics", help="Open3D PinholeCameraIntrinsic JSON (default DIR/intrinsics.json)")
    ap.add_argument("--workers", type=int, default=None, help="CPUs of the local Ray (default all); ignored with --address")
    ap.add_argument("--address", help="connect to an existing Ray cluster (HEAD:6379 or 'auto')")
    ap.add_argument("--fan-in", type=int, default=8, help="models merged per merge task (default %(default)s)")
    ap.add_argument("--tile-size", type=float, default=2.0,
                    help="merge tiles by camera position, metres (0 = one tile; default %(default)s)")
    ap.add_argument("--on-error", choices=("skip", "fail"), default="skip",
                    help="a bad frame is skipped (and reported) or fails the job (default %(default)s)")
    ap.add_argument("--max-retries", type=int, default=3, help="Ray retries of a task whose worker died")
    ap.add_argument("--frames-per-task", default="auto",
                    help="--reduce merge: consecutive frames fitted per Ray task (amortises Ray's per-task cost); "
                         "auto = at least 4 tasks per CPU, at most 8 frames (default %(default)s)")
    ap.add_argument("--reduce", choices=("merge", "map"), default="merge",
                    help="merge: world-frame merge of every frame's fit; map: one sogmm.Map per tile "
                         "(default %(default)s)")
    m = MapSettings()
    mg = ap.add_argument_group("map flags (as `sogmm map`; with --reduce map)")
    mg.add_argument("--threshold", type=float, default=m.novelty_threshold,
                    help="novelty threshold (nats): points whose 3-D log-likelihood is below it are new")
    mg.add_argument("--batch", type=int, default=m.batch_size, help="novel points that trigger a fit")
    mg.add_argument("--novelty-bandwidth-scale", type=float, default=m.novelty_bandwidth_scale,
                    help="s in (0, 1]: a batch of novel points is fitted with --bandwidth times s + (1 - s) h^2, "
                         "h the share of its point pairs from one frame")
    mg.add_argument("--revisit-refit-ratio", type=float, default=m.revisit_refit_ratio,
                    help="refit what a frame sees when its explained points have this many times as many modes "
                         "as the map has components there, 0 (off) or >= 1")
    mg.add_argument("--no-novelty", action="store_true", help="every point is new: fit each frame whole")
    mg.add_argument("--fusion", choices=("off", "hellinger", "kl"), default=m.fusion, help="fuse close components")
    mg.add_argument("--fusion-threshold", type=float, default=m.fusion_threshold,
                    help="fuse below this distance (Hellinger in [0, 1]; KL in nats)")
    g = ap.add_argument_group("fit and depth flags (as `sogmm fit`)")
    g.add_argument("--bandwidth", type=float, default=d.bandwidth)
    g.add_argument("--components", type=int, default=None, help="fixed number of components K")
    g.add_argument("--seed", type=int, default=d.seed)
    g.add_argument("--n-init", type=int, default=d.n_init)
    g.add_argument("--threads", type=int, default=d.threads, help="threads per fit task (default %(default)s)")
    g.add_argument("--tol", type=float, default=d.tol)
    g.add_argument("--max-iter", type=int, default=d.max_iter)
    g.add_argument("--reg-covar", type=lambda v: v if v == "auto" else float(v), default=d.reg_covar,
                   help="auto (default) or a value added to all four diagonals")
    g.add_argument("--truncate", type=float, default=d.truncate)
    g.add_argument("--dequantise-depth", action="store_const", const=True, default=None,
                   help="floor variances along viewing rays at the depth quantisation (the default for frames)")
    g.add_argument("--no-dequantise-depth", dest="dequantise_depth", action="store_const", const=False,
                   help="the paper's plain EM on quantised depth")
    g.add_argument("--decimate", type=int, default=None, help="default 1, 5 with --reduce map (as sogmm map)")
    g.add_argument("--depth-scale", type=float, default=d.depth_scale)
    g.add_argument("--depth-min", type=float, default=d.depth_min)
    g.add_argument("--depth-max", type=float, default=d.depth_max)
    ap.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    ap.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    return ap


def _frames_per_task(text: str) -> int | None:
    if text == "auto":
        return None
    if not text.isdigit() or int(text) < 1:
        raise SogmmError(f"--frames-per-task {text}: expected an integer >= 1 or auto")
    return int(text)


def main(argv=None) -> int:
    # Asked first (even before --help), so that a missing Ray is one line and
    # not a traceback from inside build_map: nothing here runs without it.
    try:
        import ray  # noqa: F401
    except ImportError:
        print("sogmm_ray: Ray is not installed: pip install 'sogmm[ray]' (Ray 2.40.0: Python 3.9 to 3.12)",
              file=sys.stderr)
        return 1
    a = _parser().parse_args(argv)
    map_flags = [f for f, v in (("--threshold", a.threshold != MapSettings.novelty_threshold),
                                ("--batch", a.batch != MapSettings.batch_size), ("--no-novelty", a.no_novelty),
                                ("--fusion", a.fusion != MapSettings.fusion),
                                ("--fusion-threshold", a.fusion_threshold != MapSettings.fusion_threshold),
                                ("--novelty-bandwidth-scale",
                                 a.novelty_bandwidth_scale != MapSettings.novelty_bandwidth_scale),
                                ("--revisit-refit-ratio", a.revisit_refit_ratio != MapSettings.revisit_refit_ratio))
                 if v]
    if a.decimate is None:
        a.decimate = 5 if a.reduce == "map" else FitSettings.decimate
    try:
        if a.reduce != "map" and map_flags:
            raise SogmmError(f"{map_flags[0]} is a map flag: give --reduce map")
        map_settings = None if a.reduce != "map" else MapSettings(
            novelty=not a.no_novelty, novelty_threshold=a.threshold, batch_size=a.batch, fusion=a.fusion,
            fusion_threshold=a.fusion_threshold, novelty_bandwidth_scale=a.novelty_bandwidth_scale,
            revisit_refit_ratio=a.revisit_refit_ratio)
        frames_per_task = _frames_per_task(a.frames_per_task)
        settings = FitSettings(bandwidth=a.bandwidth, n_components=a.components, seed=a.seed, n_init=a.n_init,
                               threads=a.threads, tol=a.tol, max_iter=a.max_iter, reg_covar=a.reg_covar,
                               truncate=a.truncate, dequantise_depth=a.dequantise_depth, decimate=a.decimate,
                               depth_scale=a.depth_scale, depth_min=a.depth_min, depth_max=a.depth_max)
        intrinsics = a.intrinsics or str(Path(a.sequence) / "intrinsics.json")
        if not a.intrinsics and not os.path.lexists(intrinsics):
            raise SogmmError(f"no camera: give --intrinsics FILE (or put intrinsics.json in {a.sequence})")
        check_output("-o", a.output, [("--trajectory", a.trajectory), ("--intrinsics", intrinsics)])
        camera = Camera.from_json(intrinsics)
        frames = load_frames(a.sequence, a.trajectory, a.frames, a.pair_by_order)
        meta = {"sequence": a.sequence, "trajectory": a.trajectory}  # as sogmm fit --sequence and sogmm map
        r = build_map(frames, settings, camera, workers=a.workers, address=a.address, fan_in=a.fan_in,
                      tile_size=a.tile_size, on_error=a.on_error, max_retries=a.max_retries, progress=not a.quiet,
                      metadata=meta, map=map_settings, frames_per_task=frames_per_task)
        r.model.save(a.output)
    except (SogmmError, OSError) as e:
        print(f"sogmm_ray: {e}", file=sys.stderr)
        return 1
    for frame, message in r.skipped:
        print(f"sogmm_ray: skipped frame {frame}: {message}", file=sys.stderr)
    summary = {"output": a.output, "frames": r.n_frames, "skipped": [f for f, _ in r.skipped],
               "n_components": r.model.n_components_, "seconds_wall": r.seconds_wall, "seconds_fit": r.seconds_fit,
               "seconds_merge": r.seconds_merge, "bytes_moved_per_frame": r.bytes_moved / max(len(frames), 1),
               "tasks": r.tasks, "merge_tasks": r.merges}
    if a.json:
        print(json.dumps(summary))
    else:
        print(f"Fitted {r.n_frames} frames of {a.sequence} ({len(r.skipped)} skipped) into {summary['n_components']} "
              f"components in {r.seconds_wall:.2f} s (fit {r.seconds_fit:.2f} s, merge {r.seconds_merge:.2f} s of "
              f"task time; {summary['bytes_moved_per_frame'] / 1024:.1f} KiB moved per frame). Wrote {a.output}.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
