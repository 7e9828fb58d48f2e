#!/usr/bin/env python3
"""sogmm-inspect against hostile files (issue 13, findings 1, 5b, 9).

Usage: inspect_hostile_files.py --inspect PATH --vectors spec/conformance
Checks: strings are printed with control characters escaped; a string that
is not UTF-8 makes every mode exit 3 (no silent U+FFFD in --json); a FIFO is
refused at once (exit 4) instead of blocking; a sparse 4 GiB file whose
metadata length wraps 32 bits exits 3 with bad_header, using little memory.
Exit 0 = pass, 1 = failure.
"""
import argparse
import json
import os
import resource
import struct
import subprocess
import sys
import tempfile

FAILURES = []


def check(cond, what):
    if not cond:
        FAILURES.append(what)
        print("FAIL:", what)


def run(inspect, args, timeout=30, address_space=None):
    """Runs sogmm-inspect; returns (exit code, stdout bytes, stderr text, peak RSS in KiB).
    The peak is the largest of all children so far (RUSAGE_CHILDREN): an upper
    bound of this one's."""
    def limit():
        if address_space:
            resource.setrlimit(resource.RLIMIT_AS, (address_space, address_space))
    p = subprocess.Popen([inspect] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, preexec_fn=limit)
    try:
        out, err = p.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        p.kill()
        p.communicate()
        return None, b"", "timed out after %d s" % timeout, 0
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return p.returncode, out, err.decode("utf-8", "replace"), peak


def raw_controls(text):
    """Control or direction-changing code points that reached the output raw."""
    s = text.decode("utf-8")
    bad = [c for c in s if (ord(c) < 0x20 and c != "\n") or 0x7F <= ord(c) <= 0x9F
           or 0x2028 <= ord(c) <= 0x202E or 0x2066 <= ord(c) <= 0x2069]
    return bad


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--inspect", required=True)
    ap.add_argument("--vectors", required=True)
    a = ap.parse_args()
    valid = os.path.join(a.vectors, "valid")
    invalid = os.path.join(a.vectors, "invalid")

    # Finding 9: escape sequences, CR LF and bidi controls are shown escaped.
    controls = os.path.join(valid, "control_characters.sogmm")
    for mode in ([], ["--metadata"]):
        rc, out, err, _ = run(a.inspect, mode + [controls])
        check(rc == 0, f"{mode} on control_characters: exit {rc} ({err})")
        check(not raw_controls(out), f"{mode}: raw control characters {raw_controls(out)!r} in the output")
        check(b"\\x1b[2J\\x1b[31mred\\x0d\\x0aforged: line\\u202e\\u009b" in out, f"{mode}: escaped value missing")
        check(b"sogmm\\x1b]0;title\\x07" in out, f"{mode}: escaped producer name missing")
    rc, out, err, _ = run(a.inspect, ["--json", controls])
    with open(os.path.join(valid, "control_characters.json")) as f:
        check(rc == 0 and json.loads(out) == json.load(f), "--json of control_characters differs from its dump")

    # Finding 9: not UTF-8 (or NUL) is invalid in every mode, never replaced.
    for name in ("string_not_utf8", "string_nul", "string_surrogate", "shared_strings_over_block"):
        for mode in ([], ["--metadata"], ["--json"], ["--verify"]):
            rc, out, err, _ = run(a.inspect, mode + [os.path.join(invalid, name + ".sogmm")])
            check(rc == 3, f"{mode} on {name}: exit {rc}, expected 3")
            check("bad_metadata" in err or b"bad_metadata" in out, f"{mode} on {name}: no bad_metadata ({err})")
            check("\ufffd".encode() not in out, f"{mode} on {name}: U+FFFD in the output")

    # Finding 10: one verdict for float64 values that float32 cannot hold.
    rc, out, _, _ = run(a.inspect, ["--verify", os.path.join(invalid, "f64_underflows_float32.sogmm")])
    check(rc == 3 and b"not_spd" in out, f"--verify f64_underflows_float32: exit {rc}, {out!r}")

    with tempfile.TemporaryDirectory(prefix="sogmm-inspect-hostile-") as tmp:
        # Finding 5b: nobody writes this FIFO; opening it for reading would block.
        fifo = os.path.join(tmp, "pipe.sogmm")
        os.mkfifo(fifo)
        for mode in (["--verify"], ["--metadata"]):
            rc, out, err, _ = run(a.inspect, mode + [fifo], timeout=20)
            check(rc == 4 and "FIFO" in err + out.decode(), f"{mode} on a FIFO: exit {rc}, {err}{out!r}")

        # Finding 1: metadata_length 0xFFFFFFF9 in a sparse file of 4 GiB + 36
        # bytes (32 + pad8(L) + 4 fits it). The address space is limited to
        # 1 GiB, so a reader that reads the whole file fails instead.
        huge = os.path.join(tmp, "huge.sogmm")
        length = 0xFFFFFFF9
        size = 32 + ((length + 7) & ~7) + 4
        with open(huge, "wb") as f:
            f.write(b"\x89SOG\r\n\x1a\n" + struct.pack("<HHIQII", 1, 0, 0, size, length, 0))
            f.truncate(size)
            f.seek(size - 4)
            f.write(b"SGMM")
        for mode in (["--verify"], ["--metadata"], []):
            rc, out, err, peak_kib = run(a.inspect, mode + [huge], address_space=1 << 30)
            check(rc == 3 and "bad_header" in err + out.decode(), f"{mode} on the 4 GiB header: exit {rc}, {err}{out!r}")
            check(peak_kib < 64 * 1024, f"{mode} on the 4 GiB header: peak RSS {peak_kib} KiB")
        os.unlink(huge)

    print("inspect_hostile_files: %d failure(s)" % len(FAILURES))
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main())
