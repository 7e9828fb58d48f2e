"""Partial maps: what the merge tree of :mod:`sogmm_ray` passes around.

A partial map is a dict of plain bytes, ints, strings and lists (Ray moves it
without pickling any sogmm object). Its unit is a *row*: one fitted frame
(the plain merge) or one tile's map (``sogmm.Map``, see
:mod:`sogmm_ray.map_tile`):

- ``model``: a world-frame ``.sogmm`` file (uncompressed: zstd level 19 costs
  more than the bytes it saves between tasks) holding the components of its
  rows, row by row in the order of ``table``;
- ``table``: one :data:`TABLE` row per unit (its first frame id, which orders
  the rows; support size, components, the fit's mean log-likelihood, EM
  iterations, converged);
- ``weights``: each row's own weights (float32, summing to 1 per row), in
  model order;
- ``frames``: per row, the frame ids it holds in insertion order;
- ``map_frames``: per row, its map's ``map_frames`` provenance text
  (spec/format.md 2.3), "" for a fitted frame; ``map_options``: the maps'
  ``map_options`` text (the same for every tile), "" for fitted frames.

:func:`reduce_partials` is the one reduce function of the tree (today a plain
world-frame merge, ``sogmm_model_merge``; a map with fusion plugs in here), and
:func:`finalize` turns the root into the canonical model.

Why a canonical model: ``sogmm_model_merge`` concatenates means and
covariances bit for bit but rescales every weight, ``float(w * s_a / (s_a +
s_b))``, rounding once per merge, so the weights of a chain of merges (the
sequential ``sogmm fit --sequence``) and of a tree differ in the last bits,
and so does the fit record's weighted mean log-likelihood. :func:`finalize`
therefore orders components by (frame id, component index) and recomputes
every weight from the frame's own weight with one rounding,
``float32(w_fk * (s_f / S))`` with S the total support, and the mean
log-likelihood as an exactly rounded sum (``math.fsum``). The result is a pure
function of the set of fitted frames: independent of completion order,
worker count, fan-in and tiling, and bitwise equal to
:func:`sequential_partial` (the frames folded one by one) after the same step.
"""

from __future__ import annotations

import math

import numpy as np

from sogmm import GMM, InvalidDataError

#: Per-frame provenance row of a partial map.
TABLE = np.dtype([("frame", "<i8"), ("support", "<u8"), ("n", "<i8"), ("log_likelihood", "<f8"),
                  ("n_iter", "<i8"), ("converged", "<i8"), ("fits", "<i8")])


def leaf(frame: int, world: GMM) -> dict:
    """The partial map of one fitted frame already moved to the world frame."""
    row = np.array([(frame, world.support_size_, world.n_components_, world.lower_bound_ or 0.0,
                     world.n_iter_ or 0, int(bool(world.converged_)), 1)], dtype=TABLE)
    return {"model": world.to_bytes(compress=False), "table": row.tobytes(),
            "weights": world.weights_.astype("<f4").tobytes(), "frames": [[frame]], "map_frames": [""],
            "map_options": ""}


def size_bytes(part: dict | None) -> int:
    """Bytes a partial map occupies in the object store (its three buffers)."""
    if part is None:
        return 0
    return (len(part["model"]) + len(part["table"]) + len(part["weights"]) + 8 * sum(map(len, part["frames"]))
            + sum(map(len, part["map_frames"])))


def reduce_partials(parts: list) -> dict | None:
    """One node of the merge tree: the union of the partial maps (None = no frame).

    Inputs are merged in order of their first frame id, so the tree's interior
    models are reproducible too (the canonical result does not need it)."""
    parts = sorted((p for p in parts if p is not None), key=lambda p: int(np.frombuffer(p["table"], TABLE)["frame"][0]))
    if not parts:
        return None
    if len(parts) == 1:
        return parts[0]
    model = GMM.from_bytes(parts[0]["model"])
    for p in parts[1:]:
        model = model.merge(GMM.from_bytes(p["model"]))
    return {"model": model.to_bytes(compress=False), "table": b"".join(p["table"] for p in parts),
            "weights": b"".join(p["weights"] for p in parts), "frames": [f for p in parts for f in p["frames"]],
            "map_frames": [t for p in parts for t in p["map_frames"]], "map_options": parts[0]["map_options"]}


