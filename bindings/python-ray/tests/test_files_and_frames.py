"""sogmm_ray's inputs, output and failure policy (issue 36): a bad
frame is skipped by its identity, never the frame whose insert happened to
trigger a fit; frames and poses are paired by frame number; a FIFO input is
refused at once; the output is checked before the run."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

import sogmm
from sogmm_ray import FitSettings, MapSettings, load_frames, sequential_build

from conftest import NO_RAY, write_sequence

pytest.importorskip("ray", reason=NO_RAY)

SETTINGS = FitSettings(bandwidth=0.05, decimate=2, seed=3)


def _sequence(folder: Path, n: int = 3, bad: dict | None = None) -> Path:
    """An n-frame sequence whose pose translations x are replaced by ``bad`` (frame -> text)."""
    write_sequence(folder, n)
    lines = (folder / "trajectory.log").read_text().splitlines()
    for frame, x in (bad or {}).items():
        row = lines[5 * frame + 1].split()
        row[3] = x
        lines[5 * frame + 1] = " ".join(row)
    (folder / "trajectory.log").write_text("\n".join(lines) + "\n")
    return folder


def _build(seq: Path, batch: int):
    frames = load_frames(str(seq), str(seq / "trajectory.log"))
    camera = sogmm.Camera.from_json(str(seq / "intrinsics.json"))
    return sequential_build(frames, SETTINGS, camera, map=MapSettings(batch_size=batch), tile_size=0)


def test_a_far_frame_does_not_get_the_frames_that_trigger_the_fit_skipped(tmp_path):
    # Frame 0 at x = 1e10 is pending when frame 1 fills the batch (1728
    # points a frame, batch 3000): the fit of frames 0 and 1 together fails.
    # Frames 1 and 2 fit with each other; whatever the library decides about
    # frame 0, they must stay.
    r = _build(_sequence(tmp_path / "seq", bad={0: "1e10"}), batch=3000)
    skipped = {f for f, _ in r.skipped}
    assert skipped <= {0}, r.skipped
    assert r.n_frames == 3 - len(skipped)


@pytest.mark.parametrize("batch", [1000, 3000, 12288])
def test_a_frame_that_cannot_be_fitted_is_skipped_by_its_identity(tmp_path, batch):
    # Frame 1 at x = 1e39 (beyond float32) is accepted by its insert and fails
    # in whichever fit holds its points: alone (batch 1000), with frame 2's
    # insert (3000) or at the final flush (12288). Only frame 1 is skipped.
    r = _build(_sequence(tmp_path / "seq", bad={1: "1e39"}), batch=batch)
    assert [f for f, _ in r.skipped] == [1], r.skipped
    assert r.n_frames == 2
    assert r.model.metadata["frames"] == "0,2"


def test_the_command_line_skips_by_identity(local_ray, tmp_path):
    seq = _sequence(tmp_path / "seq", bad={0: "1e10"})
    out = tmp_path / "map.sogmm"
    p = subprocess.run([sys.executable, "-m", "sogmm_ray", "--address",
                        local_ray.get_runtime_context().gcs_address, "--reduce", "map", "--on-error", "skip",
                        "--tile-size", "0", "--batch", "3000", "--decimate", "2", "--bandwidth", "0.05", "--sequence",
                        str(seq), "--trajectory", str(seq / "trajectory.log"), "-o", str(out), "-q"],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    assert "skipped frame 1" not in p.stderr and "skipped frame 2" not in p.stderr, p.stderr


def _renamed(seq: Path, folder: Path, names: list[int]) -> Path:
    """The frames of ``seq`` copied under the frame numbers ``names``."""
    for sub in ("depth", "color"):
        (folder / sub).mkdir(parents=True)
        for k, n in enumerate(names):
            (folder / sub / f"{n:05d}.png").write_bytes((seq / sub / f"{k:05d}.png").read_bytes())
    return folder


def _log(path: Path, blocks: list[tuple[int, str]]) -> Path:
    path.write_text("".join(f"{i} {i + 1} {len(blocks)}\n{m}" for i, m in blocks))
    return path


def test_frames_get_the_pose_of_their_number(tmp_path):
    seq = write_sequence(tmp_path / "seq", 3)
    text = (seq / "trajectory.log").read_text().splitlines()
    matrix = ["\n".join(text[5 * k + 1:5 * k + 5]) + "\n" for k in range(3)]
    gaps = _renamed(seq, tmp_path / "gaps", [0, 2, 4])
    # Poses numbered 0, 1, 2 for images 0, 2, 4: refused, naming the way out.
    with pytest.raises(sogmm.InvalidDataError, match=r"no pose of frame 4 .*--pair-by-order"):
        load_frames(str(gaps), str(seq / "trajectory.log"))
    by_order = load_frames(str(gaps), str(seq / "trajectory.log"), pair_by_order=True)
    # Numbered 0, 2, 4 in the order 4, 0, 2: each image gets its own pose.
    shuffled = _log(tmp_path / "shuffled.log", [(4, matrix[2]), (0, matrix[0]), (2, matrix[1])])
    by_number = load_frames(str(gaps), str(shuffled))
    assert [f.pose for f in by_number] == [f.pose for f in by_order]
    assert [Path(f.depth).name for f in by_number] == ["00000.png", "00002.png", "00004.png"]
    # Two poses for one frame, or a name that is no number: refused.
    with pytest.raises(sogmm.InvalidDataError, match="two poses of frame 0"):
        load_frames(str(gaps), str(_log(tmp_path / "dup.log", [(0, matrix[0]), (0, matrix[1]), (4, matrix[2])])))
    (gaps / "color" / "00004.png").rename(gaps / "color" / "last.png")
    with pytest.raises(sogmm.InvalidDataError, match="last.png: the name is not a frame number"):
        load_frames(str(gaps), str(shuffled))


def _one_line_run(args: list[str], env: dict | None = None, timeout: float = 60) -> subprocess.CompletedProcess:
    p = subprocess.run([sys.executable, "-m", "sogmm_ray"] + args, capture_output=True, text=True,
                       timeout=timeout, env=env)
    assert p.returncode == 1, p.stderr
    assert p.stderr.count("\n") == 1 and p.stderr.startswith("sogmm_ray: "), p.stderr
    return p


def test_a_fifo_input_is_refused_at_once(tmp_path):
    seq = write_sequence(tmp_path / "seq", 3)
    fifo = tmp_path / "in.fifo"
    os.mkfifo(fifo)
    base = ["--sequence", str(seq), "-o", str(tmp_path / "m.sogmm"), "--address", "127.0.0.1:1"]
    # A blocked open would hang: the timeout turns that into a failure.
    p = _one_line_run(base + ["--trajectory", str(fifo)], timeout=60)
    assert "FIFO" in p.stderr
    p = _one_line_run(base + ["--trajectory", str(seq / "trajectory.log"), "--intrinsics", str(fifo)], timeout=60)
    assert "FIFO" in p.stderr


def test_the_output_is_checked_before_the_run(tmp_path):
    seq = write_sequence(tmp_path / "seq", 3)
    traj = seq / "trajectory.log"
    before = traj.read_bytes()
    # No cluster at this address: a run would fail to connect, after the check.
    base = ["--sequence", str(seq), "--trajectory", str(traj), "--address", "127.0.0.1:1"]
    p = _one_line_run(base + ["-o", str(traj)])
    assert "is also the input --trajectory" in p.stderr
    assert traj.read_bytes() == before
    fifo = tmp_path / "out.fifo"
    os.mkfifo(fifo)
    p = _one_line_run(base + ["-o", str(fifo)])
    assert "FIFO" in p.stderr
    folder = "/sys" if os.geteuid() == 0 else str(tmp_path / "ro")
    if folder != "/sys":
        os.mkdir(folder, 0o555)
    p = _one_line_run(base + ["-o", os.path.join(folder, "m.sogmm")])
    assert f"cannot write in folder {folder}" in p.stderr
