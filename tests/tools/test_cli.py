#!/usr/bin/env python3
"""End-to-end tests of the `sogmm` command-line tool.

Usage: test_cli.py --sogmm PATH --data SHARED_DATA_DIR --mode MODE
Modes:
  help       --help of the tool and of every subcommand (exit 0, an example)
  errors     documented exit codes (2 usage, 3 invalid data, 4 I/O), one-line
             messages naming the file, atomic writes
  synthetic  fit / eval / render / sample on the synthetic frame written by
             `sogmm demo --write-frame` (no external data needed)
  sequence   fit --sequence / eval --sequence / render --trajectory on a
             3-frame synthetic sequence; support size = sum of frame points
  map        sogmm map on a 16-frame room loop (demo --loop): CSV, plot,
             fewer components than fit --sequence, eval, bad input
  shared     the same on ../shared/data/rgbd (prints "SKIP: ..." and exits 0
             only when that folder is absent)
Checks parse the PNG (chunks, zlib stream, scanline filters) and PLY (header
and binary body) outputs themselves. Exit 0 = pass, 1 = failure.
"""
import argparse
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import zlib

import numpy as np

SOGMM = None
FAILURES = []


def check(cond, what):
    if not cond:
        FAILURES.append(what)
        print("FAIL:", what)
    return cond


