"""A map's deltas as an MCAP file for Foxglove and ROS 2 users (issue 33).

``write_mcap(path, deltas)`` replays map deltas (``Map.export_delta``, or the
files of ``sogmm map --deltas DIR``) into a fresh receiver, as a robot's peer
would, and writes with the registry's MCAP writer (``mcap``,
``mcap-protobuf-support``) and Foxglove's published schemas
(``foxglove-schemas-protobuf``):

- topic ``/sogmm/map``: one ``foxglove.SceneUpdate`` per delta, the whole map
  after it as one entity (id ``sogmm_map``, which replaces the previous one):
  each component an ellipsoid (a ``SpherePrimitive`` rotated to the
  covariance's eigenvectors, its diameters ``2 * sigma`` standard deviations,
  coloured by the component's mean gray);
- topic ``/sogmm/camera``: one ``foxglove.PoseInFrame`` per frame the deltas
  bring (the camera-to-world poses of the map's frame lines).

Frame k is stamped ``k * period_ns`` nanoseconds (the deltas carry no clock),
and each scene update the time of the last frame it brings. Open the file in
Foxglove (File > Open local file) or replay it into ROS 2 with
``ros2 bag play`` (rosbag2's MCAP storage plugin). Needs the extra
``sogmm[mcap]``; command line: ``python -m sogmm.foxglove DIR -o map.mcap``.
"""
from __future__ import annotations

import argparse
import os
import sys
from typing import Iterable

import numpy as np

from .errors import SogmmError
from .map import Map

MAP_TOPIC = "/sogmm/map"
CAMERA_TOPIC = "/sogmm/camera"
ENTITY_ID = "sogmm_map"


def _quaternions(rotations: np.ndarray) -> np.ndarray:
    """(N, 3, 3) proper rotations -> (N, 4) unit quaternions (x, y, z, w),
    by the largest of the four candidate divisors (no division by ~0)."""
    r = rotations
    t = np.stack([1 + r[:, 0, 0] - r[:, 1, 1] - r[:, 2, 2], 1 - r[:, 0, 0] + r[:, 1, 1] - r[:, 2, 2],
                  1 - r[:, 0, 0] - r[:, 1, 1] + r[:, 2, 2], 1 + r[:, 0, 0] + r[:, 1, 1] + r[:, 2, 2]], axis=1)
    k = np.argmax(t, axis=1)
    s = np.sqrt(np.maximum(t[np.arange(len(r)), k], 1e-300)) * 2  # 4 |q_k|
    q = np.empty((len(r), 4))
    a, b, c = r[:, 2, 1] - r[:, 1, 2], r[:, 0, 2] - r[:, 2, 0], r[:, 1, 0] - r[:, 0, 1]
    p, m, n = r[:, 0, 1] + r[:, 1, 0], r[:, 0, 2] + r[:, 2, 0], r[:, 1, 2] + r[:, 2, 1]
    rows = {0: (s / 4, p / s, m / s, a / s), 1: (p / s, s / 4, n / s, b / s),
            2: (m / s, n / s, s / 4, c / s), 3: (a / s, b / s, c / s, s / 4)}
    for kk, (x, y, z, w) in rows.items():
        sel = k == kk
        q[sel] = np.stack([x, y, z, w], axis=1)[sel]
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def ellipsoids(means: np.ndarray, covariances: np.ndarray, sigma: float):
    """Centres (N, 3), orientations (N, 4 quaternions) and diameters (N, 3)
    of the ``sigma`` ellipsoids of the 3-D marginals."""
    values, vectors = np.linalg.eigh(np.asarray(covariances, dtype=np.float64)[:, :3, :3])
    flip = np.linalg.det(vectors) < 0  # a proper rotation: the eigenvectors' sign is free
    vectors[flip, :, 0] *= -1
    diameters = 2 * sigma * np.sqrt(np.maximum(values, 0))
    return np.asarray(means, dtype=np.float64)[:, :3], _quaternions(vectors), diameters


def _stamp(message_time, ns: int) -> None:
    message_time.seconds, message_time.nanos = divmod(int(ns), 1_000_000_000)


def _scene_update(gmm, sigma: float, ns: int, frame_id: str):
    from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
    update = SceneUpdate()
    entity = update.entities.add()
    _stamp(entity.timestamp, ns)
    entity.frame_id, entity.id = frame_id, ENTITY_ID
    centres, orientations, diameters = ellipsoids(gmm.means_, gmm.covariances_, sigma)
    gray = np.clip(np.asarray(gmm.means_, dtype=np.float64)[:, 3], 0.0, 1.0)
    for c, q, d, g in zip(centres, orientations, diameters, gray):
        sphere = entity.spheres.add()
        sphere.pose.position.x, sphere.pose.position.y, sphere.pose.position.z = c
        sphere.pose.orientation.x, sphere.pose.orientation.y, sphere.pose.orientation.z, sphere.pose.orientation.w = q
        sphere.size.x, sphere.size.y, sphere.size.z = d
        sphere.color.r = sphere.color.g = sphere.color.b = g
        sphere.color.a = 1.0
    return update


