"""sogmm.foxglove (issue 33): a map's deltas as an MCAP file with Foxglove's
schemas, read back with the registry's MCAP reader."""
from __future__ import annotations

import math

import numpy as np
import pytest

import sogmm

pytest.importorskip("mcap_protobuf", reason="the extra sogmm[mcap] (tools/requirements-dev.txt pins it)")
from mcap_protobuf.decoder import DecoderFactory  # noqa: E402
from mcap.reader import make_reader  # noqa: E402

from conftest import blobs  # noqa: E402
from sogmm import foxglove  # noqa: E402


def rigid(yaw_deg: float, t) -> np.ndarray:
    a = math.radians(yaw_deg)
    p = np.eye(4)
    p[:3, :3] = [[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]]
    p[:3, 3] = t
    return p


def quaternion_matrix(q) -> np.ndarray:
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def test_an_ellipsoid_rebuilds_its_covariance():
    # Independent truth: R diag((d / 2 sigma)^2) R^T is the 3-D covariance,
    # for random SPD matrices and for a hand case (axes 1, 2, 3 cm turned 90
    # degrees about z: diameters at 2 sigma are 4, 8 and 12 cm).
    rng = np.random.default_rng(5)
    a = rng.normal(size=(50, 3, 3))
    cov = np.zeros((51, 4, 4))
    cov[:50, :3, :3] = a @ a.transpose(0, 2, 1) + 1e-3 * np.eye(3)
    turn = rigid(90, [0, 0, 0])[:3, :3]
    cov[50, :3, :3] = turn @ np.diag([4e-4, 1e-4, 9e-4]) @ turn.T
    cov[:, 3, 3] = 1.0
    means = rng.normal(size=(51, 4))
    centres, quats, diameters = foxglove.ellipsoids(means, cov, sigma=2.0)
    assert np.array_equal(centres, means[:, :3])
    for c, q, d in zip(cov, quats, diameters):
        r = quaternion_matrix(q)
        assert np.allclose(r @ r.T, np.eye(3), atol=1e-12) and np.linalg.det(r) > 0
        assert np.allclose(r @ np.diag((d / 4.0) ** 2) @ r.T, c[:3, :3], rtol=1e-9, atol=1e-12)
    assert np.allclose(diameters[50], [0.04, 0.08, 0.12])


def test_the_mcap_holds_a_scene_update_per_delta_and_a_pose_per_frame(tmp_path):
    poses = [rigid(0, [0, 0, 0]), rigid(20, [0.3, -0.1, 0.2]), rigid(-10, [0.1, 0.2, 0.0])]
    deltas, sizes = [], []
    with sogmm.Map(novelty=False, bandwidth=0.08, seed=3, n_threads=1) as sender:
        for k, pose in enumerate(poses):
            since = sender.revision
            sender.insert_points(blobs(n_per=200, seed=k), pose)
            deltas.append(sender.export_delta(since))
            sizes.append(sender.n_components_)
        final = sender.export()
    out = tmp_path / "map.mcap"
    r = foxglove.write_mcap(out, deltas)
    assert r == {"scene_updates": 3, "poses": 3, "components": sizes[-1], "bytes": out.stat().st_size}

    scenes, cameras = [], []
    with open(out, "rb") as f:
        for _, channel, message, decoded in make_reader(f, decoder_factories=[DecoderFactory()]).iter_decoded_messages():
            (scenes if channel.topic == foxglove.MAP_TOPIC else cameras).append((message.log_time, decoded))
    assert [len(d.entities[0].spheres) for _, d in scenes] == sizes
    assert all(d.entities[0].id == foxglove.ENTITY_ID for _, d in scenes)
    assert [t for t, _ in cameras] == [0, 10**9, 2 * 10**9]
    for (_, cam), pose in zip(cameras, poses):
        p = cam.pose
        assert np.allclose([p.position.x, p.position.y, p.position.z], pose[:3, 3])
        q = [p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w]
        assert np.allclose(quaternion_matrix(q), pose[:3, :3], atol=1e-12)
    # The last scene is the sender's map: centres are its means, gray its colour.
    spheres = scenes[-1][1].entities[0].spheres
    means = final.means_
    assert np.allclose([[s.pose.position.x, s.pose.position.y, s.pose.position.z] for s in spheres], means[:, :3])
    assert np.allclose([s.color.r for s in spheres], np.clip(means[:, 3], 0, 1))


def test_a_gap_writes_nothing(tmp_path):
    with sogmm.Map(novelty=False, bandwidth=0.08, seed=3, n_threads=1) as sender:
        deltas = []
        for k in range(2):
            since = sender.revision
            sender.insert_points(blobs(n_per=200, seed=k), rigid(0, [0.5 * k, 0, 0]))
            deltas.append(sender.export_delta(since))
    out = tmp_path / "map.mcap"
    out.write_bytes(b"kept")
    with pytest.raises(sogmm.InvalidArgumentError, match="revision"):
        foxglove.write_mcap(out, deltas[1:])
    assert out.read_bytes() == b"kept" and sorted(p.name for p in tmp_path.iterdir()) == ["map.mcap"]
