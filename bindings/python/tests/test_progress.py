"""fit(progress=...) and Ctrl-C: reports, cancel by the callable, exceptions
and SIGINT (KeyboardInterrupt) during a long fit."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import sogmm
from sogmm.progress import STAGE_EM, STAGE_MODE_COUNT, STAGE_SEEDING

from conftest import blobs, data_dir


def cube(n=4000, seed=1):
    return np.random.default_rng(seed).random((n, 4), dtype=np.float32)


def fixed_k(**kw):
    params = dict(n_components=8, tol=1e-12, max_iter=25, seed=5, n_threads=2)
    params.update(kw)
    return sogmm.SOGMM(**params)


def test_reports_stages_and_em_iterations_and_change_nothing():
    seen = []
    g = sogmm.SOGMM(bandwidth=0.08, seed=3).fit(blobs(), progress=lambda *r: seen.append(r))
    plain = sogmm.SOGMM(bandwidth=0.08, seed=3).fit(blobs())
    np.testing.assert_array_equal(g.means_, plain.means_)
    np.testing.assert_array_equal(g.covariances_, plain.covariances_)
    stages = [r[0] for r in seen]
    assert stages[0] == STAGE_MODE_COUNT and STAGE_SEEDING in stages and stages[-1] == STAGE_EM
    em = [r for r in seen if r[0] == STAGE_EM]
    steps = [r[1] for r in em]
    assert steps == sorted(steps), "EM steps decrease"
    assert sorted(set(steps)) == list(range(g.n_iter_ + 1)), "every EM iteration is reported"
    assert all(r[2] == 100 for r in em), "total = max_iter"
    assert em[-1][3] == g.lower_bound_


def test_truthy_return_cancels_and_leaves_the_estimator_unfitted():
    est = fixed_k()
    calls = []

    def stop_at_em_2(stage, step, total, ll):
        calls.append((stage, step))
        return stage == STAGE_EM and step == 2

    with pytest.raises(sogmm.CancelledError, match="EM iteration 2") as e:
        est.fit(cube(), progress=stop_at_em_2)
    assert e.value.status == -12
    assert calls[-1] == (STAGE_EM, 2), "no report after the cancel"
    with pytest.raises(sogmm.NotFittedError):
        est.means_
    # The same estimator fits normally afterwards.
    assert est.fit(cube()).n_components_ == 8


def test_an_exception_in_the_callable_cancels_and_is_raised():
    def boom(stage, step, total, ll):
        if stage == STAGE_EM and step >= 1:
            raise ValueError("boom")

    with pytest.raises(ValueError, match="boom"):
        fixed_k().fit(cube(), progress=boom)


def test_progress_true_draws_a_tqdm_bar(capsys):
    pytest.importorskip("tqdm")
    g = fixed_k().fit(cube(), progress=True)
    assert g.n_components_ == 8
    assert "EM" in capsys.readouterr().err


def test_progress_true_without_tqdm_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)  # import tqdm.auto now fails, as when not installed
    est = fixed_k()
    with pytest.raises(ImportError, match=r"pip install 'sogmm\[progress\]'"):
        est.fit(cube(), progress=True)
    with pytest.raises(sogmm.NotFittedError):
        est.means_


def test_progress_must_be_none_true_or_callable():
    with pytest.raises(TypeError, match="progress"):
        fixed_k().fit(cube(), progress="yes")


# The child fits a full frame at d = 1 (the shared livingroom frame when
# present, else a synthetic cloud of the same size) with EM that does not stop
# early, prints "started" just before the fit and reports how the fit ended.
CHILD = textwrap.dedent(
    """
    import sys
    import numpy as np
    import sogmm
    frame = sys.argv[1]
    if frame:
        from PIL import Image
        depth = np.asarray(Image.open(frame + "/depth/00000.png"))
        color = np.asarray(Image.open(frame + "/color/00000.jpg").convert("RGB"))
        pts = sogmm.rgbd_to_points(depth, color, sogmm.Camera.from_json(frame + "/intrinsics.json"))
    else:
        pts = np.random.default_rng(0).random((300000, 4), dtype=np.float32)
    est = sogmm.SOGMM(n_components=400, tol=1e-300, max_iter=500, seed=1)
    print("started", flush=True)
    try:
        est.fit(pts)
        print("fit finished", flush=True)
    except KeyboardInterrupt:
        print("KeyboardInterrupt", flush=True)
    # The library is usable after the interrupt.
    print("after", sogmm.SOGMM(n_components=2, seed=1).fit(pts[:1000]).n_components_, flush=True)
    """
)


def test_ctrl_c_cancels_a_long_fit_with_keyboard_interrupt():
    frame = data_dir() / "rgbd" / "livingroom"
    use_frame = (frame / "depth" / "00000.png").is_file()
    if use_frame:
        pytest.importorskip("PIL")
    env = dict(os.environ)
    package_root = str(Path(sogmm.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join([package_root, env.get("PYTHONPATH", "")])
    child = subprocess.Popen([sys.executable, "-c", CHILD, str(frame) if use_frame else ""], env=env,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert child.stdout.readline().strip() == "started"
        # SIGINT about 1 s into the fit (the fit itself runs minutes).
        try:
            child.wait(timeout=1.0)
        except subprocess.TimeoutExpired:
            pass
        child.send_signal(signal.SIGINT)
        out, err = child.communicate()
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
    lines = out.split()
    assert "KeyboardInterrupt" in out, (out, err)
    assert "fit finished" not in out
    assert "after 2" in " ".join(lines), (out, err)
    assert child.returncode == 0, err