def _pose_in_frame(pose: np.ndarray, ns: int, frame_id: str):
    from foxglove_schemas_protobuf.PoseInFrame_pb2 import PoseInFrame
    message = PoseInFrame()
    _stamp(message.timestamp, ns)
    message.frame_id = frame_id
    p = message.pose
    p.position.x, p.position.y, p.position.z = pose[:3, 3]
    p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w = _quaternions(pose[None, :3, :3])[0]
    return message


def _delta_bytes(delta) -> bytes:
    if isinstance(delta, (bytes, bytearray, memoryview)):
        return bytes(delta)
    with open(delta, "rb") as f:
        return f.read()


def write_mcap(path: str | os.PathLike, deltas: Iterable, *, sigma: float = 2.0, frame_id: str = "world",
               period_ns: int = 1_000_000_000) -> dict:
    """Writes the MCAP file of ``deltas`` (bytes or file paths, in order) to
    ``path`` (replaced atomically) and returns ``{"scene_updates", "poses",
    "components", "bytes"}``. A delta the receiver refuses raises its
    SogmmError (a gap, another map's delta, a damaged one) and writes
    nothing; so does a non-positive ``sigma`` or ``period_ns``."""
    try:
        from mcap_protobuf.writer import Writer
    except ImportError as e:  # the extra is optional
        raise SogmmError("sogmm.foxglove needs the extra sogmm[mcap] (mcap, mcap-protobuf-support, "
                         "foxglove-schemas-protobuf): pip install 'sogmm[mcap]'") from e
    if not (np.isfinite(sigma) and sigma > 0) or int(period_ns) <= 0:
        raise ValueError("sigma and period_ns must be positive")
    path = os.fspath(path)
    tmp = path + ".tmp-%d" % os.getpid()
    counts = {"scene_updates": 0, "poses": 0, "components": 0}
    try:
        with Map() as receiver, open(tmp, "wb") as f:
            writer = Writer(f)
            frames_sent = 0
            for delta in deltas:
                receiver.apply_delta(_delta_bytes(delta))
                n_frames = len(receiver)
                for k in range(frames_sent, n_frames):
                    writer.write_message(CAMERA_TOPIC, _pose_in_frame(receiver.frame_stats(k)["pose"],
                                                                      k * period_ns, frame_id),
                                         log_time=k * period_ns, publish_time=k * period_ns)
                    counts["poses"] += 1
                frames_sent = n_frames
                ns = max(n_frames - 1, 0) * period_ns
                if receiver.n_components_ > 0:
                    gmm = receiver.export()
                    writer.write_message(MAP_TOPIC, _scene_update(gmm, sigma, ns, frame_id), log_time=ns,
                                         publish_time=ns)
                    counts["scene_updates"] += 1
                    counts["components"] = gmm.n_components_
            writer.finish()
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
    counts["bytes"] = os.path.getsize(path)
    return counts


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m sogmm.foxglove",
                                 description="Write the deltas of `sogmm map --deltas DIR` as an MCAP file "
                                             "(foxglove.SceneUpdate per delta, foxglove.PoseInFrame per frame)")
    ap.add_argument("deltas", help="folder of delta files (replayed in name order)")
    ap.add_argument("-o", "--output", required=True, help="the .mcap file to write")
    ap.add_argument("--sigma", type=float, default=2.0, help="ellipsoid size in standard deviations (default 2)")
    ap.add_argument("--period", type=float, default=1.0, help="seconds between frames' stamps (default 1)")
    a = ap.parse_args(argv)
    try:
        names = sorted(n for n in os.listdir(a.deltas) if n.endswith(".sogmm"))
        if not names:
            raise SogmmError(f"{a.deltas}: no .sogmm delta files")
        r = write_mcap(a.output, [os.path.join(a.deltas, n) for n in names], sigma=a.sigma,
                       period_ns=round(a.period * 1e9))
    except (OSError, SogmmError, ValueError) as e:
        print(f"sogmm.foxglove: error: {e}", file=sys.stderr)
        return 1
    print(f"Wrote {a.output}: {r['scene_updates']} scene updates, {r['poses']} poses, "
          f"{r['components']} components, {r['bytes']} bytes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
