#!/usr/bin/env python3
"""`sogmm fit` and Ctrl-C: SIGINT about 1 s into a long d = 1 fit cancels it
through the progress mechanism: exit 130, one line on stderr, no output file
(and no temporary file left in its folder), and the fit was still running
(its EM is configured to run minutes: --tol 1e-300 --max-iter 500).
`sogmm view --serve` and Ctrl-C: the served page is byte for byte the page
-o writes; other paths 404, other methods 405, a foreign Host 403, a
malformed request 400, a port in use exit 4; SIGINT stops it with exit 0.

Usage: test_cli_interrupt.py --sogmm PATH. Frame: `sogmm demo --write-frame`
(640 x 480 synthetic scene). Exit 0 = pass, 1 = failure."""
import argparse
import http.client
import os
import signal
import socket
import subprocess
import sys
import tempfile

VECTOR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "spec", "conformance", "valid",
                      "all_metadata.sogmm")


def request(port, method, path, headers=None):
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    conn.request(method, path, headers=headers or {})
    r = conn.getresponse()
    body = r.read()
    conn.close()
    return r.status, body


def check_serve(sogmm, d, failures):
    page = os.path.join(d, "page.html")
    subprocess.run([sogmm, "view", VECTOR, "-o", page], check=True, stdout=subprocess.DEVNULL)
    with open(page, "rb") as f:
        expected = f.read()
    p = subprocess.Popen([sogmm, "view", VECTOR, "--serve", "--port", "0"], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    try:
        first = p.stdout.readline()  # "serving on http://127.0.0.1:PORT/ ..."
        port = int(first.split("http://127.0.0.1:")[1].split("/")[0])
        status, body = request(port, "GET", "/")
        if status != 200 or body != expected:
            failures.append(f"GET /: {status}, {len(body)} bytes; -o wrote {len(expected)}")
        status, body = request(port, "HEAD", "/index.html")
        if status != 200 or body:
            failures.append(f"HEAD /index.html: {status} with {len(body)} body bytes")
        for method, path, headers, want in [("GET", "/other.html", {}, 404), ("POST", "/", {}, 405),
                                            ("GET", "/", {"Host": "attacker.example"}, 403)]:
            status, _ = request(port, method, path, headers)
            if status != want:
                failures.append(f"{method} {path} {headers}: {status}, expected {want}")
        with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
            s.sendall(b"nonsense\r\n\r\n")
            reply = s.recv(64)
        if not reply.startswith(b"HTTP/1.0 400"):
            failures.append(f"a malformed request got {reply!r}")
        busy = subprocess.run([sogmm, "view", VECTOR, "--serve", "--port", str(port)], capture_output=True,
                              text=True, timeout=30)
        if busy.returncode != 4 or "cannot listen: Address already in use" not in busy.stderr:
            failures.append(f"a second server on port {port}: exit {busy.returncode}, {busy.stderr!r}")
    except (OSError, IndexError, ValueError, http.client.HTTPException) as e:
        failures.append(f"sogmm view --serve: {e!r}")
    p.send_signal(signal.SIGINT)
    try:
        p.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        p.kill()
        p.communicate()
        failures.append("sogmm view --serve did not stop after SIGINT")
    if p.returncode != 0:
        failures.append(f"sogmm view --serve: exit {p.returncode} after SIGINT, expected 0")


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
        check_serve(args.sogmm, d, failures)
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
