"""sogmm_ray: the map of a Ray job equals the sequential build bit for
bit (after the canonical order), whatever the worker count, fan-in, tiling or
completion order, with a worker killed mid-task, and with a bad frame skipped;
the "fail" policy names the bad frame."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import sogmm
from sogmm_ray import (FitSettings, FrameError, MapSettings, build_map, finalize, fit_frame, load_frames,
                       map_tile, merge_tree, reduce_partials, sequential_build, tiles_of)
from sogmm_ray.frame_fit import camera_dict
from sogmm_ray.sequence import read_trajectory

from conftest import BAD_FRAME, N_FRAMES, NO_RAY

pytest.importorskip("ray", reason=NO_RAY)

SETTINGS = FitSettings(bandwidth=0.05, decimate=2, seed=3)
# A batch below one frame's 1728 points: every insert fits, later frames are
# scored against the map (novelty), and fusion has neighbours to fuse into.
MAP = MapSettings(batch_size=1000, novelty_threshold=4.0, fusion="hellinger", fusion_threshold=0.3)
TILE = 0.5  # the 12 orbit cameras fall into 4 tiles (quadrants) of 2 to 4 frames


def _camera(seq):
    return sogmm.Camera.from_json(seq / "intrinsics.json")


def _frames(seq):
    return load_frames(str(seq), str(seq / "trajectory.log"))


def assert_same_map(a: sogmm.GMM, b: sogmm.GMM):
    """Bitwise: arrays, support and key/values (the files then differ only in
    created_unix_ms, the creation time)."""
    for name in ("weights_", "means_", "covariances_"):
        assert getattr(a, name).tobytes() == getattr(b, name).tobytes(), name
    assert a.support_size_ == b.support_size_
    assert a.metadata == b.metadata


@pytest.fixture(scope="module")
def reference(sequence):
    r = sequential_build(_frames(sequence), SETTINGS, _camera(sequence))
    assert [f for f, _ in r.skipped] == [BAD_FRAME]
    assert r.n_frames == N_FRAMES - 1
    return r.model


@pytest.fixture(scope="module")
def map_reference(sequence):
    r = sequential_build(_frames(sequence), SETTINGS, _camera(sequence), map=MAP, tile_size=TILE)
    assert [f for f, _ in r.skipped] == [BAD_FRAME]
    return r.model


# Runs first, before the session's 2-CPU Ray exists: build_map starts (and stops) its own.
def test_one_worker_equals_sequential(sequence, reference):
    import ray
    assert not ray.is_initialized()
    r = build_map(_frames(sequence), SETTINGS, _camera(sequence), workers=1, fan_in=2, progress=False)
    assert not ray.is_initialized()
    assert_same_map(r.model, reference)


@pytest.mark.parametrize("fan_in,tile_size,frames_per_task", [(2, 0.0, 1), (3, 0.5, 3), (16, 2.0, None)])
def test_two_workers_equal_sequential_for_any_fan_in_tiling_and_chunking(local_ray, sequence, reference, fan_in,
                                                                          tile_size, frames_per_task):
    r = build_map(_frames(sequence), SETTINGS, _camera(sequence), fan_in=fan_in, tile_size=tile_size, progress=False,
                  frames_per_task=frames_per_task)
    assert [f for f, _ in r.skipped] == [BAD_FRAME]
    assert r.n_frames == N_FRAMES - 1 and r.bytes_moved > 0
    assert_same_map(r.model, reference)


def test_any_merge_order_gives_the_canonical_model(sequence, reference):
    """Without Ray: leaves merged in shuffled orders and tree shapes (as tasks
    finishing in any order would) give the same canonical model; the raw
    merged weights do differ, which is why finalize() exists."""
    cam = camera_dict(_camera(sequence))
    leaves = [p for _, p in (fit_frame(f, SETTINGS, cam) for f in _frames(sequence)) if p is not None]
    rng = np.random.default_rng(5)
    raw = set()
    for fan_in in (2, 3, 5):
        order = rng.permutation(len(leaves))
        root = merge_tree([leaves[i] for i in order], fan_in, lambda *p: reduce_partials(list(p)))
        raw.add(sogmm.from_bytes(root["model"]).weights_.tobytes())
        assert_same_map(finalize(root), reference)
    assert len(raw) > 1, "the raw tree weights were expected to differ in the last bits"


@pytest.mark.parametrize("reduce", ["merge", "map"])
def test_killed_worker_is_retried_and_the_map_is_identical(local_ray, sequence, reference, map_reference, pid_dir,
                                                           reduce):
    victim = 4
    (pid_dir / "hold").write_text(str(victim))
    marker = pid_dir / f"{victim}.pid"
    marker.unlink(missing_ok=True)  # left by the other parametrization
    killed = []

    def killer():
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and not marker.exists():
            time.sleep(0.05)
        if marker.exists():
            pid = int(marker.read_text())
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)

    t = threading.Thread(target=killer)
    t.start()
    try:
        r = build_map(_frames(sequence), SETTINGS, _camera(sequence), fan_in=4, max_retries=3, progress=False,
                      map=MAP if reduce == "map" else None, tile_size=TILE)
    finally:
        t.join()
        (pid_dir / "hold").unlink()
    assert killed, "the held task never reported its pid"
    with pytest.raises(ProcessLookupError):
        os.kill(killed[0], 0)  # that worker is gone
    assert [f for f, _ in r.skipped] == [BAD_FRAME]
    assert_same_map(r.model, map_reference if reduce == "map" else reference)


def test_fail_policy_names_the_bad_frame(local_ray, sequence):
    with pytest.raises(FrameError, match=f"frame {BAD_FRAME}:") as e:
        build_map(_frames(sequence), SETTINGS, _camera(sequence), on_error="fail", progress=False)
    assert e.value.frame == BAD_FRAME


def test_skip_policy_reports_the_bad_frame(local_ray, sequence):
    r = build_map(_frames(sequence), SETTINGS, _camera(sequence), progress=False)
    (frame, message), = r.skipped
    assert frame == BAD_FRAME and message


def test_command_line_on_an_existing_cluster(local_ray, sequence, reference, tmp_path):
    out = tmp_path / "map.sogmm"
    address = local_ray.get_runtime_context().gcs_address
    cmd = [sys.executable, "-m", "sogmm_ray", "--address", address, "--sequence", str(sequence),
           "--trajectory", str(sequence / "trajectory.log"), "-o", str(out), "--bandwidth", "0.05", "--decimate", "2",
           "--seed", "3", "--fan-in", "3"]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    assert f"skipped frame {BAD_FRAME}" in p.stderr
    assert f"{N_FRAMES}/{N_FRAMES}" in p.stderr  # the progress bar counted every frame
    m = sogmm.load(out)
    for name in ("weights_", "means_", "covariances_"):
        assert getattr(m, name).tobytes() == getattr(reference, name).tobytes(), name
    assert m.metadata["frames"] == reference.metadata["frames"]
    assert m.info()["fit_bandwidth"] == 0.05 and m.metadata["sequence"] == str(sequence)


def test_command_line_bad_input_is_one_line(tmp_path):
    p = subprocess.run([sys.executable, "-m", "sogmm_ray", "--sequence", str(tmp_path / "none"),
                        "--trajectory", str(tmp_path / "t.log"), "--intrinsics", str(tmp_path / "none.json"), "-o",
                        str(tmp_path / "m.sogmm")], capture_output=True, text=True, timeout=120)
    assert p.returncode == 1
    assert p.stderr.count("\n") == 1 and "sogmm_ray:" in p.stderr


def test_trajectory_errors_name_the_line(tmp_path):
    bad = tmp_path / "t.log"
    bad.write_text("0 1 1\n1 0 0 0\n0 2 0 0\n0 0 1 0\n0 0 0 1\n")
    with pytest.raises(sogmm.InvalidDataError, match=r"t.log:5: pose 0 is not a rigid transform"):
        read_trajectory(str(bad))
    bad.write_text("0 1 1\n1 0 0 0\n0 1 0 0\n")
    with pytest.raises(sogmm.InvalidDataError, match="truncated"):
        read_trajectory(str(bad))


def test_matches_the_cli_sequential_fit_up_to_weight_rounding(sequence, tmp_path):
    """Against `sogmm fit --sequence` (a chain of merges, one float32 rounding of
    every weight per merge): means and covariances bit for bit, weights within
    k - 1 roundings for k frames, the mean log-likelihood within what those
    roundings allow."""
    cli = os.environ.get("SOGMM_CLI")
    if not cli or not os.path.isfile(cli):
        pytest.skip("SOGMM_CLI (the sogmm tool) not given; ctest sets it")
    out = tmp_path / "cli.sogmm"
    subprocess.run([cli, "fit", "--sequence", str(sequence), "--trajectory", str(sequence / "trajectory.log"),
                    "--frames", f"0:{BAD_FRAME}", "--bandwidth", "0.05", "--decimate", "2", "--seed", "3",
                    "--threads", "1", "-q", "-o", str(out)], check=True, stdout=subprocess.DEVNULL, timeout=300)
    chain = sogmm.load(out)
    frames = [f for f in _frames(sequence) if f.index < BAD_FRAME]
    ours = sequential_build(frames, SETTINGS, _camera(sequence)).model
    assert chain.means_.tobytes() == ours.means_.tobytes()
    assert chain.covariances_.tobytes() == ours.covariances_.tobytes()
    ulps = np.abs(chain.weights_.view(np.int32).astype(np.int64) - ours.weights_.view(np.int32))
    assert ulps.max() <= len(frames) - 1
    x = ours.sample(5000, seed=1)
    # Each point's mixture density sum_k w_k p_k moves by at most the largest
    # factor between two weights, so the scores by at most that many nats.
    factor = np.max(np.abs(np.log(chain.weights_.astype(np.float64)) - np.log(ours.weights_.astype(np.float64))))
    assert abs(chain.score(x) - ours.score(x)) <= factor + 1e-12
    # The same provenance: fit record (settings, EM sums, camera) and key/values.
    ci, oi = chain.info(), ours.info()
    del ci["created_unix_ms"], oi["created_unix_ms"]
    assert abs(ci.pop("fit_log_likelihood") - oi.pop("fit_log_likelihood")) <= 1e-12 * abs(chain.lower_bound_)
    assert ci == oi
    for key in ("coordinate_frame", "frames", "merged_fits"):
        assert chain.metadata[key] == ours.metadata[key], key


# ---- the map-building reduce (--reduce map) --------------------------------------------------------------------


@pytest.mark.parametrize("fan_in", [2, 16])
def test_map_reduce_equals_the_sequential_map_build_for_any_fan_in(local_ray, sequence, map_reference, fan_in):
    r = build_map(_frames(sequence), SETTINGS, _camera(sequence), fan_in=fan_in, tile_size=TILE, map=MAP,
                  progress=False)
    assert [f for f, _ in r.skipped] == [BAD_FRAME]
    assert r.tasks == 4  # one task per tile
    assert_same_map(r.model, map_reference)


def test_map_reduce_in_any_tile_order_gives_the_canonical_model(sequence, map_reference, reference):
    """Without Ray: tile maps united in shuffled orders and tree shapes give
    the same model; its provenance lists every fitted frame once, tile by tile
    in the order of their first frame, frames in id order inside a tile."""
    frames = _frames(sequence)
    cam = camera_dict(_camera(sequence))
    tiles = tiles_of(frames, TILE)
    parts = [map_tile(t, SETTINGS, MAP, cam)[1] for t in tiles]
    rng = np.random.default_rng(7)
    for fan_in in (2, 3):
        order = rng.permutation(len(parts))
        root = merge_tree([parts[i] for i in order], fan_in, lambda *p: reduce_partials(list(p)))
        assert_same_map(finalize(root), map_reference)
    expected = [f.index for t in sorted(tiles, key=lambda t: t[0].index) for f in t if f.index != BAD_FRAME]
    assert map_reference.metadata["frames"] == ",".join(map(str, expected))
    lines = map_reference.metadata["map_frames"].splitlines()
    assert [int(line.split()[0]) for line in lines] == list(range(len(expected)))
    poses = [np.array([float(v) for v in line.split()[3:15]]).reshape(3, 4) for line in lines]
    by_id = {f.index: np.array(f.pose).reshape(4, 4)[:3] for f in frames}
    assert all(np.array_equal(p, by_id[i]) for p, i in zip(poses, expected))
    # The components after each frame count the earlier tiles' too: they rise
    # and end at the united map's size (spec/format.md 2.3).
    counts = [int(line.split()[15]) for line in lines]
    assert counts == sorted(counts) and counts[-1] == map_reference.n_components_
    # Novelty did its work: points the tile's map already explained were not fitted again.
    assert map_reference.support_size_ < reference.support_size_


def test_one_tile_map_is_the_sogmm_map_of_the_sequence(local_ray, sequence, tmp_path):
    """--tile-size 0: one task builds the map over every frame, as `sogmm map`
    (the C++ tool, an independent front end) does: the same components bit for
    bit and the same provenance (file contents equal but for the creation time)."""
    cli = os.environ.get("SOGMM_CLI")
    if not cli or not os.path.isfile(cli):
        pytest.skip("SOGMM_CLI (the sogmm tool) not given; ctest sets it")
    out = tmp_path / "map.sogmm"
    subprocess.run([cli, "map", str(sequence), "--trajectory", str(sequence / "trajectory.log"),
                    "--frames", f"0:{BAD_FRAME}", "--bandwidth", "0.05", "--decimate", "2", "--seed", "3",
                    "--threads", "1", "--batch", "1000", "--threshold", "4", "--fusion", "hellinger",
                    "--fusion-threshold", "0.3", "-q", "-o", str(out)], check=True, stdout=subprocess.DEVNULL,
                   timeout=300)
    tool = sogmm.load(out)
    frames = [f for f in _frames(sequence) if f.index < BAD_FRAME]
    meta = {"sequence": str(sequence), "trajectory": str(sequence / "trajectory.log")}  # as the tool records them
    ours = build_map(frames, SETTINGS, _camera(sequence), tile_size=0.0, map=MAP, progress=False,
                     metadata=meta).model
    for name in ("weights_", "means_", "covariances_"):
        assert getattr(tool, name).tobytes() == getattr(ours, name).tobytes(), name
    # A saved map also records its identity (map_id, random per map, and map_revision;
    # spec/format.md 2.5), which two builds of the same map do not share.
    identity = ("map_id", "map_revision")
    tool_meta = {k: v for k, v in tool.metadata.items() if k not in identity}
    assert tool_meta == ours.metadata  # map_frames, map_options, frames, merged_fits, ...
    assert tool.support_size_ == ours.support_size_
    ti, oi = tool.info(), ours.info()
    del ti["created_unix_ms"], oi["created_unix_ms"]
    assert ti == oi  # the fit record and camera of the map, as the tool writes them


def test_command_line_map_reduce(local_ray, sequence, map_reference, tmp_path):
    out = tmp_path / "map.sogmm"
    address = local_ray.get_runtime_context().gcs_address
    cmd = [sys.executable, "-m", "sogmm_ray", "--address", address, "--sequence", str(sequence),
           "--trajectory", str(sequence / "trajectory.log"), "-o", str(out), "--bandwidth", "0.05", "--decimate", "2",
           "--seed", "3", "--reduce", "map", "--tile-size", str(TILE), "--batch", "1000", "--threshold", "4",
           "--fusion", "hellinger", "--fusion-threshold", "0.3", "-q", "--json"]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    m = sogmm.load(out)
    for name in ("weights_", "means_", "covariances_"):
        assert getattr(m, name).tobytes() == getattr(map_reference, name).tobytes(), name
    assert m.metadata["map_frames"] == map_reference.metadata["map_frames"]
    with sogmm.Map.load(out) as reopened:  # the core Map reads the provenance back
        assert len(reopened) == N_FRAMES - 1


def test_map_flags_need_the_map_reduce(tmp_path):
    p = subprocess.run([sys.executable, "-m", "sogmm_ray", "--sequence", str(tmp_path), "--trajectory",
                        str(tmp_path / "t.log"), "-o", str(tmp_path / "m.sogmm"), "--fusion", "kl"],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 1
    assert p.stderr.strip() == "sogmm_ray: --fusion is a map flag: give --reduce map"


def test_auto_chunking_keeps_four_tasks_per_cpu_and_at_most_eight_frames():
    from sogmm_ray import auto_frames_per_task
    assert [auto_frames_per_task(n, c) for n, c in [(200, 1), (200, 2), (24, 2), (5, 2), (2870, 128), (0, 0)]] == \
        [8, 8, 3, 1, 5, 1]
