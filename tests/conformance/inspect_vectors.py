"""sogmm-inspect against every conformance vector: `--json` of a valid vector
equals its dump, `--verify` of an invalid one exits 3 naming its reason, and
`--verify` of a valid one prints "ok" (spec/format.md section 12); the map
delta files of deltas/manifest.json verify as deltas, or are rejected for the
reason their case names.

    python3 inspect_vectors.py --inspect PATH --vectors spec/conformance
"""
import argparse
import json
import pathlib
import subprocess
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--inspect", required=True)
    ap.add_argument("--vectors", required=True)
    a = ap.parse_args()
    root = pathlib.Path(a.vectors)
    failures = 0
    vectors = json.loads((root / "manifest.json").read_text())["vectors"]
    for v in vectors:
        path = str(root / v["file"])
        verify = subprocess.run([a.inspect, "--verify", path], capture_output=True, text=True, timeout=60)
        if v["expect"] == "valid":
            dump = subprocess.run([a.inspect, "--json", path], capture_output=True, text=True, timeout=60)
            ok = (verify.returncode == 0 and dump.returncode == 0
                  and json.loads(dump.stdout) == json.loads((root / v["json"]).read_text()))
        else:
            ok = verify.returncode == 3 and verify.stdout.startswith(f"invalid: {v['reason']}:")
        if not ok:
            failures += 1
            print(f"FAIL {v['file']}: --verify exit {verify.returncode}: {verify.stdout.strip()[:200]}")
    print(f"{len(vectors) - failures}/{len(vectors)} vectors agree with sogmm-inspect")
    # Map deltas (section 2.5): every delta a chain applies verifies as one; a
    # refused case with a reason is a file a delta reader rejects for it.
    cases = json.loads((root / "deltas" / "manifest.json").read_text())["cases"]
    checks = {name: None for c in cases for name in c["apply"]}
    checks.update({c["then"]: c["reason"] for c in cases if "reason" in c})
    for name, reason in sorted(checks.items()):
        verify = subprocess.run([a.inspect, "--verify", str(root / "deltas" / name)], capture_output=True, text=True,
                                timeout=60)
        ok = (verify.returncode == 0 and verify.stdout == "ok (map delta)\n" if reason is None else
              verify.returncode == 3 and verify.stdout.startswith(f"invalid: {reason}:"))
        if not ok:
            failures += 1
            print(f"FAIL deltas/{name}: --verify exit {verify.returncode}: {verify.stdout.strip()[:200]}")
    print(f"{len(checks)} delta files checked with sogmm-inspect")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
