#!/usr/bin/env python3
"""The files the `sogmm` tool reads and writes (issue 36).

Usage: test_cli_files.py --sogmm PATH
Each check names the finding it guards; all run on a 3-frame synthetic
sequence (`sogmm demo --write-frame DIR --frames 3`) at --decimate 10, so the
whole script takes seconds. Exit 0 = pass, 1 = failure.

- Writers: an output that names a FIFO or a symbolic link (--csv, --plot,
  sample -o) is refused or written through, never replaced; an output that is
  also an input or another output is refused; an output folder that cannot be
  written is found before the run.
- Inputs: a FIFO as --trajectory or --intrinsics is refused at once (map,
  fit --sequence, eval), not waited on.
- Frames and poses: paired by the trajectory's frame numbers and the image
  names; a mismatch is refused unless --pair-by-order.
"""
import argparse
import json
import os
import shutil
import stat
import subprocess
import sys
import tempfile

SOGMM = None
FAILURES = []
TIMEOUT = 60  # a hang detector: every command here ends in seconds


def check(cond, what):
    if not cond:
        FAILURES.append(what)
        print("FAIL:", what)
    return cond


def run(args, expect=0):
    """Runs the tool; a command still running after TIMEOUT counts as a hang."""
    try:
        p = subprocess.run([SOGMM] + [str(a) for a in args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           text=True, timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        check(False, "sogmm %s: still running after %d s (blocked)" % (" ".join(map(str, args)), TIMEOUT))
        return None
    check(p.returncode == expect, "sogmm %s: exit %d, expected %d\nstdout: %s\nstderr: %s" %
          (" ".join(map(str, args)), p.returncode, expect, p.stdout[-1500:], p.stderr[-1500:]))
    if expect != 0:  # one error line (after notes, e.g. eval's about a camera-frame model)
        lines = p.stderr.splitlines()
        check(len(lines) > 0 and lines[-1].startswith("sogmm: error:") and p.stderr.count("sogmm: error:") == 1,
              "sogmm %s: expected one error line, got %r" % (" ".join(map(str, args)), p.stderr))
    return p


def read(path):
    with open(path, "rb") as f:
        return f.read()


def restore(path, data):
    """Puts a file back as it was (a regular file with these bytes)."""
    if os.path.lexists(path) and (os.path.islink(path) or read(path) != data):
        os.remove(path)
    if not os.path.exists(path):
        with open(path, "wb") as f:
            f.write(data)


def write_log(path, blocks):
    """A Redwood .log of (frame id, 16 numbers) blocks, in the given order."""
    with open(path, "w") as f:
        for fid, m in blocks:
            f.write("%d %d %d\n" % (fid, fid + 1, len(blocks)))
            for r in range(4):
                f.write(" ".join(m[4 * r:4 * r + 4]) + "\n")


def read_log(path):
    lines = [s for s in open(path).read().splitlines() if s.strip()]
    return [(int(lines[i].split()[0]), sum((lines[i + r].split() for r in range(1, 5)), []))
            for i in range(0, len(lines), 5)]


def writers(tmp, seq, traj, model):
    base = ["map", seq, "--trajectory", traj, "--decimate", 10, "--bandwidth", 0.05, "-q"]
    # A FIFO named as --csv or sample -o: refused before the run, still a FIFO.
    fifo = os.path.join(tmp, "out.fifo")
    os.mkfifo(fifo)
    p = run(base + ["-o", os.path.join(tmp, "m.sogmm"), "--csv", fifo], expect=4)
    check(p is not None and "FIFO" in p.stderr, "map --csv FIFO: the message does not say why")
    check(stat.S_ISFIFO(os.lstat(fifo).st_mode), "map --csv FIFO: the FIFO was replaced")
    check(not os.path.exists(os.path.join(tmp, "m.sogmm")), "map --csv FIFO: the map was written anyway")
    run(["sample", model, "-n", 100, "-o", fifo], expect=4)
    check(stat.S_ISFIFO(os.lstat(fifo).st_mode), "sample -o FIFO: the FIFO was replaced")

    # A symbolic link named as --plot and sample -o: written through, the link kept.
    target = os.path.join(tmp, "plot_target.svg")
    with open(target, "w") as f:
        f.write("old")
    link = os.path.join(tmp, "plot_link.svg")
    os.symlink(target, link)
    out = os.path.join(tmp, "m.sogmm")
    run(base + ["-o", out, "--plot", link])
    check(os.path.islink(link), "map --plot LINK: the link was replaced by a file")
    check(read(target).startswith(b"<svg") or b"<svg" in read(target)[:200], "map --plot LINK: the target was not written")
    ply_target = os.path.join(tmp, "s_target.ply")
    open(ply_target, "w").close()
    ply_link = os.path.join(tmp, "s_link.ply")
    os.symlink(ply_target, ply_link)
    run(["sample", model, "-n", 100, "-o", ply_link])
    check(os.path.islink(ply_link) and read(ply_target).startswith(b"ply"), "sample -o LINK: not written through")

    # An output that is also an input or another output: refused, nothing touched.
    map_bytes = read(out)
    run(base + ["-o", out, "--csv", out], expect=2)
    check(read(out) == map_bytes, "map --csv equal to -o: the map was overwritten")
    traj_bytes = read(traj)
    run(["fit", "--sequence", seq, "--trajectory", traj, "--decimate", 10, "--components", 3, "-q", "-o", traj],
        expect=2)
    check(read(traj) == traj_bytes, "fit -o equal to --trajectory: the trajectory was overwritten")
    restore(traj, traj_bytes)  # so that a failure here does not spoil the checks after it
    alias = os.path.join(tmp, "traj_alias.log")
    os.symlink(traj, alias)
    run(base + ["-o", alias], expect=2)
    check(read(traj) == traj_bytes and os.path.islink(alias), "map -o LINK-TO-TRAJECTORY: the trajectory was overwritten")
    restore(traj, traj_bytes)
    hard = os.path.join(tmp, "model_hard.sogmm")
    os.link(model, hard)
    model_bytes = read(model)
    run(["sample", model, "-n", 100, "-o", hard], expect=2)
    check(read(model) == model_bytes, "sample -o HARDLINK-TO-MODEL: the model was overwritten")
    restore(model, model_bytes)

    # An output folder that cannot be written: found before the run (no frame
    # is mapped: --progress would print a line per frame).
    folder = unwritable_folder(tmp)
    if folder is None:
        print("SKIP: no unwritable folder for this user (root without a read-only /sys)")
        return
    p = run(base[:-1] + ["--progress", "-o", os.path.join(folder, "m.sogmm")], expect=4)
    check(p is not None and "frame" not in p.stderr and folder in p.stderr,
          "map -o UNWRITABLE/m.sogmm: not refused before the run: %r" % (p.stderr if p else None))


def unwritable_folder(tmp):
    """A folder where creating a file fails: a mode-555 one (not root), else /sys (read-only for root too)."""
    candidates = ["/sys"]
    if os.geteuid() != 0:
        ro = os.path.join(tmp, "ro")
        os.mkdir(ro, 0o555)
        candidates.insert(0, ro)
    for d in candidates:
        try:
            fd, probe = tempfile.mkstemp(dir=d)
        except OSError:
            return d
        os.close(fd)
        os.remove(probe)
    return None


def fifo_inputs(tmp, seq, traj, model):
    fifo = os.path.join(tmp, "in.fifo")
    os.mkfifo(fifo)
    out = os.path.join(tmp, "fifo_out.sogmm")
    for args in (["map", seq, "--trajectory", fifo, "-o", out],
                 ["map", seq, "--trajectory", traj, "--intrinsics", fifo, "-o", out],
                 ["fit", "--sequence", seq, "--trajectory", fifo, "-o", out],
                 ["fit", "--sequence", seq, "--trajectory", traj, "--intrinsics", fifo, "-o", out],
                 ["eval", model, "--sequence", seq, "--trajectory", fifo],
                 ["eval", model, "--sequence", seq, "--trajectory", traj, "--intrinsics", fifo]):
        p = run(args + ["--decimate", 10], expect=4)
        check(p is None or "FIFO" in p.stderr, "sogmm %s: the message does not say FIFO" % " ".join(args))


def pairing(tmp, seq, traj):
    blocks = read_log(traj)
    # Images 00000, 00002, 00004 (the frames of poses 0, 1, 2 renamed) and a
    # log with ids 0, 1, 2: frame 4 has no pose -> refused.
    odd = os.path.join(tmp, "gaps")
    for sub in ("depth", "color"):
        os.makedirs(os.path.join(odd, sub))
        for k in range(3):
            shutil.copy(os.path.join(seq, sub, "%05d.png" % k), os.path.join(odd, sub, "%05d.png" % (2 * k)))
    shutil.copy(os.path.join(seq, "intrinsics.json"), odd)
    out = os.path.join(tmp, "pair.sogmm")
    args = ["fit", "--sequence", odd, "--decimate", 10, "--components", 3, "-q", "--json", "-o", out]
    p = run(args + ["--trajectory", traj], expect=3)
    check(p is not None and "no pose of frame 4" in p.stderr and "--pair-by-order" in p.stderr,
          "images 0,2,4 with poses 0,1,2: the message does not name frame 4 and --pair-by-order")
    run(args + ["--trajectory", traj, "--pair-by-order"])  # asked for: paired by order
    # The same log with ids 0, 2, 4, blocks shuffled: each image gets its own
    # pose, so the map equals the one paired in order (eval LL bitwise).
    shuffled = os.path.join(tmp, "shuffled.log")
    write_log(shuffled, [(2 * k, blocks[k][1]) for k in (2, 0, 1)])
    by_id = os.path.join(tmp, "by_id.sogmm")
    by_order = os.path.join(tmp, "by_order.sogmm")
    run(["fit", "--sequence", odd, "--trajectory", shuffled, "--decimate", 10, "--components", 3, "-q", "-o", by_id])
    run(["fit", "--sequence", odd, "--trajectory", traj, "--pair-by-order", "--decimate", 10, "--components", 3,
         "-q", "-o", by_order])
    scores = []
    for m in (by_id, by_order):  # the per-frame and mean scores (not the file: its metadata names the log)
        p = run(["eval", m, "--sequence", seq, "--trajectory", traj, "--json"])
        j = json.loads(p.stdout) if p else {}
        scores.append((j.get("frames"), j.get("mean"), j.get("n_components")))
    check(bool(scores[0][0]) and scores[0] == scores[1],
          "poses paired by id differ from the same poses paired in order:\n%s\n%s" % tuple(scores))
    # Two poses claiming one frame: refused.
    dup = os.path.join(tmp, "dup.log")
    write_log(dup, [(0, blocks[0][1]), (0, blocks[1][1]), (4, blocks[2][1])])
    p = run(args + ["--trajectory", dup], expect=3)
    check(p is not None and "two poses of frame 0" in p.stderr, "a frame with two poses is not named")


def main():
    global SOGMM
    ap = argparse.ArgumentParser()
    ap.add_argument("--sogmm", required=True)
    SOGMM = os.path.abspath(ap.parse_args().sogmm)
    tmp = tempfile.mkdtemp(prefix="sogmm_cli_files_")
    try:
        seq = os.path.join(tmp, "seq")
        run(["demo", "--write-frame", seq, "--frames", 3])
        traj = os.path.join(seq, "trajectory.log")
        model = os.path.join(tmp, "frame.sogmm")
        run(["fit", "--depth", os.path.join(seq, "depth", "00000.png"), "--color",
             os.path.join(seq, "color", "00000.png"), "--intrinsics", os.path.join(seq, "intrinsics.json"),
             "--decimate", 10, "--components", 3, "-q", "-o", model])
        writers(tmp, seq, traj, model)
        fifo_inputs(tmp, seq, traj, model)
        pairing(tmp, seq, traj)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    if FAILURES:
        print("%d failure(s)" % len(FAILURES))
        return 1
    print("OK")
    return 0


if __name__ == "__main__":
    sys.exit(main())