def run(args, expect=0, env=None):
    p = subprocess.run([SOGMM] + [str(a) for a in args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       text=True, env=env, timeout=120)
    check(p.returncode == expect,
          "sogmm %s: exit %d, expected %d\nstdout: %s\nstderr: %s" %
          (" ".join(map(str, args)), p.returncode, expect, p.stdout[-2000:], p.stderr[-2000:]))
    return p


def run_json(args, with_stderr=False):
    p = run(list(args) + ["--json"])
    try:
        j = json.loads(p.stdout)
    except ValueError:
        check(False, "sogmm %s: stdout is not JSON: %r" % (" ".join(map(str, args)), p.stdout[:500]))
        j = {}
    return (j, p.stderr) if with_stderr else j


# ---------------------------------------------------------------- PNG / PLY
def read_png(path):
    """Decodes a non-interlaced 8/16-bit gray/RGB/RGBA PNG. Returns an array
    (h, w) or (h, w, c)."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "%s: not a PNG" % path
    pos, idat, ihdr = 8, b"", None
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + n]
        (crc,) = struct.unpack(">I", data[pos + 8 + n:pos + 12 + n])
        assert zlib.crc32(kind + body) & 0xFFFFFFFF == crc, "%s: bad CRC in %s" % (path, kind)
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        elif kind == b"IEND":
            break
        pos += 12 + n
    w, h, bits, ctype, _, _, interlace = ihdr
    assert interlace == 0 and bits in (8, 16)
    channels = {0: 1, 2: 3, 4: 2, 6: 4}[ctype]
    bpp = channels * bits // 8
    raw = zlib.decompress(idat)
    stride = w * bpp
    assert len(raw) == h * (stride + 1), "%s: %d bytes of pixel data, expected %d" % (path, len(raw), h * (stride + 1))
    out = np.zeros((h, stride), dtype=np.uint8)
    prev = np.zeros(stride, dtype=np.int32)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = np.frombuffer(raw, dtype=np.uint8, count=stride, offset=y * (stride + 1) + 1).astype(np.int32)
        if f == 0:
            cur = line
        elif f == 2:
            cur = (line + prev) & 0xFF
        else:
            cur = np.zeros(stride, dtype=np.int32)
            for x in range(stride):
                a = cur[x - bpp] if x >= bpp else 0
                b = prev[x]
                c = prev[x - bpp] if x >= bpp else 0
                if f == 1:
                    pred = a
                elif f == 3:
                    pred = (a + b) // 2
                else:
                    p = a + b - c
                    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                    pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                cur[x] = (line[x] + pred) & 0xFF
        out[y] = cur
        prev = cur
    if bits == 16:
        img = out.reshape(h, w * channels, 2)
        img = (img[:, :, 0].astype(np.uint16) << 8) | img[:, :, 1]
    else:
        img = out
    return img.reshape(h, w, channels) if channels > 1 else img.reshape(h, w)


def png_size(path):
    data = open(path, "rb").read(33)
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "%s: not a PNG" % path
    w, h, bits, ctype = struct.unpack(">IIBB", data[16:26])
    return w, h, {0: 1, 2: 3, 4: 2, 6: 4}[ctype], bits


def read_ply(path):
    """Parses a binary little-endian PLY: returns (elements, comments) with
    elements = [(name, count, properties, data)]."""
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    lines = data[:end].decode("ascii").splitlines()
    assert lines[0] == "ply", "%s: no ply magic" % path
    assert lines[1] == "format binary_little_endian 1.0", "%s: %s" % (path, lines[1])
    elements = []
    for ln in lines[2:]:
        t = ln.split()
        if t[0] == "element":
            elements.append([t[1], int(t[2]), []])
        elif t[0] == "property":
            elements[-1][2].append(tuple(t[1:]))
    types = {"float": "<f4", "uchar": "u1", "int": "<i4", "uint": "<u4", "double": "<f8"}
    pos, parsed = end, []
    for name, count, props in elements:
        if any(p[0] == "list" for p in props):
            assert len(props) == 1 and props[0][:3] == ("list", "uchar", "int")
            dt = np.dtype([("n", "u1"), ("idx", "<i4", (3,))])
            arr = np.frombuffer(data, dtype=dt, count=count, offset=pos)
            assert (arr["n"] == 3).all(), "%s: non-triangle face" % path
        else:
            dt = np.dtype([(p[1], types[p[0]]) for p in props])
            arr = np.frombuffer(data, dtype=dt, count=count, offset=pos)
        pos += dt.itemsize * count
        parsed.append((name, count, props, arr))
    assert pos == len(data), "%s: %d bytes after the body, expected none" % (path, len(data) - pos)
    return parsed


def no_temp_files(folder):
    left = [f for f in os.listdir(folder) if ".tmp" in f]
    check(not left, "temporary files left in %s: %s" % (folder, left))


# ---------------------------------------------------------------- modes
def mode_help(tmp):
    p = run(["--help"])
    check("Exit codes" in p.stdout and "Example" in p.stdout, "sogmm --help lacks exit codes or an example")
    for sub in ["demo", "eval", "fit", "map", "render", "sample"]:
        p = run([sub, "--help"])
        check("Example" in p.stdout, "sogmm %s --help has no example" % sub)
    run(["--version"])


def write_synthetic(tmp, frames):
    d = os.path.join(tmp, "synth")
    p = run(["demo", "--write-frame", d, "--frames", frames])
    check("Wrote" in p.stdout, "demo --write-frame prints nothing")
    depth = read_png(os.path.join(d, "depth", "00000.png"))  # full decode of the first frame only (slow in Python)
    check(depth.shape == (480, 640) and depth.dtype == np.uint16, "synthetic depth shape %s" % (depth.shape,))
    check(depth.min() > 500 and depth.max() < 4000, "synthetic depth range %d..%d mm" % (depth.min(), depth.max()))
    for k in range(frames):
        check(png_size(os.path.join(d, "depth", "%05d.png" % k)) == (640, 480, 1, 16), "synthetic depth %d" % k)
        check(png_size(os.path.join(d, "color", "%05d.png" % k)) == (640, 480, 1, 8), "synthetic color %d" % k)
    cam = json.load(open(os.path.join(d, "intrinsics.json")))
    check(cam["width"] == 640 and cam["intrinsic_matrix"][0] == 525.0, "synthetic intrinsics.json")
    return d


def frame_args(d, k, ext):
    return ["--depth", os.path.join(d, "depth", "%05d.png" % k), "--color", os.path.join(d, "color", "%05d.%s" % (k, ext))]


def exercise_frame(tmp, d, ext, dec, bandwidth, extra_camera, expect_w, expect_h, min_psnr):
    """fit -> eval (saved and refit) -> render (3 kinds + compare) -> sample."""
    model = os.path.join(tmp, "m.sogmm")
    fargs = frame_args(d, 0, ext)
    fit, progress = run_json(["fit"] + fargs + extra_camera + ["--decimate", dec, "--bandwidth", bandwidth, "-o", model,
                              "--progress"], with_stderr=True)
    check("mode count" in progress and "EM done" in progress, "fit --progress lines: %r" % progress)
    m, n = fit.get("n_components", 0), fit.get("n_points", 0)
    check(m >= 1 and n > m, "fit: %d components for %d points" % (m, n))
    check(fit.get("support_size") == n, "fit: support size %s != points %s" % (fit.get("support_size"), n))
    check(fit.get("file_bytes", 0) == os.path.getsize(model), "fit: file_bytes differs from the file size")
    check(fit.get("seconds_total", -1) >= 0 and fit.get("em_iterations", 0) >= 1, "fit: timings/iterations")
    # Human summary paragraph, no progress with --quiet.
    p = run(["fit"] + fargs + extra_camera + ["--decimate", dec, "--bandwidth", bandwidth, "-o", model, "--quiet"])
    check(p.stdout.startswith("Fitted %d points" % n) and "bytes per component" in p.stdout,
          "fit summary paragraph: %r" % p.stdout)
    check(p.stderr == "", "fit --quiet wrote to stderr: %r" % p.stderr)
    no_temp_files(tmp)

    # eval of the saved model (camera and decimation from the file) == eval with a fresh fit.
    ev = run_json(["eval", model] + fargs)
    check(ev.get("n_points") == n and ev.get("n_components") == m, "eval MODEL: points/components %s" % ev)
    check(ev.get("psnr", 0) > min_psnr, "eval MODEL: PSNR %.2f <= %.1f" % (ev.get("psnr", 0), min_psnr))
    check(0 <= ev.get("fscore", -1) <= 1 and ev.get("mre", 1) < 0.05, "eval MODEL: fscore/mre %s" % ev)
    ref = run_json(["eval"] + fargs + extra_camera + ["--decimate", dec, "--bandwidth", bandwidth])
    check(abs(ref.get("psnr", 0) - ev.get("psnr", 1)) < 1e-9 and ref.get("n_components") == m,
          "eval MODEL (%.6f) differs from eval --bandwidth (%.6f)" % (ev.get("psnr", 0), ref.get("psnr", 0)))
    p = run(["eval", model] + fargs)
    check("PSNR (honest)" in p.stdout and "F-score" in p.stdout, "eval MODEL human output")
    check("MRE (mass-weighted)" in p.stdout and "held-out (d = %d minus d = %d)" % (dec + 1, dec) in p.stdout,
          "eval MODEL human output: mass-weighted labels and per-pixel rows: %r" % p.stdout)
    # The bandwidth as typed (6 significant digits), not the double's 17.
    check("bandwidth %s)" % ("%.6g" % bandwidth) in p.stdout, "eval MODEL bandwidth: %r" % p.stdout)
    # Per-pixel figures (issue 29): the model rendered from the frame's camera. A frame's own fit shows
    # the surface it was fitted on, on the fitting grid and on the held-out grid (d + 1 minus d) alike:
    # the coarse fits here (d = 10; 68 components on the synthetic frame, 9 cm depth MAE) stay within
    # 20 cm on average, with few empty pixels; the same model gives the same figures whether it was
    # saved first or not. Per-pixel PSNR sits below the honest PSNR (the first surface along a ray
    # that grazes a nearer object's silhouette has that object's gray): livingroom at d = 8,
    # bandwidth 0.04, 18.4 dB fitting grid / 18.0 held out against an honest 26.7, so the bound
    # is min_psnr - 6.
    for key in ("", "_heldout"):
        mae, empty, pix = ev.get("depth_mae" + key), ev.get("empty_share" + key), ev.get("pixel_psnr" + key)
        check(mae is not None and 0 <= mae < 0.2 and empty is not None and 0 <= empty < 0.2 and
              pix is not None and pix > min_psnr - 6, "eval MODEL per-pixel figures%s: %s" % (key, ev))
        check(ref.get("depth_mae" + key) == mae and ref.get("pixel_psnr" + key) == pix,
              "eval --bandwidth per-pixel figures%s differ from eval MODEL: %s vs %s" % (key, ref, ev))
    check(ev.get("heldout_decimate") == dec + 1 and 0 < ev.get("n_pixels_heldout", 0) and
          0 < ev.get("n_pixels", 0) <= n, "eval MODEL grids: %s" % ev)
    ll, llh = ev.get("log_likelihood_fit_grid"), ev.get("log_likelihood_heldout")
    check(ll is not None and llh is not None and math.isfinite(ll) and math.isfinite(llh) and llh < ll + 1.0,
          "eval MODEL log-likelihoods: fit grid %s, held out %s" % (ll, llh))
    check(ref.get("log_likelihood_heldout") == llh and "log_likelihood" in ref, "eval --bandwidth held-out LL: %s" % ref)
    # --data-range R: the honest PSNR is 10 log10(R^2 / MSE), so R = 2 adds 20 log10 2 dB; the
    # paper-compatible figure keeps the authors' range 2 whatever R is.
    ev2 = run_json(["eval", model] + fargs + ["--data-range", 2])
    check(ev.get("psnr_data_range") == 1 and ev2.get("psnr_data_range") == 2, "eval --data-range: %s" % ev2)
    check(abs(ev2.get("psnr", 0) - ev.get("psnr", 0) - 20 * math.log10(2)) < 1e-9 and
          ev2.get("psnr_paper") == ev.get("psnr_paper"), "eval --data-range 2: %s vs %s" % (ev2, ev))
    # --surface-sigma S only rejects modes (a pixel shown at S = 2 shows a mode that S = 0 also
    # finds, and a pixel empty at S = 0 has no mode at all): never fewer empty pixels, the same
    # observed pixels, the mass-weighted figures untouched; S < 0 is a usage error.
    ev3 = run_json(["eval", model] + fargs + ["--surface-sigma", 2])
    for key in ("", "_heldout"):
        check(ev3.get("empty_share" + key, -1) >= ev.get("empty_share" + key, 2) and
              ev3.get("n_pixels" + key) == ev.get("n_pixels" + key), "eval --surface-sigma 2%s: %s vs %s" % (key, ev3, ev))
    check(ev3.get("psnr") == ev.get("psnr") and ev3.get("mre") == ev.get("mre"), "eval --surface-sigma 2 moved MRE/PSNR")
    p = run(["eval", model] + fargs + ["--surface-sigma", -1], expect=2)
    check("--surface-sigma" in p.stderr, "eval --surface-sigma -1: %r" % p.stderr)
    # --n-init: the kept run is the best, and a single fit with its seed is the same model.
    best = run_json(["eval"] + fargs + extra_camera + ["--decimate", dec, "--bandwidth", bandwidth, "--seed", 5,
                                                       "--n-init", 3])
    lls, kept = best.get("run_log_likelihoods", []), best.get("run", -1)
    check(best.get("n_init") == 3 and len(lls) == 3 and 0 <= kept < 3, "eval --n-init 3: %s" % best)
    if check(len(lls) == 3 and 0 <= kept < 3, "eval --n-init 3 runs"):
        check(best.get("log_likelihood") == max(lls) and lls.index(max(lls)) == kept, "eval --n-init kept %s" % best)
        one = run_json(["eval"] + fargs + extra_camera + ["--decimate", dec, "--bandwidth", bandwidth, "--seed",
                                                          5 + kept])
        check(one.get("log_likelihood") == best.get("log_likelihood") and one.get("psnr") == best.get("psnr"),
              "eval --seed %d differs from the kept run of --n-init 3" % (5 + kept))

    # render: expected surface, at the ground-truth depth, uncertainty, compare.
    out = os.path.join(tmp, "r.png")
    run(["render", model, "-o", out])
    img = read_png(out)
    check(img.shape == (expect_h, expect_w), "render: %s, expected %dx%d" % (img.shape, expect_w, expect_h))
    check((img > 0).mean() > 0.6, "render: only %.2f of the pixels show the surface" % (img > 0).mean())
    run(["render", model, "-o", out, "--surface-sigma", 2])
    strict = read_png(out)
    # Empty pixels are black; S = 2 only rejects modes, so it shows no more pixels than S = 0.
    check(strict.shape == img.shape and 0 < (strict > 0).sum() <= (img > 0).sum(),
          "render --surface-sigma 2: %d shown pixels against %d at S = 0" % ((strict > 0).sum(), (img > 0).sum()))
    run(["render", model, "-o", out, "--scale", "2"])
    check(png_size(out)[:2] == (2 * expect_w, 2 * expect_h), "render --scale 2 size %s" % (png_size(out),))
    run(["render", model, "-o", out, "--depth", fargs[1]])
    gt = read_png(out)
    check(gt.shape == (expect_h, expect_w), "render --depth: %s" % (gt.shape,))
    run(["render", model, "-o", out, "--uncertainty"])
    w, h, c, _ = png_size(out)
    check(c == 3 and w > expect_w and h > expect_h, "render --uncertainty size %dx%dx%d" % (w, h, c))
    read_png(out)
    p = run(["render", model, "--compare"] + fargs + ["-o", out])
    w, h, c, _ = png_size(out)
    scale = max(1, -(-320 // expect_w))
    check(c == 3 and w >= 3 * expect_w * scale and h >= expect_h * scale, "render --compare size %dx%d" % (w, h))
    check("PSNR %.2f dB" % ev.get("psnr", 0) in p.stdout, "render --compare PSNR differs from eval: %r" % p.stdout)
    no_temp_files(tmp)

    # sample + ellipsoids.
    ply, ell = os.path.join(tmp, "s.ply"), os.path.join(tmp, "e.ply")
    run(["sample", model, "-n", 5000, "--seed", 3, "-o", ply, "--ellipsoids", ell])
    (name, count, props, v), = read_ply(ply)
    check(name == "vertex" and count == 5000, "sample: %s x %d" % (name, count))
    check([p[1] for p in props] == ["x", "y", "z", "intensity", "red", "green", "blue"] and
          [p[0] for p in props] == ["float"] * 4 + ["uchar"] * 3, "sample: properties %s" % props)
    xyz = np.stack([v["x"], v["y"], v["z"]], 1)
    check(np.isfinite(xyz).all() and np.isfinite(v["intensity"]).all(), "sample: non-finite values")
    check((v["red"] == v["green"]).all() and (v["green"] == v["blue"]).all(), "sample: color is not gray")
    expect_red = np.clip(np.round(np.clip(v["intensity"], 0, 1) * 255), 0, 255)
    check(np.abs(expect_red - v["red"]).max() <= 1, "sample: red != 255 * clamp(intensity)")
    check(np.median(v["z"]) > 0.3 and np.median(v["z"]) < 3.5, "sample: median depth %.2f" % np.median(v["z"]))
    verts, faces = read_ply(ell)
    check(verts[1] == 42 * m and faces[1] == 80 * m, "ellipsoids: %d vertices, %d faces for %d components" %
          (verts[1], faces[1], m))
    check(faces[3]["idx"].min() >= 0 and faces[3]["idx"].max() < verts[1], "ellipsoids: face index out of range")
    first = open(ply, "rb").read()
    run(["sample", model, "-n", 5000, "--seed", 3, "-o", ply])
    check(open(ply, "rb").read() == first, "sample: same seed, different file")
    run(["sample", model, "-n", 5000, "--seed", 4, "-o", ply])
    check(open(ply, "rb").read() != first, "sample: different seed, same file")
    run(["sample", model, "-o", ply])
    check(read_ply(ply)[0][1] == n, "sample without -n: not the support size %d" % n)
    no_temp_files(tmp)
    return model


def exercise_sequence(tmp, d, ext, frames, dec, bandwidth, extra, human):
    seq = os.path.join(tmp, "seq.sogmm")
    traj = os.path.join(d, "trajectory.log")
    fit, progress = run_json(["fit", "--sequence", d, "--trajectory", traj, "--frames", "0:%d" % frames, "--decimate",
                              dec, "--bandwidth", bandwidth, "-o", seq, "--progress"] + extra, with_stderr=True)
    check(progress.count("; map ") == frames, "fit --sequence: one progress line per frame expected: %r" % progress)
    per = fit.get("frames", [])
    check(len(per) == frames, "fit --sequence: %d frames reported" % len(per))
    check(fit.get("support_size") == sum(f["n_points"] for f in per),
          "fit --sequence: support size %s != sum of frame points %s" %
          (fit.get("support_size"), [f["n_points"] for f in per]))
    check(fit.get("n_components") == sum(f["n_components"] for f in per), "fit --sequence: merged M != sum of M")
    ev = run_json(["eval", seq, "--sequence", d, "--trajectory", traj, "--frames", "0:%d" % frames])
    rows = ev.get("frames", [])
    check(len(rows) == frames, "eval --sequence: %d rows" % len(rows))
    check(ev.get("support_size") == sum(r["n_points"] for r in rows),
          "eval --sequence: support size %s != sum of frame points %s" %
          (ev.get("support_size"), [r["n_points"] for r in rows]))
    # Each frame scores about as well as a model fitted on that frame alone
    # (a wrong or missing pose would put the map metres away: F-score ~ 0).
    intr = extra if extra else ["--intrinsics", os.path.join(d, "intrinsics.json")]
    for r in rows:
        k = r["frame"]
        single = run_json(["eval"] + frame_args(d, k, ext) + intr + ["--decimate", dec, "--bandwidth", bandwidth])
        check(r["n_points"] == single.get("n_points"), "eval --sequence frame %d: %d points, single fit %s" %
              (k, r["n_points"], single.get("n_points")))
        check(r["psnr"] > single.get("psnr", 0) - 2.0 and r["n_samples"] > 0 and
              r["fscore"] > 0.6 * single.get("fscore", 0) and r["fscore"] > 0.05,
              "eval --sequence frame %d: PSNR %.2f, F %.3f vs single-frame fit PSNR %.2f, F %.3f (pose applied wrongly?)"
              % (k, r["psnr"], r["fscore"], single.get("psnr", 0), single.get("fscore", 0)))
    if human:
        p = run(["eval", seq, "--sequence", d, "--trajectory", traj, "--frames", "0:%d" % frames])
        check("mean" in p.stdout, "eval --sequence table has no mean row")
    # A world-frame model on one frame: refused without its pose; with --trajectory --frame it scores
    # exactly as that frame's row of eval --sequence.
    k = frames - 1
    err_p = run(["eval", seq] + frame_args(d, k, ext) + intr, expect=2)
    check("world coordinates" in err_p.stderr and "--frame" in err_p.stderr and err_p.stdout == "",
          "eval of a world-frame model without a pose: %r" % err_p.stderr)
    one = run_json(["eval", seq] + frame_args(d, k, ext) + intr + ["--trajectory", traj, "--frame", k])
    row = rows[k] if len(rows) > k else {}
    for key in ("n_points", "psnr", "depth_mae", "pixel_psnr", "depth_mae_heldout", "empty_share_heldout",
                "log_likelihood_heldout"):
        check(key in row and one.get(key) == row.get(key),
              "eval --trajectory --frame %d: %s = %s, eval --sequence row %s" % (k, key, one.get(key), row.get(key)))
    run(["eval", seq] + frame_args(d, k, ext) + intr + ["--trajectory", traj], expect=2)
    run(["eval", seq] + frame_args(d, k, ext) + intr + ["--trajectory", traj, "--frame", 99], expect=2)
    out = os.path.join(tmp, "view.png")
    run(["render", seq, "--trajectory", traj, "--frame", frames - 1, "-o", out])
    img = read_png(out)
    check((img > 0).mean() > 0.6, "render --trajectory: only %.2f of the pixels covered" % (img > 0).mean())


def mode_synthetic(tmp):
    d = write_synthetic(tmp, 1)
    intr = ["--intrinsics", os.path.join(d, "intrinsics.json")]
    exercise_frame(tmp, d, "png", 10, 0.05, intr, 64, 48, 12.0)
    # fixed-K fit and explicit camera flags
    model = os.path.join(tmp, "k.sogmm")
    fit = run_json(["fit"] + frame_args(d, 0, "png") + ["--fx", 525, "--fy", 525, "--cx", 319.5, "--cy", 239.5,
                                                        "--decimate", 10, "--components", 20, "-o", model])
    check(fit.get("n_components") == 20, "fit --components 20 gave %s" % fit.get("n_components"))


def mode_sequence(tmp):
    d = write_synthetic(tmp, 3)
    exercise_sequence(tmp, d, "png", 3, 10, 0.05, [], False)
    # --warm-start: each frame starts from the previous one moved by the
    # relative pose; the map scores every frame about as well as the cold map.
    traj = os.path.join(d, "trajectory.log")
    scores = []
    for extra in ([], ["--warm-start"]):
        out = os.path.join(tmp, "seq%d.sogmm" % len(extra))
        run(["fit", "--sequence", d, "--trajectory", traj, "--decimate", 10, "--bandwidth", 0.05, "-o", out,
             "--quiet"] + extra)
        ev = run_json(["eval", out, "--sequence", d, "--trajectory", traj])
        scores.append([r["psnr"] for r in ev.get("frames", [])])
    check(len(scores[1]) == 3 and all(w > c - 1.0 for w, c in zip(scores[1], scores[0])),
          "fit --sequence --warm-start: per-frame PSNR %r vs cold %r" % (scores[1], scores[0]))


def write_png16(path, img):
    """A 16-bit gray PNG (filter 0 on every row)."""
    h, w = img.shape
    raw = b"".join(b"\x00" + img[y].astype(">u2").tobytes() for y in range(h))

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)

    open(path, "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 16, 0, 0, 0, 0)) +
                          chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def mode_map(tmp):
    """sogmm map on a short room loop: CSV, plot, fewer components than
    append-everything, eval --sequence on the result, one-line errors."""
    d = os.path.join(tmp, "loop")
    n = 16
    p = run(["demo", "--write-frame", d, "--loop", "--frames", n])
    check("Wrote %d" % n in p.stdout, "demo --loop: %r" % p.stdout)
    traj = os.path.join(d, "trajectory.log")
    lines = open(traj).read().split("\n")
    first, last = [np.array(" ".join(lines[b + 1:b + 5]).split(), dtype=float) for b in (0, 5 * (n - 1))]
    check(np.abs(first - last).max() < 1e-12, "demo --loop: the last pose is not the first")
    base = ["--trajectory", traj, "--decimate", 10, "--bandwidth", 0.05]
    out = os.path.join(tmp, "loop.sogmm")
    summary, progress = run_json(["map", d] + base + ["-o", out, "--progress"], with_stderr=True)
    check(progress.count("novel") >= n, "map --progress: one line per frame expected: %r" % progress[-500:])
    rows = open(os.path.join(tmp, "loop.csv")).read().strip().split("\n")
    check(rows[0] == "frame,points,novel_points,components,pending,flushed,ms_novelty,ms_fit,ms_merge,replaced,"
          "pose,inlier_ratio,registration_ll",
          "map CSV header: %r" % rows[0])
    check(len(rows) == n + 1, "map CSV: %d rows for %d frames" % (len(rows) - 1, n))
    table = [r.split(",") for r in rows[1:]]
    check([int(r[0]) for r in table] == list(range(n)), "map CSV frame column")
    check(all(int(r[2]) <= int(r[1]) for r in table), "map CSV: more novel points than points")
    # A refit replaces components that exist: never more than the map held before the frame.
    check(all(int(r[9]) <= int(p[3]) for p, r in zip(table, table[1:])) and int(table[0][9]) == 0,
          "map CSV: a frame replaced more components than the map had")
    check(int(table[0][2]) == int(table[0][1]), "map CSV: the first frame is all novel")
    # The last frame revisits the first: almost nothing of it is new.
    check(int(table[-1][2]) < 0.2 * int(table[-1][1]), "map CSV: the loop's last frame is %s/%s novel" %
          (table[-1][2], table[-1][1]))
    svg = open(os.path.join(tmp, "loop.svg")).read()
    check(svg.startswith("<svg") and svg.count("<polyline") == 5, "map plot: not an SVG with 5 lines")
    seq = os.path.join(tmp, "append.sogmm")
    fit = run_json(["fit", "--sequence", d, "-o", seq] + base)
    check(0 < summary.get("n_components", 0) < fit.get("n_components", 0),
          "map: %s components, append-everything %s" % (summary.get("n_components"), fit.get("n_components")))
    # --no-novelty is append-everything: the same components as fit --sequence.
    same = run_json(["map", d, "--no-novelty", "-o", os.path.join(tmp, "same.sogmm")] + base)
    check(same.get("n_components") == fit.get("n_components") and same.get("support_size") == fit.get("support_size"),
          "map --no-novelty %s vs fit --sequence %s" % (same, fit))
    # The map scores each frame about as well as append-everything does.
    ev_map, ev_all = [run_json(["eval", m, "--sequence", d, "--trajectory", traj, "--frames", "0:%d:5" % n])
                      .get("frames", []) for m in (out, seq)]
    check(len(ev_map) == 4 and len(ev_all) == 4, "eval --sequence on the map: %d rows" % len(ev_map))
    for r, a in zip(ev_map, ev_all):
        check(r["psnr"] > a["psnr"] - 2.0 and r["fscore"] > 0.6 * a["fscore"],
              "eval --sequence frame %d: map PSNR %.2f F %.3f, append-everything PSNR %.2f F %.3f" %
              (r["frame"], r["psnr"], r["fscore"], a["psnr"], a["fscore"]))
    query_map(tmp, d, out, lines)
    # Without --trajectory each pose is registered to the map from a
    # constant-velocity guess: on the first 10 frames of the 300-frame loop
    # (1.2 degrees apart; the 16-frame loop's 22.5 degrees are beyond the
    # registration's reach) every frame is inserted and the estimated poses
    # (relative to the first) are within 1 cm of the truth.
    slow = os.path.join(tmp, "loop300")
    run(["demo", "--write-frame", slow, "--loop"])
    lines = open(os.path.join(slow, "trajectory.log")).read().split("\n")
    est_log = os.path.join(tmp, "estimated.log")
    est = run_json(["map", slow, "--frames", "0:10", "-o", os.path.join(tmp, "est.sogmm"), "--trajectory-out", est_log])
    check(est.get("n_skipped") == 0 and est.get("n_frames") == 10, "map without a trajectory: %r" % est)
    blocks = open(est_log).read().split("\n")
    truth = [np.array(" ".join(lines[5 * k + 1:5 * k + 5]).split(), dtype=float).reshape(4, 4) for k in range(10)]
    poses = [np.array(" ".join(blocks[5 * k + 1:5 * k + 5]).split(), dtype=float).reshape(4, 4)
             for k in range(len(blocks) // 5)]
    check(len(poses) == 10, "--trajectory-out: %d poses for 10 frames" % len(poses))
    ate = max([np.linalg.norm((np.linalg.inv(truth[0]) @ t)[:3, 3] - e[:3, 3]) for t, e in zip(truth, poses)] + [0])
    check(ate <= 0.01, "map without a trajectory: largest position error %.4f m" % ate)
    # --registration-depth-noise reaches the registration (other poses; the
    # loop's exact depth needs none, but 10 frames stay within 1 cm).
    noisy_est_log = os.path.join(tmp, "estimated_noise.log")
    run_json(["map", slow, "--frames", "0:10", "--registration-depth-noise", 0.001, "-o",
              os.path.join(tmp, "est_noise.sogmm"), "--trajectory-out", noisy_est_log])
    blocks = open(noisy_est_log).read().split("\n")
    noisy_poses = [np.array(" ".join(blocks[5 * k + 1:5 * k + 5]).split(), dtype=float).reshape(4, 4)
                   for k in range(len(blocks) // 5)]
    check(len(noisy_poses) == 10 and any(not np.array_equal(a, b) for a, b in zip(poses, noisy_poses)),
          "--registration-depth-noise changed no pose")
    ate = max(np.linalg.norm((np.linalg.inv(truth[0]) @ t)[:3, 3] - e[:3, 3]) for t, e in zip(truth, noisy_poses))
    check(ate <= 0.01, "map --registration-depth-noise 0.001: largest position error %.4f m" % ate)
    # --refine-poses: the same frames with a trajectory off by 3 cm and 1
    # degree per frame (seeded) are registered from those poses and land
    # within 1 cm of the truth; without it they stay 3 cm off.
    rng = np.random.default_rng(4)
    noisy_log = os.path.join(tmp, "noisy.log")
    with open(noisy_log, "w") as f:
        for k in range(6):
            a = math.radians(1.0)
            turn = np.array([[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]])
            p = truth[k].copy()
            if k > 0:
                p[:3, :3] = p[:3, :3] @ turn
                p[:3, 3] += 0.03 * rng.choice([-1.0, 1.0], size=3) / math.sqrt(3)
            f.write("%d %d %d\n" % (k, k, k + 1) + "".join(" ".join("%.17g" % v for v in row) + "\n" for row in p))
    refined_log = os.path.join(tmp, "refined.log")
    ref = run_json(["map", slow, "--frames", "0:6", "--trajectory", noisy_log, "--refine-poses", "-o",
                    os.path.join(tmp, "refined.sogmm"), "--trajectory-out", refined_log])
    check(ref.get("n_skipped") == 0 and ref.get("n_frames") == 6, "map --refine-poses: %r" % ref)
    blocks = open(refined_log).read().split("\n")
    refined = [np.array(" ".join(blocks[5 * k + 1:5 * k + 5]).split(), dtype=float).reshape(4, 4) for k in range(6)]
    worst = max(np.linalg.norm(t[:3, 3] - e[:3, 3]) for t, e in zip(truth, refined))
    check(worst <= 0.01, "map --refine-poses: largest position error %.4f m (given poses 0.03 m off)" % worst)
    err_ref = run(["map", slow, "--frames", "0:2", "--refine-poses", "-o", os.path.join(tmp, "x.sogmm")], expect=2)
    check("--refine-poses" in err_ref.stderr, "map --refine-poses without --trajectory: %r" % err_ref.stderr)
    no_temp_files(tmp)

    def err(args, code, names):
        p = run(args, expect=code)
        check(len(p.stderr.strip().splitlines()) == 1, "sogmm %s: expected one error line, got %r" %
              (" ".join(map(str, args)), p.stderr))
        check(names in p.stderr, "sogmm %s: error does not name %s: %r" % (" ".join(map(str, args)), names, p.stderr))

    bad = os.path.join(tmp, "bad")
    os.makedirs(bad)
    for sub in ("depth", "color"):
        os.makedirs(os.path.join(bad, sub))
        for k in range(3):
            name = "%05d.png" % k
            open(os.path.join(bad, sub, name), "wb").write(open(os.path.join(d, sub, name), "rb").read())
    open(os.path.join(bad, "intrinsics.json"), "w").write(open(os.path.join(d, "intrinsics.json")).read())
    m = os.path.join(tmp, "bad.sogmm")
    badargs = ["--decimate", 10, "--bandwidth", 0.05, "-o", m]
    nan = os.path.join(tmp, "nan.log")
    open(nan, "w").write("0 0 1\n1 0 0 nan\n0 1 0 0\n0 0 1 0\n0 0 0 1\n")
    err(["map", bad, "--trajectory", nan] + badargs, 3, "nan.log")
    scaled = os.path.join(tmp, "scaled.log")
    open(scaled, "w").write("0 0 1\n2 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n")
    err(["map", bad, "--trajectory", scaled] + badargs, 3, "scaled.log")
    err(["map", bad, "--trajectory", os.path.join(tmp, "none.log")] + badargs, 4, "none.log")
    err(["map", bad, "--trajectory", traj, "--threshold", "nan"] + badargs, 2, "threshold")
    err(["map", bad, "--trajectory", traj, "--trajectory-out", traj] + badargs, 2, "trajectory")  # would replace an input
    err(["map", bad, "--trajectory", traj, "--batch", 0] + badargs, 2, "batch")
    err(["map", bad, "--registration-depth-noise", 2] + badargs, 2, "depth_noise")
    write_png16(os.path.join(bad, "depth", "00001.png"), np.zeros((480, 640), np.uint16))
    err(["map", bad, "--trajectory", traj] + badargs, 3, "00001.png")  # empty frame
    write_png16(os.path.join(bad, "depth", "00001.png"), np.full((240, 320), 1500, np.uint16))
    err(["map", bad, "--trajectory", traj] + badargs, 3, "00001.png")  # another size
    os.remove(os.path.join(bad, "color", "00002.png"))
    err(["map", bad, "--trajectory", traj] + badargs, 3, "color")  # 3 depth images, 2 color
    check(not os.path.exists(m), "a failed map run wrote %s" % m)
    no_temp_files(tmp)


def mode_deltas(tmp):
    """sogmm map --deltas writes one delta per fitting insert, names that
    sort; sogmm apply-deltas rebuilds the map bit for bit (sogmm-inspect
    --components of both) and refuses a gap with one line naming the file."""
    d = os.path.join(tmp, "loop")
    run(["demo", "--write-frame", d, "--loop", "--frames", 6])
    base = ["--trajectory", os.path.join(d, "trajectory.log"), "--decimate", 10, "--bandwidth", 0.05, "--batch", 400]
    out, deltas = os.path.join(tmp, "loop.sogmm"), os.path.join(tmp, "deltas")
    summary = run_json(["map", d] + base + ["-o", out, "--deltas", deltas])
    names = sorted(os.listdir(deltas))
    check(len(names) == summary.get("n_deltas") and len(names) >= 2, "map --deltas: %s for %s" % (names, summary))
    revisions = [int(n[len("delta-"):-len(".sogmm")]) for n in names]
    check(revisions == sorted(revisions) and revisions[-1] >= 6, "delta names do not sort by revision: %s" % names)
    rebuilt = os.path.join(tmp, "rebuilt.sogmm")
    r = run_json(["apply-deltas", deltas, "-o", rebuilt])
    check(r.get("n_deltas") == len(names) and r.get("n_components") == summary.get("n_components"),
          "apply-deltas: %s vs map %s" % (r, summary))
    inspect = os.path.join(os.path.dirname(SOGMM), "..", "sogmm-inspect", "sogmm-inspect")
    if os.path.exists(inspect):
        comps = [subprocess.run([inspect, "--components", f], stdout=subprocess.PIPE, text=True).stdout
                 for f in (out, rebuilt)]
        check(comps[0] == comps[1] and comps[0].count("component") == summary.get("n_components"),
              "apply-deltas: the rebuilt components differ from the map's")
        v = subprocess.run([inspect, "--verify", os.path.join(deltas, names[0])], stdout=subprocess.PIPE, text=True)
        check(v.returncode == 0 and "map delta" in v.stdout, "sogmm-inspect --verify on a delta: %r" % v.stdout)
    # From a base map: the sender's final map already holds every delta.
    p = run(["apply-deltas", deltas, "-o", os.path.join(tmp, "none.sogmm"), "--base", out], expect=2)
    check("no delta after revision %d" % revisions[-1] in p.stderr, "apply-deltas --base: %r" % p.stderr)
    # A gap: the second delta missing. Nothing is written.
    os.remove(os.path.join(deltas, names[1]))
    p = run(["apply-deltas", deltas, "-o", os.path.join(tmp, "gap.sogmm")], expect=3)
    check(names[2 if len(names) > 2 else 1] in p.stderr or "missing" in p.stderr, "apply-deltas gap: %r" % p.stderr)
    check(not os.path.exists(os.path.join(tmp, "gap.sogmm")), "apply-deltas wrote a map after a gap")


def query_map(tmp, d, map_path, traj_lines):
    """sogmm query on the loop map against what the frames show: frame 0's
    observed surface (back-projected with its pose) is occupied and within
    2 cm of the surface, points halfway along the same rays are free and
    farther, points 1 km away are unknown (exactly 0.5), 1 km from the
    surface and collision-free; CSV and .npy give the same numbers; bad
    input gets one line and the documented exit code."""
    depth = read_png(os.path.join(d, "depth", "00000.png")).astype(float) / 1000.0
    intr = json.load(open(os.path.join(d, "intrinsics.json")))
    k = intr["intrinsic_matrix"]
    fx, fy, cx, cy = k[0], k[4], k[6], k[7]
    pose = np.array(" ".join(traj_lines[1:5]).split(), dtype=float).reshape(4, 4)
    v, u = np.mgrid[40:440:40, 40:600:40]
    z = depth[v, u]
    ok = (z > 0.2) & (z < 2.9)
    u, v, z = u[ok], v[ok], z[ok]
    cam = np.stack([(u - cx) / fx * z, (v - cy) / fy * z, z, np.ones_like(z)])
    surface = (pose @ cam)[:3].T
    half = (pose @ np.vstack([cam[:3] * 0.5, np.ones_like(z)]))[:3].T
    far = surface + np.array([1000.0, 0, 0])
    pts = np.vstack([surface, half, far]).astype(np.float32)  # what the tool reads, from both files
    n = len(surface)
    check(n > 50, "query: only %d valid pixels on the sampling grid" % n)
    csv_in = os.path.join(tmp, "probes.csv")
    with open(csv_in, "w") as f:
        f.write("x,y,z\n# frame 0: surface, halfway, 1 km away\n")
        for x in pts:
            f.write("%.9g, %.9g\t%.9g\n" % tuple(x))
    npy_in = os.path.join(tmp, "probes.npy")
    np.save(npy_in, np.asfortranarray(pts))  # column-major, as NumPy often writes
    args = ["--occupancy", "--gradient", "--robot-radius", 0.05]
    p = run(["query", map_path, "--points", csv_in, "-o", os.path.join(tmp, "answers.csv")] + args)
    check("Wrote" in p.stdout and "%d points" % len(pts) in p.stdout, "query: %r" % p.stdout)
    rows = open(os.path.join(tmp, "answers.csv")).read().strip().split("\n")
    check(rows[0] == "x,y,z,p_occupied,state,distance,gx,gy,gz,p_collision", "query CSV header: %r" % rows[0])
    a = np.array([r.split(",") for r in rows[1:]], dtype=float)
    run(["query", map_path, "--points", npy_in, "-o", os.path.join(tmp, "answers.npy")] + args)
    b = np.load(os.path.join(tmp, "answers.npy"))
    check(a.shape == b.shape == (len(pts), 10) and np.array_equal(a, b), "query: CSV and .npy answers differ")
    s, h, f = a[:n], a[n:2 * n], a[2 * n:]
    check(np.mean(s[:, 4] == 1) > 0.9, "query: %.2f of frame 0's surface points occupied" % np.mean(s[:, 4] == 1))
    check(np.median(s[:, 5]) < 0.02, "query: surface points %.4f m from the surface" % np.median(s[:, 5]))
    check(np.mean(h[:, 4] == 0) > 0.95 and np.all(h[:, 3] < 0.5), "query: halfway points not free")
    check(np.all(h[:, 5] > s[:, 5]), "query: a halfway point is nearer the surface than its surface point")
    check(np.all(f[:, 3] == 0.5) and np.all(f[:, 4] == 2), "query: points 1 km away not unknown")
    check(np.all(f[:, 5] > 990) and np.allclose(np.linalg.norm(f[:, 6:9], axis=1), 1), "query: far distance/gradient")
    check(np.all(f[:, 9] == 0) and np.mean(s[:, 9] > 0.99) > 0.9, "query: collision at far / surface points")
    # The picture: a slice with free, occupied and unknown cells beside the view.
    png = os.path.join(tmp, "occupancy.png")
    p = run(["render", map_path, "--occupancy", "-o", png])
    img = read_png(png)
    r, g, b = [img[..., k].astype(int) for k in range(3)]
    for name, cells in (("free", (g > r + 40) & (g > b + 40)), ("occupied", (r > 150) & (g < 120)),
                        ("unknown", (r == 128) & (g == 128) & (b == 128))):
        check(cells.sum() > 20, "render --occupancy: %d %s pixels" % (cells.sum(), name))
    check("% free" in p.stdout and "unknown" in p.stdout, "render --occupancy: %r" % p.stdout)
    bad = os.path.join(tmp, "bad_points.csv")
    with open(bad, "w") as f2:
        f2.write("0 0 1\n0 nope 1\n")
    for q_args, code, name in ((["--points", bad, "--distance"], 3, "bad_points.csv:2"),
                               (["--points", csv_in], 2, "--occupancy"),
                               (["--points", os.path.join(tmp, "absent.csv"), "--distance"], 4, "absent.csv")):
        p = run(["query", map_path, "-o", os.path.join(tmp, "q.csv")] + q_args, expect=code)
        check(len(p.stderr.strip().splitlines()) == 1 and name in p.stderr, "query %s: %r" % (q_args, p.stderr))


def mode_errors(tmp):
    d = write_synthetic(tmp, 1)
    intr = ["--intrinsics", os.path.join(d, "intrinsics.json")]
    fa = frame_args(d, 0, "png")
    model = os.path.join(tmp, "ok.sogmm")
    run(["fit"] + fa + intr + ["--decimate", 10, "--components", 5, "-o", model, "--quiet"])

    def err(args, code, names):
        p = run(args, expect=code)
        lines = p.stderr.strip().splitlines()
        check(len(lines) == 1, "sogmm %s: expected one error line, got %r" % (" ".join(map(str, args)), p.stderr))
        if names:
            check(names in p.stderr, "sogmm %s: error does not name %s: %r" % (" ".join(map(str, args)), names, p.stderr))

    missing = os.path.join(tmp, "missing.png")
    nodir = os.path.join(tmp, "no", "such", "out.sogmm")
    # usage: 2
    err([], 2, None)
    err(["fit", "--bogus-flag"] + fa + ["-o", model], 2, None)
    err(["fit"] + fa + intr + ["--bandwidth", 0.02, "--components", 5, "-o", model], 2, None)
    err(["fit"] + fa + intr + ["--bandwidth", -1, "-o", model], 2, "bandwidth")
    err(["fit"] + fa + ["-o", model], 2, "--intrinsics")
    err(["fit", "--sequence", d, "-o", model], 2, "--trajectory")
    err(["fit", "--sequence", d, "--trajectory", os.path.join(d, "trajectory.log"), "--frames", "3:9", "-o", model],
        2, "--frames")
    err(["fit"] + fa + intr + ["--warm-start", "-o", model], 2, "--warm-start")
    for reg in (-1, "-1e-9", "nan", "inf", "autox", "1e-6x"):  # --reg-covar auto|VALUE >= 0
        err(["fit"] + fa + intr + ["--reg-covar", reg, "-o", model], 2, "--reg-covar")
    for reg, expect in ((None, (1e-6, 1e-6, "auto")), ("auto", (1e-6, 1e-6, "auto")), (2e-4, (2e-4, 2e-4, "user"))):
        extra = ["--reg-covar", reg] if reg is not None else []
        j = run_json(["fit"] + fa + intr + ["--decimate", 10, "--components", 5, "-o", model, "--quiet"] + extra)
        got = (j["reg_covar"], j["reg_covar_gray"], j["reg_covar_source"])
        check(got == expect, "fit --reg-covar %s: recorded %r, expected %r" % (reg, got, expect))
    err(["eval", model] + fa + ["--bandwidth", 0.02], 2, "--bandwidth")
    err(["eval", model] + fa + ["--n-init", 3], 2, "--n-init")
    err(["eval", model], 2, "--depth")
    err(["render", model, "--compare", "-o", os.path.join(tmp, "x.png")], 2, "--depth")
    err(["sample", model], 2, "-o")
    err(["sample", model, "-n", 0, "-o", os.path.join(tmp, "x.ply")], 2, "-n")
    # I/O: 4
    err(["fit", "--depth", missing, fa[2], fa[3]] + intr + ["-o", model], 4, missing)
    err(["fit"] + fa + intr + ["--components", 5, "-o", nodir], 4, nodir)
    err(["eval", os.path.join(tmp, "missing.sogmm")] + fa, 4, "missing.sogmm")
    err(["render", model, "-o", os.path.join(tmp, "no", "x.png")], 4, "x.png")
    err(["sample", model, "-n", 10, "-o", os.path.join(tmp, "no", "x.ply")], 4, "x.ply")
    err(["fit", "--sequence", os.path.join(tmp, "nosuchdir"), "--trajectory", os.path.join(d, "trajectory.log"),
         "-o", model], 4, "nosuchdir")
    # invalid data: 3
    bad = os.path.join(tmp, "bad.sogmm")
    open(bad, "wb").write(b"this is not a model at all" * 10)
    err(["eval", bad] + fa, 3, "bad.sogmm")
    err(["sample", bad, "-o", os.path.join(tmp, "x.ply")], 3, "bad.sogmm")
    err(["render", bad, "-o", os.path.join(tmp, "x.png")], 3, "bad.sogmm")
    trunc = os.path.join(tmp, "trunc.sogmm")
    open(trunc, "wb").write(open(model, "rb").read()[:-20])
    err(["eval", trunc] + fa, 3, "trunc.sogmm")
    err(["fit"] + fa + intr + ["--depth-max", 0.2, "--components", 5, "-o", model], 3, fa[1])  # no valid depth
    cmp_png = os.path.join(tmp, "cmp.png")
    run(["render", model, "--compare"] + fa + ["-o", cmp_png])
    err(["fit", "--depth", cmp_png, "--color", cmp_png] + intr + ["-o", model], 3, "cmp.png")  # 3-channel depth
    badtraj = os.path.join(tmp, "bad.log")
    open(badtraj, "w").write("0 0 1\n1 0 0 0\n0 1 0 0\n")
    err(["eval", model, "--sequence", d, "--trajectory", badtraj], 3, "bad.log")
    notrigid = os.path.join(tmp, "scaled.log")
    open(notrigid, "w").write("0 0 1\n2 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n")
    err(["fit", "--sequence", d, "--trajectory", notrigid, "--components", 5, "-o", model], 3, "scaled.log")
    small = os.path.join(tmp, "small.png")
    run(["render", model, "-o", small])  # 64x48 gray PNG, not a 640x480 frame
    err(["fit", "--depth", fa[1], "--color", small] + intr + ["-o", model], 3, "small.png")
    # A failed run leaves the previous output untouched and no temporary file.
    before = open(model, "rb").read()
    run(["fit"] + fa + intr + ["--bandwidth", -1, "-o", model], expect=2)
    run(["fit"] + fa + intr + ["--n-init", 0, "-o", model], expect=2)
    run(["fit", "--depth", missing, fa[2], fa[3]] + intr + ["-o", model], expect=4)
    check(open(model, "rb").read() == before, "a failed fit modified the existing output")
    no_temp_files(tmp)


def mode_shared(tmp, data):
    room = os.path.join(data, "rgbd", "livingroom")
    if not os.path.isdir(room):
        print("SKIP: %s is absent (the real frames live in ../shared/data)" % room)
        return "skip"
    intr = ["--intrinsics", os.path.join(room, "intrinsics.json")]
    exercise_frame(tmp, room, "jpg", 8, 0.04, intr, 80, 60, 22.0)
    exercise_sequence(tmp, room, "jpg", 3, 10, 0.05, [], True)
    tum = os.path.join(data, "rgbd", "tum")
    if os.path.isdir(tum):
        model = os.path.join(tmp, "tum.sogmm")
        fa = ["--depth", os.path.join(tum, "depth.png"), "--color", os.path.join(tum, "color.png")]
        fit = run_json(["fit"] + fa + ["--intrinsics", os.path.join(tum, "intrinsics.json"), "--depth-scale", 5000,
                                       "--decimate", 10, "--bandwidth", 0.05, "-o", model])
        ev = run_json(["eval", model] + fa)  # depth scale and decimation come from the file
        check(ev.get("n_points") == fit.get("n_points") and ev.get("psnr", 0) > 15,
              "tum: eval MODEL took the wrong depth scale/decimation: %s vs %s" % (ev, fit))


def main():
    global SOGMM
    ap = argparse.ArgumentParser()
    ap.add_argument("--sogmm", required=True)
    ap.add_argument("--data", required=True)
    # Every mode but "shared" (which needs the data folder) takes only the scratch folder.
    modes = {"help": mode_help, "errors": mode_errors, "synthetic": mode_synthetic, "sequence": mode_sequence,
             "map": mode_map, "deltas": mode_deltas}
    ap.add_argument("--mode", required=True, choices=list(modes) + ["shared"])
    a = ap.parse_args()
    SOGMM = a.sogmm
    with tempfile.TemporaryDirectory(prefix="sogmm_cli_test_") as tmp:
        if a.mode in modes:
            modes[a.mode](tmp)
        elif mode_shared(tmp, a.data) == "skip":
            return 0
    if FAILURES:
        print("%d check(s) failed" % len(FAILURES))
        return 1
    print("OK: %s" % a.mode)
    return 0


if __name__ == "__main__":
    sys.exit(main())
