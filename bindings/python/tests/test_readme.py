"""The README's example runs as written: every ```python block of
bindings/python/README.md, in order and in one namespace, from a folder where
`livingroom` is the shared livingroom sequence (../shared/data/rgbd); then
what it wrote is checked against the files' own content and the trajectory's
numbers. Skips, saying why, without the frames, Pillow (extra `examples`) or
tqdm (extra `progress`)."""

from __future__ import annotations

import re

import numpy as np
import pytest

import sogmm

from conftest import REPO_ROOT, data_dir

README = REPO_ROOT / "bindings" / "python" / "README.md"

# Frame 2 of livingroom/trajectory.log, its first row, as printed in the file.
FRAME_2_ROW_0 = [-0.26535185454036697, 0.04522708142999141, -0.9630902888085378, -0.3097373196756845]


def python_blocks(text: str) -> list[str]:
    return re.findall(r"^```python\n(.*?)^```$", text, flags=re.S | re.M)


def test_the_readme_has_one_example_that_reads_fits_saves_and_maps():
    blocks = python_blocks(README.read_text())
    assert len(blocks) == 1
    for call in ("read_frame(", "fit_rgbd", ".save(", "sogmm.Map(", "insert_rgbd", "trajectory.log"):
        assert call in blocks[0], call


def test_the_readme_example_runs_as_written(tmp_path, monkeypatch, capsys):
    folder = data_dir() / "rgbd" / "livingroom"
    if not (folder / "trajectory.log").is_file():
        pytest.skip(f"the livingroom sequence is not at {folder} (../shared/data is absent)")
    pytest.importorskip("tqdm", reason="tqdm (the extra `progress`) is not installed")
    (tmp_path / "livingroom").symlink_to(folder)
    monkeypatch.chdir(tmp_path)
    ns: dict = {"__name__": "__readme__"}
    for k, block in enumerate(python_blocks(README.read_text())):
        exec(compile(block, f"{README}: python block {k + 1}", "exec"), ns)
    out = capsys.readouterr()
    assert "EM" in out.err  # progress=True drew its bars

    model = ns["model"]
    assert model.n_components_ > 0 and np.isfinite(model.lower_bound_)
    saved = sogmm.load(tmp_path / "frame0.sogmm")
    for name in ("weights_", "means_", "covariances_"):
        assert getattr(saved, name).tobytes() == getattr(model, name).tobytes(), name
    assert len(sogmm.read_ply(tmp_path / "samples.ply")) == 10_000

    world = sogmm.Map.load(tmp_path / "map.sogmm")
    assert len(world) == 3 and world.n_components_ > 0
    pose = world.frame_stats(2)["pose"]
    np.testing.assert_allclose(pose[0], FRAME_2_ROW_0, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(pose[3], [0, 0, 0, 1])