def finalize(part: dict, metadata: dict[str, str] | None = None) -> GMM:
    """The canonical world-frame model of a root partial map (see the module doc).

    Provenance as the sequential tools write it (spec/format.md 2.2 and 2.3):
    the fit record (the settings and camera shared by every unit, as
    ``sogmm_model_merge`` keeps them, with ``n_iter`` the sum, ``converged``
    the conjunction and ``log_likelihood`` the support-weighted mean of the
    units', summed exactly), and the key/values ``coordinate_frame`` = world,
    ``frames``, ``merged_fits`` and, for maps, ``map_frames`` and
    ``map_options``; then ``metadata`` (e.g. ``sequence``, ``trajectory``)."""
    if part is None:
        raise InvalidDataError("no frame was fitted: the map is empty")
    table = np.frombuffer(part["table"], TABLE)
    w0 = np.frombuffer(part["weights"], "<f4")
    model = GMM.from_bytes(part["model"])
    if len(np.unique(table["frame"])) != len(table):
        raise InvalidDataError("a frame appears twice in the merge tree")
    if int(table["n"].sum()) != model.n_components_ or w0.size != model.n_components_:
        raise InvalidDataError("partial map: table and model disagree on the number of components")
    start = np.concatenate([[0], np.cumsum(table["n"])[:-1]])
    order = np.argsort(table["frame"], kind="stable")
    index = np.concatenate([np.arange(start[i], start[i] + table["n"][i]) for i in order])
    total = sum(int(s) for s in table["support"])  # exact integer sum
    share = np.repeat(table["support"][order].astype(np.float64) / float(total), table["n"][order])
    weights = (w0[index].astype(np.float64) * share).astype(np.float32)
    out = GMM.from_arrays(weights, model.means_[index], model.covariances_[index], support_size=total)
    t = table[order]
    # The tree's merges kept the settings and camera where every unit agrees
    # (a pure function of the set of units); the sums are recomputed exactly.
    shared = {k: v for k, v in model.info().items() if k.startswith(("fit_", "camera_")) and k in _STORED}
    if "fit_bandwidth" in shared and len(t) >= 2:  # one unit keeps its own record as it is
        shared.update(fit_iterations=min(int(np.maximum(t["n_iter"], 0).sum()), 2**31 - 1),
                      fit_converged=int(t["converged"].all()),
                      fit_log_likelihood=math.fsum(float(s) * l for s, l in zip(t["support"], t["log_likelihood"]))
                      / total)
    out.set_info(**shared)
    frames = [f for i in order for f in part["frames"][i]]
    values = {"coordinate_frame": "world", "frames": ",".join(str(int(f)) for f in frames)}
    if int(t["fits"].sum()) >= 2:  # spec/format.md 2.2: written only for a merge (>= 2)
        values["merged_fits"] = str(int(t["fits"].sum()))
    texts = [part["map_frames"][i] for i in order]
    if any(texts):  # maps: one provenance line per frame, renumbered in the canonical insertion order
        lines = [_united_line(line, offset) for text, offset in zip(texts, np.cumsum(t["n"]) - t["n"])
                 for line in text.splitlines()]
        values["map_frames"] = "".join(f"{k} {rest}\n" for k, rest in enumerate(lines))
        values["map_options"] = part["map_options"]
    values.update(metadata or {})
    for k, v in values.items():
        out.set_metadata(k, v)
    return out


def _united_line(line: str, offset: int) -> str:
    """A tile map's ``map_frames`` line without its index, in the united map:
    the optional last field, the map's components after the frame
    (spec/format.md 2.3), counts the components of the tiles before it too,
    since the united model holds the tiles' components tile by tile."""
    fields = line.split(" ")[1:]
    if len(fields) == 15:  # n_points n_novel, 12 pose numbers, n_components
        fields[-1] = str(int(fields[-1]) + int(offset))
    return " ".join(fields)


#: The info names a .sogmm file stores (GMM.set_info accepts them).
_STORED = ("fit_iterations", "fit_converged", "fit_log_likelihood", "fit_bandwidth", "fit_n_components_requested",
           "fit_tol", "fit_reg_covar", "fit_max_iter", "fit_seed", "camera_width", "camera_height", "camera_fx",
           "camera_fy", "camera_cx", "camera_cy", "camera_decimation", "camera_depth_scale", "camera_depth_min",
           "camera_depth_max")


def sequential_partial(leaves: list) -> dict | None:
    """The frames folded one by one in the given order (the sequential build)."""
    acc = None
    for p in leaves:
        acc = p if acc is None else reduce_partials([acc, p])
    return acc
