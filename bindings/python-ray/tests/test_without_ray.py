"""`python -m sogmm_ray` where Ray is not importable (Python 3.13, or sogmm-ray
installed without its dependencies): one line on stderr naming the fix, exit
status 1, no traceback; whatever the arguments, as nothing runs without Ray.
Runs with or without Ray: a `ray` package that fails to import shadows the
real one."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

import sogmm
import sogmm_ray

from conftest import write_sequence


@pytest.fixture
def env_without_ray(tmp_path) -> dict:
    fake = tmp_path / "noray" / "ray"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("raise ImportError(\"No module named 'ray'\")\n")
    # The packages under test, after the fake ray.
    src = [str(Path(m.__file__).resolve().parents[1]) for m in (sogmm, sogmm_ray)]
    return dict(os.environ, PYTHONPATH=os.pathsep.join([str(fake.parent), *src, os.environ.get("PYTHONPATH", "")]))


@pytest.mark.parametrize("with_args", [False, True])
def test_one_line_and_exit_1(tmp_path, env_without_ray, with_args):
    args = []
    if with_args:
        seq = write_sequence(tmp_path / "seq", 3)
        args = ["--sequence", str(seq), "--trajectory", str(seq / "trajectory.log"), "-o", str(tmp_path / "m.sogmm")]
    p = subprocess.run([sys.executable, "-m", "sogmm_ray", *args], capture_output=True, text=True, timeout=60,
                       env=env_without_ray)
    assert p.returncode == 1, p.stderr
    assert p.stderr == "sogmm_ray: Ray is not installed: pip install 'sogmm[ray]' (Ray 2.40.0: Python 3.9 to 3.12)\n"
    assert p.stdout == ""
    assert not (tmp_path / "m.sogmm").exists()
