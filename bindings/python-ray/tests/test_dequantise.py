"""FitSettings.dequantise_depth (the CLI's --dequantise-depth) reaches the fit:
a frame fitted by fit_frame, and a tile map built by MapSettings.new_map, equal
bit for bit what SOGMM / Map give with dequantise_depth=True, and differ from
the plain fit (dequantise_depth=False; None, the default, floors frames
too). The frame is a staircase of 8 fronto-parallel steps 10 cm apart
(exact depth levels, so the quantisation is detected and the flat steps'
variances along the rays are floored). No Ray cluster is needed."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import sogmm
from sogmm_ray import FitSettings, Frame, MapSettings
from sogmm_ray import __main__ as cli
from sogmm_ray.frame_fit import camera_dict, fit_frame, read_images

from conftest import NO_RAY

PLAIN = FitSettings(bandwidth=0.05, decimate=2, seed=3, dequantise_depth=False)
DEQ = dataclasses.replace(PLAIN, dequantise_depth=True)


def _same(a: sogmm.GMM, b: sogmm.GMM) -> bool:
    return all(getattr(a, n).tobytes() == getattr(b, n).tobytes() for n in ("weights_", "means_", "covariances_"))


def _staircase(folder):
    Image = pytest.importorskip("PIL.Image", reason="Pillow is not installed")
    width, height = 96, 72
    v, u = np.mgrid[0:height, 0:width]
    depth = (1000 + 100 * (u // 12)).astype(np.uint16)
    gray = (60 + 2 * u + v).astype(np.uint8)
    Image.fromarray(depth).save(folder / "d.png")
    Image.fromarray(gray).save(folder / "c.png")
    cam = sogmm.Camera(width, height, 77.0, 77.0, (width - 1) / 2, (height - 1) / 2)
    return Frame(0, str(folder / "d.png"), str(folder / "c.png"), tuple(np.eye(4).ravel())), cam


def test_fit_frame_fits_with_dequantised_depth(tmp_path):
    frame, cam = _staircase(tmp_path)
    depth, color = read_images(frame)
    direct = sogmm.SOGMM(bandwidth=0.05, seed=3, n_threads=1, dequantise_depth=True).fit_rgbd(depth, color, cam,
                                                                                             decimate=2)
    direct = direct.transform(np.asarray(frame.pose).reshape(4, 4))
    models = {}
    for s in (PLAIN, DEQ):
        info, part = fit_frame(frame, s, camera_dict(cam))
        assert info["error"] is None
        models[s.dequantise_depth] = sogmm.from_bytes(part["model"])
    assert _same(models[True], direct)
    assert not _same(models[False], direct)


def test_new_map_fits_with_dequantised_depth(tmp_path):
    frame, cam = _staircase(tmp_path)
    depth, color = read_images(frame)
    pose = np.asarray(frame.pose).reshape(4, 4)
    ms = MapSettings(batch_size=1000)

    def build(m: sogmm.Map) -> sogmm.GMM:
        m.insert_rgbd(depth, color, cam, pose)
        m.flush()
        return m.export()

    direct = build(sogmm.Map(batch_size=1000, decimate=2, bandwidth=0.05, seed=3, n_threads=1, dequantise_depth=True))
    assert _same(build(ms.new_map(DEQ)), direct)
    assert not _same(build(ms.new_map(PLAIN)), direct)


def test_the_command_line_flag_sets_it(monkeypatch, sequence, tmp_path):
    pytest.importorskip("ray", reason=NO_RAY)  # the command line asks for Ray first
    seen = []

    def fake_build_map(frames, settings, camera, **kw):
        seen.append(settings)
        raise sogmm.SogmmError("stop here")

    monkeypatch.setattr(cli, "build_map", fake_build_map)
    args = ["--sequence", str(sequence), "--trajectory", str(sequence / "trajectory.log"), "-o", str(tmp_path / "o"),
            "-q"]
    assert cli.main(args) == 1 and cli.main(args + ["--dequantise-depth"]) == 1
    assert cli.main(args + ["--no-dequantise-depth"]) == 1
    assert [s.dequantise_depth for s in seen] == [None, True, False]
