#!/usr/bin/env python3
"""`sogmm fit` and Ctrl-C: SIGINT about 1 s into a long d = 1 fit cancels it
through the progress mechanism: exit 130, one line on stderr, no output file
(and no temporary file left in its folder), and the fit was still running
(its EM is configured to run minutes: --tol 1e-300 --max-iter 500).

Usage: test_cli_interrupt.py --sogmm PATH. Frame: `sogmm demo --write-frame`
(640 x 480 synthetic scene). Exit 0 = pass, 1 = failure."""
import argparse
import os
import signal
import subprocess
import sys
import tempfile


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sogmm", required=True)
    args = ap.parse_args()
    failures = []
    with tempfile.TemporaryDirectory() as d:
        subprocess.run([args.sogmm, "demo", "--write-frame", d, "--frames", "1"], check=True,
                       stdout=subprocess.DEVNULL)
        depth = [os.path.join(d, "depth", f) for f in sorted(os.listdir(os.path.join(d, "depth")))][0]
        color = [os.path.join(d, "color", f) for f in sorted(os.listdir(os.path.join(d, "color")))][0]
        out_dir = os.path.join(d, "out")
        os.mkdir(out_dir)
        model = os.path.join(out_dir, "m.sogmm")
        p = subprocess.Popen([args.sogmm, "fit", "--depth", depth, "--color", color, "--intrinsics",
                              os.path.join(d, "intrinsics.json"), "--decimate", "1", "--components", "300",
                              "--tol", "1e-300", "--max-iter", "500", "--progress", "-o", model],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        # Wait for the first progress line (the fit has started), then ~1 s.
        first = p.stderr.readline()
        try:
            p.wait(timeout=1.0)
        except subprocess.TimeoutExpired:
            pass
        p.send_signal(signal.SIGINT)
        try:
            out, err = p.communicate(timeout=600)
        except subprocess.TimeoutExpired:
            p.kill()
            out, err = p.communicate()
            failures.append("sogmm fit did not stop after SIGINT")
        lines = [l for l in err.splitlines() if l.startswith("sogmm:")]
        if p.returncode != 130:
            failures.append(f"exit {p.returncode}, expected 130\nstdout: {out}\nstderr: {first}{err}")
        if len(lines) != 1 or "interrupted" not in lines[0] or "nothing written" not in lines[0]:
            failures.append(f"expected one 'sogmm: interrupted ...; nothing written' line, got {lines}")
        if os.listdir(out_dir):
            failures.append(f"files left in the output folder: {os.listdir(out_dir)}")
        if "Fitted" in out:
            failures.append("the fit finished: SIGINT was ignored")
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
